//! The examples of the reference pages of `extrude`, `t`, `translate`, `s`,
//! `r`, `rotate`, `center` and "CGA Euler Angles", with the numbers they
//! document or that their pictures imply. The pages do not name the lots:
//! each test says which it uses (`rect:W,D` is `(0,0,0) (W,0,0) (W,0,-D)
//! (0,0,-D)`, whose scope starts at `(0,0,-D)` relative to the pivot).

use crate::ops_common::*;
use cga_geometry::{measure, DVec3};

const EPS: f64 = 1e-9;

// ---------------------------------------------------------------------------
// extrude
// ---------------------------------------------------------------------------

/// A rule file with the scope printer and a rule that prints the geometry's
/// measures (area, volume, vertex and face counts, closedness).
fn with_printers(src: &str) -> String {
    format!(
        "{src}\n{SCOPE_PRINTER}\nGeo --> print([geometry.area, geometry.volume, geometry.nVertices, geometry.nFaces]) print(geometry.isClosedSurface) NIL\n"
    )
}

/// The two lines `Geo` prints, from `p[i]` on: area, volume, vertices, faces, closed.
fn geo_line(p: &[String], i: usize) -> (f64, f64, f64, f64, bool) {
    let v = array(&p[i]);
    (v[0], v[1], v[2], v[3], p[i + 1] == "true")
}

/// op_extrude, "Extrusion along normals" 1: `Lot --> extrude(10)` on an
/// initial shape of two faces. The faces are extruded and combined without
/// internal faces; the scope's y-axis is the extrusion direction. Two 10x10
/// squares side by side give one closed 20x10x10 block of 10 faces.
#[test]
fn extrude_two_flat_faces_combines_them() {
    let g = gen(&with_printers(
        "Lot --> i(\"flat2.obj\", yUp, keepSizeAndPosition) extrude(10) Scope Geo",
    ))
    .ok();
    let p = g.prints();
    let s = scope_line(&p[0]);
    assert_vec_near(s.s, [20.0, 10.0, 10.0], EPS);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
    let (area, volume, nv, nf, closed) = geo_line(&p, 1);
    assert_near(area, 2.0 * 200.0 + 60.0 * 10.0, EPS);
    assert_near(volume, 2000.0, EPS);
    assert_eq!((nv, nf, closed), (12.0, 10.0, true));
}

/// op_extrude, "Extrusion along normals" 1 on a lot: `extrude(10)` on
/// `rect:20,30` gives a 20x10x30 block (the scope the `s` page starts from).
#[test]
fn extrude_lot() {
    let g = gen(&with_printers("Lot --> extrude(10) Scope Geo X")).ok();
    let p = g.prints();
    let s = scope_line(&p[0]);
    assert_vec_near(s.t, [0.0, 0.0, -30.0], EPS);
    assert_vec_near(s.s, [20.0, 10.0, 30.0], EPS);
    let (area, volume, nv, nf, closed) = geo_line(&p, 1);
    assert_near(area, 2.0 * 600.0 + 100.0 * 10.0, EPS);
    assert_near(volume, 6000.0, EPS);
    assert_eq!((nv, nf, closed), (8.0, 6.0, true));
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], EPS);
    assert_vec_near(hi, [20.0, 10.0, 0.0], EPS);
}

/// op_extrude, "Extrusion along normals" 2: `extrude(face.normal,10)` on an
/// uneven shape extrudes each face by itself (internal faces are created),
/// the scope's y-axis is the normal of the first face. The second square of
/// `bent2.obj` rises at 45 degrees: two prisms of 6 faces, each with the
/// area 2*100 + 40*10; the first face is flat, so the scope stays upright.
#[test]
fn extrude_face_normal_on_uneven_faces() {
    for rule in ["extrude(face.normal,10)", "extrude(10)"] {
        let g = gen(&with_printers(&format!(
            "Lot --> i(\"bent2.obj\", yUp, keepSizeAndPosition) {rule} Scope Geo X"
        )))
        .ok();
        let p = g.prints();
        let s = scope_line(&p[0]);
        assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
        // The tilted prism reaches 7.07 + 10 * cos 45 = 14.14.
        let half = 50f64.sqrt();
        assert_vec_near(s.s, [10.0 + half, 2.0 * half, 10.0], 1e-9);
        let (area, _, _, nf, _) = geo_line(&p, 1);
        assert_eq!(nf, 12.0, "{rule}: two prisms of 6 faces");
        assert_near(area, 2.0 * (200.0 + 400.0), 1e-9);
    }
}

/// op_extrude, "Extrusion along normals" 3: `extrude(vertex.normal,10)` keeps
/// the faces together: one closed solid of 10 faces, no internal faces.
#[test]
fn extrude_vertex_normal_keeps_faces_together() {
    let g = gen(&with_printers(
        "Lot --> i(\"bent2.obj\", yUp, keepSizeAndPosition) extrude(vertex.normal,10) Scope Geo",
    ))
    .ok();
    let p = g.prints();
    let (_, volume, nv, nf, closed) = geo_line(&p, 1);
    assert_eq!((nv, nf, closed), (12.0, 10.0, true));
    assert!(volume > 1000.0, "a solid, volume {volume}");
}

/// The world-up extrusions of op_extrude ("Extrusion along world coordinate
/// axis") on the bent shape (heights 0 .. 7.07): `world.up` moves every
/// vertex up by 10; `world.up.flatTop` puts a flat top at lowest + 10;
/// distance 0 gives a flat top at the highest vertex; -10 measures from the
/// highest vertex down, with a negative scope.sy.
#[test]
fn extrude_world_up_variants() {
    let top = 50f64.sqrt(); // 7.0710678...
    let cases: [(&str, f64, f64, f64); 4] = [
        // rule, lowest y, highest y, scope.sy
        ("extrude(world.up,10)", 0.0, top + 10.0, top + 10.0),
        ("extrude(world.up.flatTop,10)", 0.0, 10.0, 10.0),
        ("extrude(world.up.flatTop,0)", 0.0, top, top),
        ("extrude(world.up.flatTop,-10)", top - 10.0, top, -10.0),
    ];
    for (rule, lo_y, hi_y, sy) in cases {
        let g = gen(&with_printers(&format!(
            "Lot --> i(\"bent2.obj\", yUp, keepSizeAndPosition) {rule} Scope Geo X"
        )))
        .ok();
        let p = g.prints();
        let s = scope_line(&p[0]);
        assert_near(s.s.y, sy, 1e-9);
        assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
        let (lo, hi) = g.bounds();
        assert_near(lo.y, lo_y, 1e-9);
        assert_near(hi.y, hi_y, 1e-9);
        let (_, _, _, nf, _) = geo_line(&p, 1);
        assert_eq!(nf, 10.0, "{rule}: one solid");
    }
    // flatTop with distance 0: bottom 200 (the two squares), flat top
    // 17.07 x 10, two side faces of 10*7.07 + 7.07^2/2, the back 7.07 x 10.
    let g = gen(&with_printers(
        "Lot --> i(\"bent2.obj\", yUp, keepSizeAndPosition) extrude(world.up.flatTop,0) Geo",
    ))
    .ok();
    let (area, ..) = geo_line(&g.prints(), 0);
    let side = 10.0 * top + top * top / 2.0;
    assert_near(
        area,
        200.0 + (10.0 + top) * 10.0 + 2.0 * side + top * 10.0,
        1e-9,
    );
}

/// op_extrude: "If distance is negative, the scope.sy attribute will be
/// negative." The base stays at the scope origin.
#[test]
fn extrude_negative_distance() {
    let g = gen(&with_printers("Lot --> extrude(-10) Scope X")).ok();
    let s = scope_line(&g.prints()[0]);
    assert_vec_near(s.t, [0.0, 0.0, -30.0], EPS);
    assert_vec_near(s.s, [20.0, -10.0, 30.0], EPS);
    let (lo, hi) = g.bounds();
    assert_near(lo.y, -10.0, EPS);
    assert_near(hi.y, 0.0, EPS);
}

/// op_extrude, "Extrusion of edges": `comp(e)` edges are extruded along the
/// average normal of their faces (up, for a lot): four 10 m high walls on
/// the lot's outline.
#[test]
fn extrude_edges_of_comp_e() {
    let g = gen("@StartRule\nStart --> InitialShape comp(e) { all = Edges }\nEdges --> extrude(10)\nInitialShape --> color(0,1,0)\n")
        .ok();
    // the lot itself (600) and 4 walls: perimeter 100 x 10
    assert_near(g.area(), 600.0 + 1000.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [20.0, 10.0, 0.0], 1e-9);
}

/// op_extrude, "Extrusion of edges": `comp(fe)` face edges are extruded
/// perpendicular to the face normal, outwards: flat strips 10 m wide around
/// the lot; along vertex normals they are kept together (mitred corners).
#[test]
fn extrude_face_edges_of_comp_fe() {
    let g = gen("@StartRule\nStart --> InitialShape comp(fe) { all = Edges }\nEdges --> extrude(10)\nInitialShape --> color(0,1,0)\n")
        .ok();
    assert_near(g.area(), 600.0 + 1000.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [-10.0, 0.0, -40.0], 1e-9);
    assert_vec_near(hi, [30.0, 0.0, 10.0], 1e-9);
    // Along vertex normals the strips stay together: the four quads share
    // their corners (8 vertices, a closed ring around the lot).
    let g = gen("@StartRule\nStart --> InitialShape comp(fe) { all = Edges }\nEdges --> extrude(vertex.normal, 10) print(geometry.nVertices + \" \" + geometry.nFaces)\nInitialShape --> color(0,1,0)\n")
        .ok();
    assert_eq!(g.prints(), ["8 4"]);
}

// ---------------------------------------------------------------------------
// t
// ---------------------------------------------------------------------------

/// op_t, "Translate - Rotation Concatenation", on `rect:1,1` (the page's
/// cube has scope.sx = 1): t(2,0,0), r(0,30,0), then t('2,0,0) along the
/// rotated x-axis `(cos 30, 0, -sin 30)`.
#[test]
fn t_rotation_concatenation() {
    let src = format!(
        "A--> primitiveCube() Scope t(2,0,0) Scope r(0,30,0) Scope t('2,0,0) Scope X\n{SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &Opts::rect(1.0, 1.0).start("A")).ok();
    let p: Vec<ScopeLine> = g.prints().iter().map(|l| scope_line(l)).collect();
    assert_vec_near(p[0].t, [0.0, 0.0, -1.0], EPS);
    assert_vec_near(p[0].s, [1.0, 1.0, 1.0], EPS);
    assert_vec_near(p[1].t, [2.0, 0.0, -1.0], EPS);
    assert_vec_near(p[2].t, [2.0, 0.0, -1.0], EPS);
    assert_vec_near(p[2].r, [0.0, 30.0, 0.0], EPS);
    let x_axis = mat_mul(&euler_matrix([0.0, 30.0, 0.0]), DVec3::X);
    let t = DVec3::new(2.0, 0.0, -1.0) + 2.0 * x_axis;
    assert_vec_near(p[3].t, t.to_array(), EPS);
    assert_vec_near(p[3].r, [0.0, 30.0, 0.0], EPS);
    // The cube went along: its corners are t + R * {0,1}^3.
    let (lo, hi) = g.bounds();
    let z_axis = mat_mul(&euler_matrix([0.0, 30.0, 0.0]), DVec3::Z);
    let corners = [DVec3::ZERO, x_axis, z_axis, x_axis + z_axis].map(|c| t + c);
    let min_x = corners.iter().map(|c| c.x).fold(f64::INFINITY, f64::min);
    let max_z = corners
        .iter()
        .map(|c| c.z)
        .fold(f64::NEG_INFINITY, f64::max);
    assert_near(lo.x, min_x, EPS);
    assert_near(hi.z, max_z, EPS);
    assert_near(hi.y - lo.y, 1.0, EPS);
}

/// op_t: "t(x,y,z) is the same as translate(rel, scope, x, y, z)".
#[test]
fn t_is_translate_rel_scope() {
    let src = format!(
        "Lot --> extrude(4) r(10,20,30) [ t(1,2,3) Scope ] [ translate(rel, scope, 1,2,3) Scope ]\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = g.prints();
    assert_eq!(p.len(), 2);
    assert_all_near(&array(&p[0]), &array(&p[1]), EPS);
}

// ---------------------------------------------------------------------------
// translate
// ---------------------------------------------------------------------------

/// A lot like `rect:10,10` turned by `deg` about the world y-axis, so that
/// object and world axes differ.
fn turned_square(deg: f64, side: f64) -> Opts {
    let (s, c) = deg.to_radians().sin_cos();
    // Ry(deg) applied to (x, 0, z)
    let rot = |x: f64, z: f64| DVec3::new(c * x + s * z, 0.0, -s * x + c * z);
    Opts::polygon(&[
        rot(0.0, 0.0),
        rot(side, 0.0),
        rot(side, -side),
        rot(0.0, -side),
    ])
}

/// op_translate, "Translate a shape along the world x-axis" and "... along
/// the object x-axis": the red cubes are copies of the white ones moved by
/// 2 along the world (object) x-axis. The lot is turned by 30 degrees so the
/// two axes differ; each white cube is followed by its red copy.
#[test]
fn translate_rel_world_and_object() {
    for (system, dir) in [
        ("world", DVec3::X),
        (
            "object",
            DVec3::new(30f64.to_radians().cos(), 0.0, -(30f64.to_radians().sin())),
        ),
    ] {
        let src = format!(
            "Init --> split(x) {{ '0.2 : split(z) {{ '0.2 : PP }}* }}*\n\
             PP --> 43% : primitiveCube() X translate(rel, {system}, 2, 0, 0) color(\"#ff0000\") X\n\
                    else : NIL\n"
        );
        let g = gen_with(&src, &turned_square(30.0, 10.0).start("Init")).ok();
        let meshes = g.meshes();
        assert!(
            meshes.len() >= 2 && meshes.len().is_multiple_of(2),
            "pairs of cubes, got {}",
            meshes.len()
        );
        // 43% of 25 cells: between 3 and 20 pairs for any seed
        assert!((3..=20).contains(&(meshes.len() / 2)));
        for pair in meshes.chunks(2) {
            let (w, r) = (&pair[0], &pair[1]);
            assert_eq!(rgb255(&w.materials[0]), [255, 255, 255]);
            assert_eq!(rgb255(&r.materials[0]), [255, 0, 0]);
            let d = measure::bounds(r).unwrap().0 - measure::bounds(w).unwrap().0;
            // bounds of a turned cube move with it
            assert_vec_near(d, (2.0 * dir).to_array(), 1e-9);
        }
    }
}

/// op_translate, modes: `abs` sets the position in the given system, `rel`
/// adds; `pivot` and `object` coincide for an initial shape's descendants.
#[test]
fn translate_abs_and_rel() {
    let src = format!(
        "Lot --> translate(abs, world, 1, 2, 3) Scope translate(abs, pivot, 1, 2, 3) Scope \
         translate(rel, scope, 1, 0, 0) Scope translate(abs, object, 5, 0, 0) Scope\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p: Vec<ScopeLine> = g.prints().iter().map(|l| scope_line(l)).collect();
    assert_vec_near(p[0].t, [1.0, 2.0, 3.0], EPS);
    assert_vec_near(p[1].t, [1.0, 2.0, 3.0], EPS);
    assert_vec_near(p[2].t, [2.0, 2.0, 3.0], EPS);
    assert_vec_near(p[3].t, [5.0, 0.0, 0.0], EPS);
    // On a turned lot, an absolute world position is not the pivot position.
    let src = "Lot --> translate(abs, world, 1, 2, 3) print(convert(scope, world, pos, [0,0,0])) print([scope.tx, scope.ty, scope.tz])\n";
    let g = gen_with(src, &turned_square(90.0, 10.0)).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &[1.0, 2.0, 3.0], 1e-9);
    // pivot axes: x = (0,0,-1), y up, z = (1,0,0): world (1,2,3) is (-3,2,1)
    assert_all_near(&array(&p[1]), &[-3.0, 2.0, 1.0], 1e-9);
}

// ---------------------------------------------------------------------------
// s
// ---------------------------------------------------------------------------

/// op_s, "Basic Usage" on `rect:20,30`: extrude(10) gives the scope
/// 20x10x30; s(5,5,5) sets it to 5x5x5; s('0.5,'1,'1.5) to 10x10x45. The
/// geometry is scaled with the scope, from the scope origin.
#[test]
fn s_absolute_and_relative() {
    for (op, size) in [
        ("", [20.0, 10.0, 30.0]),
        ("s(5,5,5)", [5.0, 5.0, 5.0]),
        ("s('0.5,'1,'1.5)", [10.0, 10.0, 45.0]),
        (
            "s(0.5*scope.sx, scope.sy, 1.5*scope.sz)",
            [10.0, 10.0, 45.0],
        ),
    ] {
        let src = format!("Lot--> extrude(10) {op} Scope X\n{SCOPE_PRINTER}");
        let g = gen(&src).ok();
        let s = scope_line(&g.prints()[0]);
        assert_vec_near(s.s, size, EPS);
        assert_vec_near(s.t, [0.0, 0.0, -30.0], EPS);
        let (lo, hi) = g.bounds();
        assert_vec_near(lo, [0.0, 0.0, -30.0], EPS);
        assert_vec_near(hi, [size[0], size[1], size[2] - 30.0], EPS);
        assert_near(g.volume(), size[0] * size[1] * size[2], 1e-6);
    }
}

/// op_s: "Negative sizes result in mirroring along the corresponding axes":
/// the box lies on the other side of the scope origin.
#[test]
fn s_negative_mirrors() {
    let src = format!("Lot--> extrude(10) s(-5,5,5) Scope X\n{SCOPE_PRINTER}");
    let g = gen(&src).ok();
    let s = scope_line(&g.prints()[0]);
    assert_vec_near(s.s, [-5.0, 5.0, 5.0], EPS);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [-5.0, 0.0, -30.0], EPS);
    assert_vec_near(hi, [0.0, 5.0, -25.0], EPS);
    assert_near(g.volume().abs(), 125.0, 1e-9);
}

// ---------------------------------------------------------------------------
// r
// ---------------------------------------------------------------------------

/// op_r, "Rotation Centers", on `rect:10,10`: the 18 m mass is split into 9
/// slices of 2 m, slice i turned by 40*i degrees about the y-axis through
/// its scope origin (the slices' scope.t stays) or its centre (scope.t moves
/// around the centre, which stays put).
#[test]
fn r_scope_origin_and_center() {
    for center in [false, true] {
        let sel = if center { "scopeCenter, " } else { "" };
        let src = format!(
            "height = 18\ndy = 2\n\
             Lot--> extrude(height) split(y) {{ dy : r({sel}0, 360*split.index/split.total, 0) Scope X }}*\n\
             {SCOPE_PRINTER}"
        );
        let g = gen_with(&src, &Opts::rect(10.0, 10.0)).ok();
        let p: Vec<ScopeLine> = g.prints().iter().map(|l| scope_line(l)).collect();
        assert_eq!(p.len(), 9);
        assert_eq!(g.meshes().len(), 9);
        for (i, s) in p.iter().enumerate() {
            let angle = 40.0 * i as f64;
            assert_vec_near(s.r, [0.0, angle, 0.0], 1e-9);
            assert_vec_near(s.s, [10.0, 2.0, 10.0], 1e-9);
            let origin = DVec3::new(0.0, 2.0 * i as f64, -10.0);
            let m = euler_matrix([0.0, angle, 0.0]);
            let expected = if center {
                let c = origin + DVec3::new(5.0, 1.0, 5.0);
                c + mat_mul(&m, DVec3::new(-5.0, -1.0, -5.0))
            } else {
                origin
            };
            assert_vec_near(s.t, expected.to_array(), 1e-9);
            // The slice turned with its scope: its bounds are centred on the
            // rotation centre (scopeCenter) or contain the scope origin.
            let (lo, hi) = mesh_bounds(&g.meshes()[i]);
            if center {
                let c = 0.5 * (lo + hi);
                assert_vec_near(c, [5.0, 2.0 * i as f64 + 1.0, -5.0], 1e-9);
            } else {
                assert!(g.meshes()[i]
                    .positions
                    .iter()
                    .any(|p| (*p - origin).length() < 1e-9));
            }
        }
    }
}

/// op_r: "r(x, y, z) is the same as rotate(rel, pivot, x, y, z)".
#[test]
fn r_is_rotate_rel_pivot() {
    let src = format!(
        "Lot --> extrude(4) r(5,10,15) [ r(10,20,30) Scope ] [ rotate(rel, pivot, 10,20,30) Scope ]\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &array(&p[1]), 1e-9);
}

// ---------------------------------------------------------------------------
// rotate
// ---------------------------------------------------------------------------

/// op_rotate, "Set scope orientation to world coordinate system angles", on
/// `rect:20,30`: after t('0.2,0,'0.3) s('0.5,'1,'0.5) the scope is 10x10x15
/// at (4,0,-21); rotate(abs, world, 0,90,0) turns it about its origin so
/// that its x-axis is the world's -z and its z-axis the world's x.
#[test]
fn rotate_abs_world() {
    let src = format!(
        "Init --> extrude(10) t('0.2, 0, '0.3) s('0.5, '1, '0.5) rotate(abs, world, 0, 90, 0) Scope \
         print(convert(scope, world, orient, [0,0,0])) X\n{SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &Opts::default().start("Init")).ok();
    // Init's own print comes before the one of `Scope`, a generation later.
    let mut p = g.prints().to_vec();
    p.swap(0, 1);
    let s = scope_line(&p[0]);
    assert_vec_near(s.t, [4.0, 0.0, -21.0], EPS);
    assert_vec_near(s.r, [0.0, 90.0, 0.0], EPS);
    assert_vec_near(s.s, [10.0, 10.0, 15.0], EPS);
    assert_all_near(&array(&p[1]), &[0.0, 90.0, 0.0], 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [4.0, 0.0, -31.0], 1e-9);
    assert_vec_near(hi, [19.0, 10.0, -21.0], 1e-9);

    // On a lot turned by 90 degrees the world orientation is still 0,90,0,
    // while the angles relative to the pivot differ.
    let g = gen_with(&src, &turned_square(90.0, 20.0).start("Init")).ok();
    let mut p = g.prints().to_vec();
    p.swap(0, 1);
    assert_all_near(&array(&p[1]), &[0.0, 90.0, 0.0], 1e-9);
    assert_vec_near(scope_line(&p[0]).r, [0.0, 0.0, 0.0], 1e-9);
}

/// op_rotate: "relative means the angles are added" in the given system.
/// After r(30,0,0), turning by 20 degrees about y in world angles gives the
/// world angles (30,20,0); in the scope system the turn is about the scope's
/// own (tilted) y-axis, which is the composition R(30,0,0) * R(0,20,0).
#[test]
fn rotate_rel_adds_angles_in_the_system() {
    let src = "Lot --> extrude(4) r(30,0,0) [ rotate(rel, world, 0,20,0) W ] [ rotate(rel, scope, 0,20,0) W ]\n\
               W --> print(convert(scope, world, orient, [0,0,0])) print(convert(scope, world, pos, [0,0,1]) .- convert(scope, world, pos, [0,0,0])) NIL\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &[30.0, 20.0, 0.0], 1e-9);
    let composed = |v: DVec3| {
        mat_mul(
            &euler_matrix([30.0, 0.0, 0.0]),
            mat_mul(&euler_matrix([0.0, 20.0, 0.0]), v),
        )
    };
    assert_all_near(&array(&p[3]), &composed(DVec3::Z).to_array(), 1e-9);
}

// ---------------------------------------------------------------------------
// center
// ---------------------------------------------------------------------------

/// op_center, "Positions of the axes selectors": a 4x4x4 cube around the
/// scope origin of `rect:1,1` (from (-2,-2,-3)); unit cubes in push/pop
/// blocks start at its corner and are centred on the selected axes of the
/// previous shape (SelCube): 1.5 further along each selected axis.
#[test]
fn center_axes_selectors() {
    let src = format!(
        "Lot--> primitiveCube() s(4,4,4) t(-2,-2,-2) SelCube\n\
         SelCube-->\n\
           [ color(\"#ff0000\") s(1,1,1) center(x) Scope X ]\n\
           [ color(\"#00ff00\") s(1,1,1) center(y) Scope X ]\n\
           [ color(\"#0000ff\") s(1,1,1) center(z) Scope X ]\n\
           [ color(\"#ffff00\") s(1,1,1) center(xy) Scope X ]\n\
           [ color(\"#ff00ff\") s(1,1,1) center(xz) Scope X ]\n\
           [ color(\"#00ffff\") s(1,1,1) center(yz) Scope X ]\n\
           [ color(\"#ffffff\") s(1,1,1) center(xyz) Scope X ]\n{SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &Opts::rect(1.0, 1.0)).ok();
    let p: Vec<ScopeLine> = g.prints().iter().map(|l| scope_line(l)).collect();
    let corner = DVec3::new(-2.0, -2.0, -3.0);
    let cases = [
        ("x", [255, 0, 0]),
        ("y", [0, 255, 0]),
        ("z", [0, 0, 255]),
        ("xy", [255, 255, 0]),
        ("xz", [255, 0, 255]),
        ("yz", [0, 255, 255]),
        ("xyz", [255, 255, 255]),
    ];
    assert_eq!(p.len(), 7);
    for (i, (axes, color)) in cases.iter().enumerate() {
        let mut t = corner;
        for (k, a) in ["x", "y", "z"].iter().enumerate() {
            if axes.contains(a) {
                t[k] += 1.5;
            }
        }
        assert_vec_near(p[i].t, t.to_array(), EPS);
        assert_vec_near(p[i].s, [1.0, 1.0, 1.0], EPS);
        let m = &g.meshes()[i];
        assert_eq!(rgb255(&m.materials[0]), *color, "{axes}");
        let (lo, _) = mesh_bounds(m);
        // object coordinates = pivot coordinates for rect lots
        assert_vec_near(lo, t.to_array(), EPS);
    }
}

// ---------------------------------------------------------------------------
// CGA Euler angles
// ---------------------------------------------------------------------------

/// cga_eulerAngles: the scope axes after `r(a, b, g)` are the columns of the
/// matrix the page gives (x first, then y, then z, about the pivot axes).
#[test]
fn euler_angles_match_the_reference_matrix() {
    for angles in [
        [10.0, 20.0, 30.0],
        [-35.0, 80.0, 120.0],
        [90.0, 0.0, 45.0],
        [0.0, -60.0, 200.0],
    ] {
        let src = format!(
            "Lot --> primitiveCube() r({}, {}, {}) \
             print(convert(scope, world, pos, [1,0,0]) .- convert(scope, world, pos, [0,0,0])) \
             print(convert(scope, world, pos, [0,1,0]) .- convert(scope, world, pos, [0,0,0])) \
             print(convert(scope, world, pos, [0,0,1]) .- convert(scope, world, pos, [0,0,0])) \
             print(convert(scope, world, orient, [0,0,0]))\n",
            angles[0], angles[1], angles[2]
        );
        let g = gen_with(&src, &Opts::rect(1.0, 1.0)).ok();
        let p = g.prints();
        let m = euler_matrix(angles);
        for (k, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
            let col = mat_mul(&m, axis);
            assert_all_near(&array(&p[k]), &col.to_array(), 1e-12);
        }
        // The world orientation of the scope gives back the same matrix.
        let back = array(&p[3]);
        let m2 = euler_matrix([back[0], back[1], back[2]]);
        for r in 0..3 {
            assert_all_near(&m2[r], &m[r], 1e-9);
        }
    }
}
