//! Footprints (CGA's `footprint`) and the polygon booleans of the plane the
//! footprint toolkit needs, on top of `i_overlay`.
//!
//! Polygons here are lists of loops of 2D points; loops are closed
//! implicitly. Results follow `i_overlay`'s conventions: every shape is an
//! outer loop (counter-clockwise) followed by its holes (clockwise).

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::overlay::FloatOverlay;
use i_overlay::float::simplify::SimplifyShape;

use crate::mesh::Mesh;
use crate::skeleton::polygon_area;

/// Polygons with holes: each an outer loop, then its holes.
pub type Shapes = Vec<Vec<Vec<DVec2>>>;

fn to_raw(loops: &[Vec<DVec2>]) -> Vec<Vec<[f64; 2]>> {
    loops
        .iter()
        .filter(|l| l.len() >= 3 && l.iter().all(|p| p.is_finite()))
        .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
        .collect()
}

fn from_raw(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes {
    shapes
        .into_iter()
        .map(|s| {
            s.into_iter()
                .map(|l| l.into_iter().map(|[x, y]| DVec2::new(x, y)).collect())
                .collect()
        })
        .collect()
}

/// The union of loops under the non-zero winding rule: counter-clockwise
/// loops add, clockwise loops (holes) subtract.
pub fn union(loops: &[Vec<DVec2>]) -> Shapes {
    let raw = to_raw(loops);
    if raw.is_empty() {
        return Vec::new();
    }
    from_raw(raw.simplify_shape(FillRule::NonZero))
}

/// `subject` minus `clip` (both read with the non-zero rule).
pub fn difference(subject: &[Vec<DVec2>], clip: &[Vec<DVec2>]) -> Shapes {
    let (s, c) = (to_raw(subject), to_raw(clip));
    if s.is_empty() {
        return Vec::new();
    }
    if c.is_empty() {
        return union(subject);
    }
    let mut overlay = FloatOverlay::with_subj_and_clip(&s, &c);
    from_raw(overlay.overlay(OverlayRule::Difference, FillRule::NonZero))
}

/// `footprint()`: the faces of `mesh` projected orthogonally onto the
/// plane y = 0 and united, as faces facing +y (counter-clockwise seen from
/// above). Faces seen from below count like faces seen from above;
/// vertical faces add nothing.
pub fn footprint(mesh: &Mesh) -> Mesh {
    // (x, -z): counter-clockwise seen from +y is counter-clockwise here.
    let to2 = |p: DVec3| DVec2::new(p.x, -p.z);
    let mut loops: Vec<Vec<DVec2>> = Vec::new();
    for f in 0..mesh.faces.len() {
        let fl: Vec<Vec<DVec2>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| mesh.loop_points(l).map(to2).collect())
            .collect();
        let a = polygon_area(&fl[0]);
        if a.abs() <= 1e-12 * (1.0 + bounds_size(&fl[0]).powi(2)) {
            continue;
        }
        for mut l in fl {
            if a < 0.0 {
                l.reverse();
            }
            loops.push(l);
        }
    }
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    for shape in union(&loops) {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for l in &shape {
            let s = out.positions.len() as u32;
            out.positions
                .extend(l.iter().map(|q| DVec3::new(q.x, 0.0, -q.y)));
            ids.push((s..s + l.len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.add_face(&refs, 0);
    }
    out
}

fn bounds_size(l: &[DVec2]) -> f64 {
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in l {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    (hi - lo).max_element().max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extrude::{extrude, Extrusion};
    use crate::measure::{face_area, face_normal, mesh_area};

    #[test]
    fn footprint_of_a_box_and_an_l() {
        let l = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(12.0, 0.0, 0.0),
            DVec3::new(12.0, 0.0, -5.0),
            DVec3::new(5.0, 0.0, -5.0),
            DVec3::new(5.0, 0.0, -12.0),
            DVec3::new(0.0, 0.0, -12.0),
        ]);
        let solid = extrude(&l, Extrusion::FaceNormal, 7.0);
        let f = footprint(&solid);
        assert_eq!(f.faces.len(), 1);
        assert!((face_area(&f, 0) - 95.0).abs() < 1e-6);
        assert!(face_normal(&f, 0).y > 0.999);
        assert!(f.positions.iter().all(|p| p.y == 0.0));
        assert_eq!(f.outer_loop(0).len, 6);
    }

    #[test]
    fn booleans() {
        let sq = |x0: f64, y0: f64, s: f64| {
            vec![
                DVec2::new(x0, y0),
                DVec2::new(x0 + s, y0),
                DVec2::new(x0 + s, y0 + s),
                DVec2::new(x0, y0 + s),
            ]
        };
        let u = union(&[sq(0.0, 0.0, 2.0), sq(1.0, 1.0, 2.0)]);
        assert_eq!(u.len(), 1);
        assert!((polygon_area(&u[0][0]) - 7.0).abs() < 1e-6);
        let d = difference(&[sq(0.0, 0.0, 4.0)], &[sq(1.0, 1.0, 2.0)]);
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].len(), 2);
        let a: f64 = d[0].iter().map(|l| polygon_area(l)).sum();
        assert!((a - 12.0).abs() < 1e-6);
        let m = footprint(&Mesh::new());
        assert_eq!(mesh_area(&m), 0.0);
    }
}
