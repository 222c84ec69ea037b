//! Property tests of `splitArea` through the interpreter: random simple lots
//! (star-shaped, concave, with and without a hole, turned to any heading)
//! and random absolute / relative / floating / repeated patterns. Every part
//! must measure (`geometry.area`) what `split_layout` assigns it on the lot's
//! area, with `split.index` / `split.total` as laid out, and the parts must
//! add up to what the pattern uses of the lot.

use std::path::PathBuf;

use cga_engine::assets::Assets;
use cga_engine::lot::Lot;
use cga_engine::split_layout::{layout, Size, SplitPattern};
use cga_engine::{generate_lot, GenerateOptions, Program};
use cga_geometry::{DMat3, DVec3, Mesh};
use cga_syntax::SourceMap;
use cga_value::Value;
use proptest::prelude::*;

fn program() -> (Program, Assets) {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/rules/split_area/property.cga");
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
    let assets = Assets::on_disk(&sources);
    (loaded.usable().expect("property.cga loads"), assets)
}

/// A star-shaped ring in the xz plane (counter-clockwise seen from +y unless
/// `clockwise`), jittered evenly spaced angles: simple, usually concave.
fn star(radii: &[f64], jitter: &[f64], center: (f64, f64), clockwise: bool) -> Vec<DVec3> {
    let n = radii.len();
    let step = std::f64::consts::TAU / n as f64;
    let mut pts: Vec<DVec3> = (0..n)
        .map(|i| {
            let a = (i as f64 + jitter[i] / 3.0) * step;
            DVec3::new(
                center.0 + a.cos() * radii[i],
                0.0,
                center.1 - a.sin() * radii[i],
            )
        })
        .collect();
    if clockwise {
        pts.reverse();
    }
    pts
}

/// A hole: radii, angle jitter, centre.
type HoleSpec = (Vec<f64>, Vec<f64>, (f64, f64));

#[derive(Clone, Debug)]
struct LotSpec {
    radii: Vec<f64>,
    jitter: Vec<f64>,
    hole: Option<HoleSpec>,
    heading: f64,
}

impl LotSpec {
    fn lot(&self) -> Lot {
        let turn = DMat3::from_rotation_y(self.heading);
        let mut rings = vec![star(&self.radii, &self.jitter, (0.0, 0.0), false)];
        if let Some((r, j, c)) = &self.hole {
            rings.push(star(r, j, *c, true));
        }
        let mut mesh = Mesh::new();
        let mut loops = Vec::new();
        for ring in &rings {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(ring.iter().map(|&p| turn * p));
            loops.push((base..base + ring.len() as u32).collect::<Vec<u32>>());
        }
        let refs: Vec<&[u32]> = loops.iter().map(|l| l.as_slice()).collect();
        mesh.add_face(&refs, 0);
        Lot {
            name: "random".into(),
            mesh,
            attrs: Vec::new(),
            geo_origin: None,
        }
    }
}

fn lot_strategy() -> impl Strategy<Value = LotSpec> {
    let outer = (5usize..20).prop_flat_map(|n| {
        (
            prop::collection::vec(20.0f64..50.0, n),
            prop::collection::vec(-1.0f64..1.0, n),
        )
    });
    // A hole of radius < 5 within 6 of the centre stays inside the outer
    // ring (which contains the disk of radius 0.7 * 20).
    let hole = (4usize..9).prop_flat_map(|n| {
        (
            prop::collection::vec(2.0f64..5.0, n),
            prop::collection::vec(-1.0f64..1.0, n),
            (-6.0f64..6.0, -6.0f64..6.0),
        )
    });
    (outer, prop::option::of(hole), 0.0f64..std::f64::consts::TAU).prop_map(
        |((radii, jitter), hole, heading)| LotSpec {
            radii,
            jitter,
            hole,
            heading,
        },
    )
}

/// The sizes of the start rule's pattern with the attribute values.
fn pattern(start: &str, along_z: bool, r1: f64, a2: f64, w3: f64, r4: f64) -> SplitPattern {
    match (start, along_z) {
        ("Plain", _) => {
            let mut p = SplitPattern::new(false);
            p.push(Size::Relative(r1));
            p.push(Size::Absolute(a2));
            p.push(Size::Floating(w3));
            p.push(Size::Relative(r4));
            p
        }
        (_, true) => {
            let mut p = SplitPattern::new(false);
            p.push(Size::Absolute(a2));
            p.open();
            p.push(Size::Relative(r1));
            p.push(Size::Floating(w3));
            p.close(true).unwrap();
            p.push(Size::Relative(r4));
            p
        }
        (_, false) => {
            let mut p = SplitPattern::new(true);
            p.push(Size::Relative(r1));
            p.push(Size::Absolute(a2));
            p
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(120))]

    #[test]
    fn parts_measure_what_the_layout_assigns(
        spec in lot_strategy(),
        repeat in any::<bool>(),
        along_z in any::<bool>(),
        r1 in 0.02f64..0.5,
        a2 in 20.0f64..800.0,
        w3 in 0.1f64..3.0,
        r4 in 0.0f64..0.3,
    ) {
        let start = if repeat { "Repeat" } else { "Plain" };
        let (program, assets) = program();
        let rule = program.start_rule(Some(start)).unwrap();
        let mut options = GenerateOptions::default();
        for (name, v) in [
            ("alongZ", Value::Bool(along_z)),
            ("r1", Value::Float(r1)),
            ("a2", Value::Float(a2)),
            ("w3", Value::Float(w3)),
            ("r4", Value::Float(r4)),
        ] {
            options.attrs.push((program.main_attr(name).unwrap(), v));
        }
        let lot = spec.lot();
        let (out, err) = generate_lot(&program, &assets, rule, &lot, 0, &options);
        prop_assert!(err.is_none(), "{:?}", err);
        prop_assert!(out.warnings.is_empty(), "{:?}", out.warnings);

        let total: f64 = out.prints[0].strip_prefix("total ").unwrap().parse().unwrap();
        let want = layout(&pattern(start, along_z, r1, a2, w3, r4), total).unwrap();
        let got: Vec<(usize, usize, f64)> = out.prints[1..]
            .iter()
            .map(|p| {
                let v: Vec<&str> = p.split(' ').collect();
                (v[0].parse().unwrap(), v[1].parse().unwrap(), v[2].parse().unwrap())
            })
            .collect();
        prop_assert_eq!(got.len(), want.len());
        let mut sum = 0.0;
        for (g, w) in got.iter().zip(&want) {
            prop_assert_eq!(g.0, w.index);
            prop_assert_eq!(g.1, want.len());
            // 1e-9 relative; parts below a thousandth of the lot to 1e-12 of the lot.
            let tol = 1e-9 * w.size.max(1e-3 * total);
            prop_assert!(
                (g.2 - w.size).abs() <= tol,
                "part {} measures {} instead of {}", w.index, g.2, w.size
            );
            sum += g.2;
        }
        let used = want.last().map_or(0.0, |p| p.end);
        prop_assert!((sum - used).abs() <= 1e-9 * total);
    }
}
