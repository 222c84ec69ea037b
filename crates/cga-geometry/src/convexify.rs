//! Splitting faces into convex pieces (CGA's `convexify`).
//!
//! Every reflex corner is resolved by one split line: the extension of one
//! of its two edges into the face, up to the first boundary or split line
//! it meets (the shorter of the two extensions; the incoming edge's on a
//! tie). A split along an edge's extension leaves the corner straight on
//! one side and convex on the other, so once every reflex corner has its
//! line, all pieces are convex; on rectilinear footprints the pieces are
//! rectangles (an L gives two), as rules that test
//! `geometry.isRectangular` after `convexify` expect. With a maximum
//! length, longer split lines are not made and a piece may stay concave.
//!
//! Holes take part like outer loops (their corners are reflex seen from
//! the face), so a hole is joined to the boundary by split lines; a hole no
//! line reaches (maximum length) stays a hole of the piece around it.
//!
//! The pieces are read off the planar graph of boundary edges and split
//! lines (each piece is the region left of a closed walk that turns as far
//! right as possible at every vertex). Corners that a split line made
//! straight are dropped from the pieces; the input's own corners are kept.
//! Faces whose graph cannot be walked consistently (self-intersecting
//! input) are kept whole. Cost: `O(r · n)` for `r` reflex corners and `n`
//! edges.

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::skeleton::polygon_area;
use crate::triangulate::plane_basis;

/// Splits every face of `mesh` into convex faces (see the module docs).
/// `max_length`: the longest split line made (`None`: no limit). Faces
/// keep their material; per-corner attributes are not carried over.
pub fn convexify(mesh: &Mesh, max_length: Option<f64>) -> Mesh {
    let mut out = Mesh::new();
    out.share_slots(mesh);
    for f in 0..mesh.faces.len() {
        let material = mesh.faces[f].material;
        let group = mesh.faces[f].group;
        let tags = mesh.faces[f].tags;
        let first_new = out.faces.len();
        let n = face_normal(mesh, f);
        let pieces = if n == DVec3::ZERO {
            None
        } else {
            convex_pieces(mesh, f, n, max_length)
        };
        match pieces {
            Some(pieces) => {
                for piece in pieces {
                    let mut ids: Vec<Vec<u32>> = Vec::new();
                    for l in &piece {
                        let s = out.positions.len() as u32;
                        out.positions.extend_from_slice(l);
                        ids.push((s..s + l.len() as u32).collect());
                    }
                    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
                    out.add_face(&refs, material);
                }
            }
            None => {
                // Kept whole.
                let mut ids: Vec<Vec<u32>> = Vec::new();
                for &l in mesh.face_loops(f) {
                    let s = out.positions.len() as u32;
                    out.positions.extend(mesh.loop_points(l));
                    ids.push((s..s + l.len).collect());
                }
                let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
                out.add_face(&refs, material);
            }
        }
        // Pieces keep their face's tags; edge and vertex tags are not
        // carried (like the other per-corner attributes).
        for face in &mut out.faces[first_new..] {
            face.group = group;
            face.tags = tags;
        }
    }
    out
}

/// A segment of the planar graph: boundary edges are walked one way
/// (interior on the left), split lines both ways.
#[derive(Clone, Copy)]
struct Seg {
    a: u32,
    b: u32,
    two_way: bool,
}

/// The convex pieces of face `f` (loops of 3D points, outer first), or
/// `None` to keep the face whole.
fn convex_pieces(
    mesh: &Mesh,
    f: usize,
    n: DVec3,
    max_length: Option<f64>,
) -> Option<Vec<Vec<Vec<DVec3>>>> {
    let (u, v) = plane_basis(n);
    let o = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
    // Points welded by exact position, loops without repeated points.
    let mut pts: Vec<DVec2> = Vec::new();
    let mut index: HashMap<[u64; 2], u32> = HashMap::new();
    let mut loops: Vec<Vec<u32>> = Vec::new();
    let mut scale = 0.0f64;
    for &l in mesh.face_loops(f) {
        let mut ids: Vec<u32> = Vec::new();
        for p in mesh.loop_points(l) {
            let q = DVec2::new((p - o).dot(u), (p - o).dot(v));
            if !q.is_finite() {
                return None;
            }
            scale = scale.max(q.abs().max_element());
            let key = [q.x + 0.0, q.y + 0.0].map(f64::to_bits);
            let id = *index.entry(key).or_insert_with(|| {
                pts.push(q);
                (pts.len() - 1) as u32
            });
            if ids.last() != Some(&id) {
                ids.push(id);
            }
        }
        while ids.len() > 1 && ids.first() == ids.last() {
            ids.pop();
        }
        if ids.len() >= 3 {
            loops.push(ids);
        }
    }
    if loops.is_empty() {
        return None;
    }
    let eps = 1e-9 * scale.max(1.0);
    let lift = |q: DVec2| o + u * q.x + v * q.y;
    let is_reflex = |a: DVec2, b: DVec2, c: DVec2| {
        let (d1, d2) = (b - a, c - b);
        d1.perp_dot(d2) < -1e-12 * d1.length() * d2.length()
    };
    let reflex: Vec<(u32, u32, u32)> = loops
        .iter()
        .flat_map(|l| {
            let k = l.len();
            (0..k).map(move |i| (l[(i + k - 1) % k], l[i], l[(i + 1) % k]))
        })
        .filter(|&(a, b, c)| is_reflex(pts[a as usize], pts[b as usize], pts[c as usize]))
        .collect();
    if reflex.is_empty() && loops.len() == 1 {
        let piece: Vec<DVec3> = loops[0].iter().map(|&i| lift(pts[i as usize])).collect();
        return Some(vec![vec![piece]]);
    }
    let mut segs: Vec<Seg> = Vec::new();
    for l in &loops {
        for i in 0..l.len() {
            segs.push(Seg {
                a: l[i],
                b: l[(i + 1) % l.len()],
                two_way: false,
            });
        }
    }
    let mut cut_vertex = vec![false; pts.len()];
    for &(pa, p, pn) in &reflex {
        let vp = pts[p as usize];
        if resolved(&pts, &segs, p, pa, pn) {
            continue;
        }
        let d_in = (vp - pts[pa as usize]).normalize_or_zero();
        let d_out = (vp - pts[pn as usize]).normalize_or_zero();
        let mut best: Option<(f64, usize, f64)> = None;
        for d in [d_in, d_out] {
            if d == DVec2::ZERO {
                continue;
            }
            if let Some((t, s, ts)) = ray_cast(&pts, &segs, p, d, eps) {
                if best.is_none_or(|b| t < b.0 - eps) {
                    best = Some((t, s, ts));
                }
            }
        }
        let Some((t, s, ts)) = best else {
            continue;
        };
        if max_length.is_some_and(|m| t > m) {
            continue;
        }
        let seg = segs[s];
        let len = (pts[seg.b as usize] - pts[seg.a as usize]).length();
        let hit = if ts * len <= eps {
            seg.a
        } else if (1.0 - ts) * len <= eps {
            seg.b
        } else {
            // Split the segment at the hit point.
            let q = pts[seg.a as usize] + (pts[seg.b as usize] - pts[seg.a as usize]) * ts;
            pts.push(q);
            cut_vertex.push(false);
            let m = (pts.len() - 1) as u32;
            segs[s].b = m;
            segs.push(Seg {
                a: m,
                b: seg.b,
                two_way: seg.two_way,
            });
            m
        };
        if hit == p {
            continue;
        }
        cut_vertex[p as usize] = true;
        cut_vertex[hit as usize] = true;
        segs.push(Seg {
            a: p,
            b: hit,
            two_way: true,
        });
    }
    let walks = walk_faces(&pts, &segs)?;
    // Outer walks (counter-clockwise) are pieces; clockwise walks are holes
    // no split line reached: they go to the smallest piece around them.
    let area = |w: &[u32]| {
        let p: Vec<DVec2> = w.iter().map(|&i| pts[i as usize]).collect();
        polygon_area(&p)
    };
    let (outers, holes): (Vec<Vec<u32>>, Vec<Vec<u32>>) =
        walks.into_iter().partition(|w| area(w) > 0.0);
    let mut holes_of: Vec<Vec<usize>> = vec![Vec::new(); outers.len()];
    for (h, hw) in holes.iter().enumerate() {
        let p = pts[hw[0] as usize];
        let best = outers
            .iter()
            .enumerate()
            .filter(|(_, w)| {
                let poly: Vec<DVec2> = w.iter().map(|&i| pts[i as usize]).collect();
                contains(&poly, p)
            })
            .min_by(|a, b| area(a.1).total_cmp(&area(b.1)));
        match best {
            Some((k, _)) => holes_of[k].push(h),
            None => return None,
        }
    }
    let mut pieces = Vec::with_capacity(outers.len());
    for (k, w) in outers.iter().enumerate() {
        let mut piece = vec![simplify(w, &pts, &cut_vertex, eps)
            .iter()
            .map(|&i| lift(pts[i as usize]))
            .collect::<Vec<DVec3>>()];
        for &h in &holes_of[k] {
            piece.push(holes[h].iter().map(|&i| lift(pts[i as usize])).collect());
        }
        pieces.push(piece);
    }
    Some(pieces)
}

/// Drops the corners of a walk that split lines made straight.
fn simplify(w: &[u32], pts: &[DVec2], cut_vertex: &[bool], eps: f64) -> Vec<u32> {
    let k = w.len();
    let mut out: Vec<u32> = Vec::with_capacity(k);
    for i in 0..k {
        let (a, b, c) = (w[(i + k - 1) % k], w[i], w[(i + 1) % k]);
        if cut_vertex[b as usize] {
            let (pa, pb, pc) = (pts[a as usize], pts[b as usize], pts[c as usize]);
            let d = (pc - pa).normalize_or_zero();
            let off = (pb - pa).perp_dot(d).abs();
            if off <= eps && (pb - pa).dot(pc - pb) > 0.0 {
                continue;
            }
        }
        out.push(b);
    }
    if out.len() < 3 {
        w.to_vec()
    } else {
        out
    }
}

/// True if a split line already ends at reflex corner `p` (between `pa`
/// and `pn`) and divides its angle into parts of at most 180 degrees.
fn resolved(pts: &[DVec2], segs: &[Seg], p: u32, pa: u32, pn: u32) -> bool {
    let vp = pts[p as usize];
    let d_prev = pts[pa as usize] - vp;
    let d_next = pts[pn as usize] - vp;
    // Directions of split lines at p, as angles counter-clockwise from
    // the outgoing edge; the interior spans (0, reflex angle).
    let ang = |d: DVec2| {
        let a = d_next.perp_dot(d).atan2(d_next.dot(d));
        if a < 0.0 {
            a + std::f64::consts::TAU
        } else {
            a
        }
    };
    let total = ang(d_prev);
    let mut cuts: Vec<f64> = segs
        .iter()
        .filter(|s| s.two_way && (s.a == p || s.b == p))
        .map(|s| {
            let other = if s.a == p { s.b } else { s.a };
            ang(pts[other as usize] - vp)
        })
        .filter(|&a| a > 0.0 && a < total)
        .collect();
    if cuts.is_empty() {
        return false;
    }
    cuts.push(0.0);
    cuts.push(total);
    cuts.sort_by(f64::total_cmp);
    cuts.windows(2)
        .all(|w| w[1] - w[0] <= std::f64::consts::PI + 1e-12)
}

/// The first segment hit by the ray from point `p` along `d` (skipping
/// segments that end at `p`): distance, segment, parameter on it.
fn ray_cast(pts: &[DVec2], segs: &[Seg], p: u32, d: DVec2, eps: f64) -> Option<(f64, usize, f64)> {
    let o = pts[p as usize];
    let mut best: Option<(f64, usize, f64)> = None;
    for (k, s) in segs.iter().enumerate() {
        if s.a == p || s.b == p {
            continue;
        }
        let (a, b) = (pts[s.a as usize], pts[s.b as usize]);
        let e = b - a;
        let den = d.perp_dot(e);
        if den.abs() <= 1e-15 * e.length() {
            continue;
        }
        let w = a - o;
        let t = w.perp_dot(e) / den;
        let ts = w.perp_dot(d) / den;
        let tol = eps / e.length().max(eps);
        if t > eps && ts >= -tol && ts <= 1.0 + tol && best.is_none_or(|x| t < x.0) {
            best = Some((t, k, ts.clamp(0.0, 1.0)));
        }
    }
    best
}

/// The closed walks of the planar graph with the region on their left: at
/// every vertex the walk leaves by the first edge clockwise from the one it
/// came in by. `None` if the walks do not close (inconsistent input).
fn walk_faces(pts: &[DVec2], segs: &[Seg]) -> Option<Vec<Vec<u32>>> {
    // Half-edges: (from, to).
    let mut half: Vec<(u32, u32)> = Vec::with_capacity(segs.len() * 2);
    for s in segs {
        if s.a == s.b {
            continue;
        }
        half.push((s.a, s.b));
        if s.two_way {
            half.push((s.b, s.a));
        }
    }
    let mut out_of: Vec<Vec<usize>> = vec![Vec::new(); pts.len()];
    for (h, &(a, _)) in half.iter().enumerate() {
        out_of[a as usize].push(h);
    }
    let angle = |h: usize| {
        let (a, b) = half[h];
        let d = pts[b as usize] - pts[a as usize];
        d.y.atan2(d.x)
    };
    let mut used = vec![false; half.len()];
    let mut walks = Vec::new();
    for start in 0..half.len() {
        if used[start] {
            continue;
        }
        let mut w = Vec::new();
        let mut h = start;
        let mut steps = 0;
        loop {
            if used[h] {
                if h == start {
                    break;
                }
                return None;
            }
            used[h] = true;
            let (a, b) = half[h];
            w.push(a);
            steps += 1;
            if steps > half.len() {
                return None;
            }
            // Direction back along h, seen from b.
            let d = pts[a as usize] - pts[b as usize];
            let back = d.y.atan2(d.x);
            let mut best: Option<(f64, usize)> = None;
            for &g in &out_of[b as usize] {
                let mut delta = (back - angle(g)).rem_euclid(std::f64::consts::TAU);
                if half[g].1 == a || delta <= 1e-12 {
                    // Going straight back only if nothing else.
                    delta = std::f64::consts::TAU;
                }
                if best.is_none_or(|x| delta < x.0) {
                    best = Some((delta, g));
                }
            }
            h = best?.1;
        }
        if w.len() >= 3 {
            walks.push(w);
        }
    }
    Some(walks)
}

/// Even-odd point in polygon.
fn contains(poly: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{face_area, is_face_concave, is_rectangular, mesh_area};

    fn poly(pts: &[(f64, f64)]) -> Mesh {
        let p: Vec<DVec3> = pts.iter().map(|&(x, z)| DVec3::new(x, 0.0, z)).collect();
        Mesh::polygon(&p)
    }

    fn face(m: &Mesh, f: usize) -> Mesh {
        let pts: Vec<DVec3> = m.loop_points(m.outer_loop(f)).collect();
        Mesh::polygon(&pts)
    }

    #[test]
    fn l_gives_two_rectangles() {
        let l = poly(&[
            (0.0, 0.0),
            (12.0, 0.0),
            (12.0, -5.0),
            (5.0, -5.0),
            (5.0, -12.0),
            (0.0, -12.0),
        ]);
        let c = convexify(&l, None);
        assert_eq!(c.faces.len(), 2);
        let mut areas: Vec<f64> = (0..2).map(|f| face_area(&c, f)).collect();
        areas.sort_by(f64::total_cmp);
        // The incoming edge (12,-5)->(5,-5) is extended to (0,-5).
        assert!((areas[0] - 35.0).abs() < 1e-9 && (areas[1] - 60.0).abs() < 1e-9);
        for f in 0..2 {
            assert!(is_rectangular(&face(&c, f), 1e-9));
            assert!(face_normal(&c, f).y > 0.999);
        }
        // Too short a limit: nothing is split.
        let c = convexify(&l, Some(4.0));
        assert_eq!(c.faces.len(), 1);
        assert!(is_face_concave(&c, 0));
    }

    #[test]
    fn convex_faces_stay_and_area_is_kept() {
        let r = poly(&[(0.0, 0.0), (4.0, 0.0), (4.0, -3.0), (0.0, -3.0)]);
        let c = convexify(&r, None);
        assert_eq!(c.faces.len(), 1);
        assert_eq!(c.outer_loop(0).len, 4);
        // A U (two reflex corners) and a comb of random depth.
        let u = poly(&[
            (0.0, 0.0),
            (15.0, 0.0),
            (15.0, -12.0),
            (10.0, -12.0),
            (10.0, -5.0),
            (5.0, -5.0),
            (5.0, -12.0),
            (0.0, -12.0),
        ]);
        let c = convexify(&u, None);
        assert_eq!(c.faces.len(), 3);
        assert!((mesh_area(&c) - mesh_area(&u)).abs() < 1e-9);
        for f in 0..c.faces.len() {
            assert!(!is_face_concave(&c, f));
        }
        let star: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 10.0;
                let r = if i % 2 == 0 { 5.0 } else { 2.0 };
                (r * a.cos(), -r * a.sin())
            })
            .collect();
        let s = poly(&star);
        let c = convexify(&s, None);
        assert!((mesh_area(&c) - mesh_area(&s)).abs() < 1e-9);
        for f in 0..c.faces.len() {
            assert!(!is_face_concave(&c, f), "piece {f}");
        }
    }

    #[test]
    fn holes_are_joined_and_degenerate_faces_kept() {
        let mut m = Mesh::new();
        for (x, z) in [(0.0, 0.0), (10.0, 0.0), (10.0, -10.0), (0.0, -10.0)] {
            m.positions.push(DVec3::new(x, 0.0, z));
        }
        for (x, z) in [(3.0, -3.0), (3.0, -7.0), (7.0, -7.0), (7.0, -3.0)] {
            m.positions.push(DVec3::new(x, 0.0, z));
        }
        m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
        let c = convexify(&m, None);
        assert!((mesh_area(&c) - 84.0).abs() < 1e-9);
        for f in 0..c.faces.len() {
            assert_eq!(c.faces[f].loop_count, 1);
            assert!(!is_face_concave(&c, f));
        }
        let line = poly(&[(0.0, 0.0), (1.0, 0.0), (2.0, 0.0)]);
        assert_eq!(convexify(&line, None).faces.len(), 1);
    }
}
