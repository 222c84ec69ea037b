//! The largest rectangle inside a polygon (CGA's `innerRectangle`).
//!
//! `scope` alignment looks for rectangles with sides parallel to a given
//! axis; `edge` alignment tries every edge longer than a quarter of the
//! longest edge of its loop and keeps the largest.
//!
//! The search is a grid search refined exactly: the plane is cut by the
//! lines through all vertices plus a uniform subdivision (so that slanted
//! edges are followed), grid cells lying wholly inside the polygon are
//! marked, the largest block of free cells is found (`O(R² C)` over rows
//! `R` and columns `C`), and then every side of that rectangle is pushed
//! outwards as far as the polygon allows, exactly. The result is optimal
//! for rectilinear polygons aligned with the axis, and within a grid cell of
//! the optimum otherwise.

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::triangulate::plane_basis;

/// Uniform grid lines added per axis on top of the vertex coordinates.
const SUBDIVISIONS: usize = 40;

/// Grid lines per axis at most. A polygon with more distinct vertex
/// coordinates (a round footprint of thousands of vertices) gets an evenly
/// thinned selection of them: the grid has up to this many squared cells,
/// each tested against the edges near its row, instead of a cell count that
/// grows with the square of the vertex count.
const MAX_LINES: usize = 400;

/// Edge directions tried at most by `innerRectangle(edge)`.
const MAX_DIRECTIONS: usize = 24;

/// The largest rectangle inside the polygon `loops` (outer boundary
/// counter-clockwise first, holes clockwise) with sides parallel to `axis`
/// and its perpendicular. Returns its corners counter-clockwise, or `None`
/// for polygons without area.
pub fn largest_inner_rectangle(loops: &[Vec<DVec2>], axis: DVec2) -> Option<[DVec2; 4]> {
    let ax = axis.normalize_or(DVec2::X);
    let ay = ax.perp();
    let to = |p: DVec2| DVec2::new(p.dot(ax), p.dot(ay));
    let local: Vec<Vec<DVec2>> = loops
        .iter()
        .map(|l| l.iter().map(|&p| to(p)).collect())
        .collect();
    let edges: Vec<(DVec2, DVec2)> = local
        .iter()
        .flat_map(|l| (0..l.len()).map(move |i| (l[i], l[(i + 1) % l.len()])))
        .filter(|(a, b)| a != b)
        .collect();
    if edges.len() < 3 || local.iter().flatten().any(|p| !p.is_finite()) {
        return None;
    }
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in local.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if hi.x <= lo.x || hi.y <= lo.y {
        return None;
    }
    let lines = |k: usize| -> Vec<f64> {
        let mut v: Vec<f64> = local.iter().flatten().map(|p| p[k]).collect();
        for i in 0..=SUBDIVISIONS {
            v.push(lo[k] + (hi[k] - lo[k]) * i as f64 / SUBDIVISIONS as f64);
        }
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * (hi[k] - lo[k]));
        if v.len() > MAX_LINES {
            // Evenly by rank, the first and last kept.
            let last = v.len() - 1;
            v = (0..MAX_LINES)
                .map(|i| v[i * last / (MAX_LINES - 1)])
                .collect();
        }
        v
    };
    let (xs, ys) = (lines(0), lines(1));
    let (nc, nr) = (xs.len() - 1, ys.len() - 1);
    // The edges that reach into each row (closed band): no other edge can
    // cross a cell of the row or decide whether a point of it is inside.
    let mut row_edges: Vec<Vec<u32>> = vec![Vec::new(); nr];
    for (i, &(a, b)) in edges.iter().enumerate() {
        let (y_lo, y_hi) = (a.y.min(b.y), a.y.max(b.y));
        let first = ys.partition_point(|&y| y < y_lo).saturating_sub(1);
        let end = ys.partition_point(|&y| y <= y_hi).min(nr);
        for row in &mut row_edges[first.min(end)..end] {
            row.push(i as u32);
        }
    }
    // free[r][c]: cell wholly inside.
    let mut free = vec![false; nr * nc];
    for r in 0..nr {
        let near: Vec<(DVec2, DVec2)> = row_edges[r].iter().map(|&i| edges[i as usize]).collect();
        for c in 0..nc {
            let (x0, x1, y0, y1) = (xs[c], xs[c + 1], ys[r], ys[r + 1]);
            let centre = DVec2::new(0.5 * (x0 + x1), 0.5 * (y0 + y1));
            free[r * nc + c] = inside(&near, centre)
                && !near
                    .iter()
                    .any(|&(a, b)| segment_crosses_box(a, b, x0, x1, y0, y1));
        }
    }
    // Largest block of free cells: with each row as the bottom, the free
    // runs above every column form a histogram whose largest rectangle a
    // stack finds in one pass (widths and heights are the grid's, not
    // equal): linear in the cells instead of cubic in the lines.
    // run[c]: the first row of the free run of column c ending at the
    // current row (the row after it when the cell is not free).
    let mut best = (0.0, 0, 0, 0, 0);
    let mut run = vec![0usize; nc];
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(nc + 1);
    for r in 0..nr {
        for (c, start) in run.iter_mut().enumerate() {
            if !free[r * nc + c] {
                *start = r + 1;
            }
        }
        stack.clear();
        for c in 0..=nc {
            // The column's run start; past the last column an empty one
            // closes every open rectangle.
            let here = if c < nc { run[c] } else { r + 1 };
            let mut from = c;
            // Columns whose runs are taller than this one end here.
            while let Some(&(c0, r0)) = stack.last() {
                if r0 >= here {
                    break;
                }
                stack.pop();
                let a = (xs[c] - xs[c0]) * (ys[r + 1] - ys[r0]);
                if a > best.0 {
                    best = (a, c0, c, r0, r + 1);
                }
                from = c0;
            }
            if here <= r && stack.last().is_none_or(|&(_, r0)| r0 > here) {
                stack.push((from, here));
            }
        }
    }
    if best.0 <= 0.0 {
        return None;
    }
    let (mut x0, mut x1, mut y0, mut y1) = (xs[best.1], xs[best.2], ys[best.3], ys[best.4]);
    // Push every side out as far as the polygon allows.
    for _ in 0..2 {
        x1 = push(&edges, x1, y0, y1, 1.0, false).max(x1);
        x0 = push(&edges, x0, y0, y1, -1.0, false).min(x0);
        y1 = push(&edges, y1, x0, x1, 1.0, true).max(y1);
        y0 = push(&edges, y0, x0, x1, -1.0, true).min(y0);
    }
    let back = |p: DVec2| ax * p.x + ay * p.y;
    Some([
        back(DVec2::new(x0, y0)),
        back(DVec2::new(x1, y0)),
        back(DVec2::new(x1, y1)),
        back(DVec2::new(x0, y1)),
    ])
}

/// How far the side at `at` (an x if `!swap`, a y if `swap`) spanning
/// `[lo, hi]` in the other coordinate can move in direction `sign` before
/// touching an edge.
fn push(edges: &[(DVec2, DVec2)], at: f64, lo: f64, hi: f64, sign: f64, swap: bool) -> f64 {
    let mut limit = f64::INFINITY;
    for &(a, b) in edges {
        let (a, b) = if swap {
            (DVec2::new(a.y, a.x), DVec2::new(b.y, b.x))
        } else {
            (a, b)
        };
        // Clip the edge to the band lo..hi of the second coordinate.
        let (mut p, mut q) = (a, b);
        if p.y > q.y {
            std::mem::swap(&mut p, &mut q);
        }
        if q.y < lo || p.y > hi {
            continue;
        }
        let clip = |y: f64| {
            if q.y == p.y {
                p.x.min(q.x)
            } else {
                p.x + (q.x - p.x) * ((y - p.y) / (q.y - p.y))
            }
        };
        let (ya, yb) = (p.y.max(lo), q.y.min(hi));
        let (xa, xb) = if q.y == p.y {
            (p.x, q.x)
        } else {
            (clip(ya), clip(yb))
        };
        // Touching the band only at its border (an edge along the side)
        // does not block.
        let eps = 1e-12 * (1.0 + lo.abs() + hi.abs());
        if (yb - ya).abs() <= eps && ((ya - lo).abs() <= eps || (ya - hi).abs() <= eps) {
            continue;
        }
        for x in [xa, xb] {
            let d = (x - at) * sign;
            if d >= -1e-12 {
                limit = limit.min(d.max(0.0));
            }
        }
    }
    if limit.is_finite() {
        at + sign * limit
    } else {
        at
    }
}

/// Whether `p` is inside the polygon with these edges (winding number;
/// only edges that straddle `p`'s height count, so any subset holding
/// those gives the same answer).
fn inside(edges: &[(DVec2, DVec2)], p: DVec2) -> bool {
    let c = |q: DVec2| robust::Coord { x: q.x, y: q.y };
    let mut wn = 0i32;
    for &(a, b) in edges {
        let o = robust::orient2d(c(a), c(b), c(p));
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                wn += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            wn -= 1;
        }
    }
    wn != 0
}

/// True if segment `a b` passes through the open box.
fn segment_crosses_box(a: DVec2, b: DVec2, x0: f64, x1: f64, y0: f64, y1: f64) -> bool {
    // Liang-Barsky clipping against the open box.
    let d = b - a;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-d.x, a.x - x0),
        (d.x, x1 - a.x),
        (-d.y, a.y - y0),
        (d.y, y1 - a.y),
    ] {
        if p == 0.0 {
            if q <= 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    t1 - t0 > 1e-12
}

/// The direction of the first edge of a loop of positive length.
fn first_edge(l: &[DVec2]) -> DVec2 {
    (0..l.len())
        .map(|i| l[(i + 1) % l.len()] - l[i])
        .find(|d| d.length_squared() > 0.0)
        .unwrap_or(DVec2::X)
}

/// The rectangle's corners rotated (still counter-clockwise) so that its
/// first edge points most nearly along `dir`.
fn first_edge_like(r: [DVec2; 4], dir: DVec2) -> [DVec2; 4] {
    let d = dir.normalize_or(DVec2::X);
    let along = |k: usize| (r[(k + 1) % 4] - r[k]).normalize_or_zero().dot(d);
    let mut k = 0;
    for i in 1..4 {
        // Of two equally good edges (rounding), the earlier one.
        if along(i) > along(k) + 1e-9 {
            k = i;
        }
    }
    [r[k], r[(k + 1) % 4], r[(k + 2) % 4], r[(k + 3) % 4]]
}

/// `innerRectangle(scope | edge)` on face `face` of `mesh`: the rectangle
/// (a face in the face's plane, counter-clockwise) and the remainder (the
/// original face with the rectangle cut out as an extra hole loop, which
/// touches the boundary where the rectangle does). With `axis = Some(d)`
/// the rectangle is parallel to `d` projected onto the face (scope
/// alignment); with `None` every edge longer than a quarter of the longest
/// edge of its loop is tried (edge alignment).
pub fn inner_rectangle(mesh: &Mesh, face: usize, axis: Option<DVec3>) -> Option<(Mesh, Mesh)> {
    let n = face_normal(mesh, face);
    if n == DVec3::ZERO {
        return None;
    }
    let (u, v) = plane_basis(n);
    let o = mesh.positions[mesh.corners[mesh.outer_loop(face).start as usize] as usize];
    let loops: Vec<Vec<DVec2>> = mesh
        .face_loops(face)
        .iter()
        .map(|&l| {
            mesh.loop_points(l)
                .map(|p| DVec2::new((p - o).dot(u), (p - o).dot(v)))
                .collect()
        })
        .collect();
    let area = |r: &[DVec2; 4]| (r[1] - r[0]).length() * (r[3] - r[0]).length();
    let rect = match axis {
        Some(a) => largest_inner_rectangle(&loops, DVec2::new(a.dot(u), a.dot(v))),
        None => {
            // Candidate edges, in loop order, then each direction once
            // (parallel and perpendicular edges give the same rectangle),
            // at most MAX_DIRECTIONS of them, longest edges first: a round
            // footprint of thousands of edges would otherwise try each.
            let mut edges: Vec<(f64, DVec2)> = Vec::new();
            for l in &loops {
                let len = |i: usize| (l[(i + 1) % l.len()] - l[i]).length();
                let longest = (0..l.len()).map(len).fold(0.0, f64::max);
                for i in 0..l.len() {
                    if len(i) > 0.25 * longest {
                        edges.push((len(i), l[(i + 1) % l.len()] - l[i]));
                    }
                }
            }
            let mut order: Vec<usize> = (0..edges.len()).collect();
            order.sort_by(|&a, &b| edges[b].0.total_cmp(&edges[a].0));
            let quarter = std::f64::consts::FRAC_PI_2;
            let mut angles: Vec<f64> = Vec::new();
            let mut tried: Vec<usize> = Vec::new();
            for i in order {
                let d = edges[i].1;
                let a = d.y.atan2(d.x).rem_euclid(quarter);
                let same = |t: &f64| {
                    let gap = (t - a).abs();
                    gap.min(quarter - gap) <= 1e-9
                };
                if angles.iter().any(same) {
                    continue;
                }
                if tried.len() == MAX_DIRECTIONS {
                    break;
                }
                angles.push(a);
                tried.push(i);
            }
            // Tried in loop order, so that of equal rectangles the first
            // edge's wins.
            tried.sort_unstable();
            let mut best: Option<[DVec2; 4]> = None;
            for i in tried {
                if let Some(r) = largest_inner_rectangle(&loops, edges[i].1) {
                    if best.is_none_or(|b| area(&r) > area(&b)) {
                        best = Some(r);
                    }
                }
            }
            // CityEngine keeps the face's edge order: the rectangle's first
            // edge is the one that runs most nearly like the face's first
            // edge (parallel and the same way when the rectangle has such
            // an edge), measured with its runtime on rectangles in every
            // vertex rotation, squares, trapezoids and an L.
            best.map(|r| first_edge_like(r, first_edge(&loops[0])))
        }
    }?;
    let lift = |p: DVec2| o + u * p.x + v * p.y;
    let mut shape = Mesh::polygon(&rect.map(lift));
    shape.materials = mesh.materials.clone();
    shape.tags = mesh.tags.clone();
    shape.faces[0].material = mesh.faces[face].material;
    shape.faces[0].tags = mesh.faces[face].tags;
    let mut rem = Mesh::new();
    rem.materials = mesh.materials.clone();
    rem.tags = mesh.tags.clone();
    let mut ids: Vec<Vec<u32>> = Vec::new();
    for &l in mesh.face_loops(face) {
        let s = rem.positions.len() as u32;
        rem.positions.extend(mesh.loop_points(l));
        ids.push((s..s + l.len).collect());
    }
    let s = rem.positions.len() as u32;
    rem.positions
        .extend([rect[0], rect[3], rect[2], rect[1]].map(lift));
    ids.push((s..s + 4).collect());
    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
    let nf = rem.add_face(&refs, mesh.faces[face].material);
    rem.faces[nf].tags = mesh.faces[face].tags;
    Some((shape, rem))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> DVec2 {
        DVec2::new(x, y)
    }

    fn rect_area(r: &[DVec2; 4]) -> f64 {
        (r[1] - r[0]).length() * (r[3] - r[0]).length()
    }

    #[test]
    fn rectangle_and_l() {
        let r = largest_inner_rectangle(
            &[vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 6.0), v(0.0, 6.0)]],
            DVec2::X,
        )
        .unwrap();
        assert!((rect_area(&r) - 60.0).abs() < 1e-9);
        // L: 10x4 bottom bar + 4x6 left wing: best is the 10x4 bar (40) vs 4x10 (40).
        let l = vec![
            v(0.0, 0.0),
            v(10.0, 0.0),
            v(10.0, 4.0),
            v(4.0, 4.0),
            v(4.0, 10.0),
            v(0.0, 10.0),
        ];
        let r = largest_inner_rectangle(&[l], DVec2::X).unwrap();
        assert!((rect_area(&r) - 40.0).abs() < 1e-9);
    }

    #[test]
    fn triangle_and_rotated_square() {
        // Right triangle with legs 4: the best axis-aligned rectangle is 2x2.
        let t = vec![v(0.0, 0.0), v(4.0, 0.0), v(0.0, 4.0)];
        let r = largest_inner_rectangle(&[t], DVec2::X).unwrap();
        assert!((rect_area(&r) - 4.0).abs() < 0.05, "{}", rect_area(&r));
        // A square rotated by 45 degrees, aligned with its edge: the whole square.
        let s = vec![v(0.0, -1.0), v(1.0, 0.0), v(0.0, 1.0), v(-1.0, 0.0)];
        let r = largest_inner_rectangle(std::slice::from_ref(&s), v(1.0, 1.0)).unwrap();
        assert!((rect_area(&r) - 2.0).abs() < 1e-9);
        // Axis-aligned in the diamond: the inscribed square of area 1.
        let r = largest_inner_rectangle(&[s], DVec2::X).unwrap();
        assert!((rect_area(&r) - 1.0).abs() < 0.02);
    }

    #[test]
    fn with_a_hole_and_on_a_mesh() {
        let outer = vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 10.0), v(0.0, 10.0)];
        let hole = vec![v(3.0, 3.0), v(3.0, 7.0), v(7.0, 7.0), v(7.0, 3.0)];
        let r = largest_inner_rectangle(&[outer, hole], DVec2::X).unwrap();
        assert!((rect_area(&r) - 30.0).abs() < 1e-9);
        let m = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(8.0, 0.0, 0.0),
            DVec3::new(8.0, 0.0, -3.0),
            DVec3::new(4.0, 0.0, -6.0),
            DVec3::new(0.0, 0.0, -6.0),
        ]);
        let (shape, rem) = inner_rectangle(&m, 0, None).unwrap();
        let a = crate::measure::face_area(&shape, 0);
        let b = crate::measure::face_area(&rem, 0);
        assert!((a + b - crate::measure::face_area(&m, 0)).abs() < 1e-9);
        assert!(a >= 8.0 * 3.0 - 1e-9);
        assert!(face_normal(&shape, 0).y > 0.99);
    }
}
