//! Triangulation of polygon faces (with holes) for export and rendering.
//!
//! Each face is projected onto its own plane (basis from its Newell normal)
//! and handed to `earcut`, a port of Mapbox's ear-clipping triangulator that
//! copes with concave outlines, collinear points and holes touching the
//! outline. Triangles index `Mesh::corners` (not positions) so that per-corner
//! texture coordinates and normals can follow each triangle corner.

use std::cell::RefCell;

use earcut::Earcut;
use glam::{DVec2, DVec3};

use crate::mesh::{Loop, Mesh};

/// Reused per-thread buffers: exporting a city triangulates millions of
/// faces, so none of them should allocate.
struct Scratch {
    earcut: Earcut<f64>,
    points: Vec<[f64; 2]>,
    /// Corner index of each entry of `points`.
    corner_of: Vec<u32>,
    holes: Vec<u32>,
    tris: Vec<u32>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch {
        earcut: Earcut::new(),
        points: Vec::new(),
        corner_of: Vec::new(),
        holes: Vec::new(),
        tris: Vec::new(),
    });
}

/// An orthonormal basis `(u, v)` of the plane with normal `n`, such that
/// `u × v = n` (so counter-clockwise around `n` stays counter-clockwise in
/// the `(u, v)` coordinates). `n` must be of unit length.
pub fn plane_basis(n: DVec3) -> (DVec3, DVec3) {
    // Pick the world axis least aligned with n to build u from.
    let a = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        DVec3::X
    } else if n.y.abs() <= n.z.abs() {
        DVec3::Y
    } else {
        DVec3::Z
    };
    let u = a.cross(n).normalize();
    let v = n.cross(u);
    (u, v)
}

/// Appends the triangles of face `face` to `out`, as triples of indices into
/// `mesh.corners`, counter-clockwise seen from the side the face normal points
/// to. Faces with loops of fewer than three corners (edge and vertex shapes)
/// and faces of zero area give no triangles.
pub fn triangulate_face(mesh: &Mesh, face: usize, out: &mut Vec<[u32; 3]>) {
    triangulate_face_at(mesh, &mesh.positions, face, out)
}

/// [`triangulate_face`] with the mesh's vertices at `positions` instead of
/// its own (the exporter triangulates a shape's geometry where it places
/// it, without copying the mesh).
pub fn triangulate_face_at(mesh: &Mesh, positions: &[DVec3], face: usize, out: &mut Vec<[u32; 3]>) {
    if face < mesh.faces.len() && mesh.outer_loop(face).len >= 3 {
        let n = crate::measure::face_normal_at(mesh, positions, face);
        triangulate_face_with_normal(mesh, positions, face, n, out);
    }
}

/// [`triangulate_face_at`] given the face's unit normal `n`, which must be
/// `measure::face_normal_at(mesh, positions, face)` (the exporter computes
/// it in one pass with the normal it writes).
pub fn triangulate_face_with_normal(
    mesh: &Mesh,
    positions: &[DVec3],
    face: usize,
    n: DVec3,
    out: &mut Vec<[u32; 3]>,
) {
    if face < mesh.faces.len() {
        triangulate_loops_with_normal(mesh, positions, mesh.face_loops(face), n, out);
    }
}

/// [`triangulate_loops_with_normal`] given the face's Newell vector
/// relative to its first corner (`measure::newell` of the outer loop, not
/// made unit), with the same triangles.
///
/// A quad's triangles are decided by the sign of the areas of two of its
/// triangles, which the projection onto the face's plane measures; most
/// quads are far from both signs' border, and there the sign of a product
/// of the edges' cross product and the Newell vector is certain to be the
/// same (`quad_diagonal`): the face's unit normal and plane basis (two
/// square roots and two divisions) are only made for quads near it and for
/// other faces.
pub fn triangulate_loops_newell(
    mesh: &Mesh,
    positions: &[DVec3],
    loops: &[Loop],
    newell: DVec3,
    out: &mut Vec<[u32; 3]>,
) {
    if let [outer] = loops {
        if outer.len == 4 {
            // The unit normal is zero exactly when this is not positive and
            // finite (`measure::unit_newell`): no triangles then.
            let d = newell.length_squared();
            if !(d > 0.0 && d.is_finite()) {
                return;
            }
            if let Some(first_diagonal) = quad_diagonal(mesh, positions, outer.start, newell) {
                push_quad(outer.start, first_diagonal, out);
                return;
            }
        }
    }
    let unit = crate::measure::unit_newell(newell);
    triangulate_loops_with_normal(mesh, positions, loops, unit, out);
}

/// The two triangles of the quad whose corners start at `s`, cut along
/// its first diagonal (corners 0–2) or its second (1–3).
#[inline]
fn push_quad(s: u32, first_diagonal: bool, out: &mut Vec<[u32; 3]>) {
    // One check of the room for both.
    out.extend_from_slice(&if first_diagonal {
        [[s, s + 1, s + 2], [s, s + 2, s + 3]]
    } else {
        [[s + 1, s + 2, s + 3], [s + 1, s + 3, s]]
    });
}

/// [`triangulate_loops_newell`] for a face of the one loop `outer` of four
/// corners whose positions are finite (the writers leave faces with other
/// values out before they triangulate), without its Newell vector: the
/// same triangles, with the edges' cross products computed once for both
/// the Newell vector and the diagonal's test.
///
/// For finite corners, `measure::newell` of the loop is
/// `(0 + r1 × r2) + r2 × r3` for the edges `r` from corner 0: its first two
/// terms are cross products with `p0 - p0`, zeros of either sign, which
/// added to +0 leave +0. Finite corners also let the largest magnitudes be
/// taken without `f64::max`'s care for NaN (Newell vectors of corners that
/// are finite but whose edges overflow are not finite, and give no
/// triangles both ways).
///
/// Returns the place in the loop of the corner the appended triangles fan
/// out from, where this is known without reading them back: `Some(0)` for
/// exactly the corners (0, 1, 2) and (0, 2, 3) (the cut along the first
/// diagonal), `Some(1)` for (1, 2, 3) and (1, 3, 0) (the second); `None`
/// for no triangles, and for the other triangulations the general path
/// makes. (Told by the caller comparing the triangles, it cost a stall per
/// quad: the comparison read back as wide words values just stored one by
/// one.)
pub fn triangulate_finite_quad(
    mesh: &Mesh,
    positions: &[DVec3],
    outer: Loop,
    out: &mut Vec<[u32; 3]>,
) -> Option<u32> {
    let s = outer.start as usize;
    let p = |k: usize| positions[mesh.corners[s + k] as usize];
    let (p0, p1, p2, p3) = (p(0), p(1), p(2), p(3));
    let (r1, r2, r3) = (p1 - p0, p2 - p0, p3 - p0);
    let (c1, c2) = (r1.cross(r2), r2.cross(r3));
    let n = (DVec3::ZERO + c1) + c2;
    let d = n.length_squared();
    if !(d > 0.0 && d.is_finite()) {
        return None;
    }
    let l = largest_magnitude(&[r1, r2, r3]);
    let a = largest_magnitude(&[n]);
    let (a1, a2) = (c1.dot(n), c2.dot(n));
    // Most quads are convex and far from degenerate: both areas are
    // positive beyond the threshold even with a bound on the corners'
    // magnitude from corner 0 alone (every corner is within `l` of it in
    // each coordinate; the factor covers the rounding of the edges). A
    // larger `big` only raises the threshold, so what this decides the
    // exact test decides the same way; the rest take that test.
    let big_bound = (largest_magnitude(&[p0]) + l) * (1.0 + 1e-9);
    if diagonal_by_sign(a1, a2, l, big_bound, a) == Some(true) {
        push_quad(outer.start, true, out);
        return Some(0);
    }
    let big = largest_magnitude(&[p0, p1, p2, p3]);
    match diagonal_by_sign(a1, a2, l, big, a) {
        Some(first) => {
            push_quad(outer.start, first, out);
            Some(if first { 0 } else { 1 })
        }
        None => {
            let before = out.len();
            let unit = crate::measure::unit_newell(n);
            triangulate_loops_with_normal(mesh, positions, &[outer], unit, out);
            let s = outer.start;
            (out[before..] == [[s, s + 1, s + 2], [s, s + 2, s + 3]]).then_some(0)
        }
    }
}

/// The largest magnitude of the coordinates of `vs`, none of them NaN:
/// comparisons instead of `f64::max`, which is several instructions for
/// its care for NaN, and gives the same number for numbers.
#[inline(always)]
fn largest_magnitude(vs: &[DVec3]) -> f64 {
    let max = |a: f64, b: f64| if a > b { a } else { b };
    vs.iter().fold(0.0, |m, v| {
        let v = v.abs();
        max(max(max(m, v.x), v.y), v.z)
    })
}

/// Whether the quad whose corners start at `s` is cut along its first
/// diagonal (corners 0–2) by [`triangulate_loops_with_normal`], when that
/// is certain without projecting it; `None` when it is not.
///
/// The projection decides by the signs of the areas of triangles 0-1-2
/// and 0-2-3 in the plane's basis. Mathematically they are the signs of
/// `c · n` for the triangles' cross products `c` of the edges from corner
/// 0 (`r1 × r2`, `r2 × r3`, computed as the Newell vector computes them)
/// and the Newell vector `n`. The projection's rounding errors grow with
/// the coordinates' magnitude `P` (it projects positions, not their
/// differences), this test's with the edges' `L`; both stay below
/// `64 ε (L P + L²) |n| + 72 ε L⁴` in the worst case, with `ε = 2⁻⁵³` and
/// lengths bounded by `√3` times their largest coordinate. A sign counts
/// only beyond `10⁻¹²` times those terms (over 40 times the bound): a
/// facade's quad 400 m from the origin decides this way down to areas of
/// a few square micrometres. (A second session's adversarial search, ten
/// million quads and a hill climb towards disagreement, found the worst
/// case a thousand times below that threshold, and the underflow case the
/// floor now covers.)
fn quad_diagonal(mesh: &Mesh, positions: &[DVec3], s: u32, n: DVec3) -> Option<bool> {
    let s = s as usize;
    let p = |k: usize| positions[mesh.corners[s + k] as usize];
    let (p0, p1, p2, p3) = (p(0), p(1), p(2), p(3));
    let (r1, r2, r3) = (p1 - p0, p2 - p0, p3 - p0);
    let a1 = r1.cross(r2).dot(n);
    let a2 = r2.cross(r3).dot(n);
    let l = r1.abs().max(r2.abs()).max(r3.abs()).max_element();
    let big = p0
        .abs()
        .max(p1.abs())
        .max(p2.abs())
        .max(p3.abs())
        .max_element();
    diagonal_by_sign(a1, a2, l, big, n.abs().max_element())
}

/// The diagonal a quad is cut along, from the two areas `a1` and `a2`
/// measured against its Newell vector (see [`quad_diagonal`]), when their
/// signs are certain: `l` is the largest magnitude of the edges' and `big`
/// of the corners' coordinates, `n` of the Newell vector's.
#[inline(always)]
fn diagonal_by_sign(a1: f64, a2: f64, l: f64, big: f64, n: f64) -> Option<bool> {
    // The least normal number as a floor: products that underflow lose
    // their relative precision (a quad 10⁻⁸⁰ m across), the projection's
    // do not.
    let t = 1e-12 * (l * (big + l) * n + l * l * l * l) + f64::MIN_POSITIVE;
    // Comparisons with NaN or infinite bounds are false: undecided.
    if a1 > t && a2 > t {
        Some(true)
    } else if a1 < -t || a2 < -t {
        Some(false)
    } else {
        None
    }
}

/// [`triangulate_face_with_normal`] for a face given by its loops (the
/// outer one first), for callers that looked them up already.
pub fn triangulate_loops_with_normal(
    mesh: &Mesh,
    positions: &[DVec3],
    loops: &[Loop],
    n: DVec3,
    out: &mut Vec<[u32; 3]>,
) {
    let Some(&outer) = loops.first() else {
        return;
    };
    if outer.len < 3 || n == DVec3::ZERO {
        return;
    }
    let single = loops.len() == 1;
    let s = outer.start;
    // Fast paths for the overwhelmingly common triangles and quads (a
    // triangle needs no projection).
    if single && outer.len == 3 {
        out.push([s, s + 1, s + 2]);
        return;
    }
    let (u, v) = plane_basis(n);
    let project = |c: usize| {
        let p = positions[mesh.corners[c] as usize];
        DVec2::new(p.dot(u), p.dot(v))
    };
    if single && outer.len == 4 {
        // Not `[0, 1, 2, 3].map(..)`: that is not inlined, and this runs
        // for most faces of a model.
        let s0 = s as usize;
        let q = [
            project(s0),
            project(s0 + 1),
            project(s0 + 2),
            project(s0 + 3),
        ];
        let area = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
        // Use the diagonal a–c if both halves turn left, else b–d (one of the
        // two diagonals of a simple quad always lies inside it).
        let first_diagonal = area(q[0], q[1], q[2]) > 0.0 && area(q[0], q[2], q[3]) > 0.0;
        push_quad(s, first_diagonal, out);
        return;
    }

    SCRATCH.with(|scratch| {
        let mut guard = scratch.borrow_mut();
        let sc = &mut *guard;
        sc.points.clear();
        sc.corner_of.clear();
        sc.holes.clear();
        for (k, l) in loops.iter().enumerate() {
            if l.len < 3 {
                continue; // a degenerate hole contributes no area
            }
            if k > 0 {
                sc.holes.push(sc.points.len() as u32);
            }
            for c in mesh.loop_corners(*l) {
                let p = project(c);
                sc.points.push([p.x, p.y]);
                sc.corner_of.push(c as u32);
            }
        }
        let Scratch {
            earcut,
            points,
            corner_of,
            holes,
            tris,
        } = sc;
        earcut.earcut(points.iter().copied(), holes, tris);
        for t in tris.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let pa = DVec2::from(points[a]);
            let pb = DVec2::from(points[b]);
            let pc = DVec2::from(points[c]);
            // earcut's output winding is not specified: make it match the face.
            if (pb - pa).perp_dot(pc - pa) >= 0.0 {
                out.push([corner_of[a], corner_of[b], corner_of[c]]);
            } else {
                out.push([corner_of[a], corner_of[c], corner_of[b]]);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{face_area, face_normal};

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// Triangulates every face and checks that the triangles cover the face
    /// area exactly once, each wound counter-clockwise around the face normal.
    fn check(mesh: &Mesh) -> Vec<[u32; 3]> {
        let mut all = Vec::new();
        for f in 0..mesh.faces.len() {
            let mut tris = Vec::new();
            triangulate_face(mesh, f, &mut tris);
            let n = face_normal(mesh, f);
            let mut sum = 0.0;
            for t in &tris {
                let p = t.map(|c| mesh.positions[mesh.corners[c as usize] as usize]);
                let a = (p[1] - p[0]).cross(p[2] - p[0]);
                assert!(a.dot(n) >= 0.0, "triangle {t:?} wound against the face");
                sum += 0.5 * a.length();
                let r = mesh.loop_corners(mesh.outer_loop(f));
                let last = mesh.face_loops(f).last().unwrap();
                for &c in t {
                    assert!(
                        r.start <= c as usize && (c as usize) < (last.start + last.len) as usize
                    );
                }
            }
            assert!(
                (sum - face_area(mesh, f)).abs() <= 1e-9 * sum.max(1.0),
                "face {f}: triangles {sum} vs area {}",
                face_area(mesh, f)
            );
            all.extend(tris);
        }
        all
    }

    #[test]
    fn triangle_and_quads() {
        let tri = Mesh::polygon(&[v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)]);
        assert_eq!(check(&tri), vec![[0, 1, 2]]);
        let quad = Mesh::polygon(&[v(0., 0., 0.), v(2., 0., 0.), v(2., 0., -1.), v(0., 0., -1.)]);
        assert_eq!(check(&quad).len(), 2);
        // A dart (concave quad): the reflex corner is at index 3, so only the
        // diagonal 1-3 lies inside.
        let dart = Mesh::polygon(&[
            v(0., 0., 0.),
            v(2., 0., -1.),
            v(0., 0., -2.),
            v(0.5, 0., -1.),
        ]);
        assert_eq!(check(&dart), vec![[1, 2, 3], [1, 3, 0]]);
    }

    #[test]
    fn concave_polygon_with_collinear_points() {
        // An L with extra collinear points along its long edges.
        let m = Mesh::polygon(&[
            v(0., 0., 0.),
            v(1., 0., 0.),
            v(2., 0., 0.),
            v(2., 0., -1.),
            v(1., 0., -1.),
            v(1., 0., -2.),
            v(0., 0., -2.),
            v(0., 0., -1.),
        ]);
        let tris = check(&m);
        assert_eq!(tris.len(), 6); // n - 2 for a simple polygon without holes
    }

    #[test]
    fn holes_including_one_touching_the_outline() {
        let mut m = Mesh::new();
        m.positions.extend([
            v(0., 0., 0.),
            v(4., 0., 0.),
            v(4., 0., -4.),
            v(0., 0., -4.),
            // a clockwise hole in the middle
            v(1., 0., -1.),
            v(1., 0., -2.),
            v(2., 0., -2.),
            v(2., 0., -1.),
        ]);
        m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
        assert_eq!(check(&m).len(), 8);
        assert_eq!(face_area(&m, 0), 15.0);
        // A hole touching the outline at the corner (4, 0, -4).
        m.positions.extend([
            v(3., 0., -3.),
            v(3., 0., -4.),
            v(4., 0., -4.),
            v(4., 0., -3.),
        ]);
        m.add_face(&[&[0, 1, 2, 3], &[8, 9, 10, 11]], 0);
        check(&m);
        assert_eq!(face_area(&m, 1), 15.0);
    }

    #[test]
    fn vertical_and_degenerate_faces() {
        // A facade quad facing +z (x right, y up).
        let m = Mesh::polygon(&[v(0., 0., 0.), v(5., 0., 0.), v(5., 3., 0.), v(0., 3., 0.)]);
        assert_eq!(check(&m).len(), 2);
        let mut e = Mesh::new();
        e.positions.extend([v(0., 0., 0.), v(1., 0., 0.)]);
        e.add_face(&[&[0, 1]], 0);
        let mut out = Vec::new();
        triangulate_face(&e, 0, &mut out);
        triangulate_face(&e, 7, &mut out); // out of range: nothing, no panic
        assert!(out.is_empty());
    }

    proptest::proptest! {
        #[test]
        fn star_polygons_with_holes_are_covered_exactly(
            radii in proptest::collection::vec(0.5f64..2.0, 3..24),
            hole in proptest::option::of(3usize..9),
            tilt in -1.0f64..1.0,
        ) {
            // A star-shaped (generally concave) outline in a tilted plane,
            // optionally with a clockwise regular hole well inside it.
            let n = radii.len();
            let frame = |x: f64, z: f64| v(x, tilt * x, z);
            let mut m = Mesh::new();
            for (i, r) in radii.iter().enumerate() {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                m.positions.push(frame(r * a.cos(), -r * a.sin()));
            }
            let outer: Vec<u32> = (0..n as u32).collect();
            let mut hole_idx = Vec::new();
            if let Some(h) = hole {
                // Every edge of the outline is at least min(r) cos(pi/n)
                // from the centre: a hole within 0.9 of that stays inside
                // (a fixed 0.3 would cross a triangle of radius 0.5).
                let min_r = radii.iter().copied().fold(f64::INFINITY, f64::min);
                let hr = 0.9 * min_r * (std::f64::consts::PI / n as f64).cos();
                for i in 0..h {
                    let a = -std::f64::consts::TAU * i as f64 / h as f64;
                    hole_idx.push(m.positions.len() as u32);
                    m.positions.push(frame(hr * a.cos(), -hr * a.sin()));
                }
            }
            if hole_idx.is_empty() {
                m.add_face(&[&outer], 0);
            } else {
                m.add_face(&[&outer, &hole_idx], 0);
            }
            let tris = check(&m);
            let expected = n - 2 + if hole_idx.is_empty() { 0 } else { hole_idx.len() + 2 };
            proptest::prop_assert_eq!(tris.len(), expected);
        }
    }

    /// One quad's triangles through the Newell-vector path and through the
    /// projection with the unit normal.
    fn quad_both_ways(corners: [DVec3; 4]) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
        let mut m = Mesh::new();
        m.positions.extend(corners);
        m.add_face(&[&[0, 1, 2, 3]], 0);
        let n = crate::measure::newell(&m.positions, &m.corners);
        let (mut fast, mut reference) = (Vec::new(), Vec::new());
        triangulate_loops_newell(&m, &m.positions, m.face_loops(0), n, &mut fast);
        let unit = crate::measure::unit_newell(n);
        triangulate_loops_with_normal(&m, &m.positions, m.face_loops(0), unit, &mut reference);
        // The writers' path for finite quads gives the Newell path's
        // triangles (and so the projection's).
        let mut writers = Vec::new();
        let fan = triangulate_finite_quad(&m, &m.positions, m.loops[0], &mut writers);
        assert_eq!(writers, fast, "{corners:?}");
        assert_eq!(
            fan == Some(0),
            writers == [[0, 1, 2], [0, 2, 3]],
            "{corners:?}"
        );
        if fan == Some(1) {
            assert_eq!(writers, [[1, 2, 3], [1, 3, 0]], "{corners:?}");
        }
        (fast, reference)
    }

    #[test]
    fn quads_decided_without_projecting_are_those_the_projection_gives() {
        let far = DVec3::new(2_683_000.0, 431.0, -1_247_000.0);
        // Convex, concave at corner 1 or 3 (the other diagonal), a bow
        // tie, collinear halves, collapsed, far away and tiny.
        let cases = [
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0., 1., 0.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(0.2, 0.2, 0.), v(0., 1., 0.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 1., 0.), v(0.8, 0.2, 0.)],
            [v(0., 0., 0.), v(1., 1., 0.), v(1., 0., 0.), v(0., 1., 0.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(2., 0., 0.), v(0., 1., 0.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 0.), v(0., 0., 0.)],
        ];
        for c in cases {
            for (shift, scale) in [
                (DVec3::ZERO, 1.0),
                (far, 1.0),
                (far, 1e-4),
                (DVec3::ZERO, 1e-9),
            ] {
                let q = c.map(|p| shift + p * scale);
                let (fast, reference) = quad_both_ways(q);
                assert_eq!(fast, reference, "{q:?}");
            }
        }
    }

    /// Corners so close together that the cross products underflow into
    /// subnormal numbers, where their sign is no longer certain (found by
    /// a reviewing session): the projection decides.
    #[test]
    fn quads_of_underflowing_size_are_projected() {
        let p = |b: [u64; 3]| DVec3::from(b.map(f64::from_bits));
        let q = [
            p([0xaf2b159e0ae59438, 0x2f22ae18474216d6, 0x2f3220a1766fa896]),
            p([0x2f19f26521cd84ec, 0xaef9400445fdb814, 0x2f29172a0d329374]),
            p([0x2f25fa9efe9c5c35, 0x2f32ad7e83259420, 0x2f307336b2a5ee10]),
            p([0xaf1429dd36204e08, 0xaf207e83e7e05adb, 0x2f3593c5dd634f74]),
        ];
        let (fast, reference) = quad_both_ways(q);
        assert_eq!(reference, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(fast, reference);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig { cases: 4000, .. Default::default() })]

        /// Quads from 10⁻⁸¹ to 10⁷⁷ across, far from the origin or not,
        /// thin (one side up to 10⁸ times the other) and strongly
        /// non-planar: the same triangles both ways.
        #[test]
        fn quads_of_any_size_give_the_projections_triangles(
            xy in proptest::array::uniform4(proptest::array::uniform2(-1.0f64..1.0)),
            lift in proptest::array::uniform4(-1.0f64..1.0),
            exponent in -81i32..77,
            far in -3i32..8,
            thin in 0i32..9,
        ) {
            let scale = 10f64.powi(exponent);
            let stretch = 10f64.powi(thin);
            // Negative: at the origin.
            let base = match far {
                ..0 => DVec3::ZERO,
                _ => DVec3::new(1.0, -0.4, 0.7) * 10f64.powi(far),
            };
            let corners: [DVec3; 4] = std::array::from_fn(|i| {
                base + DVec3::new(xy[i][0] * stretch, xy[i][1], lift[i]) * scale
            });
            let (fast, reference) = quad_both_ways(corners);
            proptest::prop_assert_eq!(fast, reference);
        }

        /// Random quads, far from the origin or not, large or tiny, planar
        /// or not, and many with a corner on or a hair from the line of a
        /// diagonal (where the two ways of deciding could part): the same
        /// triangles both ways.
        #[test]
        fn quads_give_the_projections_triangles(
            xy in proptest::array::uniform4(proptest::array::uniform2(-1.0f64..1.0)),
            lift in proptest::array::uniform4(-1.0f64..1.0),
            tilt in proptest::array::uniform3(-1.0f64..1.0),
            far in 0usize..4,
            size in 0usize..4,
            border in 0usize..3,
            hair in -1.0f64..1.0,
        ) {
            let shift = [0.0, 1e3, 1.2e6, 1e7][far];
            let scale = [1e-6, 1e-2, 1.0, 30.0][size];
            let mut q: [DVec2; 4] = xy.map(DVec2::from);
            if border > 0 {
                // Corner 3 on the line through corners 0 and 2 (or corner 1
                // on it), moved off it by a relative hair.
                let (a, b, k) = if border == 1 { (0, 2, 3) } else { (0, 2, 1) };
                let t = q[k].x;
                q[k] = q[a] + (q[b] - q[a]) * (1.0 + t) + (q[b] - q[a]).perp() * hair * 1e-12;
            }
            let n = DVec3::new(tilt[0], tilt[1], tilt[2] + 1.5).normalize();
            let (u, w) = plane_basis(n);
            let base = DVec3::new(shift, 0.3 * shift, -0.7 * shift);
            let flat = (size + far) % 2 == 0;
            let corners: [DVec3; 4] = std::array::from_fn(|i| {
                let off = if flat { 0.0 } else { lift[i] * 1e-3 };
                base + (u * q[i].x + w * q[i].y + n * off) * scale
            });
            let (fast, reference) = quad_both_ways(corners);
            proptest::prop_assert_eq!(fast, reference);
        }
    }
}
