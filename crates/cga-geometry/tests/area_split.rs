//! Property tests of the area profile and of cutting by areas: random simple
//! polygons (concave, with and without holes, as one face or as many, flat
//! or tilted in 3D, exactly or nearly planar) cut into parts of random areas.

use cga_geometry::area_split::{split_by_areas, AreaProfile};
use cga_geometry::measure::mesh_area;
use cga_geometry::{DMat3, DVec3, Mesh};
use proptest::prelude::*;

/// A star-shaped polygon around the origin in the xz plane: `n` vertices at
/// evenly spaced angles (jittered by up to a third of the spacing) and the
/// given radii, counter-clockwise seen from +y. With angle steps below 90
/// degrees the polygon contains the disk of radius `0.7 * min(radii)`.
fn star(radii: &[f64], jitter: &[f64], center: DVec3) -> Vec<DVec3> {
    let n = radii.len();
    let step = std::f64::consts::TAU / n as f64;
    (0..n)
        .map(|i| {
            let a = (i as f64 + jitter[i] / 3.0) * step;
            // Counter-clockwise seen from +y: x = cos, z = -sin.
            center + DVec3::new(a.cos(), 0.0, -a.sin()) * radii[i]
        })
        .collect()
}

#[derive(Clone, Debug)]
struct Lot {
    outer: Vec<DVec3>,
    holes: Vec<Vec<DVec3>>,
}

impl Lot {
    /// One face with holes (holes wound clockwise).
    fn mesh(&self, rotation: DMat3, offset: DVec3) -> Mesh {
        let mut m = Mesh::new();
        let mut loops: Vec<Vec<u32>> = Vec::new();
        let mut push_loop = |m: &mut Mesh, pts: &[DVec3], reverse: bool| {
            let base = m.positions.len() as u32;
            m.positions
                .extend(pts.iter().map(|&p| rotation * p + offset));
            let mut idx: Vec<u32> = (base..base + pts.len() as u32).collect();
            if reverse {
                idx.reverse();
            }
            loops.push(idx);
        };
        push_loop(&mut m, &self.outer, false);
        for h in &self.holes {
            push_loop(&mut m, h, true);
        }
        let refs: Vec<&[u32]> = loops.iter().map(|l| l.as_slice()).collect();
        m.add_face(&refs, 0);
        m
    }

    /// The polygon (no holes) as a fan of triangles from its centre: a
    /// multi-face planar mesh of the same area.
    fn fan(&self, rotation: DMat3, offset: DVec3) -> Mesh {
        let mut m = Mesh::new();
        m.positions.push(offset);
        m.positions
            .extend(self.outer.iter().map(|&p| rotation * p + offset));
        let n = self.outer.len() as u32;
        for i in 0..n {
            m.add_face(&[&[0, 1 + i, 1 + (i + 1) % n]], 0);
        }
        m
    }
}

fn lot_strategy(with_holes: bool) -> impl Strategy<Value = Lot> {
    let outer = (5usize..24).prop_flat_map(|n| {
        (
            prop::collection::vec(20.0f64..60.0, n),
            prop::collection::vec(-1.0f64..1.0, n),
        )
    });
    let hole = (4usize..10).prop_flat_map(|n| {
        (
            prop::collection::vec(2.0f64..5.0, n),
            prop::collection::vec(-1.0f64..1.0, n),
            // Hole centre within 6 of the origin: the hole stays within radius 11 < 0.7 * 20.
            (-6.0f64..6.0, -6.0f64..6.0),
        )
    });
    let holes = if with_holes {
        prop::collection::vec(hole, 1..2).boxed()
    } else {
        Just(Vec::new()).boxed()
    };
    (outer, holes).prop_map(|((r, j), holes)| Lot {
        outer: star(&r, &j, DVec3::ZERO),
        holes: holes
            .into_iter()
            .map(|(r, j, (cx, cz))| star(&r, &j, DVec3::new(cx, 0.0, cz)))
            .collect(),
    })
}

/// A rotation from three angles (radians).
fn rotation(a: f64, b: f64, c: f64) -> DMat3 {
    DMat3::from_rotation_z(c) * DMat3::from_rotation_y(b) * DMat3::from_rotation_x(a)
}

/// Normalised positive weights into fractions summing to `total` (at most).
fn fractions(weights: &[f64], total: f64) -> Vec<f64> {
    let sum: f64 = weights.iter().sum();
    weights.iter().map(|w| w / sum * total).collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Cuts `mesh` into parts of `areas` (and the rest) along `dir` and checks
/// every part's area against the request (relative `tol`), and that they add
/// up to the whole (relative `sum_tol`: for planar faces the pieces' areas add
/// up to rounding; for bent faces each piece is measured in its own plane).
fn check_split(
    mesh: &Mesh,
    dir: DVec3,
    areas: &[f64],
    tol: f64,
    sum_tol: f64,
) -> Result<(), TestCaseError> {
    let whole = mesh_area(mesh);
    let parts = split_by_areas(mesh, dir, areas);
    prop_assert_eq!(parts.len(), areas.len() + 1);
    let mut sum = 0.0;
    for (i, (part, &want)) in parts.iter().zip(areas).enumerate() {
        let got = mesh_area(part);
        prop_assert!(
            rel(got, want) <= tol,
            "part {} has area {} instead of {} (rel {:e})",
            i,
            got,
            want,
            rel(got, want)
        );
        sum += got;
    }
    let rest = mesh_area(&parts[areas.len()]);
    let want_rest = whole - areas.iter().sum::<f64>();
    prop_assert!(
        (rest - want_rest).abs() <= tol.max(sum_tol) * whole,
        "rest {} instead of {}",
        rest,
        want_rest
    );
    prop_assert!(rel(sum + rest, whole) <= sum_tol);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Flat lots in the xz plane, cut along x or z.
    #[test]
    fn flat_lots_split_into_requested_areas(
        lot in lot_strategy(false),
        weights in prop::collection::vec(0.05f64..1.0, 1..8),
        fill in 0.3f64..1.0,
        along_z in any::<bool>(),
    ) {
        let mesh = lot.mesh(DMat3::IDENTITY, DVec3::ZERO);
        let total = AreaProfile::of_mesh(&mesh, DVec3::X).total();
        prop_assert!(rel(total, mesh_area(&mesh)) <= 1e-12);
        let dir = if along_z { DVec3::Z } else { DVec3::X };
        check_split(&mesh, dir, &fractions(&weights, fill * total), 1e-9, 1e-12)?;
    }

    /// Lots with a hole, tilted and moved in 3D, cut along a random direction
    /// (also reversed): true 3D areas.
    #[test]
    fn lots_with_holes_in_3d_split_into_requested_areas(
        lot in lot_strategy(true),
        weights in prop::collection::vec(0.05f64..1.0, 1..8),
        fill in 0.3f64..1.0,
        (a, b, c) in (-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0),
        offset in (-1e3f64..1e3, -1e3f64..1e3, -1e3f64..1e3),
        dir in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
    ) {
        let dir = DVec3::new(dir.0, dir.1, dir.2);
        prop_assume!(dir.length() > 0.1);
        let dir = dir.normalize();
        let mesh = lot.mesh(rotation(a, b, c), DVec3::new(offset.0, offset.1, offset.2));
        let profile = AreaProfile::of_mesh(&mesh, dir);
        // Skip lots (nearly) perpendicular to the direction: their area is a
        // step, not something planes along `dir` can divide.
        prop_assume!(profile.flatness().is_nearly_planar());
        prop_assert!(rel(profile.total(), mesh_area(&mesh)) <= 1e-12);
        check_split(&mesh, dir, &fractions(&weights, fill * profile.total()), 1e-9, 1e-12)?;
    }

    /// The same polygon as one face and as a fan of triangles: same profile,
    /// and the fan splits into the requested areas too.
    #[test]
    fn multi_face_lots_match_single_face(
        lot in lot_strategy(false),
        weights in prop::collection::vec(0.05f64..1.0, 1..6),
        (a, b, c) in (-3.0f64..3.0, -3.0f64..3.0, -3.0f64..3.0),
        probes in prop::collection::vec(0.0f64..1.0, 10),
    ) {
        let rot = rotation(a, b, c);
        let one = lot.mesh(rot, DVec3::ZERO);
        let fan = lot.fan(rot, DVec3::ZERO);
        let dir = rot * DVec3::X;
        let p1 = AreaProfile::of_mesh(&one, dir);
        let p2 = AreaProfile::of_mesh(&fan, dir);
        prop_assert!(rel(p1.total(), p2.total()) <= 1e-12);
        let (lo, hi) = p1.range().unwrap();
        for &s in &probes {
            let t = lo + s * (hi - lo);
            prop_assert!((p1.area_below(t) - p2.area_below(t)).abs() <= 1e-11 * p1.total());
        }
        check_split(&fan, dir, &fractions(&weights, p2.total()), 1e-9, 1e-12)?;
    }

    /// `A` and its inverse are monotonic and inverse to each other.
    #[test]
    fn profile_is_monotonic_and_inverts(
        lot in lot_strategy(true),
        mut targets in prop::collection::vec(0.0f64..1.0, 2..40),
        dir_angle in 0.0f64..std::f64::consts::TAU,
    ) {
        let mesh = lot.mesh(DMat3::IDENTITY, DVec3::ZERO);
        let dir = DVec3::new(dir_angle.cos(), 0.0, dir_angle.sin());
        let p = AreaProfile::of_mesh(&mesh, dir);
        let total = p.total();
        targets.sort_by(f64::total_cmp);
        let mut prev_t = f64::NEG_INFINITY;
        let mut prev_a = 0.0;
        for &s in &targets {
            let want = s * total;
            let t = p.position_of(want);
            prop_assert!(t >= prev_t, "position_of is not monotonic: {} after {}", t, prev_t);
            let got = p.area_below(t);
            prop_assert!((got - want).abs() <= 1e-12 * total, "A(T({})) = {}", want, got);
            prop_assert!(got >= prev_a - 1e-12 * total);
            prev_t = t;
            prev_a = got;
        }
        // A is non-decreasing on a fine grid too, with the cross-section as its slope.
        let (lo, hi) = p.range().unwrap();
        let mut prev = 0.0;
        for i in 0..=200 {
            let t = lo + (hi - lo) * i as f64 / 200.0;
            let a = p.area_below(t);
            prop_assert!(a >= prev);
            prop_assert!(p.cross_section(t) >= 0.0);
            prev = a;
        }
        prop_assert_eq!(p.area_below(hi + 1.0), total);
        prop_assert_eq!(p.position_of(2.0 * total), hi);
        prop_assert_eq!(p.position_of(-1.0), lo);
    }

    /// Nearly planar lots (vertices moved off the plane by up to 1e-4 of the
    /// lot's size): no warning, and the parts' areas as measured still match
    /// (the cuts are polished on the bent face).
    #[test]
    fn nearly_planar_lots_split_closely(
        lot in lot_strategy(false),
        bumps in prop::collection::vec(-1.0f64..1.0, 24),
        weights in prop::collection::vec(0.05f64..1.0, 1..6),
    ) {
        let mut mesh = lot.mesh(DMat3::IDENTITY, DVec3::ZERO);
        for (p, b) in mesh.positions.iter_mut().zip(&bumps) {
            p.y += b * 1e-2; // lots are 40..120 across
        }
        let p = AreaProfile::of_mesh(&mesh, DVec3::X);
        prop_assert!(p.flatness().is_nearly_planar());
        prop_assert!(rel(p.total(), mesh_area(&mesh)) <= 1e-12);
        check_split(&mesh, DVec3::X, &fractions(&weights, 0.9 * p.total()), 1e-9, 1e-6)?;
    }
}

/// A concave (U-shaped) lot: the cut through both arms gives one part of two
/// pieces, of exactly the requested area.
#[test]
fn u_shaped_lot_cut_through_both_arms() {
    // A U open to +z: arms x in [0, 10] and [20, 30], z in [0, 30]; base z in [-10, 0].
    let u = Mesh::polygon(&[
        DVec3::new(0.0, 0.0, -10.0),
        DVec3::new(30.0, 0.0, -10.0),
        DVec3::new(30.0, 0.0, 30.0),
        DVec3::new(20.0, 0.0, 30.0),
        DVec3::new(20.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 30.0),
        DVec3::new(0.0, 0.0, 30.0),
    ]);
    assert_eq!(mesh_area(&u), 900.0);
    // From +z down: the arms first (20 per unit of z), then the base (30).
    let parts = split_by_areas(&u, -DVec3::Z, &[500.0, 250.0]);
    assert_eq!(parts.len(), 3);
    assert!((mesh_area(&parts[0]) - 500.0).abs() < 1e-10);
    assert_eq!(parts[0].faces.len(), 2, "the arms are two pieces");
    assert!((mesh_area(&parts[1]) - 250.0).abs() < 1e-10);
    assert!((mesh_area(&parts[2]) - 150.0).abs() < 1e-10);
    let p = AreaProfile::of_mesh(&u, -DVec3::Z);
    assert!((p.position_of(500.0) - -5.0).abs() < 1e-12);
    assert!((p.position_of(750.0) - 5.0).abs() < 1e-12);
}

/// A closed box: not planar (a warning case for `splitArea`), yet the
/// surface profile is exact and the split runs.
#[test]
fn closed_box_is_not_planar_but_splits() {
    let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
    let p = AreaProfile::of_mesh(&cube, DVec3::X);
    let f = p.flatness();
    assert!(!f.is_nearly_planar());
    assert!(f.normal_agreement < 1e-12);
    // The two end faces (3 x 4) are perpendicular to x: steps at 0 and 2.
    assert!((f.perpendicular_area - 24.0).abs() < 1e-12);
    assert!((p.total() - 52.0).abs() < 1e-12);
    assert!((p.area_below(1.0) - (12.0 + 14.0)).abs() < 1e-12);
    let parts = split_by_areas(&cube, DVec3::X, &[26.0]);
    assert_eq!(parts.len(), 2);
    assert!(!parts[0].is_empty() && !parts[1].is_empty());
}
