//! The cut workloads measured by the `cut` benchmark and by
//! `examples/cut_timing.rs` (which includes this file by path).

use cga_geometry::{extrude, primitive, DVec2, DVec3, Extrusion, Mesh};

/// One workload: split `mesh` along `axis` at `cuts`.
pub struct Case {
    pub name: &'static str,
    pub mesh: Mesh,
    pub axis: usize,
    pub cuts: Vec<f64>,
}

/// A 20 x 30 lot extruded by 10: the mass model of a building (6 quads,
/// 8 shared positions).
fn mass() -> Mesh {
    let lot = Mesh::polygon(&[
        DVec3::new(0., 0., 0.),
        DVec3::new(20., 0., 0.),
        DVec3::new(20., 0., -30.),
        DVec3::new(0., 0., -30.),
    ]);
    extrude(&lot, Extrusion::FaceNormal, 10.0)
}

/// The workloads, cheapest first.
pub fn cases() -> Vec<Case> {
    // A facade (a flat quad with UVs in the xy-plane) as CGA's split passes
    // it: cuts at both ends of every tile, so the first and last cut lie on
    // the quad's border.
    let mut facade = Mesh::polygon(&[
        DVec3::new(0., 0., 0.),
        DVec3::new(20., 0., 0.),
        DVec3::new(20., 10., 0.),
        DVec3::new(0., 10., 0.),
    ]);
    facade.uvs[0] = Some(vec![
        DVec2::new(0., 0.),
        DVec2::new(1., 0.),
        DVec2::new(1., 1.),
        DVec2::new(0., 1.),
    ]);
    vec![
        Case {
            name: "box_4",
            mesh: mass(),
            axis: 1,
            cuts: vec![3.0, 6.0, 9.0],
        },
        Case {
            // Floors as CGA's split passes them: both ends included.
            name: "box_12",
            mesh: mass(),
            axis: 1,
            cuts: (0..=12).map(|i| i as f64 * 10.0 / 12.0).collect(),
        },
        Case {
            name: "quad_10",
            mesh: facade,
            axis: 0,
            cuts: (0..=10).map(|i| i as f64 * 2.0).collect(),
        },
        Case {
            name: "cylinder16_20",
            mesh: primitive::cylinder(16, DVec3::new(4.0, 10.0, 4.0)),
            axis: 1,
            cuts: (1..20).map(|i| i as f64 * 0.5).collect(),
        },
        Case {
            name: "sphere4096_50",
            mesh: primitive::sphere(64, 64, DVec3::splat(10.0)),
            axis: 0,
            cuts: (1..50).map(|i| i as f64 * 0.2).collect(),
        },
    ]
}
