//! Per-face helpers shared by the writers: face normals, finiteness checks
//! and (for now) triangulation.

use std::cell::RefCell;

use cga_geometry::{DVec2, DVec3, Mesh};

/// Unit normal of a face from its outer loop (Newell's method, which works
/// for any planar polygon, convex or not, and averages slightly non-planar
/// ones). `None` for a degenerate (zero-area) loop.
pub(crate) fn face_normal(mesh: &Mesh, face: usize) -> Option<DVec3> {
    let outer = mesh.outer_loop(face);
    let idx = mesh.loop_indices(outer);
    let mut n = DVec3::ZERO;
    let &last = idx.last()?;
    let mut prev = mesh.positions[last as usize];
    for &i in idx {
        let p = mesh.positions[i as usize];
        n += DVec3::new(
            (prev.y - p.y) * (prev.z + p.z),
            (prev.z - p.z) * (prev.x + p.x),
            (prev.x - p.x) * (prev.y + p.y),
        );
        prev = p;
    }
    let len = n.length();
    (len > 0.0 && len.is_finite()).then(|| n / len)
}

/// Whether every position, UV (set 0) and normal of the face is finite;
/// NaN or infinite values would make the written file invalid.
pub(crate) fn face_is_finite(mesh: &Mesh, face: usize) -> bool {
    let uvs = mesh.uvs[0].as_deref();
    let normals = mesh.normals.as_deref();
    mesh.face_loops(face).iter().all(|&l| {
        mesh.loop_corners(l).all(|c| {
            let uv_ok = match uvs {
                Some(u) => u[c].is_finite(),
                None => true,
            };
            let normal_ok = match normals {
                Some(n) => n[c].is_finite(),
                None => true,
            };
            mesh.positions[mesh.corners[c] as usize].is_finite() && uv_ok && normal_ok
        })
    })
}

/// Triangulates a face: appends triangles as indices into `mesh.corners`,
/// counter-clockwise with respect to the face normal; holes are respected.
///
/// Stand-in with the signature of `cga_geometry::triangulate::triangulate_face`,
/// used until the geometry crate provides it; the writers call only this
/// function, so switching is a one-line change (and drops the `earcut`
/// dependency of this crate).
pub(crate) fn fallback_triangulate_face(mesh: &Mesh, face: usize, out: &mut Vec<[u32; 3]>) {
    let loops = mesh.face_loops(face);
    let Some(&outer) = loops.first() else {
        return;
    };
    if outer.len < 3 {
        return;
    }
    if loops.len() == 1 && outer.len == 3 {
        let s = outer.start;
        out.push([s, s + 1, s + 2]);
        return;
    }
    let Some(n) = face_normal(mesh, face) else {
        return;
    };
    // Project onto the face plane with a basis (u, v) where u × v = n, so a
    // loop that is counter-clockwise around n stays counter-clockwise in 2D.
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);

    thread_local! {
        static SCRATCH: RefCell<Scratch> = RefCell::new(Scratch::default());
    }
    SCRATCH.with_borrow_mut(|s| {
        s.points.clear();
        s.corners.clear();
        s.holes.clear();
        for (k, &l) in loops.iter().enumerate() {
            if k > 0 {
                s.holes.push(s.points.len() as u32);
            }
            for c in mesh.loop_corners(l) {
                let p = mesh.positions[mesh.corners[c] as usize];
                s.points.push([p.dot(u), p.dot(v)]);
                s.corners.push(c as u32);
            }
        }
        let Scratch {
            earcut,
            points,
            corners,
            holes,
            triangles,
        } = s;
        earcut.earcut(points.iter().copied(), holes, triangles);
        for t in triangles.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let p = |i: usize| DVec2::from(points[i]);
            let ccw = (p(b) - p(a)).perp_dot(p(c) - p(a)) >= 0.0;
            let (b, c) = if ccw { (b, c) } else { (c, b) };
            out.push([corners[a], corners[b], corners[c]]);
        }
    });
}

#[derive(Default)]
struct Scratch {
    earcut: earcut::Earcut<f64>,
    points: Vec<[f64; 2]>,
    corners: Vec<u32>,
    holes: Vec<u32>,
    triangles: Vec<u32>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri_area(mesh: &Mesh, t: [u32; 3], n: DVec3) -> f64 {
        let p = t.map(|c| mesh.positions[mesh.corners[c as usize] as usize]);
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).dot(n)
    }

    #[test]
    fn square_with_hole_keeps_area_and_orientation() {
        let mut m = Mesh::new();
        // Outer 4x4 square in the x-z plane, counter-clockwise seen from
        // above (+y), and a 2x2 clockwise hole.
        m.positions.extend([
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, -4.0),
            DVec3::new(0.0, 0.0, -4.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -3.0),
            DVec3::new(3.0, 0.0, -3.0),
            DVec3::new(3.0, 0.0, -1.0),
        ]);
        m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
        let n = face_normal(&m, 0).unwrap();
        assert!((n - DVec3::Y).length() < 1e-12);
        let mut tris = Vec::new();
        fallback_triangulate_face(&m, 0, &mut tris);
        assert_eq!(tris.len(), 8);
        let mut total = 0.0;
        for &t in &tris {
            let a = tri_area(&m, t, n);
            assert!(a > 0.0, "triangle {t:?} is clockwise");
            total += a;
        }
        assert!((total - 12.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_face_gives_no_triangles() {
        let m = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0]);
        assert_eq!(face_normal(&m, 0), None);
        let mut tris = Vec::new();
        fallback_triangulate_face(&m, 0, &mut tris);
        assert!(tris.is_empty());
    }
}
