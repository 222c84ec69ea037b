//! `alignScopeToGeometryBBox(alignAxes)` (op_alignScopeToGeometryBBox.md):
//! the two scope axes named by `alignAxes` turn about the third so that
//! they span the minimum-area rectangle around the geometry as seen along
//! the third axis; the first named axis runs along the rectangle's longer
//! side. The pivot takes the new axes and sits at the scope's origin, the
//! geometry stays where it is.

use cga_geometry::{DMat3, DVec2, DVec3};

use super::transform::selector;
use crate::derive::{Arg, RtError, ShapeState};
use crate::expr::OpCall;

pub fn exec(st: &mut ShapeState, call: &OpCall, args: &[Arg]) -> Result<(), RtError> {
    let Some(arg) = args.first() else {
        return Err(RtError::new(
            "`alignScopeToGeometryBBox` needs its axes (xy, yx, xz, zx, yz or zy)",
            call.span,
        ));
    };
    let which = selector(arg, &["xy", "yx", "xz", "zx", "yz", "zy"])?;
    let axis = |c: u8| (c - b'x') as usize;
    let (first, second) = (axis(which.as_bytes()[0]), axis(which.as_bytes()[1]));
    let fixed = 3 - first - second;
    let shape = &mut st.shape;
    let cur = shape.scope.frame.axes;
    let normal = cur.col(fixed);
    // The plane of the rectangle: 2D coordinates along the two current axes.
    let (u, v) = (cur.col(first), cur.col(second));
    let mesh = shape.object_mesh();
    let points: Vec<DVec2> = mesh
        .positions
        .iter()
        .filter(|p| p.is_finite())
        .map(|p| DVec2::new(p.dot(u), p.dot(v)))
        .collect();
    let Some(dir) = min_area_rect(&points) else {
        // No extent in the plane (no geometry, or a line seen end on):
        // nothing to align to; the pivot still moves to the scope origin.
        shape.pivot.axes = cur;
        shape.pivot.origin = shape.scope.frame.origin;
        shape.scope.rot = DVec3::ZERO;
        return Ok(());
    };
    // Of the two directions of the long side, the one closer to the axis
    // it replaces (so an already aligned scope keeps its axes; the
    // reference leaves the sign open).
    let long = u * dir.x + v * dir.y;
    let long = if long.dot(u) < 0.0 { -long } else { long };
    let mut cols = [DVec3::ZERO; 3];
    cols[fixed] = normal;
    cols[first] = long;
    // The second axis completes a right-handed frame.
    cols[second] = normal.cross(long);
    let mut axes = DMat3::from_cols(cols[0], cols[1], cols[2]);
    if axes.determinant() < 0.0 {
        cols[second] = -cols[second];
        axes = DMat3::from_cols(cols[0], cols[1], cols[2]);
    }
    shape.pivot.axes = axes;
    shape.fit_scope(axes);
    shape.pivot.origin = shape.scope.frame.origin;
    shape.scope.rot = DVec3::ZERO;
    Ok(())
}

/// The direction (unit) of the longer side of the minimum-area rectangle
/// enclosing `points`, or `None` if the points span no length. One side of
/// a minimum-area rectangle lies on an edge of the convex hull, so every
/// hull edge is tried (the hull is small next to the geometry).
pub(crate) fn min_area_rect(points: &[DVec2]) -> Option<DVec2> {
    let finite: Vec<DVec2> = points.iter().copied().filter(|p| p.is_finite()).collect();
    let hull = convex_hull(&finite);
    let scale = hull
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tol = 1e-9 * scale.max(1.0);
    // (area, long side direction); ties keep the first edge.
    let mut best: Option<(f64, DVec2)> = None;
    let n = hull.len();
    for i in 0..n {
        let e = hull[(i + 1) % n] - hull[i];
        let len = e.length();
        if len <= tol {
            continue;
        }
        let d = e / len;
        let p = d.perp();
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for q in &hull {
            let c = DVec2::new(q.dot(d), q.dot(p));
            lo = lo.min(c);
            hi = hi.max(c);
        }
        let ext = hi - lo;
        let area = ext.x * ext.y;
        let long = if ext.y > ext.x + tol { p } else { d };
        if best.is_none_or(|(a, _)| area < a - tol * tol.max(area * 1e-9)) {
            best = Some((area, long));
        }
    }
    best.map(|(_, d)| d)
}

/// The convex hull of `points` counter-clockwise, without collinear points
/// (Andrew's monotone chain, O(n log n)).
fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut pts: Vec<DVec2> = points.to_vec();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points() {
        let pts = [
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(0.5, 0.5),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(0.5, 0.0),
        ];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4);
    }

    #[test]
    fn rectangle_turned_by_30_degrees() {
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let d = DVec2::new(c, s);
        let p = d.perp();
        let pts: Vec<DVec2> = [(0.0, 0.0), (10.0, 0.0), (10.0, 4.0), (0.0, 4.0), (3.0, 2.0)]
            .iter()
            .map(|&(x, y)| d * x + p * y)
            .collect();
        let got = min_area_rect(&pts).unwrap();
        assert!((got.dot(d).abs() - 1.0).abs() < 1e-12, "{got}");
    }

    #[test]
    fn degenerate_inputs() {
        assert!(min_area_rect(&[]).is_none());
        assert!(min_area_rect(&[DVec2::ONE, DVec2::ONE]).is_none());
        // A segment: its direction.
        let d = min_area_rect(&[DVec2::ZERO, DVec2::new(0.0, 3.0)]).unwrap();
        assert!((d.y.abs() - 1.0).abs() < 1e-12);
        // Points that are not finite are left out.
        assert!(min_area_rect(&[DVec2::NAN, DVec2::ZERO]).is_none());
    }
}
