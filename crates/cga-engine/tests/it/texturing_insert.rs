//! `insertAlongUV`: the examples of its reference page (repeated assets on
//! a planar shape, a barrier along a street, assets bent over a sphere).

use crate::texturing_common::*;
use cga_geometry::measure::{bounds, volume};
use cga_geometry::{DVec2, DVec3, Mesh};

/// A unit cube asset from (0,0,0) to (1,1,1), faces outwards, with the
/// corner UVs of each face.
const CUBE: &str = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1
vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1
f 1/1 4/2 3/3 2/4
f 5/1 6/2 7/3 8/4
f 1/1 2/2 6/3 5/4
f 4/1 8/2 7/3 3/4
f 1/1 5/2 8/3 4/4
f 2/1 3/2 7/3 6/4
";

fn with_cube(name: &str, rules: &str, lot: &cga_engine::lot::Lot) -> Vec<Mesh> {
    let dir = project(name);
    std::fs::write(dir.join("assets/cube.obj"), CUBE).unwrap();
    let out = run_in(&dir, rules, lot);
    assert!(
        out.warnings
            .iter()
            .all(|w| !w.message.contains("insertAlongUV")),
        "{:?}",
        out.warnings
    );
    out.meshes
}

#[test]
fn repeated_assets_on_a_planar_shape() {
    // Reference: `scaleUV(0, 4.0, 4.0) insertAlongUV(0, "sphere.obj", 2.5)`:
    // 4 x 4 copies, one per uv tile, in one shape.
    let meshes = with_cube(
        "repeat",
        r#"Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0)
                   scaleUV(0, 4, 4) insertAlongUV(0, "cube.obj", 2.5) X."#,
        &rect(20.0, 30.0),
    );
    assert_eq!(meshes.len(), 1);
    let m = &meshes[0];
    assert_eq!(m.faces.len(), 16 * 6);
    let (lo, hi) = bounds(m).unwrap();
    assert!((lo - DVec3::new(0.0, 0.0, -30.0)).length() < 1e-9, "{lo:?}");
    assert!((hi - DVec3::new(20.0, 2.5, 0.0)).length() < 1e-9, "{hi:?}");
    // Each copy is a 5 x 2.5 x 7.5 box.
    let box_area = 2.0 * (5.0 * 7.5 + 5.0 * 2.5 + 7.5 * 2.5);
    assert!((area(m) - 16.0 * box_area).abs() < 1e-6, "{}", area(m));
    // The projection's uvs run clockwise seen from above (u along x, v
    // along z), so the copies are mirrored, and turned to face outwards:
    // the volume is positive. (The copies touch: the mesh is not a closed
    // manifold, but its faces are consistently oriented.)
    assert!(
        (volume(m) - 16.0 * 5.0 * 2.5 * 7.5).abs() < 1e-6,
        "{}",
        volume(m)
    );
    // A full turn leaves rounding noise in the uvs (sin 360° = -2e-16):
    // still 16 copies, no walls of neighbouring tiles on the borders.
    let noisy = with_cube(
        "repeat_noise",
        r#"Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0)
                   scaleUV(0, 4, 4) rotateUV(0, 360) insertAlongUV(0, "cube.obj", 2.5) X."#,
        &rect(20.0, 30.0),
    );
    assert_eq!(noisy[0].faces.len(), 16 * 6);
    assert!((area(&noisy[0]) - 16.0 * box_area).abs() < 1e-6);
    // The asset keeps its own texture coordinates.
    let uvs = m.uvs[0].as_ref().unwrap();
    assert!(uvs
        .iter()
        .all(|t| [0.0, 1.0].contains(&t.x) && [0.0, 1.0].contains(&t.y)));
}

#[test]
fn keep_position_and_negative_height() {
    // An asset reaching from y = -1 to 1: alignPosition puts its bottom on
    // the surface, keepPosition keeps its origin there.
    let dir = project("keep");
    std::fs::write(
        dir.join("assets/post.obj"),
        "v 0 -1 0\nv 1 -1 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let lot = rect(10.0, 10.0);
    let heights = |rules: &str| {
        let out = run_in(&dir, rules, &lot);
        let (lo, hi) = bounds(&out.meshes[0]).unwrap();
        (lo.y, hi.y)
    };
    let base = "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) ";
    assert_eq!(
        heights(&format!("{base} insertAlongUV(0, \"post.obj\", 4) X.")),
        (0.0, 4.0)
    );
    assert_eq!(
        heights(&format!(
            "{base} insertAlongUV(0, \"post.obj\", 4, scope.y, keepPosition) X."
        )),
        (-2.0, 2.0)
    );
    assert_eq!(
        heights(&format!("{base} insertAlongUV(0, \"post.obj\", -3) X.")),
        (-3.0, 0.0)
    );
}

#[test]
fn barrier_along_a_street_band() {
    // Reference (streets): split the street across (v, unitSpace) and
    // insert a barrier along the outer bands with `rotateUV(0, 90)
    // normalizeUV(0, u, collectiveAllFaces) insertAlongUV(0, "barrier.obj",
    // height)`. After the quarter turn u runs across the band and v along
    // the street; u is normalised to [0, 1], so the asset's x spans the band
    // and its z the whole street: one barrier along the street.
    let dir = project("barrier");
    street_asset(&dir, 47.0, 0.0, 47.0, 8.0);
    std::fs::write(dir.join("assets/cube.obj"), CUBE).unwrap();
    let out = run_in(
        &dir,
        r#"Lot --> i("street.obj") split(v, unitSpace, 0) { 0.5 : Barrier | ~1 : Street. | 0.5 : Barrier }
           Barrier --> rotateUV(0, 90) normalizeUV(0, u, collectiveAllFaces) insertAlongUV(0, "cube.obj", 1.2) X."#,
        &rect(47.0, 8.0),
    );
    let barriers: Vec<&Mesh> = out.meshes.iter().filter(|m| m.faces.len() == 6).collect();
    assert_eq!(barriers.len(), 2);
    let (lo, hi) = bounds(barriers[0]).unwrap();
    assert!((lo - DVec3::new(0.0, 0.0, -0.5)).length() < 1e-9, "{lo:?}");
    assert!((hi - DVec3::new(47.0, 1.2, 0.0)).length() < 1e-9, "{hi:?}");
    let (lo, hi) = bounds(barriers[1]).unwrap();
    assert!((lo - DVec3::new(0.0, 0.0, -8.0)).length() < 1e-9, "{lo:?}");
    assert!((hi - DVec3::new(47.0, 1.2, -7.5)).length() < 1e-9, "{hi:?}");
}

#[test]
fn assets_bend_over_a_sphere_along_vertex_normals() {
    // Reference (curved surfaces): `primitiveSphere() scaleUV(0, 10, 10)
    // insertAlongUV(0, "pyramid.obj", 0.5, vertex.normal, alignPosition)`.
    // Flat assets (height 0) stay on the sphere's facets; raised ones rise
    // along the normals, at most 0.5 above the facets.
    let dir = project("sphere");
    std::fs::write(
        dir.join("assets/tile.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 4 3 2\n",
    )
    .unwrap();
    let lot = rect(10.0, 10.0);
    let radius = |rules: &str| -> (usize, f64, f64) {
        let out = run_in(&dir, rules, &lot);
        let m = &out.meshes[0];
        let c = DVec3::new(5.0, 5.0, -5.0);
        let d: Vec<f64> = m.positions.iter().map(|p| p.distance(c)).collect();
        (
            m.faces.len(),
            d.iter().copied().fold(f64::INFINITY, f64::min),
            d.iter().copied().fold(0.0, f64::max),
        )
    };
    std::fs::write(
        dir.join("assets/pyramid.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0.5 1 0.5\nf 1 2 3 4\nf 1 5 2\nf 2 5 3\nf 3 5 4\nf 4 5 1\n",
    )
    .unwrap();
    let flat = radius(
        r#"Lot --> s(10, 10, 10) primitiveSphere() scaleUV(0, 10, 10)
                   insertAlongUV(0, "tile.obj", 0, vertex.normal, alignPosition) X."#,
    );
    // The unit sphere of 16 x 16 facets scaled to radius 5: facet points
    // lie between 5 cos(pi/16)^2 and 5 from the centre.
    let inner = 5.0 * (std::f64::consts::PI / 16.0).cos().powi(2);
    assert!(flat.0 > 100, "{flat:?}");
    assert!(flat.1 > inner - 1e-9 && flat.2 < 5.0 + 1e-9, "{flat:?}");
    // Pyramids of height 0.5 along the normals: their bases on the facets,
    // their tips up to 0.5 above.
    let raised = radius(
        r#"Lot --> s(10, 10, 10) primitiveSphere() scaleUV(0, 10, 10)
                   insertAlongUV(0, "pyramid.obj", 0.5, vertex.normal) X."#,
    );
    assert!(raised.0 > flat.0, "{raised:?}");
    assert!(
        raised.1 > inner - 1e-9 && raised.2 < 5.5 + 1e-9,
        "{raised:?}"
    );
    assert!(raised.2 > 5.4, "{raised:?}");
}

#[test]
fn shape_without_uvs_or_asset_warns() {
    let dir = project("insert_warn");
    let out = run_in(
        &dir,
        r#"Lot --> [ insertAlongUV(0, "builtin:cube", 1) X. ]
                   setupProjection(0, scope.xz, 1, 1) projectUV(0) insertAlongUV(0, "nothing.obj", 1) X."#,
        &rect(10.0, 10.0),
    );
    assert_eq!(out.meshes.len(), 2);
    assert!(out.meshes.iter().all(|m| (area(m) - 100.0).abs() < 1e-9));
    assert_eq!(out.warnings.len(), 2, "{:?}", out.warnings);
    let _ = DVec2::ZERO;
}
