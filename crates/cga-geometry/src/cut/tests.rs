//! Tests of the cut.

use super::*;
use crate::measure::{face_area, mesh_area, volume};
use crate::topology::Topology;
use glam::DVec2;
use proptest::prelude::*;

/// One edge crossed by many planes (the vertical edges of a box split
/// into thousands of floors) must spread over the crossing table: the
/// longest run of occupied slots stays short, so lookups stay O(1).
#[test]
fn crossings_of_one_edge_spread_over_the_table() {
    let mut t = CrossingTable::default();
    t.clear();
    let key = (7u64 << 32) | 11;
    for plane in 0..10_000u32 {
        match t.find(key, plane) {
            Err(slot) => t.insert_at(slot, key, plane, plane),
            Ok(_) => panic!("plane {plane} found before it was inserted"),
        }
    }
    for plane in (0..10_000u32).step_by(97) {
        assert_eq!(t.find(key, plane), Ok(plane));
    }
    let (mut run, mut longest) = (0, 0);
    for s in &t.slots {
        run = if s.3 == t.generation { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    assert!(
        longest < 64,
        "longest probe run {longest} of {}",
        t.slots.len()
    );
}

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// A prism over the polygon `outer` (x, z pairs, counter-clockwise seen
/// from above) with clockwise `holes`, from y = 0 to y = h, outward
/// normals, positions shared. Every corner has UV (1, 1) so that cap
/// corners (UV 0, 0) can be told apart.
pub(crate) fn prism(outer: &[(f64, f64)], holes: &[Vec<(f64, f64)>], h: f64) -> Mesh {
    let mut m = Mesh::new();
    let mut rings: Vec<Vec<u32>> = Vec::new();
    for ring in std::iter::once(outer).chain(holes.iter().map(|r| r.as_slice())) {
        let base = m.positions.len() as u32;
        for &(x, z) in ring {
            m.positions.push(v(x, 0.0, z));
        }
        rings.push((base..base + ring.len() as u32).collect());
    }
    let nb = m.positions.len() as u32;
    for i in 0..nb as usize {
        let p = m.positions[i];
        m.positions.push(p + DVec3::Y * h);
    }
    m.uvs[0] = Some(Vec::new());
    // bottom: reversed rings
    let bottom: Vec<Vec<u32>> = rings
        .iter()
        .map(|r| r.iter().rev().copied().collect())
        .collect();
    let refs: Vec<&[u32]> = bottom.iter().map(|r| r.as_slice()).collect();
    m.add_face(&refs, 0);
    let top: Vec<Vec<u32>> = rings
        .iter()
        .map(|r| r.iter().map(|i| i + nb).collect())
        .collect();
    let refs: Vec<&[u32]> = top.iter().map(|r| r.as_slice()).collect();
    m.add_face(&refs, 0);
    for r in &rings {
        for k in 0..r.len() {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            m.add_face(&[&[a, b, b + nb, a + nb]], 0);
        }
    }
    let n = m.corners.len();
    m.uvs[0] = Some(vec![DVec2::ONE; n]);
    m
}

fn unit_box() -> Mesh {
    prism(&[(0., 0.), (1., 0.), (1., -1.), (0., -1.)], &[], 1.0)
}

fn is_cap(m: &Mesh, f: usize) -> bool {
    let uv = m.uvs[0].as_ref().unwrap();
    m.face_loops(f)
        .iter()
        .all(|&l| m.loop_corners(l).all(|c| uv[c] == DVec2::ZERO))
}

fn non_cap_area(m: &Mesh) -> f64 {
    (0..m.faces.len())
        .filter(|&f| !is_cap(m, f))
        .map(|f| face_area(m, f))
        .sum()
}

fn closed(m: &Mesh) -> bool {
    Topology::new(m).is_closed(m)
}

fn no_unused_positions(m: &Mesh) -> bool {
    let mut used = vec![false; m.positions.len()];
    for &c in &m.corners {
        used[c as usize] = true;
    }
    used.iter().all(|&u| u)
}

#[test]
fn box_cut_in_the_middle() {
    let b = unit_box();
    let (lo, hi) = cut_by_plane(&b, DVec3::Y, 0.25);
    assert!((volume(&lo) - 0.25).abs() < 1e-12);
    assert!((volume(&hi) - 0.75).abs() < 1e-12);
    assert!(closed(&lo) && closed(&hi));
    assert_eq!(lo.faces.len(), 6);
    assert_eq!(hi.faces.len(), 6);
    assert_eq!(lo.positions.len(), 8);
    assert!(no_unused_positions(&lo) && no_unused_positions(&hi));
    // The cap of the lower part faces up and has area 1.
    let cap = lo.faces.len() - 1;
    assert!(is_cap(&lo, cap));
    assert_eq!(face_normal(&lo, cap), DVec3::Y);
    assert_eq!(face_area(&lo, cap), 1.0);
    assert_eq!(face_normal(&hi, hi.faces.len() - 1), -DVec3::Y);
    // Side faces keep their UVs, material and order (bottom first).
    assert!(!is_cap(&lo, 0));
    assert_eq!(face_normal(&lo, 0), -DVec3::Y);
    assert!((mesh_area(&lo) - (1.0 + 1.0 + 4.0 * 0.25)).abs() < 1e-12);
}

#[test]
fn extruded_lot_split_into_floors() {
    // Lot 20 x 30 extruded by 10, split(y) at 3, 6, 9: four closed
    // floors, the last 1 m high.
    let lot = Mesh::polygon(&[
        v(0., 0., 0.),
        v(20., 0., 0.),
        v(20., 0., -30.),
        v(0., 0., -30.),
    ]);
    let mass = crate::extrude::extrude(&lot, crate::extrude::Extrusion::FaceNormal, 10.0);
    let floors = split_along_axis(&mass, 1, &[3.0, 6.0, 9.0]);
    let vols: Vec<f64> = floors.iter().map(volume).collect();
    assert_eq!(
        vols.iter().map(|v| v.round()).collect::<Vec<_>>(),
        vec![1800.0, 1800.0, 1800.0, 600.0]
    );
    for (i, f) in floors.iter().enumerate() {
        assert!(closed(f), "floor {i}");
        assert_eq!(f.faces.len(), 6);
        assert_eq!(f.positions.len(), 8);
        // Side faces keep their order: the front (+z) comes right after
        // the bottom and top (or caps) of the original mass.
        assert!(f.faces.iter().all(|x| x.loop_count == 1));
    }
    // The ground floor: original bottom, then the 4 sides, then the cap.
    assert_eq!(face_normal(&floors[0], 0), -DVec3::Y);
    assert_eq!(face_normal(&floors[0], 1), DVec3::Z);
    assert_eq!(face_normal(&floors[0], 5), DVec3::Y);
    // The front facade split into 4 tiles along x: open, area kept.
    let facade = Mesh::polygon(&[
        v(0., 0., 0.),
        v(20., 0., 0.),
        v(20., 10., 0.),
        v(0., 10., 0.),
    ]);
    let tiles = split_along_axis(&facade, 0, &[5.0, 10.0, 15.0]);
    assert!(tiles
        .iter()
        .all(|t| mesh_area(t) == 50.0 && t.faces.len() == 1));
}

#[test]
fn cut_at_faces_lying_in_the_plane() {
    let b = unit_box();
    // At the top face: everything below, nothing above, no caps.
    let (lo, hi) = cut_by_plane(&b, DVec3::Y, 1.0);
    assert_eq!(lo.faces.len(), 6);
    assert!(hi.is_empty() && hi.positions.is_empty());
    // At the bottom face: everything above.
    let (lo, hi) = cut_by_plane(&b, DVec3::Y, 0.0);
    assert!(lo.is_empty());
    assert_eq!(hi.faces.len(), 6);
    // Within tolerance of the top: still no sliver.
    let (lo, hi) = cut_by_plane(&b, DVec3::Y, 1.0 - 1e-13);
    assert_eq!(lo.faces.len(), 6);
    assert!(hi.is_empty());
}

#[test]
fn diagonal_cut_through_edges() {
    // The plane x - z = 1 contains the vertical edges at (1, 0) and
    // (0, -1): it cuts the box into two triangular prisms.
    let b = unit_box();
    let (lo, hi) = cut_by_plane(&b, v(1.0, 0.0, -1.0), 1.0);
    assert!((volume(&lo) - 0.5).abs() < 1e-12, "{}", volume(&lo));
    assert!((volume(&hi) - 0.5).abs() < 1e-12);
    assert!(closed(&lo) && closed(&hi));
    assert_eq!(lo.faces.len(), 5);
    assert_eq!(hi.faces.len(), 5);
    assert_eq!(lo.positions.len(), 6);
    let cap = lo.faces.len() - 1;
    assert!((face_area(&lo, cap) - 2f64.sqrt()).abs() < 1e-12);
}

#[test]
fn hollow_tube_gives_ring_caps() {
    let outer = [(0., 0.), (4., 0.), (4., -4.), (0., -4.)];
    let hole = vec![(1., -1.), (1., -3.), (3., -3.), (3., -1.)];
    let tube = prism(&outer, &[hole], 2.0);
    assert!((volume(&tube) - 24.0).abs() < 1e-12);
    // Horizontal cut: ring caps with one hole each.
    let (lo, hi) = cut_by_plane(&tube, DVec3::Y, 0.5);
    assert!((volume(&lo) - 6.0).abs() < 1e-12);
    assert!((volume(&hi) - 18.0).abs() < 1e-12);
    assert!(closed(&lo) && closed(&hi));
    let cap = lo.faces.len() - 1;
    assert!(is_cap(&lo, cap));
    assert_eq!(lo.faces[cap].loop_count, 2);
    assert_eq!(face_area(&lo, cap), 12.0);
    // Vertical cut through the hole: the bottom and top faces' hole
    // becomes part of the pieces' outlines; caps are two rectangles.
    let parts = split_along_axis(&tube, 0, &[2.0]);
    assert!((volume(&parts[0]) - 12.0).abs() < 1e-12);
    assert!((volume(&parts[1]) - 12.0).abs() < 1e-12);
    assert!(closed(&parts[0]) && closed(&parts[1]));
    let caps: Vec<usize> = (0..parts[0].faces.len())
        .filter(|&f| is_cap(&parts[0], f))
        .collect();
    assert_eq!(caps.len(), 2);
    for f in caps {
        assert_eq!(face_area(&parts[0], f), 2.0);
        assert_eq!(face_normal(&parts[0], f), DVec3::X);
    }
    assert!(parts[0].faces.iter().all(|f| f.loop_count == 1));
}

#[test]
fn part_above_is_the_capped_part_without_its_caps() {
    // A tube cut across its hole and at an angle: the part above has the
    // faces of `cut_by_plane`'s, in the same order, with the same corners,
    // positions and attributes, less the caps that would close it.
    let outer = [(0., 0.), (4., 0.), (4., -4.), (0., -4.)];
    let hole = vec![(1., -1.), (1., -3.), (3., -3.), (3., -1.)];
    let tube = prism(&outer, &[hole], 2.0);
    for (n, offset) in [
        (DVec3::Y, 0.5),
        (DVec3::new(1.0, 0.5, 0.25), 2.0),
        (DVec3::new(0.0, 0.0, -2.0), 3.0),
    ] {
        let (_, capped) = cut_by_plane(&tube, n, offset);
        let open = part_above_plane(&tube, n, offset);
        let caps = (0..capped.faces.len())
            .filter(|&f| is_cap(&capped, f))
            .count();
        assert!(caps > 0, "plane {n} {offset}");
        assert_eq!(open.faces.len(), capped.faces.len() - caps);
        assert!((0..open.faces.len()).all(|f| !is_cap(&open, f)));
        // Caps come last: the faces before them are the open part's.
        let kept = open.faces.len();
        assert_eq!(open.faces[..], capped.faces[..kept]);
        let corners = capped.loops[..open.loops.len()]
            .iter()
            .map(|l| l.len as usize)
            .sum::<usize>();
        assert_eq!(open.loops[..], capped.loops[..open.loops.len()]);
        assert_eq!(open.corners[..], capped.corners[..corners]);
        assert_eq!(open.positions[..], capped.positions[..open.positions.len()]);
        assert_eq!(
            open.uvs[0].as_ref().unwrap()[..],
            capped.uvs[0].as_ref().unwrap()[..corners]
        );
        assert!(no_unused_positions(&open));
        assert!((non_cap_area(&open) - non_cap_area(&capped)).abs() < 1e-12);
    }
    // Open meshes get no caps either way; a zero normal leaves nothing.
    let quad = Mesh::polygon(&[v(0., 0., 0.), v(2., 0., 0.), v(2., 0., -2.), v(0., 0., -2.)]);
    assert_eq!(
        part_above_plane(&quad, DVec3::X, 1.0),
        cut_by_plane(&quad, DVec3::X, 1.0).1
    );
    assert!(part_above_plane(&quad, DVec3::ZERO, 1.0).faces.is_empty());
}

#[test]
fn concave_u_gives_two_pieces_above() {
    // A U open to the back (-z): arms at x in [0,1] and [2,3].
    let u = [
        (0., 0.),
        (3., 0.),
        (3., -3.),
        (2., -3.),
        (2., -1.),
        (1., -1.),
        (1., -3.),
        (0., -3.),
    ];
    let m = prism(&u, &[], 1.0);
    let total = volume(&m);
    assert!((total - 7.0).abs() < 1e-12);
    let parts = split_along_axis(&m, 2, &[-2.0]);
    // parts[0] is z < -2: the two arm ends.
    assert!((volume(&parts[0]) - 2.0).abs() < 1e-12);
    assert!((volume(&parts[1]) - 5.0).abs() < 1e-12);
    assert!(closed(&parts[0]) && closed(&parts[1]));
    let caps0 = (0..parts[0].faces.len())
        .filter(|&f| is_cap(&parts[0], f))
        .count();
    let caps1 = (0..parts[1].faces.len())
        .filter(|&f| is_cap(&parts[1], f))
        .count();
    assert_eq!((caps0, caps1), (2, 2));
    // The bottom face splits into two pieces in parts[0].
    let bottoms = (0..parts[0].faces.len())
        .filter(|&f| face_normal(&parts[0], f) == -DVec3::Y)
        .count();
    assert_eq!(bottoms, 2);
    // Cut exactly at the notch's end (z = -1): the notch edge lies in
    // the plane.
    let parts = split_along_axis(&m, 2, &[-1.0]);
    assert!((volume(&parts[0]) - 4.0).abs() < 1e-12);
    assert!((volume(&parts[1]) - 3.0).abs() < 1e-12);
    assert!(closed(&parts[0]) && closed(&parts[1]));
}

#[test]
fn flat_lot_split_keeps_area_and_interpolates_uvs() {
    let mut lot = Mesh::polygon(&[
        v(0., 0., 0.),
        v(10., 0., 0.),
        v(10., 0., -5.),
        v(0., 0., -5.),
    ]);
    lot.uvs[0] = Some(vec![
        DVec2::new(0., 0.),
        DVec2::new(1., 0.),
        DVec2::new(1., 1.),
        DVec2::new(0., 1.),
    ]);
    lot.normals = Some(vec![DVec3::Y; 4]);
    let parts = split_along_axis(&lot, 0, &[2.5, 2.5, 7.5, 20.0]);
    assert_eq!(parts.len(), 5);
    let areas: Vec<f64> = parts.iter().map(mesh_area).collect();
    assert_eq!(areas, vec![12.5, 0.0, 25.0, 12.5, 0.0]);
    assert!(parts[1].is_empty() && parts[4].is_empty());
    let p = &parts[2];
    assert_eq!(p.faces.len(), 1);
    assert_eq!(p.positions.len(), 4);
    let uv = p.uvs[0].as_ref().unwrap();
    for (k, &c) in p.corners.iter().enumerate() {
        let x = p.positions[c as usize].x;
        assert!((uv[k].x - x / 10.0).abs() < 1e-15);
    }
    assert_eq!(p.normals.as_ref().unwrap(), &vec![DVec3::Y; 4]);
    // The part keeps the counter-clockwise orientation.
    assert_eq!(face_normal(p, 0), DVec3::Y);
}

#[test]
fn cut_through_a_vertex_of_a_concave_polygon() {
    // A flat "W": the cut line y = 1 touches the middle reflex vertex.
    let w = Mesh::polygon(&[
        v(0., 0., 0.),
        v(4., 0., 0.),
        v(4., 2., 0.),
        v(3., 2., 0.),
        v(2., 1., 0.),
        v(1., 2., 0.),
        v(0., 2., 0.),
    ]);
    let total = mesh_area(&w);
    let (lo, hi) = cut_by_plane(&w, DVec3::Y, 1.0);
    assert_eq!(lo.faces.len(), 1);
    assert_eq!(hi.faces.len(), 2);
    assert!((mesh_area(&lo) - 4.0).abs() < 1e-12);
    assert!((mesh_area(&lo) + mesh_area(&hi) - total).abs() < 1e-12);
    // The lower piece has the touching vertex on its top edge.
    assert_eq!(lo.positions.len(), 5);
}

#[test]
fn edge_shapes_are_split_too() {
    let mut e = Mesh::new();
    e.positions.extend([v(0., 0., 0.), v(4., 0., 0.)]);
    e.add_face(&[&[0, 1]], 0);
    let parts = split_along_axis(&e, 0, &[1.0, 3.0]);
    let lens: Vec<f64> = parts
        .iter()
        .map(|m| m.positions[m.corners[1] as usize].distance(m.positions[m.corners[0] as usize]))
        .collect();
    assert_eq!(lens, vec![1.0, 2.0, 1.0]);
}

/// A star-shaped simple polygon (concave in general) counter-clockwise
/// from above in (x, z): radii at increasing angles.
fn star(radii: &[f64], scale: f64) -> Vec<(f64, f64)> {
    let n = radii.len();
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            // counter-clockwise seen from above = clockwise in (x, -z)...
            (scale * radii[i] * a.cos(), -scale * radii[i] * a.sin())
        })
        .collect()
}

fn check_split(m: &Mesh, axis: usize, cuts: &[f64]) {
    let total_v = volume(m);
    let total_a = mesh_area(m);
    assert!(closed(m));
    let parts = split_along_axis(m, axis, cuts);
    assert_eq!(parts.len(), cuts.len() + 1);
    let mut vsum = 0.0;
    let mut asum = 0.0;
    for (i, p) in parts.iter().enumerate() {
        if p.is_empty() {
            continue;
        }
        assert!(closed(p), "part {i} of {cuts:?} along {axis} not closed");
        assert!(no_unused_positions(p));
        let pv = volume(p);
        assert!(pv > -1e-9, "part {i} has negative volume {pv}");
        vsum += pv;
        asum += non_cap_area(p);
    }
    assert!(
        (vsum - total_v).abs() <= 1e-9 * total_v.abs(),
        "volume {vsum} vs {total_v}"
    );
    assert!(
        (asum - total_a).abs() <= 1e-9 * total_a,
        "area {asum} vs {total_a}"
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

    #[test]
    fn boxes_split_exactly(
        lo in prop::array::uniform3(-10.0f64..10.0),
        size in prop::array::uniform3(0.1f64..10.0),
        axis in 0usize..3,
        fr in prop::collection::vec(-0.2f64..1.2, 1..5),
        snap in any::<bool>(),
    ) {
        let (x0, y0, z0) = (lo[0], lo[1], lo[2]);
        let (sx, sy, sz) = (size[0], size[1], size[2]);
        let mut b = prism(&[(x0, z0), (x0 + sx, z0), (x0 + sx, z0 - sz), (x0, z0 - sz)], &[], sy);
        b.map_positions(|p| p + DVec3::Y * y0);
        let (base, ext) = match axis { 0 => (x0, sx), 1 => (y0, sy), _ => (z0 - sz, sz) };
        let mut cuts: Vec<f64> = fr.iter().map(|f| {
            // Snap some cuts onto the box faces.
            let f = if snap { (f * 2.0).round() / 2.0 } else { *f };
            base + f * ext
        }).collect();
        cuts.sort_by(f64::total_cmp);
        check_split(&b, axis, &cuts);
    }

    #[test]
    fn prisms_split_exactly(
        radii in prop::collection::vec(0.5f64..2.0, 3..12),
        hole in prop::option::of(3usize..7),
        h in 0.5f64..3.0,
        axis in 0usize..3,
        fr in prop::collection::vec(-0.1f64..1.1, 1..4),
        through_vertex in prop::option::of(0usize..12),
    ) {
        let outer = star(&radii, 1.0);
        let holes: Vec<Vec<(f64, f64)>> = hole
            .map(|n| {
                // A regular polygon well inside (radii >= 0.5), clockwise.
                let mut r = star(&vec![0.3; n], 1.0);
                r.reverse();
                vec![r]
            })
            .unwrap_or_default();
        let m = prism(&outer, &holes, h);
        let (lo, hi) = match axis { 0 => (-2.0, 2.0), 1 => (0.0, h), _ => (-2.0, 2.0) };
        let mut cuts: Vec<f64> = fr.iter().map(|f| lo + f * (hi - lo)).collect();
        if let Some(k) = through_vertex {
            // A cut exactly through a vertex of the outline.
            let (x, z) = outer[k % outer.len()];
            cuts.push(match axis { 0 => x, 1 => h, _ => z });
        }
        cuts.sort_by(f64::total_cmp);
        check_split(&m, axis, &cuts);
    }

    #[test]
    fn rectilinear_combs_split_exactly(
        heights in prop::collection::vec(1u8..4, 2..8),
        axis in prop::sample::select(vec![0usize, 2]),
        cuts in prop::collection::vec(0u8..17, 1..5),
    ) {
        // A histogram polygon: column i spans x in [i, i+1] and z from 0
        // to -heights[i]. Cuts at multiples of 0.5 hit its edges lying in
        // the cut planes and its reflex corners.
        let n = heights.len();
        let mut outer = vec![(0.0, 0.0), (n as f64, 0.0)];
        for i in (0..n).rev() {
            let h = -(heights[i] as f64);
            outer.push(((i + 1) as f64, h));
            outer.push((i as f64, h));
        }
        outer.dedup();
        let m = prism(&outer, &[], 1.0);
        let mut cs: Vec<f64> = cuts
            .iter()
            .map(|&c| if axis == 0 { c as f64 * 0.5 } else { -(c as f64) * 0.25 })
            .collect();
        cs.sort_by(f64::total_cmp);
        check_split(&m, axis, &cs);
    }

    #[test]
    fn primitives_split_exactly(
        kind in 0usize..3,
        sides in 3usize..12,
        axis in 0usize..3,
        cuts in prop::collection::vec(0u8..=8, 1..4),
    ) {
        // Cuts at multiples of 1/8 of the size hit ring vertices, poles
        // and caps exactly.
        let size = DVec3::new(2.0, 3.0, 4.0);
        let m = match kind {
            0 => crate::primitive::sphere(sides, sides.max(2), size),
            1 => crate::primitive::cylinder(sides, size),
            _ => crate::primitive::cone(sides, size),
        };
        let mut cs: Vec<f64> = cuts.iter().map(|&c| size[axis] * c as f64 / 8.0).collect();
        cs.sort_by(f64::total_cmp);
        let total_a = mesh_area(&m);
        let total_v = volume(&m);
        let parts = split_along_axis(&m, axis, &cs);
        let mut vsum = 0.0;
        let mut asum = 0.0;
        for p in &parts {
            prop_assert!(p.is_empty() || closed(p));
            vsum += volume(p);
            // Primitives carry UVs; caps are the faces whose corners all
            // have UV (0, 0) — primitives have such corners too, so
            // count areas through normals of the faces lying in the cut
            // planes instead: total area = original + 2 * cap areas.
            asum += mesh_area(p);
        }
        prop_assert!((vsum - total_v).abs() <= 1e-9 * total_v);
        prop_assert!(asum >= total_a * (1.0 - 1e-9));
    }

    #[test]
    fn general_planes_preserve_volume(
        radii in prop::collection::vec(0.5f64..2.0, 3..10),
        n in prop::array::uniform3(-1.0f64..1.0),
        off in -1.0f64..1.0,
    ) {
        let nv = DVec3::from(n);
        prop_assume!(nv.length() > 0.1);
        let m = prism(&star(&radii, 1.0), &[], 1.0);
        let (a, b) = cut_by_plane(&m, nv, off);
        let total = volume(&m);
        prop_assert!((volume(&a) + volume(&b) - total).abs() <= 1e-9 * total);
        prop_assert!(a.is_empty() || closed(&a));
        prop_assert!(b.is_empty() || closed(&b));
        prop_assert!((non_cap_area(&a) + non_cap_area(&b) - mesh_area(&m)).abs() <= 1e-9 * mesh_area(&m));
    }
}

/// `split_along_axis` by the general path only, and the number of
/// splits the fast path did in the normal run.
fn split_both_ways(m: &Mesh, axis: usize, cuts: &[f64]) -> (Vec<Mesh>, Vec<Mesh>, usize) {
    // Each run cuts: neither replays an earlier cut of the same mesh.
    forget_replays();
    SIMPLE_SPLITS.with(|c| c.set(0));
    let fast = split_along_axis(m, axis, cuts);
    let used = SIMPLE_SPLITS.with(|c| c.get());
    forget_replays();
    GENERAL_PATH_ONLY.with(|g| g.set(true));
    let general = split_along_axis(m, axis, cuts);
    GENERAL_PATH_ONLY.with(|g| g.set(false));
    (fast, general, used)
}

#[test]
fn fast_path_splits_boxes_and_quads_as_the_general_path() {
    // Floors of a mass: every side face crosses 3 planes, all split by
    // the fast path; the output is the same, face for face.
    let mass = prism(&[(0., 0.), (20., 0.), (20., -30.), (0., -30.)], &[], 10.0);
    let (fast, general, used) = split_both_ways(&mass, 1, &[0.0, 3.0, 6.0, 9.0, 10.0]);
    assert_eq!(used, 12);
    assert_eq!(fast, general);
    assert_eq!(
        fast.iter().map(|m| m.faces.len()).collect::<Vec<_>>(),
        vec![0, 6, 6, 6, 6, 0]
    );
    // A facade with UVs into tiles, cuts on its borders included.
    let mut q = Mesh::polygon(&[
        v(0., 0., 0.),
        v(20., 0., 0.),
        v(20., 10., 0.),
        v(0., 10., 0.),
    ]);
    q.uvs[0] = Some(vec![
        DVec2::new(0., 0.),
        DVec2::new(1., 0.),
        DVec2::new(1., 1.),
        DVec2::new(0., 1.),
    ]);
    let cuts: Vec<f64> = (0..=10).map(|i| i as f64 * 2.0).collect();
    let (fast, general, used) = split_both_ways(&q, 0, &cuts);
    assert_eq!(used, 9);
    assert_eq!(fast, general);
    // Tile 3 spans x in [4, 6]; UVs are interpolated along the edges.
    let t = &fast[3];
    assert_eq!((t.faces.len(), t.positions.len()), (1, 4));
    let uv = t.uvs[0].as_ref().unwrap();
    for (k, &c) in t.corners.iter().enumerate() {
        let p = t.positions[c as usize];
        assert!(p.x == 4.0 || p.x == 6.0);
        assert!((uv[k] - DVec2::new(p.x / 20.0, p.y / 10.0)).length() < 1e-15);
    }
    // A cut through a vertex is left to the general path.
    let (fast, general, used) = split_both_ways(&q, 0, &[20.0]);
    assert_eq!((used, fast.len()), (0, 2));
    assert_eq!(fast, general);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

    /// Random planar convex quads in any orientation, with UVs and
    /// normals, cut along any axis, some cuts through their vertices.
    #[test]
    fn fast_path_equals_general_path_on_quads(
        o in prop::array::uniform3(-5.0f64..5.0),
        u in prop::array::uniform3(-3.0f64..3.0),
        w in prop::array::uniform3(-3.0f64..3.0),
        stretch in 0.3f64..1.7,
        shear in -0.4f64..0.4,
        axis in 0usize..3,
        fr in prop::collection::vec(-0.2f64..1.2, 1..8),
        through_vertex in prop::option::of(0usize..4),
    ) {
        let (o, u, w) = (DVec3::from(o), DVec3::from(u), DVec3::from(w));
        prop_assume!(u.cross(w).length() > 0.1);
        // Convex: a parallelogram with one corner pushed outwards.
        let pts = [o, o + u, o + u + w * stretch, o + w + u * shear];
        let mut m = Mesh::polygon(&pts);
        m.uvs[0] = Some((0..4).map(|i| DVec2::new(i as f64, 0.5 * i as f64)).collect());
        m.normals = Some(vec![u.cross(w).normalize(); 4]);
        let lo = pts.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
        let mut cuts: Vec<f64> = fr.iter().map(|f| lo + f * (hi - lo)).collect();
        if let Some(k) = through_vertex {
            cuts.push(pts[k][axis]);
        }
        cuts.sort_by(f64::total_cmp);
        let (fast, general, _) = split_both_ways(&m, axis, &cuts);
        prop_assert_eq!(fast, general);
        // The same quad with other texture coordinates: replayed from the
        // cut just done, it is what cutting it anew gives.
        let mut other = m.clone();
        other.uvs[0] = Some((0..4).map(|i| DVec2::new(0.3 - i as f64, 2.0 * i as f64)).collect());
        let replayed = split_along_axis(&other, axis, &cuts);
        forget_replays();
        prop_assert_eq!(replayed, split_along_axis(&other, axis, &cuts));
    }

    /// Boxes, axis-aligned or rotated, split along any axis.
    #[test]
    fn fast_path_equals_general_path_on_boxes(
        size in prop::array::uniform3(0.1f64..10.0),
        at in prop::array::uniform3(-10.0f64..10.0),
        turn in prop::option::of((0.0f64..3.0, 0.0f64..1.0)),
        axis in 0usize..3,
        fr in prop::collection::vec(-0.2f64..1.2, 1..8),
        snap in any::<bool>(),
    ) {
        let mut b = crate::primitive::cube(DVec3::from(size));
        if let Some((y, x)) = turn {
            let r = glam::DAffine3::from_rotation_y(y) * glam::DAffine3::from_rotation_x(x);
            crate::transform::transform(&mut b, &r);
        }
        b.map_positions(|p| p + DVec3::from(at));
        let lo = b.positions.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
        let hi = b.positions.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
        let mut cuts: Vec<f64> = fr.iter().map(|f| {
            let f = if snap { (f * 4.0).round() / 4.0 } else { *f };
            lo + f * (hi - lo)
        }).collect();
        cuts.sort_by(f64::total_cmp);
        let (fast, general, _) = split_both_ways(&b, axis, &cuts);
        prop_assert_eq!(fast, general);
    }
}

/// A facade tile with texture coordinates in two sets, normals, and edge
/// and vertex tags, all shifted by `k` (its geometry stays the same).
fn tagged_tile(k: f64) -> Mesh {
    let mut q = Mesh::polygon(&[
        v(0., 0., 0.),
        v(3.55, 0., 0.),
        v(3.55, 3.5, 0.),
        v(0., 3.5, 0.),
    ]);
    let uv = |i: usize| DVec2::new(0.1 * i as f64 + k, 0.7 * k - 0.2 * i as f64);
    q.uvs[0] = Some((0..4).map(uv).collect());
    q.uvs[2] = Some((0..4).map(|i| uv(i) * 3.0).collect());
    q.normals = Some(
        (0..4)
            .map(|i| v(0.1 * i as f64, k, 1.0).normalize())
            .collect(),
    );
    let a = q.intern_tags(crate::tags::TagSet::from_names(["edge.a"]));
    let b = q.intern_tags(crate::tags::TagSet::from_names(["vertex.b"]));
    let pick = if k > 0.5 { [a, 0, a, 0] } else { [0, a, 0, a] };
    q.edge_tags = Some(pick.to_vec());
    q.vertex_tags = Some(vec![b, 0, 0, b]);
    q
}

/// A cut replayed from an earlier cut of the same geometry gives what
/// cutting gives, whatever the corners' attributes: a tile split into
/// three (texture coordinates, normals, tags interpolated or carried), and
/// a closed box cut into floors (caps and their normals).
#[test]
fn replayed_cuts_equal_cutting_anew() {
    let replays = || replay::REPLAYED.with(|r| r.get());
    forget_replays();
    let cuts = [0.3, 1.0, 2.5, 3.25];
    let first = split_along_axis(&tagged_tile(0.25), 0, &cuts);
    let before = replays();
    let replayed = split_along_axis(&tagged_tile(0.75), 0, &cuts);
    assert_eq!(replays(), before + 1);
    forget_replays();
    let anew = split_along_axis(&tagged_tile(0.75), 0, &cuts);
    assert_eq!(replayed, anew);
    assert_eq!(replayed.len(), 5);
    // The attributes are the second tile's, not the first's.
    assert_ne!(first[2].uvs[0], replayed[2].uvs[0]);
    assert_ne!(first[2].edge_tags, replayed[2].edge_tags);
    assert_eq!(first[2].positions, replayed[2].positions);

    let mut mass = unit_box();
    let n = mass.corners.len();
    let shifted = |m: &Mesh, k: f64| {
        let mut m = m.clone();
        m.uvs[0] = Some((0..n).map(|i| DVec2::new(k, i as f64)).collect());
        m
    };
    let floors = [0.25, 0.5, 0.75];
    forget_replays();
    mass = shifted(&mass, 1.0);
    let _ = split_along_axis(&mass, 1, &floors);
    let other = shifted(&mass, 2.0);
    let replayed = split_along_axis(&other, 1, &floors);
    forget_replays();
    let anew = split_along_axis(&other, 1, &floors);
    assert_eq!(replayed, anew);
    assert!(replayed.iter().all(closed));
    // Larger meshes are not remembered.
    let big = prism(
        &star(&[1.0, 0.5, 1.0, 0.5, 1.0, 0.5, 1.0, 0.5, 1.0, 0.5], 3.0),
        &[],
        2.0,
    );
    assert!(big.corners.len() > 32);
    let before = replays();
    let _ = split_along_axis(&big, 1, &[1.0]);
    let _ = split_along_axis(&big, 1, &[1.0]);
    assert_eq!(replays(), before);
}

/// Cuts come back after many others (a city's tiles are cut in a few
/// hundred kinds, each again and again but not in a row): up to
/// `replay::ENTRIES` kinds are all replayed, and the memory the entries
/// hold stays within `replay::BUDGET_BYTES` however large they are.
#[test]
fn replays_reach_back_many_kinds_within_a_budget() {
    let replays = || replay::REPLAYED.with(|r| r.get());
    let size = || SCRATCH.with(|c| c.borrow().replays.size());
    forget_replays();
    // 600 tiles of different widths, each cut at the same place.
    let tile =
        |w: f64| Mesh::polygon(&[v(0., 0., 0.), v(w, 0., 0.), v(w, 3.5, 0.), v(0., 3.5, 0.)]);
    let widths: Vec<f64> = (0..600).map(|i| 2.0 + i as f64 / 64.0).collect();
    let cut_all = || {
        for &w in &widths {
            assert_eq!(split_along_axis(&tile(w), 0, &[1.0]).len(), 2);
        }
    };
    cut_all();
    assert_eq!(size().0, 600);
    let before = replays();
    cut_all();
    assert_eq!(replays(), before + 600);
    // Beyond the number of entries, the oldest are forgotten.
    for i in 0..replay::ENTRIES {
        let _ = split_along_axis(&tile(20.0 + i as f64 / 64.0), 0, &[1.0]);
    }
    assert_eq!(size().0, replay::ENTRIES);
    let before = replays();
    let _ = split_along_axis(&tile(widths[0]), 0, &[1.0]);
    assert_eq!(replays(), before);
    // The bytes held, not only the count, bound the entries: with a budget
    // of 64 KiB, 30-gons cut by 31 planes into 32 parts (a few KiB each)
    // are kept a few at a time, and the newest is still replayed.
    SCRATCH.with(|c| c.borrow_mut().replays = replay::Replays::with_budget(64 << 10));
    let gon = |r: f64| {
        let pts: Vec<DVec3> = (0..30)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 30.0;
                v(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        Mesh::polygon(&pts)
    };
    let planes: Vec<f64> = (0..31).map(|i| -0.9 + i as f64 * 0.06).collect();
    for k in 0..100 {
        let parts = split_along_axis(&gon(1.0 + k as f64 / 1024.0), 0, &planes);
        assert_eq!(parts.len(), 32);
        let (entries, bytes) = size();
        assert!(bytes <= 64 << 10, "{bytes}");
        assert!((1..100).contains(&entries), "{entries}");
    }
    let (entries, bytes) = size();
    assert!(entries >= 4 && bytes > 32 << 10, "{entries} {bytes}");
    let before = replays();
    let _ = split_along_axis(&gon(1.0 + 99.0 / 1024.0), 0, &planes);
    assert_eq!(replays(), before + 1);
    forget_replays();
    assert_eq!(size(), (0, 0));
}
