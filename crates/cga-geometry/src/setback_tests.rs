use super::*;
use crate::measure::face_area;

fn rect(w: f64, d: f64) -> Mesh {
    Mesh::polygon(&[
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(w, 0.0, 0.0),
        DVec3::new(w, 0.0, -d),
        DVec3::new(0.0, 0.0, -d),
    ])
}

fn u_shape() -> Mesh {
    // A U open towards -z (the notch is 4 wide, 6 deep).
    let p = [
        (0.0, 0.0),
        (12.0, 0.0),
        (12.0, -10.0),
        (8.0, -10.0),
        (8.0, -4.0),
        (4.0, -4.0),
        (4.0, -10.0),
        (0.0, -10.0),
    ];
    Mesh::polygon(&p.map(|(x, z)| DVec3::new(x, 0.0, z)))
}

fn area_of(o: &Offset, k: OffsetFace) -> f64 {
    o.faces_of(k).iter().map(|&f| face_area(&o.mesh, f)).sum()
}

fn signed_area(o: &Offset, k: OffsetFace) -> f64 {
    o.faces_of(k)
        .iter()
        .map(|&f| {
            let mut a = crate::measure::loop_newell(&o.mesh, o.mesh.outer_loop(f)).y;
            for &h in &o.mesh.face_loops(f)[1..] {
                a += crate::measure::loop_newell(&o.mesh, h).y;
            }
            0.5 * a
        })
        .sum()
}

#[test]
fn inset_rectangle() {
    let o = offset(&rect(10.0, 6.0), -1.0);
    assert!(o.failed.is_empty());
    assert_eq!(o.faces_of(OffsetFace::Strip).len(), 4);
    assert_eq!(o.faces_of(OffsetFace::Inside).len(), 1);
    assert!((area_of(&o, OffsetFace::Inside) - 32.0).abs() < 1e-9);
    // Front strip: trapezoid (10 + 8) / 2.
    assert!((face_area(&o.mesh, 0) - 9.0).abs() < 1e-9);
    assert!((area_of(&o, OffsetFace::Strip) - 28.0).abs() < 1e-9);
    assert_eq!(
        &o.corner_tags[0..4],
        &[
            SetbackEdgeTag::Front,
            SetbackEdgeTag::Side,
            SetbackEdgeTag::Back,
            SetbackEdgeTag::Side
        ]
    );
    // Offsetting past the middle removes the inside.
    let o = offset(&rect(10.0, 6.0), -3.5);
    assert_eq!(o.faces_of(OffsetFace::Inside).len(), 0);
    assert!((area_of(&o, OffsetFace::Strip) - 60.0).abs() < 1e-9);
}

#[test]
fn inset_splits_a_dumbbell() {
    // Two 6x6 squares joined by a 2-wide neck: an inset of 1.5 splits it.
    let p = [
        (0.0, 0.0),
        (6.0, 0.0),
        (6.0, -2.0),
        (10.0, -2.0),
        (10.0, 0.0),
        (16.0, 0.0),
        (16.0, -6.0),
        (10.0, -6.0),
        (10.0, -4.0),
        (6.0, -4.0),
        (6.0, -6.0),
        (0.0, -6.0),
    ];
    let m = Mesh::polygon(&p.map(|(x, z)| DVec3::new(x, 0.0, z)));
    let o = offset(&m, -1.5);
    assert_eq!(o.faces_of(OffsetFace::Inside).len(), 2);
    assert!((area_of(&o, OffsetFace::Inside) - 2.0 * 9.0).abs() < 1e-9);
    let total = face_area(&m, 0);
    assert!(
        (area_of(&o, OffsetFace::Inside) + area_of(&o, OffsetFace::Strip) - total).abs() < 1e-9
    );
}

#[test]
fn grow_rectangle_and_close_a_notch() {
    let o = offset(&rect(10.0, 6.0), 1.0);
    assert!(o.failed.is_empty(), "{:?}", o.failed);
    assert!((area_of(&o, OffsetFace::Inside) - 12.0 * 8.0).abs() < 1e-9);
    // Border strips face down: inside + border = original in signed area.
    let s = signed_area(&o, OffsetFace::Strip);
    assert!((s + 36.0).abs() < 1e-9, "{s}");
    assert!(signed_area(&o, OffsetFace::Inside) > 0.0);
    // The U's 4-wide notch closes when grown by 2 or more.
    let o = offset(&u_shape(), 3.0);
    assert_eq!(o.faces_of(OffsetFace::Inside).len(), 1);
    let inside = o.faces_of(OffsetFace::Inside)[0];
    assert_eq!(o.mesh.face_loops(inside).len(), 1);
    let s = signed_area(&o, OffsetFace::Inside) + signed_area(&o, OffsetFace::Strip);
    assert!((s - face_area(&u_shape(), 0)).abs() < 1e-9);
}

#[test]
fn offset_with_a_hole() {
    let mut m = Mesh::new();
    m.positions.extend(
        [
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, -10.0),
            (0.0, -10.0),
            (4.0, -4.0),
            (4.0, -6.0),
            (6.0, -6.0),
            (6.0, -4.0),
        ]
        .map(|(x, z)| DVec3::new(x, 0.0, z)),
    );
    m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
    let o = offset(&m, -1.0);
    let inside = o.faces_of(OffsetFace::Inside);
    assert_eq!(inside.len(), 1);
    assert_eq!(o.mesh.face_loops(inside[0]).len(), 2);
    assert!((area_of(&o, OffsetFace::Inside) - (64.0 - 16.0)).abs() < 1e-9);
    assert_eq!(o.faces_of(OffsetFace::Strip).len(), 8);
    let o = offset(&m, 1.0);
    // Grown: the outer grows to 12x12, the hole shrinks away (2 wide).
    assert!((area_of(&o, OffsetFace::Inside) - 144.0).abs() < 1e-9);
}

#[test]
fn setback_front_and_per_edge() {
    // setback(4) { front : A | remainder : B } on a 10 x 20 lot.
    let o = setback(&rect(10.0, 20.0), &[4.0, 0.0, 0.0, 0.0]);
    assert_eq!(o.faces_of(OffsetFace::Strip).len(), 1);
    assert!((face_area(&o.mesh, 0) - 40.0).abs() < 1e-9);
    assert!((area_of(&o, OffsetFace::Inside) - 160.0).abs() < 1e-9);
    let rem = o.faces_of(OffsetFace::Inside)[0];
    let r = o.mesh.loop_corners(o.mesh.outer_loop(rem));
    let mut tags: Vec<SetbackEdgeTag> = o.corner_tags[r].to_vec();
    tags.sort_by_key(|t| *t as u8);
    use SetbackEdgeTag::*;
    assert_eq!(tags, vec![Back, Side, Side, Remainder]);
    // Per-edge distances [3, 2, 1, 0] (setbackPerEdge).
    let o = setback(&rect(10.0, 20.0), &[3.0, 2.0, 1.0]);
    assert_eq!(o.faces_of(OffsetFace::Strip).len(), 3);
    assert!((area_of(&o, OffsetFace::Inside) - 8.0 * 16.0).abs() < 1e-9);
    let src: Vec<u32> = o
        .faces_of(OffsetFace::Strip)
        .iter()
        .map(|&f| o.source_edge[f].unwrap().edge)
        .collect();
    assert_eq!(src, vec![0, 1, 2]);
}

#[test]
fn setback_to_area_examples() {
    // A 20 x 20 square set back to an area of 100: all edges by 5.
    let m = rect(20.0, 20.0);
    let (o, d, ok) = setback_to_area(&m, 100.0, &[true; 4], None, None);
    assert!(ok);
    for x in &d {
        assert!((x - 5.0).abs() < 1e-9, "{d:?}");
    }
    assert!((area_of(&o, OffsetFace::Inside) - 100.0).abs() < 1e-9);
    // Setback faces of area 300 in total (area - 300 = 100 again).
    assert!((area_of(&o, OffsetFace::Strip) - 300.0).abs() < 1e-9);
    // Front and left only (an L of 300): (20 - s)^2 = 100, s = 10.
    let (_, d, ok) = setback_to_area(&m, 100.0, &[true, false, false, true], None, None);
    assert!(ok);
    assert!((d[0] - 10.0).abs() < 1e-9 && d[1] == 0.0 && (d[3] - 10.0).abs() < 1e-9);
    // Minimum 2 on the front: (20 - 2 - s)(20 - s) = 100.
    let (o, d, ok) = setback_to_area(
        &m,
        100.0,
        &[true, false, false, true],
        Some(&[2.0, 0.0, 0.0, 0.0]),
        None,
    );
    assert!(ok);
    assert!((d[0] - d[3] - 2.0).abs() < 1e-9);
    assert!((area_of(&o, OffsetFace::Inside) - 100.0).abs() < 1e-9);
    // Maximum 4 on the front: left alone must reach 20 - s' = 100 / 16.
    let (o, d, ok) = setback_to_area(
        &m,
        100.0,
        &[true, false, false, true],
        None,
        Some(&[4.0, 0.0, 0.0, 20.0]),
    );
    assert!(ok, "{d:?}");
    assert!((d[0] - 4.0).abs() < 1e-9);
    assert!((d[3] - (20.0 - 100.0 / 16.0)).abs() < 1e-9, "{d:?}");
    assert!((area_of(&o, OffsetFace::Inside) - 100.0).abs() < 1e-9);
    // Unreachable: the maximums are too small.
    let (_, _, ok) = setback_to_area(&m, 10.0, &[true; 4], None, Some(&[1.0; 4]));
    assert!(!ok);
}

#[test]
fn shape_l_u_o() {
    // shapeO(4, 4, 4, 4) on a 20 x 20 lot: a ring with a 12 x 12 hole.
    let m = rect(20.0, 20.0);
    let o = setback(&m, &[4.0; 4]);
    let ring = merge_strips(&o);
    assert_eq!(ring.faces.len(), 1);
    assert_eq!(ring.face_loops(0).len(), 2);
    assert!((face_area(&ring, 0) - (400.0 - 144.0)).abs() < 1e-9);
    // shapeL(5, 11): front 5, left 11.
    let o = setback(&m, &[5.0, 0.0, 0.0, 11.0]);
    let l = merge_strips(&o);
    assert_eq!(l.faces.len(), 1);
    assert_eq!(l.face_loops(0).len(), 1);
    assert!((face_area(&l, 0) - (400.0 - 9.0 * 15.0)).abs() < 1e-9);
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(150))]

    /// Insets of random concave polygons: inside + border = original, the
    /// inside area shrinks as the distance grows; setbacks by random
    /// per-edge distances: strips + remainder = original.
    #[test]
    fn random_offsets(n in 5usize..25, jit in prop::collection::vec(0.0f64..0.8, 25),
                      radii in prop::collection::vec(0.5f64..1.0, 25), d in 0.1f64..4.0,
                      ds in prop::collection::vec(0.0f64..3.0, 25)) {
        let pts: Vec<DVec3> = (0..n).map(|i| {
            let a = (i as f64 + jit[i]) * std::f64::consts::TAU / n as f64;
            DVec3::new(a.cos() * radii[i] * 10.0, 0.0, -a.sin() * radii[i] * 10.0)
        }).collect();
        let m = Mesh::polygon(&pts);
        let total = face_area(&m, 0);
        let a = offset(&m, -d);
        let b = offset(&m, -d * 1.5);
        prop_assert!(a.failed.is_empty() && b.failed.is_empty());
        let (ia, ib) = (area_of(&a, OffsetFace::Inside), area_of(&b, OffsetFace::Inside));
        prop_assert!(ib <= ia + 1e-9);
        prop_assert!((ia + area_of(&a, OffsetFace::Strip) - total).abs() < 1e-9 * total);
        let g = offset(&m, d);
        prop_assert!(g.failed.is_empty(), "{:?}", g.failed);
        let s = signed_area(&g, OffsetFace::Inside) + signed_area(&g, OffsetFace::Strip);
        prop_assert!((s - total).abs() < 1e-8 * total);
        prop_assert!(area_of(&g, OffsetFace::Inside) >= total);
        let sb = setback(&m, &ds[..n]);
        prop_assert!(sb.failed.is_empty());
        prop_assert!((area_of(&sb, OffsetFace::Inside) + area_of(&sb, OffsetFace::Strip) - total).abs() < 1e-9 * total);
    }
}
