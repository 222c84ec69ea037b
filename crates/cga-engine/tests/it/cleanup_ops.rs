//! The geometry clean-up operations through the engine: op_convexify,
//! op_deleteHoles, op_cleanupGeometry, op_reverseNormals, op_setNormals,
//! op_softenNormals, op_mirror, op_reduceGeometry, op_rectify.

use crate::ops_common::*;
use cga_engine::lot::Lot;
use cga_geometry::{measure, DVec3, Mesh};

/// The test assets of these operations (absolute, for `i()`).
fn asset(name: &str) -> String {
    format!("{}/tests/rules/roofs/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// op_convexify, the example: with `maxLength` 1 no split line of the L
/// (5 m long) is made and the L stays one (green) shape; without a limit
/// it falls into two rectangles, split along the extension of the edge
/// that ends at the reflex corner.
#[test]
fn convexify_l() {
    let src = "attr maxLength = 1\nLot --> convexify(ARG) comp(f) { all : Info SubShapes }\n\
               Info --> print(geometry.area) print(geometry.isRectangular(0.001)) NIL\n\
               SubShapes -->\n  case scope.sx >= maxLength && scope.sy >= maxLength : color(\"#00ff00\")\n  else : color(\"#ff0000\")\n";
    let l = Opts::polygon(&l_lot());
    let g = gen_with(&src.replace("ARG", "maxLength"), &l).ok();
    assert_eq!(g.prints(), ["95", "false"]);
    assert_eq!(rgb255(g.face_materials()[0]), [0, 255, 0]);
    let g = gen_with(&src.replace("ARG", ""), &l).ok();
    assert_eq!(g.prints(), ["60", "true", "35", "true"]);
    // A U: three rectangles; the areas add up.
    let u = pts(&[
        (0.0, 0.0),
        (15.0, 0.0),
        (15.0, -12.0),
        (10.0, -12.0),
        (10.0, -5.0),
        (5.0, -5.0),
        (5.0, -12.0),
        (0.0, -12.0),
    ]);
    let g = gen_with(
        "Lot --> convexify comp(f) { all : print(geometry.isConcave) X. }\n",
        &Opts::polygon(&u),
    )
    .ok();
    assert_eq!(g.prints(), ["false", "false", "false"]);
    assert_near(g.area(), 15.0 * 12.0 - 5.0 * 7.0, 1e-9);
}

/// A lot with a hole: `deleteHoles` leaves the outer boundary; `convexify`
/// joins the hole to the boundary and every piece is convex.
#[test]
fn delete_holes_and_convexify_a_ring() {
    let mut mesh = Mesh::new();
    mesh.positions
        .extend(pts(&[(0.0, 0.0), (10.0, 0.0), (10.0, -10.0), (0.0, -10.0)]));
    mesh.positions
        .extend(pts(&[(3.0, -3.0), (3.0, -7.0), (7.0, -7.0), (7.0, -3.0)]));
    mesh.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
    let ring = Opts {
        lots: vec![Lot {
            name: "ring".into(),
            mesh,
            attrs: Vec::new(),
            geo_origin: None,
        }],
        ..Opts::default()
    };
    let g = gen_with(
        "Lot --> print(geometry.nHoles) print(geometry.area) deleteHoles() print(geometry.nHoles) print(geometry.area) X.\n",
        &ring,
    )
    .ok();
    assert_eq!(g.prints(), ["1", "84", "0", "100"]);
    let g = gen_with(
        "Lot --> convexify() comp(f) { all : print(geometry.isConcave) X. }\n",
        &ring,
    )
    .ok();
    assert!(g.prints().len() >= 4);
    assert!(g.prints().iter().all(|p| p == "false"));
    assert_near(g.area(), 84.0, 1e-9);
}

/// op_cleanupGeometry: a box of twelve triangles with separate vertices
/// becomes six quads on eight vertices; merging alone keeps the triangles.
#[test]
fn cleanup_geometry() {
    let src = format!(
        "Lot --> i(\"{}\") print(geometry.nFaces) print(geometry.volume) CMD print(geometry.nFaces) print(geometry.nVertices) print(geometry.volume) X.\n",
        asset("tri_box.obj")
    );
    let g = gen(&src.replace("CMD", "cleanupGeometry(all, 0)")).ok();
    let p = g.prints();
    assert_eq!(p[0], "12");
    assert_eq!(p[2..4], ["6", "8"]);
    // The same solid.
    assert_near(
        p[4].parse::<f64>().unwrap(),
        p[1].parse::<f64>().unwrap(),
        1e-6,
    );
    let g = gen(&src.replace("CMD", "cleanupGeometry(vertices, 0)")).ok();
    assert_eq!(g.prints()[2..4], ["12", "8"]);
    // A face below the area threshold (t = 1: 1 square metre) goes.
    let g = gen_with(
        "Lot --> cleanupGeometry(faces, 1) print(geometry.nFaces) X.\n",
        &Opts::rect(0.5, 0.5),
    )
    .ok();
    assert_eq!(g.prints(), ["0"]);
}

/// op_reverseNormals: the normal turns and the first edge stays the first
/// edge (run the other way: `c1 c0 cn-1 .. c2`), so that `comp(f)` scopes
/// keep their x axis along it.
#[test]
fn reverse_normals_keeps_the_first_edge() {
    let g = gen("Lot --> reverseNormals X.\n").ok();
    let m = &g.meshes()[0];
    assert!(measure::face_normal(m, 0).y < -0.999);
    let l: Vec<DVec3> = m.loop_points(m.outer_loop(0)).collect();
    assert_vec_near(l[0], [20.0, 0.0, 0.0], 1e-12);
    assert_vec_near(l[1], [0.0, 0.0, 0.0], 1e-12);
    assert_vec_near(l[2], [0.0, 0.0, -30.0], 1e-12);
}

/// op_setNormals / op_softenNormals: soft normals average the faces at a
/// vertex (a box's corners point diagonally), hard and auto (30 degrees)
/// keep the faces' own normals at 90-degree edges; conform turns an
/// inside-out face so that the solid faces outwards.
#[test]
fn set_and_soften_normals() {
    let base = format!("Lot --> i(\"{}\") CMD X.\n", asset("flipped_box.obj"));
    let corner_normals = |cmd: &str| -> (Mesh, Vec<DVec3>) {
        let g = gen(&base.replace("CMD", cmd)).ok();
        let m = g.meshes()[0].clone();
        let n = m.normals.clone().expect("normals set");
        (m, n)
    };
    let d = 1.0 / 3f64.sqrt();
    // Softened over all faces: the flipped top counts with its own normal,
    // so conform first.
    let (_, n) = corner_normals("setNormals(conform) softenNormals(180)");
    assert!(n
        .iter()
        .all(|v| (v.abs() - DVec3::splat(d)).length() < 1e-9));
    let (_, n2) = corner_normals("setNormals(conform) setNormals(soft)");
    assert_eq!(n, n2);
    for cmd in ["setNormals(hard)", "setNormals(auto)", "softenNormals(30)"] {
        let (m, n) = corner_normals(cmd);
        for f in 0..m.faces.len() {
            let fnorm = measure::face_normal(&m, f);
            for c in m.loop_corners(m.outer_loop(f)) {
                assert!((n[c] - fnorm).length() < 1e-9, "{cmd}");
            }
        }
    }
    let (m, _) = corner_normals("setNormals(conform)");
    assert!(measure::volume(&m) > 0.0);
    assert!((0..m.faces.len()).all(|f| {
        let c = m.loop_points(m.outer_loop(f)).sum::<DVec3>() / 4.0;
        measure::face_normal(&m, f).dot(c - DVec3::new(10.0, 0.5, -15.0)) > 0.0
    }));
}

/// op_mirror: the geometry flips inside the scope (x -> sx - x), the scope
/// stays, the face keeps facing up.
#[test]
fn mirror() {
    let src = format!("Lot --> Scope mirror(true, false, false) Scope X.\n{SCOPE_PRINTER}");
    let g = gen_with(&src, &Opts::polygon(&l_lot())).ok();
    let p = g.prints();
    let (a, b) = (scope_line(&p[0]), scope_line(&p[1]));
    assert_vec_near(a.t, b.t.to_array(), 1e-12);
    assert_vec_near(a.s, b.s.to_array(), 1e-12);
    let m = &g.meshes()[0];
    assert!(measure::face_normal(m, 0).y > 0.999);
    assert_near(measure::face_area(m, 0), 95.0, 1e-9);
    // The notch (x > 5, z < -5) is now at x < 7.
    let mut xs: Vec<(f64, f64)> = m.positions.iter().map(|p| (p.x, p.z)).collect();
    xs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let expected = [
        (0.0, -5.0),
        (0.0, 0.0),
        (7.0, -12.0),
        (7.0, -5.0),
        (12.0, -12.0),
        (12.0, 0.0),
    ];
    for (g, e) in xs.iter().zip(expected) {
        assert_near(g.0, e.0, 1e-9);
        assert_near(g.1, e.1, 1e-9);
    }
}

/// op_reduceGeometry: the vertex count drops by the fraction given (80 %
/// in the page's terrain example).
#[test]
fn reduce_geometry() {
    let g = gen("Lot --> primitiveSphere(24, 24) print(geometry.nVertices) reduceGeometry(0.8) print(geometry.nVertices) X.\n").ok();
    let p = g.prints();
    let (before, after): (f64, f64) = (p[0].parse().unwrap(), p[1].parse().unwrap());
    assert_near(after, (before * 0.2).round(), 0.0);
    let (lo, hi) = g.bounds();
    // Still about the sphere's size.
    assert!((hi.x - lo.x) > 15.0 && (hi.x - lo.x) <= 20.0 + 1e-9);
}

/// op_rectify: edges within the angle of the scope axes become parallel to
/// them; a quad off by a few degrees becomes a rectangle, not with 1 degree.
#[test]
fn rectify() {
    let skew = Opts::polygon(&pts(&[(0.0, 0.0), (10.0, -0.5), (10.3, -6.0), (0.2, -6.1)]));
    let g = gen_with(
        "Lot --> rectify(15) print(geometry.isRectangular(0.001)) X.\n",
        &skew,
    )
    .ok();
    assert_eq!(g.prints(), ["true"]);
    let g = gen_with(
        "Lot --> rectify(1) print(geometry.isRectangular(0.001)) X.\n",
        &skew,
    )
    .ok();
    assert_eq!(g.prints(), ["false"]);
}
