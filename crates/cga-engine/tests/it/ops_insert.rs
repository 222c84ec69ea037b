//! The examples of the reference pages of the primitives (`primitiveQuad`,
//! `primitiveDisk`, `primitiveCube`, `primitiveSphere`, `primitiveCylinder`,
//! `primitiveCone`) and of `i` (insert), with the sizes they document or
//! that their pictures imply, on the lot `rect:20,30` (scope 20 x 0 x 30 at
//! `(0,0,-30)` relative to the pivot).
//!
//! `box.obj` (tests/rules/ops/assets) stands for the page's "beethoven.obj":
//! a 2 x 3 x 1 box translated by (12.3, 4.3, 7.2), the translation the page
//! gives for its asset.

use crate::ops_common::*;

const EPS: f64 = 1e-9;

/// Derives `body` as the rule `Lot` and returns the scope line printed by
/// `Scope` and the geometry measures `area, volume, nVertices, nFaces`.
fn run(body: &str, opts: &Opts) -> (ScopeLine, [f64; 4], Gen) {
    let src = format!(
        "Lot --> {body} Scope Geo X\n{SCOPE_PRINTER}\n\
         Geo --> print([geometry.area, geometry.volume, geometry.nVertices, geometry.nFaces]) NIL\n"
    );
    let g = gen_with(&src, opts).ok();
    let p = g.prints();
    let geo = array(&p[1]);
    (scope_line(&p[0]), [geo[0], geo[1], geo[2], geo[3]], g)
}

/// Area of a regular polygon with `n` sides (a multiple of 4) whose flat
/// sides touch the square of side `2 r`, as CityEngine makes its disks,
/// cylinders and cones (vertices half a step off the axes): apothem `r`.
fn ngon_area(n: f64, r: f64) -> f64 {
    n * r * r * (std::f64::consts::PI / n).tan()
}

// ---------------------------------------------------------------------------
// primitiveQuad
// ---------------------------------------------------------------------------

/// op_primitive, primitiveQuad example 1: after rotateScope(0, 0, 90) the
/// scope's x-axis points up and scope.sx is 0; the quad is fit into the
/// scope's yz extent, i.e. it covers the lot. The quad has UVs in set 0.
#[test]
fn primitive_quad_fits_the_yz_scope() {
    let (s, geo, g) = run(
        "rotateScope(0, 0, 90) primitiveQuad() texture(\"builtin:uvtest.png\")",
        &Opts::default(),
    );
    assert_vec_near(s.s, [0.0, 20.0, 30.0], EPS);
    assert_vec_near(s.r, [0.0, 0.0, 90.0], EPS);
    assert_all_near(&geo, &[600.0, 0.0, 4.0, 1.0], EPS);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], EPS);
    assert_vec_near(hi, [20.0, 0.0, 0.0], EPS);
    assert!(g.meshes()[0].uvs[0].is_some());
    assert_eq!(g.face_materials()[0].colormap(), "builtin:uvtest.png");
}

/// op_primitive, primitiveQuad example 2: primitiveQuad(10,20) in the same
/// scope: width 10 (along the scope's y), length 20 (along z), positioned
/// in the yz centre of the 20 x 30 scope. The scope's y-axis points along
/// the world's -x, so the quad spans x 5..15 and z -25..-5.
#[test]
fn primitive_quad_with_size_is_centred_in_yz() {
    let (s, geo, g) = run(
        "rotateScope(0, 0, 90) primitiveQuad(10,20) texture(\"builtin:uvtest.png\")",
        &Opts::default(),
    );
    assert_vec_near(s.s, [0.0, 10.0, 20.0], EPS);
    assert_all_near(&geo, &[200.0, 0.0, 4.0, 1.0], EPS);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [5.0, 0.0, -25.0], EPS);
    assert_vec_near(hi, [15.0, 0.0, -5.0], EPS);
}

/// primitiveQuad(w, l) on the lot itself (no zero size but y): centred in
/// x and z, lying on y = 0.
#[test]
fn primitive_quad_with_size_on_a_lot() {
    let (s, geo, g) = run("primitiveQuad(10,20)", &Opts::default());
    assert_vec_near(s.s, [10.0, 0.0, 20.0], EPS);
    assert_vec_near(s.t, [5.0, 0.0, -25.0], EPS);
    assert_all_near(&geo, &[200.0, 0.0, 4.0, 1.0], EPS);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [5.0, 0.0, -25.0], EPS);
    assert_vec_near(hi, [15.0, 0.0, -5.0], EPS);
}

// ---------------------------------------------------------------------------
// primitiveDisk
// ---------------------------------------------------------------------------

/// op_primitive, primitiveDisk example 1: after rotateScope(-90, 0, 0)
/// scope.sz is 0; the 16-vertex disk is fit into the scope's xy extent
/// (the lot's 20 x 30): a 16-gon filling it, its flat sides touching it.
#[test]
fn primitive_disk_fits_the_xy_scope() {
    let (s, geo, g) = run(
        "rotateScope(-90, 0, 0) primitiveDisk() texture(\"builtin:uvtest.png\")",
        &Opts::default(),
    );
    assert_vec_near(s.s, [20.0, 30.0, 0.0], 1e-9);
    assert_near(geo[0], ngon_area(16.0, 1.0) * 10.0 * 15.0, 1e-9);
    assert_eq!((geo[2], geo[3]), (16.0, 1.0));
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [20.0, 0.0, 0.0], 1e-9);
    assert!(g.meshes()[0].uvs[0].is_some());
}

/// op_primitive, primitiveDisk example 2: primitiveDisk(8,10) has 8
/// vertices, radius 10, and is positioned in the xy centre of the 20 x 30
/// scope (whose y-axis points along the world's -z): z from -25 to -5.
#[test]
fn primitive_disk_with_radius_is_centred_in_xy() {
    let (s, geo, g) = run(
        "rotateScope(-90, 0, 0) primitiveDisk(8,10) texture(\"builtin:uvtest.png\")",
        &Opts::default(),
    );
    assert_vec_near(s.s, [20.0, 20.0, 0.0], 1e-9);
    assert_near(geo[0], ngon_area(8.0, 10.0), 1e-9);
    assert_eq!((geo[2], geo[3]), (8.0, 1.0));
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -25.0], 1e-9);
    assert_vec_near(hi, [20.0, 0.0, -5.0], 1e-9);
}

// ---------------------------------------------------------------------------
// primitiveCube, primitiveSphere, primitiveCylinder, primitiveCone
// ---------------------------------------------------------------------------

/// op_primitive, example 1 of cube, sphere, cylinder and cone: the solid is
/// fit into the scope; the zero size (scope.sy of the lot) becomes the
/// average of the two others: (20/1 + 30/1) * 0.5 * 1 = 25. Segment counts
/// default to 16 (sphere: 16 sides and 16 divisions).
#[test]
fn primitive_solids_fit_the_scope() {
    let octa16 = ngon_area(16.0, 1.0) * 10.0 * 15.0; // base of cylinder and cone
    let cases: [(&str, Option<f64>, f64, f64); 4] = [
        // op, volume (when exact), vertices, faces
        ("primitiveCube()", Some(20.0 * 25.0 * 30.0), 8.0, 6.0),
        ("primitiveSphere()", None, 2.0 + 15.0 * 16.0, 16.0 * 16.0),
        ("primitiveCylinder()", Some(octa16 * 25.0), 32.0, 18.0),
        ("primitiveCone()", Some(octa16 * 25.0 / 3.0), 17.0, 17.0),
    ];
    for (op, volume, nv, nf) in cases {
        let (s, geo, g) = run(
            &format!("{op} texture(\"builtin:uvtest.png\")"),
            &Opts::default(),
        );
        assert_vec_near(s.t, [0.0, 0.0, -30.0], EPS);
        assert_vec_near(s.s, [20.0, 25.0, 30.0], EPS);
        if let Some(v) = volume {
            assert_near(geo[1], v, 1e-6);
        }
        assert_eq!((geo[2], geo[3]), (nv, nf), "{op}");
        let (lo, hi) = g.bounds();
        assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
        assert_vec_near(hi, [20.0, 25.0, 0.0], 1e-9);
        assert!(g.meshes()[0].uvs[0].is_some(), "{op} has UVs in set 0");
    }
    // The cube's area: 2 * (20*25 + 25*30 + 20*30).
    let (_, geo, _) = run("primitiveCube()", &Opts::default());
    assert_near(geo[0], 3700.0, 1e-9);
}

/// op_primitive, example 2 of cube, sphere, cylinder and cone: the given
/// dimensions, positioned in the xz centre of the 20 x 30 scope, on y = 0.
#[test]
fn primitive_solids_with_dimensions() {
    let octa = ngon_area(8.0, 10.0);
    type Case<'a> = (&'a str, [f64; 3], Option<f64>, f64, f64);
    let cases: [Case; 4] = [
        // op, size, volume (when exact), vertices, faces
        (
            "primitiveCube(10,15,20)",
            [10.0, 15.0, 20.0],
            Some(3000.0),
            8.0,
            6.0,
        ),
        (
            "primitiveSphere(8,4,10)",
            [20.0, 20.0, 20.0],
            None,
            2.0 + 3.0 * 8.0,
            8.0 * 4.0,
        ),
        (
            "primitiveCylinder(8,10,15)",
            [20.0, 15.0, 20.0],
            Some(octa * 15.0),
            16.0,
            10.0,
        ),
        (
            "primitiveCone(8,10,15)",
            [20.0, 15.0, 20.0],
            Some(octa * 5.0),
            9.0,
            9.0,
        ),
    ];
    for (op, size, volume, nv, nf) in cases {
        let (s, geo, g) = run(
            &format!("{op} texture(\"builtin:uvtest.png\")"),
            &Opts::default(),
        );
        let t = [(20.0 - size[0]) / 2.0, 0.0, -30.0 + (30.0 - size[2]) / 2.0];
        assert_vec_near(s.t, t, EPS);
        assert_vec_near(s.s, size, EPS);
        if let Some(v) = volume {
            assert_near(geo[1], v, 1e-6);
        }
        assert_eq!((geo[2], geo[3]), (nv, nf), "{op}");
        let (lo, hi) = g.bounds();
        assert_vec_near(lo, t, 1e-9);
        assert_vec_near(hi, [t[0] + size[0], size[1], t[2] + size[2]], 1e-9);
    }
}

/// op_primitive: "Zero scope sizes are handled the same way as in the i
/// operation": a point scope gets the unit cube, a line scope of 9 a cube of
/// 9, a scope of 9 x 9 x 0 a depth of (9/1 + 9/1) / 2 = 9.
#[test]
fn primitive_cube_in_zero_sized_scopes() {
    // The unit cube, as an asset, is centred on its origin in x and z and
    // stands on y = 0; a zero size keeps (scaled) the asset's position.
    for (op, size, t) in [
        ("s(0,0,0)", [1.0, 1.0, 1.0], [-0.5, 0.0, -30.5]),
        ("s(9,0,0)", [9.0, 9.0, 9.0], [0.0, 0.0, -34.5]),
        ("s(0,9,0)", [9.0, 9.0, 9.0], [-4.5, 0.0, -34.5]),
        ("s(9,9,0)", [9.0, 9.0, 9.0], [0.0, 0.0, -30.0]),
        ("s(4,0,8)", [4.0, 6.0, 8.0], [0.0, 0.0, -30.0]),
    ] {
        let (s, geo, _) = run(&format!("{op} primitiveCube()"), &Opts::default());
        assert_vec_near(s.s, size, EPS);
        assert_vec_near(s.t, t, EPS);
        assert_near(geo[1], size[0] * size[1] * size[2], 1e-9);
    }
}

/// op_primitive: "There must be at least 3 vertices" (sides, and at least 2
/// divisions for the sphere): fewer is an error, not a panic.
#[test]
fn primitive_segment_counts_are_checked() {
    for op in [
        "primitiveDisk(2)",
        "primitiveCylinder(2)",
        "primitiveCone(1, 1, 1)",
        "primitiveSphere(3, 1)",
    ] {
        let g = gen(&format!("Lot --> {op}\n"));
        assert_eq!(g.errors.len(), 1, "{op}");
    }
}

// ---------------------------------------------------------------------------
// i (insert)
// ---------------------------------------------------------------------------

/// op_i, "Insertion and Zero Scope Dimensions" 1: `s(0,0,0) i(asset)` keeps
/// the asset's size and position: the scope becomes the asset's bounding
/// box, translated by the asset's translation.
#[test]
fn insert_into_a_point_scope_keeps_the_asset() {
    let (s, geo, g) = run("s(0,0,0) i(\"box.obj\")", &Opts::default());
    assert_vec_near(s.t, [12.3, 4.3, -30.0 + 7.2], 1e-9);
    assert_vec_near(s.s, [2.0, 3.0, 1.0], 1e-9);
    assert_near(geo[1], 6.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [12.3, 4.3, -22.8], 1e-9);
    assert_vec_near(hi, [14.3, 7.3, -21.8], 1e-9);
    // keepSizeAndPosition is "the same as setting zero scope dimensions".
    let (s2, _, g2) = run("i(\"box.obj\", yUp, keepSizeAndPosition)", &Opts::default());
    assert_all_near(&s2.t.to_array(), &s.t.to_array(), 1e-9);
    assert_all_near(&s2.s.to_array(), &s.s.to_array(), 1e-9);
    assert_all_near(&g2.bounds().0.to_array(), &lo.to_array(), 1e-9);
}

/// op_i, "Insertion and Zero Scope Dimensions" 2: `s(9,0,0)`: the two zero
/// sizes are scaled like the non-zero one (9/2 = 4.5), and the scope moves
/// along them by 4.5 times the asset's translation (tx stays).
#[test]
fn insert_into_a_line_scope_scales_uniformly() {
    let (s, geo, g) = run("s(9,0,0) i(\"box.obj\")", &Opts::default());
    assert_vec_near(s.t, [0.0, 4.5 * 4.3, -30.0 + 4.5 * 7.2], 1e-9);
    assert_vec_near(s.s, [9.0, 13.5, 4.5], 1e-9);
    assert_near(geo[1], 9.0 * 13.5 * 4.5, 1e-6);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 19.35, 2.4], 1e-9);
    assert_vec_near(hi, [9.0, 32.85, 6.9], 1e-9);
}

/// op_i, "Insertion and Zero Scope Dimensions" 3: `s(9,9,0)`: the zero
/// size is the average of the two scale factors times the asset's size,
/// (9/2 + 9/3) * 0.5 * 1 = 3.75; the position is not modified.
#[test]
fn insert_into_a_flat_scope_uses_the_average_scale() {
    let (s, geo, g) = run("s(9,9,0) i(\"box.obj\")", &Opts::default());
    assert_vec_near(s.t, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(s.s, [9.0, 9.0, 3.75], 1e-9);
    assert_near(geo[1], 9.0 * 9.0 * 3.75, 1e-6);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [9.0, 9.0, -26.25], 1e-9);
}

/// op_i: the default insert fits the asset's bounding box to the scope; the
/// lot's zero height is the average rule again: (20/2 + 30/1) * 0.5 * 3.
#[test]
fn insert_fits_the_scope() {
    let (s, geo, g) = run("extrude(5) i(\"box.obj\")", &Opts::default());
    assert_vec_near(s.s, [20.0, 5.0, 30.0], 1e-9);
    assert_near(geo[1], 3000.0, 1e-6);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [20.0, 5.0, 0.0], 1e-9);
    let (s, _, _) = run("i(\"box.obj\")", &Opts::default());
    assert_vec_near(s.s, [20.0, 60.0, 30.0], 1e-9);
}

/// op_i, insertMode keepSizeAlignPosition: the asset's size is kept, it is
/// positioned in the xz centre of the scope, its bounding box on y = 0.
#[test]
fn insert_keep_size_align_position() {
    let (s, _, g) = run(
        "i(\"box.obj\", yUp, keepSizeAlignPosition)",
        &Opts::default(),
    );
    assert_vec_near(s.s, [2.0, 3.0, 1.0], 1e-9);
    assert_vec_near(s.t, [9.0, 0.0, -15.5], 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [9.0, 0.0, -15.5], 1e-9);
    assert_vec_near(hi, [11.0, 3.0, -14.5], 1e-9);
}

/// op_i, upAxisOfGeometry zUp: the asset is turned by -90 degrees about x
/// first, so its 2 x 3 x 1 box becomes 2 x 1 x 3; in a point scope its
/// size is kept.
#[test]
fn insert_z_up() {
    let (s, _, _) = run("s(0,0,0) i(\"box.obj\", zUp)", &Opts::default());
    assert_vec_near(s.s, [2.0, 1.0, 3.0], 1e-9);
    // in the lot's scope, the zero height is (20/2 + 30/3) * 0.5 * 1
    let (s, _, _) = run("i(\"box.obj\", zUp)", &Opts::default());
    assert_vec_near(s.s, [20.0, 10.0, 30.0], 1e-9);
}

/// A missing asset does not stop the model: a warning, the shape keeps its
/// geometry.
#[test]
fn insert_missing_asset_warns() {
    let (s, geo, g) = run("extrude(2) i(\"no/such/asset.obj\")", &Opts::default());
    assert_vec_near(s.s, [20.0, 2.0, 30.0], EPS);
    assert_near(geo[1], 1200.0, 1e-9);
    assert!(
        g.warnings().iter().any(|w| w.contains("not found")),
        "{:?}",
        g.warnings()
    );
}

/// op_i, "Window insertion": a 47 m mass, facades split into floors and
/// windows, a window asset in each window.
#[test]
fn insert_windows_into_a_facade() {
    let src = "Lot --> extrude(47) comp(f){side : Facade | top : X }\n\
               Facade --> split(y) { { ~1 : X | ~8 : Floor }* | ~1 : X }\n\
               Floor --> split(x) { { ~1 : X | ~5 : Window }* | ~1 : X }\n\
               Window --> s('1,'1,0.5) i(\"box.obj\") print(scope.sz) NIL\n";
    let g = gen(src).ok();
    // 47 m: 5 floors of 9 m and a ground strip; the 20 m facades hold
    // 3 windows (3 * 6 + 1 = 19 -> ~1 stretched), the 30 m ones 5.
    let windows = g.prints().len();
    assert_eq!(windows, 5 * (2 * 3 + 2 * 5));
    assert!(g.prints().iter().all(|l| l == "0.5"));
}

/// op_i, "Trim Planes and Insertion": cylinders inserted at the four sides
/// of a cube are cut by the trim planes of the component split, unless
/// trim.vertical is disabled before the insert.
#[test]
fn insert_is_cut_by_trim_planes() {
    let trimmed = "Lot--> primitiveCube() s(10,40,10) t(-5, 0, -5) comp(f) { side: Side }\n\
                   Side--> t(0,0,-5) s('1,'1,10) i(\"builtin:cylinder\")\n";
    let untrimmed = "Lot--> primitiveCube() s(10,40,10) t(-5, 0, -5) comp(f) { side: Side }\n\
                     Side--> t(0,0,-5) s('1,'1,10) set(trim.vertical, false) i(\"builtin:cylinder\")\n";
    let a = gen(trimmed).ok();
    let b = gen(untrimmed).ok();
    // Four cylinders of diameter 10 centred on the side faces' planes; the
    // trim planes cut away where neighbours overlap at the corners.
    assert_eq!(a.meshes().len(), 4);
    assert_eq!(b.meshes().len(), 4);
    assert!(a.area() < b.area() - 1.0, "{} < {}", a.area(), b.area());
    assert!(a.warnings().is_empty() && b.warnings().is_empty());
}
