use super::*;
use crate::measure::{loop_newell, volume};

/// A footprint in the x-z plane (normal +y) from (x, z) pairs given
/// counter-clockwise seen from above.
fn footprint(loops: &[&[(f64, f64)]]) -> Mesh {
    let mut m = Mesh::new();
    let mut ids: Vec<Vec<u32>> = Vec::new();
    for l in loops {
        let mut v = Vec::new();
        for &(x, z) in l.iter() {
            v.push(m.positions.len() as u32);
            m.positions.push(DVec3::new(x, 0.0, z));
        }
        ids.push(v);
    }
    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
    m.add_face(&refs, 0);
    m
}

/// Counter-clockwise seen from +y: x to the right, z towards the viewer,
/// so the loop runs through decreasing z.
fn rect(w: f64, d: f64) -> Mesh {
    footprint(&[&[(0.0, 0.0), (w, 0.0), (w, -d), (0.0, -d)]])
}

fn projected_area(m: &Mesh, f: usize, up: DVec3) -> f64 {
    let loops = m.face_loops(f);
    let mut a = loop_newell(m, loops[0]).dot(up);
    for &h in &loops[1..] {
        a += loop_newell(m, h).dot(up);
    }
    0.5 * a
}

fn count(r: &Roof, k: RoofEdgeKind) -> usize {
    r.edge_kinds.iter().filter(|&&x| x == k).count()
}

fn assert_planar(m: &Mesh, f: usize) {
    let n = face_normal(m, f);
    let p0 = m.positions[m.corners[m.outer_loop(f).start as usize] as usize];
    for &l in m.face_loops(f) {
        for p in m.loop_points(l) {
            assert!((p - p0).dot(n).abs() < 1e-9, "face {f} not planar");
        }
    }
}

#[test]
fn gable_on_a_rectangle_matches_the_comp_order() {
    // Street front (edge 0) is the short side: gables on edges 0 and 2.
    let r = roof(
        &rect(6.0, 10.0),
        RoofSlope::Angle(30.0),
        RoofKind::Gable {
            overhang_x: 0.0,
            overhang_y: 0.0,
            even: false,
            index: None,
        },
    );
    assert!(r.failed.is_empty());
    use RoofFaceRole::*;
    assert_eq!(r.roles, vec![Bottom, Side, Top, Side, Top]);
    let h = 3.0 * 30f64.to_radians().tan();
    let top = r.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
    assert!((top - h).abs() < 1e-12);
    let area = |f| crate::measure::face_area(&r.mesh, f);
    assert!((area(1) - 3.0 * h).abs() < 1e-9);
    assert!((area(2) - 10.0 * 3.0 / 30f64.to_radians().cos()).abs() < 1e-9);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert!((volume(&r.mesh) - 6.0 * h / 2.0 * 10.0).abs() < 1e-9);
    assert_eq!(count(&r, RoofEdgeKind::Eave), 2);
    assert_eq!(count(&r, RoofEdgeKind::Ridge), 1);
    assert_eq!(count(&r, RoofEdgeKind::Hip), 0);
    assert_eq!(count(&r, RoofEdgeKind::Valley), 0);
    // The pediments are vertical, the roof planes project onto the footprint.
    assert!(face_normal(&r.mesh, 1).y.abs() < 1e-12);
    let sum: f64 = (1..5).map(|f| projected_area(&r.mesh, f, DVec3::Y)).sum();
    assert!((sum - 60.0).abs() < 1e-9);
    // A wide lot: the ridge turns, gables on edges 1 and 3.
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(30.0),
        RoofKind::Gable {
            overhang_x: 0.0,
            overhang_y: 0.0,
            even: false,
            index: None,
        },
    );
    assert_eq!(r.roles, vec![Bottom, Top, Side, Top, Side]);
    // With an index the ridge follows that edge's direction.
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(30.0),
        RoofKind::Gable {
            overhang_x: 0.0,
            overhang_y: 0.0,
            even: false,
            index: Some(1),
        },
    );
    assert_eq!(r.roles, vec![Bottom, Side, Top, Side, Top]);
}

#[test]
fn hip_on_a_rectangle() {
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(45.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    use RoofFaceRole::*;
    assert_eq!(r.roles, vec![Bottom, Top, Top, Top, Top]);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    // Ridge 4 long at height 3: volume 3 * 6 * 4 / 2 + 3 * 36 / 3.
    assert!((volume(&r.mesh) - 72.0).abs() < 1e-9);
    assert_eq!(count(&r, RoofEdgeKind::Eave), 4);
    assert_eq!(count(&r, RoofEdgeKind::Hip), 4);
    assert_eq!(count(&r, RoofEdgeKind::Ridge), 1);
    // Hips point upwards.
    for (e, k) in r.edge_kinds.iter().enumerate() {
        if *k == RoofEdgeKind::Hip {
            let [a, b] = r.edge_ends[e];
            assert!(r.mesh.positions[b as usize].y > r.mesh.positions[a as usize].y);
        }
    }
    // byHeight: the same roof scaled to height 1.5.
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Height(1.5),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    assert!((volume(&r.mesh) - 36.0).abs() < 1e-9);
}

#[test]
fn hip_with_overhang_extends_the_planes() {
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(45.0),
        RoofKind::Hip {
            overhang: 1.0,
            even: false,
        },
    );
    let c = 45f64.to_radians().cos();
    let low = r.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::min);
    assert!((low + c).abs() < 1e-12);
    let sum: f64 = (1..5).map(|f| projected_area(&r.mesh, f, DVec3::Y)).sum();
    assert!((sum - (10.0 + 2.0 * c) * (6.0 + 2.0 * c)).abs() < 1e-9);
    // Same ridge height as without overhang.
    let top = r.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
    assert!((top - 3.0).abs() < 1e-9);
    assert_eq!(count(&r, RoofEdgeKind::Eave), 4);
}

#[test]
fn hip_on_an_l_has_a_valley() {
    let m = footprint(&[&[
        (0.0, 0.0),
        (10.0, 0.0),
        (10.0, -4.0),
        (4.0, -4.0),
        (4.0, -10.0),
        (0.0, -10.0),
    ]]);
    let r = roof(
        &m,
        RoofSlope::Angle(30.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    assert_eq!(r.mesh.faces.len(), 7);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert_eq!(count(&r, RoofEdgeKind::Valley), 1);
    assert_eq!(count(&r, RoofEdgeKind::Eave), 6);
    let sum: f64 = (1..7).map(|f| projected_area(&r.mesh, f, DVec3::Y)).sum();
    assert!((sum - 64.0).abs() < 1e-9);
    for f in 0..7 {
        assert_planar(&r.mesh, f);
    }
    // Gable: the two wing ends become pediments.
    let r = roof(
        &m,
        RoofSlope::Angle(30.0),
        RoofKind::Gable {
            overhang_x: 0.0,
            overhang_y: 0.0,
            even: false,
            index: None,
        },
    );
    let sides: Vec<usize> = (0..r.roles.len())
        .filter(|&f| r.roles[f] == RoofFaceRole::Side)
        .collect();
    assert_eq!(sides, vec![2, 5]);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
}

#[test]
fn even_hip_on_a_trapezoid_levels_the_ridge() {
    let m = footprint(&[&[(0.0, 0.0), (12.0, 0.0), (10.0, -6.0), (0.0, -8.0)]]);
    let uneven = roof(
        &m,
        RoofSlope::Angle(45.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    let even = roof(
        &m,
        RoofSlope::Angle(45.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: true,
        },
    );
    let tops = |r: &Roof| -> Vec<f64> {
        let mut v: Vec<f64> = r
            .mesh
            .positions
            .iter()
            .map(|p| p.y)
            .filter(|&y| y > 1e-9)
            .collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        v
    };
    assert!(tops(&uneven).len() >= 2);
    assert_eq!(tops(&even).len(), 1);
    let avg: f64 = tops(&uneven).iter().sum::<f64>() / tops(&uneven).len() as f64;
    assert!((tops(&even)[0] - avg).abs() < 1e-9 || tops(&uneven).len() != 2);
}

#[test]
fn pyramid_shed_and_ridge() {
    let r = roof(&rect(4.0, 4.0), RoofSlope::Angle(45.0), RoofKind::Pyramid);
    assert_eq!(r.mesh.faces.len(), 5);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert!((volume(&r.mesh) - 16.0 * 2.0 / 3.0).abs() < 1e-9);
    assert_eq!(count(&r, RoofEdgeKind::Eave), 4);
    assert_eq!(count(&r, RoofEdgeKind::Hip), 4);

    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(45.0),
        RoofKind::Shed { index: 0 },
    );
    use RoofFaceRole::*;
    assert_eq!(r.roles, vec![Bottom, Top, SideOuter, SideOuter, SideOuter]);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert!((volume(&r.mesh) - 180.0).abs() < 1e-9);
    let src: Vec<u32> = r.source_edge[2..].iter().map(|s| s.unwrap().edge).collect();
    assert_eq!(src, vec![1, 2, 3]);
    // Rising from edge 1 instead, by height.
    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Height(2.0),
        RoofKind::Shed { index: 1 },
    );
    assert!((volume(&r.mesh) - 60.0).abs() < 1e-9);

    let r = roof(
        &rect(10.0, 6.0),
        RoofSlope::Angle(45.0),
        RoofKind::Ridge { ridge: DVec3::X },
    );
    assert_eq!(r.roles, vec![Bottom, Top, Top, SideOuter, SideOuter]);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert!((volume(&r.mesh) - 90.0).abs() < 1e-9);
    assert_eq!(count(&r, RoofEdgeKind::Ridge), 1);
}

#[test]
fn shed_with_a_hole_has_inner_sides() {
    let m = footprint(&[
        &[(0.0, 0.0), (10.0, 0.0), (10.0, -10.0), (0.0, -10.0)],
        &[(3.0, -3.0), (3.0, -7.0), (7.0, -7.0), (7.0, -3.0)],
    ]);
    let r = roof(&m, RoofSlope::Angle(45.0), RoofKind::Shed { index: 0 });
    let inner = r
        .roles
        .iter()
        .filter(|&&x| x == RoofFaceRole::SideInner)
        .count();
    assert_eq!(inner, 4);
    assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    assert!((volume(&r.mesh) - (500.0 - 16.0 * 5.0)).abs() < 1e-9);
    let h = roof(
        &m,
        RoofSlope::Angle(45.0),
        RoofKind::Hip {
            overhang: 0.0,
            even: false,
        },
    );
    assert_eq!(h.mesh.faces.len(), 9);
    assert!(Topology::new(&h.mesh).is_closed(&h.mesh));
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Hip and gable roofs on random concave footprints (with a hole): every
    /// roof face is planar, projects onto the footprint with areas adding up
    /// to its area, each edge owns one face, and roof + base is closed.
    #[test]
    fn random_footprints(n in 5usize..30, jit in prop::collection::vec(0.0f64..0.8, 30),
                         radii in prop::collection::vec(0.55f64..1.0, 30),
                         hole in any::<bool>(), gable in any::<bool>(), angle in 15.0f64..60.0) {
        let pts: Vec<(f64, f64)> = (0..n).map(|i| {
            let a = (i as f64 + jit[i]) * std::f64::consts::TAU / n as f64;
            (a.cos() * radii[i] * 10.0, -a.sin() * radii[i] * 10.0)
        }).collect();
        let hole_pts: Vec<(f64, f64)> = (0..4).rev().map(|i| {
            let a = i as f64 * std::f64::consts::FRAC_PI_2 + 0.3;
            (a.cos() * 2.0, -a.sin() * 2.0)
        }).collect();
        let m = if hole && n >= 8 { footprint(&[&pts, &hole_pts]) } else { footprint(&[&pts]) };
        let kind = if gable {
            RoofKind::Gable { overhang_x: 0.0, overhang_y: 0.0, even: false, index: None }
        } else {
            RoofKind::Hip { overhang: 0.0, even: false }
        };
        let r = roof(&m, RoofSlope::Angle(angle), kind);
        prop_assert!(r.failed.is_empty(), "{:?}", r.failed);
        let edges: usize = m.face_loops(0).iter().map(|l| l.len as usize).sum();
        prop_assert_eq!(r.mesh.faces.len(), 1 + edges);
        let area = crate::measure::face_area(&m, 0);
        let mut sum = 0.0;
        for f in 1..r.mesh.faces.len() {
            assert_planar(&r.mesh, f);
            let a = projected_area(&r.mesh, f, DVec3::Y);
            prop_assert!(a > -1e-9);
            sum += a;
        }
        prop_assert!((sum - area).abs() < 1e-9 * area);
        prop_assert!(Topology::new(&r.mesh).is_closed(&r.mesh));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Degenerate input never panics and ends quickly: random points on a
    /// coarse grid (collinear runs, repeated points, zero-length edges,
    /// spikes, self-intersections), through every roof, offset and setback.
    #[test]
    fn degenerate_footprints_do_not_panic(pts in prop::collection::vec((0i32..4, 0i32..4), 0..14),
                                          hole in prop::collection::vec((0i32..4, 0i32..4), 0..5),
                                          d in -2.0f64..2.0) {
        let p: Vec<(f64, f64)> = pts.iter().map(|&(x, z)| (x as f64 * 2.5, -z as f64 * 2.5)).collect();
        let h: Vec<(f64, f64)> = hole.iter().map(|&(x, z)| (x as f64 * 2.5, -z as f64 * 2.5)).collect();
        let m = if h.len() >= 3 { footprint(&[&p, &h]) } else { footprint(&[&p]) };
        let started = std::time::Instant::now();
        for kind in [
            RoofKind::Hip { overhang: 0.5, even: true },
            RoofKind::Gable { overhang_x: 0.0, overhang_y: 0.0, even: false, index: None },
            RoofKind::Gable { overhang_x: 1.0, overhang_y: 1.0, even: false, index: Some(2) },
            RoofKind::Pyramid,
            RoofKind::Shed { index: 1 },
            RoofKind::Ridge { ridge: DVec3::X },
        ] {
            let _ = roof(&m, RoofSlope::Angle(30.0), kind);
            let _ = roof(&m, RoofSlope::Height(2.0), kind);
        }
        let _ = crate::setback::offset(&m, d);
        let _ = crate::setback::setback(&m, &[d.abs(), 0.0, 1.0, d]);
        let _ = crate::setback::setback_to_area(&m, 3.0, &[true; 20], None, None);
        prop_assert!(started.elapsed().as_secs_f64() < 2.0);
    }

    /// Nearly parallel and nearly collinear edges.
    #[test]
    fn nearly_collinear(eps in prop::collection::vec(-1e-7f64..1e-7, 8), k in 3usize..8) {
        let mut p: Vec<(f64, f64)> = Vec::new();
        for i in 0..=k {
            p.push((i as f64 * 10.0 / k as f64, eps[i % 8]));
        }
        p.push((10.0, -5.0 + eps[1]));
        p.push((0.0, -5.0 + eps[2]));
        let m = footprint(&[&p]);
        let r = roof(&m, RoofSlope::Angle(45.0), RoofKind::Hip { overhang: 0.0, even: false });
        if r.failed.is_empty() {
            let sum: f64 = (1..r.mesh.faces.len()).map(|f| projected_area(&r.mesh, f, DVec3::Y)).sum();
            prop_assert!((sum - crate::measure::face_area(&m, 0)).abs() < 1e-6);
        }
    }
}
