//! Texture coordinate operations: `setupProjection` + `projectUV`, and
//! `translateUV`, `scaleUV`, `rotateUV`, `normalizeUV`, `tileUV`,
//! `deleteUV`, `copyUV`, with the examples of their reference pages.
//!
//! The lot `rect:20,30` lies in the x-z plane from (0,0,0) to (20,0,-30);
//! its scope starts at (0,0,-30) with x along +x and z along +z, so a point
//! (x, 0, z) of the lot has scope coordinates (x, 0, z + 30).

use crate::texturing_common::*;
use cga_geometry::DVec2;

fn uv(u: f64, v: f64) -> DVec2 {
    DVec2::new(u, v)
}

#[test]
fn projection_of_scope_axes() {
    let out = run(
        "scope_xz",
        "Lot --> setupProjection(0, scope.xz, 5, 10) projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 1);
    assert_uvs(&out.meshes[0], 0, |p| uv(p.x / 5.0, (p.z + 30.0) / 10.0));
}

#[test]
fn relative_sizes_and_offsets() {
    // '1 spans the scope once; the offsets move the texture by 2 units and
    // by half the scope depth.
    let out = run(
        "relative",
        "Lot --> setupProjection(0, scope.xz, '1, '0.5, 2, '0.5) projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| {
        uv((p.x - 2.0) / 20.0, (p.z + 30.0 - 15.0) / 15.0)
    });
}

#[test]
fn floating_size_spans_the_scope_with_whole_tiles() {
    // ~6 on a 20 wide scope: 3 tiles of 20/3; ~7 on 30: 4 tiles of 7.5.
    let out = run(
        "floating",
        "Lot --> setupProjection(0, scope.xz, ~6, ~7) projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| {
        uv(p.x / (20.0 / 3.0), (p.z + 30.0) / 7.5)
    });
}

#[test]
fn negative_size_mirrors_and_other_axis_orders() {
    // scope.zx: u along z, v along x.
    let out = run(
        "zx",
        "Lot --> setupProjection(3, scope.zx, -10, 4) projectUV(3) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 3, |p| uv((p.z + 30.0) / -10.0, p.x / 4.0));
    assert!(out.meshes[0].uvs[0].is_none(), "only set 3 was projected");
}

#[test]
fn world_projection_and_global_example() {
    // setupProjection's global texture example: world.xz, then v flipped.
    let out = run(
        "world",
        "Lot --> setupProjection(0, world.xz, 586, 442) projectUV(0) scaleUV(0, 1, -1) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| uv(p.x / 586.0, -p.z / 442.0));
}

#[test]
fn uw_factor_adds_depth_to_u() {
    // Five arguments: the older form with the uw factor (as Candler writes
    // it). Facing the x-z scope the w axis is x × z = -y: a point 2 units
    // above the lot has w = -2 and gets u = (x + 2) / 5.
    let out = run(
        "uw",
        "Lot --> extrude(2) setupProjection(0, scope.xz, 5, 5, 1) projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    // After extrude the scope's y axis is up and the projection frame is
    // the extruded shape's scope: origin (0,0,-30), u = x, v = z, w = -y.
    assert_uvs(&out.meshes[0], 0, |p| {
        uv((p.x + 1.0 * p.y) / 5.0, (p.z + 30.0) / 5.0)
    });
}

#[test]
fn projection_is_inherited_so_tiles_are_continuous() {
    // The facade sets up its projection, the tiles project it: u runs on
    // across the tiles instead of restarting in each.
    let out = run(
        "continuous",
        "Lot --> setupProjection(0, scope.xz, 4, 4) split(x) { 7 : Tile }*
         Tile --> projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 3);
    for m in &out.meshes {
        assert_uvs(m, 0, |p| uv(p.x / 4.0, (p.z + 30.0) / 4.0));
    }
    // A projection set up in each tile restarts at the tile's own origin.
    let out = run(
        "restart",
        "Lot --> split(x) { 7 : Tile }*
         Tile --> setupProjection(0, scope.xz, 4, 4) projectUV(0) X.",
        &rect(20.0, 30.0),
    );
    let second = &out.meshes[1];
    let x0 = span(second, 0).0;
    assert!(x0 > 6.0, "the second tile starts at x = {x0}");
    assert_uvs(second, 0, |p| uv((p.x - x0) / 4.0, (p.z + 30.0) / 4.0));
}

#[test]
fn project_uv_without_projection_warns_and_keeps_the_shape() {
    let out = run(
        "no_projection",
        "Lot --> projectUV(2) X.",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 1);
    assert!(out.meshes[0].uvs[2].is_none());
    assert!(out
        .warnings
        .iter()
        .any(|w| w.message.contains("projectUV(2)")));
}

#[test]
fn translate_scale_rotate() {
    // translateUV page: move by half a texture width.
    let out = run(
        "translate",
        "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) translateUV(0, 0.5, 0) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| {
        uv(p.x / 20.0 + 0.5, (p.z + 30.0) / 30.0)
    });

    let out = run(
        "scale",
        "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) scaleUV(0, 2, 3) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| {
        uv(2.0 * p.x / 20.0, 3.0 * (p.z + 30.0) / 30.0)
    });

    // rotateUV page: rotation about (0, 0) after the projection.
    let out = run(
        "rotate",
        "Lot --> setupProjection(0, scope.xz, scope.sx, scope.sz) projectUV(0) rotateUV(0, 10) X.",
        &rect(20.0, 30.0),
    );
    let (s, c) = 10f64.to_radians().sin_cos();
    assert_uvs(&out.meshes[0], 0, |p| {
        let (u, v) = (p.x / 20.0, (p.z + 30.0) / 30.0);
        uv(c * u - s * v, s * u + c * v)
    });
    let out = run(
        "rotate90",
        "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) rotateUV(0, 90) X.",
        &rect(20.0, 30.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| uv(-(p.z + 30.0) / 30.0, p.x / 20.0));
}

#[test]
fn uv_operations_on_a_missing_set_do_nothing() {
    let out = run(
        "missing",
        "Lot --> translateUV(1, 1, 1) scaleUV(1, 2, 2) rotateUV(1, 30) normalizeUV(1, uv, separatePerFace) tileUV(1, 2, 2) X.",
        &rect(20.0, 30.0),
    );
    assert!(out.meshes[0].uvs.iter().all(|u| u.is_none()));
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
}

#[test]
fn bad_uv_set_is_an_error_not_a_panic() {
    let dir = project("bad_set");
    let path = dir.join("rules/main.cga");
    std::fs::write(&path, "Lot --> projectUV(10) X.").unwrap();
    let mut sources = cga_syntax::SourceMap::new();
    let program = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources)
        .usable()
        .unwrap();
    let assets = cga_engine::assets::Assets::on_disk(&sources);
    let rule = program.start_rule(None).unwrap();
    let (_, error) = cga_engine::generate_lot(
        &program,
        &assets,
        rule,
        &rect(20.0, 30.0),
        0,
        &Default::default(),
    );
    assert!(error.unwrap().message.contains("uv set 10"));
}

/// An asset of two unit quads side by side in x-y (x in [0, 1] and [1, 2]),
/// with u in [0, 1] on the first and [1, 3] on the second, v in [0, 2].
const TWO_QUADS: &str = "\
v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0
vt 0 0\nvt 1 0\nvt 1 2\nvt 0 2\nvt 3 0\nvt 3 2
f 1/1 2/2 3/3 4/4
f 2/2 5/5 6/6 3/3
";

fn two_quads(name: &str, ops: &str) -> cga_geometry::Mesh {
    let dir = project(name);
    std::fs::write(dir.join("assets/two.obj"), TWO_QUADS).unwrap();
    let rules = format!("Lot --> s(2, 1, 0) i(\"two.obj\") {ops} X.");
    let out = run_in(&dir, &rules, &rect(20.0, 30.0));
    assert_eq!(out.meshes.len(), 1);
    out.meshes.into_iter().next().unwrap()
}

/// The uvs of the corners of face `f`.
fn face_uvs(m: &cga_geometry::Mesh, f: usize) -> Vec<DVec2> {
    let uvs = m.uvs[0].as_ref().unwrap();
    m.face_loops(f)
        .iter()
        .flat_map(|&l| m.loop_corners(l))
        .map(|c| uvs[c])
        .collect()
}

fn bounds(uvs: &[DVec2]) -> (DVec2, DVec2) {
    uvs.iter()
        .fold((uvs[0], uvs[0]), |(lo, hi), &t| (lo.min(t), hi.max(t)))
}

#[test]
fn inserted_asset_keeps_its_uvs() {
    let m = two_quads("asset_uvs", "");
    assert_eq!(m.faces.len(), 2);
    assert_eq!(bounds(&face_uvs(&m, 0)), (uv(0.0, 0.0), uv(1.0, 2.0)));
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(1.0, 0.0), uv(3.0, 2.0)));
}

#[test]
fn normalize_uv_modes() {
    let m = two_quads("normalize_all", "normalizeUV(0, uv, collectiveAllFaces)");
    assert_eq!(bounds(&face_uvs(&m, 0)), (uv(0.0, 0.0), uv(1.0 / 3.0, 1.0)));
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(1.0 / 3.0, 0.0), uv(1.0, 1.0)));

    let m = two_quads("normalize_face", "normalizeUV(0, uv, separatePerFace)");
    for f in 0..2 {
        assert_eq!(bounds(&face_uvs(&m, f)), (uv(0.0, 0.0), uv(1.0, 1.0)));
    }

    // uvUniform keeps the aspect: both directions divided by the larger
    // range (3 in u).
    let m = two_quads(
        "normalize_uniform",
        "normalizeUV(0, uvUniform, collectiveAllFaces)",
    );
    assert_eq!(
        bounds(&face_uvs(&m, 1)),
        (uv(1.0 / 3.0, 0.0), uv(1.0, 2.0 / 3.0))
    );

    // Only u; v keeps its [0, 2].
    let m = two_quads("normalize_u", "normalizeUV(0, u, separatePerFace)");
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(0.0, 0.0), uv(1.0, 2.0)));
    let m = two_quads("normalize_v", "normalizeUV(0, v, collectiveAllFaces)");
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(1.0, 0.0), uv(3.0, 1.0)));
}

#[test]
fn tile_uv_sizes() {
    // The asset is scaled to 2 x 1 units: u spans [0, 3] over 2 units (1
    // unit per u on the first quad, 0.5 on the second: 0.75 on average, by
    // area), v spans [0, 2] over 1 unit (0.5 per v).
    // Relative: '0.5 gives two tiles, '2 half a tile (Candler's atlas trick
    // `tileUV(0, 'n, '1)` then picks a tile with translateUV).
    let m = two_quads("tile_rel", "tileUV(0, '0.5, '2)");
    assert_eq!(bounds(&face_uvs(&m, 0)), (uv(0.0, 0.0), uv(2.0 / 3.0, 0.5)));
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(2.0 / 3.0, 0.0), uv(2.0, 0.5)));
    let m = two_quads("tile_atlas", "tileUV(0, '8, '1) translateUV(0, -3/8, 0)");
    let all = [face_uvs(&m, 0), face_uvs(&m, 1)].concat();
    let (lo, hi) = bounds(&all);
    assert!((lo - uv(-3.0 / 8.0, 0.0)).length() < 1e-12, "{lo:?}");
    assert!((hi - uv(-2.0 / 8.0, 1.0)).length() < 1e-12, "{hi:?}");

    // Absolute: one tile per 0.5 units along u, measured with the average
    // 0.75 units per u (u' = 1.5 u), v untouched (0).
    let m = two_quads("tile_abs", "tileUV(0, 0.5, 0)");
    assert_eq!(bounds(&face_uvs(&m, 0)), (uv(0.0, 0.0), uv(1.5, 2.0)));
    assert_eq!(bounds(&face_uvs(&m, 1)), (uv(1.5, 0.0), uv(4.5, 2.0)));
    // Floating: ~0.7 over 3 * 0.75 = 2.25 units is 3 tiles; ~0.3 over 1
    // unit is 3 tiles.
    let m = two_quads("tile_float", "tileUV(0, ~0.7, ~0.3)");
    let all = [face_uvs(&m, 0), face_uvs(&m, 1)].concat();
    let (lo, hi) = bounds(&all);
    assert!((lo - uv(0.0, 0.0)).length() < 1e-12, "{lo:?}");
    assert!((hi - uv(3.0, 3.0)).length() < 1e-12, "{hi:?}");
}

#[test]
fn tile_uv_street_examples() {
    // tileUV page, on a 47 x 8 street with u, v in [0, 1]: tiles of exactly
    // 20 x 10 units, then ~20 (2 tiles of 23.5) by '0.5 (2 tiles).
    let dir = project("tile_street");
    street_asset(&dir, 47.0, 0.0, 47.0, 8.0);
    let out = run_in(
        &dir,
        r#"Lot --> i("street.obj") texture("builtin:uvtest.png") tileUV(0, 20, 10) X."#,
        &rect(47.0, 8.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| uv(p.x / 20.0, -p.z / 10.0));
    let out = run_in(
        &dir,
        r#"Lot --> i("street.obj") tileUV(0, ~20, '0.5) X."#,
        &rect(47.0, 8.0),
    );
    assert_uvs(&out.meshes[0], 0, |p| uv(p.x / 23.5, -p.z / 4.0));
}

#[test]
fn delete_and_copy_uv() {
    let out = run(
        "delete_copy",
        "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) copyUV(0, 2) scaleUV(0, 2, 2) X.",
        &rect(20.0, 30.0),
    );
    let m = &out.meshes[0];
    assert_uvs(m, 2, |p| uv(p.x / 20.0, (p.z + 30.0) / 30.0));
    assert_uvs(m, 0, |p| uv(p.x / 10.0, (p.z + 30.0) / 15.0));
    let out = run(
        "delete",
        "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) copyUV(0, 5) deleteUV(0) X.",
        &rect(20.0, 30.0),
    );
    let m = &out.meshes[0];
    assert!(m.uvs[0].is_none());
    assert_uvs(m, 5, |p| uv(p.x / 20.0, (p.z + 30.0) / 30.0));
}

#[test]
fn geometry_uv_functions_see_projected_coordinates() {
    let out = run(
        "uv_functions",
        "Lot --> setupProjection(0, scope.xz, 4, '0.5) projectUV(0)
             print(geometry.uMin(0)) print(geometry.uMax(0)) print(geometry.vMax(0))
             print(geometry.du(0, uvSpace)) print(geometry.du(0, unitSpace)) print(geometry.dv(0, unitSpace)) X.",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.prints, ["0", "5", "2", "5", "20", "30"]);
}

#[test]
fn projected_uvs_survive_extrude_and_splits() {
    // Splitting interpolates the coordinates along the cut edges: every
    // piece keeps u = x / 4.
    let out = run(
        "survive",
        "Lot --> setupProjection(0, scope.xz, 4, 6) projectUV(0) split(x) { ~3 : split(z) { 7 : X }* }*",
        &rect(20.0, 30.0),
    );
    // 7 columns of 20/7; rows of 7 and the 2 that remain of 30.
    assert_eq!(out.meshes.len(), 7 * 5);
    for m in &out.meshes {
        assert_uvs(m, 0, |p| uv(p.x / 4.0, (p.z + 30.0) / 6.0));
    }
}
