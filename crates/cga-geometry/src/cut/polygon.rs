//! Plane polygon helpers of the cut: tracing a piece along a loop, areas,
//! point-in-polygon tests.

use glam::DVec2;

use super::*;

/// The loop `corners` from crossing `x0` on edge `e0` along the loop to
/// crossing `x1` on edge `e1`, into `piece`.
pub(super) fn trace_piece(
    corners: &[WCorner],
    piece: &mut Vec<WCorner>,
    (x0, e0): (WCorner, usize),
    (x1, e1): (WCorner, usize),
) {
    let n = corners.len();
    piece.clear();
    piece.push(x0);
    let mut e = e0;
    loop {
        e = if e + 1 == n { 0 } else { e + 1 };
        piece.push(corners[e]);
        if e == e1 {
            break;
        }
    }
    piece.push(x1);
}

/// An undirected edge as one sortable key (lower id in the high half).
pub(super) fn edge_key(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

/// Signed area of the polygon of points `pt(0..n)` (counter-clockwise
/// positive).
pub(super) fn signed_area_by(n: usize, pt: impl Fn(usize) -> DVec2) -> f64 {
    let mut a = 0.0;
    for i in 0..n {
        a += pt(i).perp_dot(pt(if i + 1 == n { 0 } else { i + 1 }));
    }
    0.5 * a
}

/// Even-odd point in polygon test. The cut itself uses
/// [`point_in_polygon_by`]; this slice form stays for the other geometry
/// modules of the crate.
#[allow(dead_code)]
pub(crate) fn point_in_polygon(q: DVec2, pts: &[DVec2]) -> bool {
    point_in_polygon_by(q, pts.len(), |i| pts[i])
}

/// Even-odd test of `q` against the polygon of points `pt(0..n)`.
pub(super) fn point_in_polygon_by(q: DVec2, n: usize, pt: impl Fn(usize) -> DVec2) -> bool {
    let mut inside = false;
    if n == 0 {
        return inside;
    }
    let mut b = pt(n - 1);
    for i in 0..n {
        let a = pt(i);
        if (a.y > q.y) != (b.y > q.y) {
            let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if q.x < x {
                inside = !inside;
            }
        }
        b = a;
    }
    inside
}

/// A point of a hole loop to test containment with: the midpoint of its
/// first edge that is not on the boundary of a candidate outer loop
/// (holes may touch their outer loop at vertices).
pub(super) fn hole_probe<'a>(
    verts: &[u32],
    p2: &impl Fn(u32) -> DVec2,
    outers: impl Iterator<Item = &'a [u32]> + Clone,
) -> DVec2 {
    let n = verts.len();
    for i in 0..n {
        let (a, b) = (verts[i], verts[(i + 1) % n]);
        let shared = outers.clone().any(|o| o.contains(&a) && o.contains(&b));
        if !shared {
            return (p2(a) + p2(b)) * 0.5;
        }
    }
    p2(verts[0])
}
