//! The roof operations through the engine: the examples of op_roofGable,
//! op_roofHip, op_roofPyramid, op_roofShed and op_roofRidge with their
//! numbers, the scope a roof gets, `comp(e)`'s roof edge selectors on the
//! roofs the operations build, and degenerate footprints.

use crate::ops_common::*;
use cga_geometry::roof::{roof, RoofEdgeKind, RoofKind, RoofSlope};
use cga_geometry::{measure, DVec3, Mesh};

/// A U: two 5 m wide wings joined by a 15 x 5 front.
fn u_lot() -> Vec<DVec3> {
    [
        (0.0, 0.0),
        (15.0, 0.0),
        (15.0, -12.0),
        (10.0, -12.0),
        (10.0, -5.0),
        (5.0, -5.0),
        (5.0, -12.0),
        (0.0, -12.0),
    ]
    .iter()
    .map(|&(x, z)| DVec3::new(x, 0.0, z))
    .collect()
}

/// A regular pentagon of circumradius 10 around (0, 0, -10).
fn pentagon() -> Vec<DVec3> {
    (0..5)
        .map(|i| {
            let a = -std::f64::consts::FRAC_PI_2 - std::f64::consts::PI / 5.0
                + i as f64 * std::f64::consts::TAU / 5.0;
            DVec3::new(10.0 * a.cos(), 0.0, -10.0 - 10.0 * a.sin())
        })
        .collect()
}

const MASS: &str = "Lot --> extrude(10) Mass\nMass --> comp(f) { top : Top | all : NIL }\n";

/// The roof shape's face count, then its scope (see SCOPE_PRINTER).
fn roof_rules(roof: &str) -> String {
    format!("{MASS}Top --> {roof} Roof\nRoof --> print(geometry.nFaces) Scope R.\n{SCOPE_PRINTER}")
}

/// The mesh of the leaf named `R.`: the last leaf, the roof.
fn roof_mesh(g: &Gen) -> &Mesh {
    g.meshes().last().expect("a roof")
}

fn count_up(m: &Mesh) -> usize {
    (0..m.faces.len())
        .filter(|&f| measure::face_normal(m, f).y > 1e-6)
        .count()
}

fn count_vertical(m: &Mesh) -> usize {
    (0..m.faces.len())
        .filter(|&f| measure::face_normal(m, f).y.abs() <= 1e-9)
        .count()
}

/// op_roofGable, "Simple Gable Roof": one roof face per edge of the L
/// (four roof planes and the two pediments at the wing ends) and the base.
/// The overhangs: 2 along the eaves on the roof plane (cos 30 * 2
/// outwards, sin 30 * 2 = 1 down), 1 beyond the gable ends. The scope: y
/// up (the top face's normal), x kept (the top face's first edge, along x),
/// sized to the roof from 9 m (the dropped eaves) to 10 + 2.5 tan 30.
#[test]
fn gable_on_an_l() {
    let g = gen_with(&roof_rules("roofGable(30, 2, 1)"), &Opts::polygon(&l_lot())).ok();
    let p = g.prints();
    assert_eq!(p[0], "7");
    let m = roof_mesh(&g);
    assert_eq!(m.faces.len(), 7);
    assert_eq!(count_up(m), 4);
    assert_eq!(count_vertical(m), 2);
    let (lo, hi) = mesh_bounds(m);
    let out = 2.0 * 30f64.to_radians().cos();
    let ridge = 10.0 + 2.5 * 30f64.to_radians().tan();
    assert_vec_near(lo, [-out, 9.0, -13.0], 1e-9);
    assert_vec_near(hi, [13.0, ridge, out], 1e-9);
    // The top face's pivot has y along -z and z up (Euler angles -90, 0,
    // 0); the roof's scope axes are the world's: x kept, y up, so its
    // angles relative to that pivot are (90, 0, 0) and its origin, the
    // roof's lowest corner (-out, 9, -13), is (-out, 13, -1) in the pivot
    // frame standing at (0, 10, 0).
    let s = scope_line(&p[1]);
    assert_vec_near(s.o, [-90.0, 0.0, 0.0], 1e-9);
    assert_vec_near(s.r, [90.0, 0.0, 0.0], 1e-9);
    assert_vec_near(s.t, [-out, 13.0, -1.0], 1e-9);
    assert_vec_near(s.s, [13.0 + out, ridge - 9.0, 13.0 + out], 1e-9);
}

/// op_roofHip, "Simple Hip Roof": six roof faces on the L plus the base;
/// the overhang of 2 on the roof plane reaches 2 cos 30 beyond every edge.
#[test]
fn hip_on_an_l() {
    let g = gen_with(&roof_rules("roofHip(30, 2)"), &Opts::polygon(&l_lot())).ok();
    let p = g.prints();
    assert_eq!(p[0], "7");
    let m = roof_mesh(&g);
    assert_eq!(count_up(m), 6);
    let out = 2.0 * 30f64.to_radians().cos();
    let ridge = 10.0 + 2.5 * 30f64.to_radians().tan();
    let (lo, hi) = mesh_bounds(m);
    assert_vec_near(lo, [-out, 9.0, -12.0 - out], 1e-9);
    assert_vec_near(hi, [12.0 + out, ridge, out], 1e-9);
    // Without overhang the roof is closed over its base: its volume is the
    // L's hip roof volume, the same as the geometry's own.
    let g = gen_with(&roof_rules("roofHip(30)"), &Opts::polygon(&l_lot())).ok();
    let direct = roof(
        &Mesh::polygon(&l_lot()),
        RoofSlope::Angle(30.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    assert_near(
        measure::volume(roof_mesh(&g)),
        measure::volume(&direct.mesh),
        1e-9,
    );
    assert!(measure::is_closed(roof_mesh(&g)));
    // byHeight: the highest point (the ridge) at the height given, whatever
    // the footprint; the roof's scope is that high.
    for op in [
        "roofHip(byHeight, 4)",
        "roofGable(byHeight, 4)",
        "roofHip(byHeight, 4, 0, true)",
    ] {
        let g = gen_with(&roof_rules(op), &Opts::polygon(&l_lot())).ok();
        assert_near(mesh_bounds(roof_mesh(&g)).1.y, 14.0, 1e-9);
        assert_near(scope_line(&g.prints()[1]).s.y, 4.0, 1e-9);
    }
}

/// The heights of the ridge vertices (above the eaves) of a roof mesh.
fn ridge_heights(m: &Mesh) -> Vec<f64> {
    let mut h: Vec<f64> = m
        .positions
        .iter()
        .map(|p| p.y)
        .filter(|&y| y > 10.0 + 1e-6)
        .collect();
    h.sort_by(f64::total_cmp);
    h.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    h
}

/// op_roofHip and op_roofGable, "Even ... Roof": on a trapezoid the ridge
/// is uneven; `even` sets its vertices to their average height.
#[test]
fn even_roofs_level_the_ridge() {
    let trapezoid = Opts::polygon(&[
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(24.0, 0.0, 0.0),
        DVec3::new(20.0, 0.0, -10.0),
        DVec3::new(2.0, 0.0, -8.0),
    ]);
    for (uneven, even) in [
        ("roofHip(45, 1, false)", "roofHip(45, 1, true)"),
        ("roofGable(30, 1, 1, false)", "roofGable(30, 1, 1, true)"),
    ] {
        let a = gen_with(&roof_rules(uneven), &trapezoid).ok();
        let b = gen_with(&roof_rules(even), &trapezoid).ok();
        let (ha, hb) = (ridge_heights(roof_mesh(&a)), ridge_heights(roof_mesh(&b)));
        assert_eq!(ha.len(), 2, "{uneven}: {ha:?}");
        assert_eq!(hb.len(), 1, "{even}: {hb:?}");
        // The eaves stay where they are.
        assert_near(
            mesh_bounds(roof_mesh(&a)).0.y,
            mesh_bounds(roof_mesh(&b)).0.y,
            1e-9,
        );
    }
}

/// op_roofPyramid, "Simple Pyramid Roof": one triangle per edge of the
/// pentagon plus the base; at 30 degrees the apex is the pentagon's
/// inradius (10 cos 36) times tan 30 above the centre.
#[test]
fn pyramid_on_a_pentagon() {
    let lot = Opts::polygon(&pentagon());
    let g = gen_with(&roof_rules("roofPyramid(30)"), &lot).ok();
    assert_eq!(g.prints()[0], "6");
    let m = roof_mesh(&g);
    assert_eq!(count_up(m), 5);
    let h = 10.0 * 36f64.to_radians().cos() * 30f64.to_radians().tan();
    let (_, hi) = mesh_bounds(m);
    assert_near(hi.y, 10.0 + h, 1e-9);
    let apex = m
        .positions
        .iter()
        .find(|p| (p.y - hi.y).abs() < 1e-9)
        .unwrap();
    assert_vec_near(*apex, [0.0, 10.0 + h, -10.0], 1e-9);
    let g = gen_with(&roof_rules("roofPyramid(byHeight, 5)"), &lot).ok();
    assert_near(mesh_bounds(roof_mesh(&g)).1.y, 15.0, 1e-9);
    let s = scope_line(&g.prints()[1]);
    assert_near(s.s.y, 5.0, 1e-9);
}

/// op_roofShed, "Simple Shed Roof": one plane rising from the indexed edge
/// (here the front, index 0, and the left side, index 5, of the L); one
/// side face per edge that has a height (the edge the roof rises from has
/// none), the top and the base.
#[test]
fn shed_on_an_l() {
    let lot = Opts::polygon(&l_lot());
    let g = gen_with(&roof_rules("roofShed(10)"), &lot).ok();
    assert_eq!(g.prints()[0], "7");
    let m = roof_mesh(&g);
    assert_near(
        mesh_bounds(m).1.y,
        10.0 + 12.0 * 10f64.to_radians().tan(),
        1e-9,
    );
    assert_eq!(count_vertical(m), 5);
    let g = gen_with(&roof_rules("roofShed(byHeight, 3, 5)"), &lot).ok();
    let m = roof_mesh(&g);
    assert_near(mesh_bounds(m).1.y, 13.0, 1e-9);
    // Rising from x = 0 towards +x: the highest points are at x = 12.
    let top: Vec<&DVec3> = m.positions.iter().filter(|p| p.y > 12.999).collect();
    assert!(!top.is_empty() && top.iter().all(|p| (p.x - 12.0).abs() < 1e-9));
    // Index -1 wraps to the last edge (5): the same roof.
    let w = gen_with(&roof_rules("roofShed(byHeight, 3, -1)"), &lot).ok();
    assert_near(measure::volume(roof_mesh(&w)), measure::volume(m), 1e-9);
}

/// op_roofRidge, "Scope and trim planes" and "Ridge orientation": the ridge
/// runs along the scope's x axis; turning the scope by 90 degrees about
/// the face normal (the top face's z axis) turns the ridge across the lot.
#[test]
fn ridge_follows_the_scope_x_axis() {
    let g = gen_with(&roof_rules("roofRidge(byAngle, 30)"), &Opts::default()).ok();
    let m = roof_mesh(&g);
    // Along x over the 30 m depth: ridge 15 tan 30 high, at z = -15.
    let h = 15.0 * 30f64.to_radians().tan();
    assert_near(mesh_bounds(m).1.y, 10.0 + h, 1e-9);
    let ridge: Vec<&DVec3> = m
        .positions
        .iter()
        .filter(|p| p.y > 10.0 + h - 1e-9)
        .collect();
    assert!(ridge.iter().all(|p| (p.z + 15.0).abs() < 1e-9));
    // Two roof planes, the base and the two gable walls (the front and
    // back edges have no height, so no wall).
    assert_eq!(m.faces.len(), 5);
    assert_eq!(count_up(m), 2);
    assert_eq!(count_vertical(m), 2);
    let g = gen_with(
        &roof_rules("rotateScope(0, 0, 90) roofRidge(byAngle, 30)"),
        &Opts::default(),
    )
    .ok();
    let h = 10.0 * 30f64.to_radians().tan();
    let m = roof_mesh(&g);
    assert_near(mesh_bounds(m).1.y, 10.0 + h, 1e-9);
    let ridge: Vec<&DVec3> = m
        .positions
        .iter()
        .filter(|p| p.y > 10.0 + h - 1e-9)
        .collect();
    assert!(ridge.iter().all(|p| (p.x - 10.0).abs() < 1e-9));
}

/// The comp(e) roof selectors, counted, for a roof made by an operation.
fn edge_classes(roof_op: &str, lot: &[DVec3]) -> [usize; 4] {
    let src = format!(
        "{MASS}Top --> {roof_op} comp(e) {{ eave : print(\"eave\") | hip : print(\"hip\") | valley : print(\"valley\") | ridge : print(\"ridge\") }}\n"
    );
    let g = gen_with(&src, &Opts::polygon(lot)).ok();
    let p = g.prints();
    ["eave", "hip", "valley", "ridge"].map(|k| p.iter().filter(|l| *l == k).count())
}

/// The same counts from the roof geometry's own classification.
fn geometry_classes(kind: RoofKind, lot: &[DVec3]) -> [usize; 4] {
    let r = roof(&Mesh::polygon(lot), RoofSlope::Angle(30.0), kind);
    [
        RoofEdgeKind::Eave,
        RoofEdgeKind::Hip,
        RoofEdgeKind::Valley,
        RoofEdgeKind::Ridge,
    ]
    .map(|k| r.edge_kinds.iter().filter(|&&x| x == k).count())
}

/// op_comp, "Roof Edges": on roofs built by the roof operations the edge
/// selectors take what the roof geometry classifies (eaves along the
/// footprint, hips from the corners, valleys at concave corners, ridges),
/// also with overhangs and after the roof is moved.
#[test]
fn comp_roof_edges_agree_with_the_roof_geometry() {
    let rect: Vec<DVec3> = [(0.0, 0.0), (20.0, 0.0), (20.0, -30.0), (0.0, -30.0)]
        .iter()
        .map(|&(x, z)| DVec3::new(x, 0.0, z))
        .collect();
    let hip = RoofKind::Hip {
        overhang: 0.0,
        even: false,
    };
    let gable = RoofKind::Gable {
        overhang_x: 0.0,
        overhang_y: 0.0,
        even: false,
        index: None,
    };
    let cases: [(&str, RoofKind, &[DVec3], [usize; 4]); 7] = [
        ("roofHip(30)", hip, &rect, [4, 4, 0, 1]),
        ("roofGable(30)", gable, &rect, [2, 0, 0, 1]),
        (
            "roofPyramid(30)",
            RoofKind::Pyramid,
            &pentagon(),
            [5, 5, 0, 0],
        ),
        ("roofHip(30)", hip, &l_lot(), [6, 5, 1, 2]),
        ("roofGable(30)", gable, &l_lot(), [4, 1, 1, 2]),
        ("roofHip(30)", hip, &u_lot(), [8, 6, 2, 3]),
        ("roofGable(30)", gable, &u_lot(), [6, 2, 2, 3]),
    ];
    for (op, kind, lot, expected) in cases {
        let engine = edge_classes(op, lot);
        assert_eq!(engine, geometry_classes(kind, lot), "{op} on {lot:?}");
        assert_eq!(engine, expected, "{op} on {lot:?}");
    }
    // With an overhang the eaves are the lowest border edges; moved and
    // turned about the vertical, the classes stay. ("Up" is the world's:
    // a roof tilted out of the horizontal is classified against it.)
    assert_eq!(edge_classes("roofHip(30, 1)", &rect), [4, 4, 0, 1],);
    assert_eq!(
        edge_classes("t(3, 2, 1) r(0, 0, 30) roofHip(30)", &l_lot()),
        [6, 5, 1, 2],
    );
}

/// op_comp: eaves run anti-clockwise around the footprint (each from a
/// lot corner to the next one counter-clockwise), hips upwards (from a
/// corner at the eave height to the ridge).
#[test]
fn roof_edge_directions() {
    let show = "print(\"{} \" + pivot.px + \" \" + pivot.py + \" \" + pivot.pz + \" \" + pivot.ox + \" \" + pivot.oy + \" \" + pivot.oz + \" \" + scope.sx)";
    let src = format!(
        "{MASS}Top --> roofHip(45) comp(e) {{ eave : {} | hip : {} }}\n",
        show.replace("{}", "eave"),
        show.replace("{}", "hip")
    );
    let g = gen(&src).ok();
    // Start and end of every edge: pivot origin, then along its x axis.
    let ends = |kind: &str| -> Vec<(DVec3, DVec3)> {
        g.prints()
            .iter()
            .filter(|l| l.starts_with(kind))
            .map(|l| {
                let v = numbers(l);
                let start = DVec3::new(v[0], v[1], v[2]);
                let x = mat_mul(&euler_matrix([v[3], v[4], v[5]]), DVec3::X);
                (start, start + x * v[6])
            })
            .collect()
    };
    let corners = [
        DVec3::new(0.0, 10.0, 0.0),
        DVec3::new(20.0, 10.0, 0.0),
        DVec3::new(20.0, 10.0, -30.0),
        DVec3::new(0.0, 10.0, -30.0),
    ];
    let eaves = ends("eave");
    assert_eq!(eaves.len(), 4);
    for (a, b) in eaves {
        let i = corners
            .iter()
            .position(|c| (*c - a).length() < 1e-9)
            .expect("an eave starts at a corner");
        assert!((corners[(i + 1) % 4] - b).length() < 1e-9, "{a} -> {b}");
    }
    let hips = ends("hip");
    assert_eq!(hips.len(), 4);
    for (a, b) in hips {
        assert_near(a.y, 10.0, 1e-9);
        assert_near(b.y, 20.0, 1e-9);
    }
}

/// Degenerate footprints (collinear points, repeated points, a polygon
/// touching itself, no area) give a roof or a warning, never an error.
#[test]
fn degenerate_footprints() {
    let p = |pts: &[(f64, f64)]| -> Vec<DVec3> {
        pts.iter().map(|&(x, z)| DVec3::new(x, 0.0, z)).collect()
    };
    let lots = [
        p(&[(0.0, 0.0), (5.0, 0.0), (10.0, 0.0)]),
        p(&[
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 0.0),
            (10.0, -8.0),
            (0.0, -8.0),
        ]),
        p(&[
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, -5.0),
            (5.0, -5.0),
            (5.0, -5.0 + 1e-12),
            (0.0, -5.0),
        ]),
        // Two squares touching at one corner (a figure eight).
        p(&[
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, -5.0),
            (10.0, -5.0),
            (10.0, -10.0),
            (5.0, -10.0),
            (5.0, -5.0),
            (0.0, -5.0),
        ]),
    ];
    for lot in &lots {
        for op in [
            "roofHip(30)",
            "roofHip(30, 1, true)",
            "roofGable(30, 1, 1)",
            "roofGable(30, 0, 0, false, 1)",
            "roofPyramid(30)",
            "roofShed(20, 2)",
            "roofRidge(byHeight, 3)",
        ] {
            let src = format!("Lot --> {op} R.\n");
            let g = gen_with(&src, &Opts::polygon(lot));
            assert!(g.errors.is_empty(), "{op} on {lot:?}: {:?}", g.errors);
            let h = g.bounds().1.y;
            assert!(h.is_finite() || g.meshes().is_empty(), "{op}");
        }
    }
}
