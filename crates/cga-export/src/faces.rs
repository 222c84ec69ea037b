//! Per-face helpers shared by the writers: face normals and finiteness checks.

use cga_geometry::{DVec3, Loop, Mesh};

/// Unit normal of a face from its outer loop (Newell's method, which works
/// for any planar polygon, convex or not, and averages slightly non-planar
/// ones). `None` for a degenerate (zero-area) loop. The writers take it from
/// [`face_normals`]; this is its reference.
#[cfg(test)]
pub(crate) fn face_normal(mesh: &Mesh, positions: &[DVec3], face: usize) -> Option<DVec3> {
    let outer = mesh.outer_loop(face);
    let idx = mesh.loop_indices(outer);
    let mut n = DVec3::ZERO;
    let &last = idx.last()?;
    let mut prev = positions[last as usize];
    for &i in idx {
        let p = positions[i as usize];
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

/// The two normals the writers need of a face, in one pass over its outer
/// loop (`outer`): the Newell vector relative to the first corner that the
/// triangulation works with (`cga_geometry::measure::newell`, not made
/// unit: a quad's triangles are mostly told without it, see
/// `triangulate_loops_newell`) and [`face_normal`]. Each is computed
/// exactly as its own function computes it.
pub(crate) fn face_normals(
    mesh: &Mesh,
    positions: &[DVec3],
    outer: Loop,
) -> (DVec3, Option<DVec3>) {
    let idx = mesh.loop_indices(outer);
    let (Some(&first), Some(&last)) = (idx.first(), idx.last()) else {
        return (DVec3::ZERO, None);
    };
    let o = positions[first as usize];
    let mut prev = positions[last as usize];
    let mut rel = DVec3::ZERO;
    let mut abs = DVec3::ZERO;
    for &i in idx {
        let p = positions[i as usize];
        rel += (prev - o).cross(p - o);
        abs += newell_term(prev, p);
        prev = p;
    }
    if idx.len() < 3 {
        // `newell` gives zero for edges and points.
        rel = DVec3::ZERO;
    }
    let len = abs.length();
    (rel, (len > 0.0 && len.is_finite()).then(|| abs / len))
}

/// The term of the edge from `prev` to `p` in a loop's Newell vector
/// (absolute coordinates), as [`face_normals`] and [`quad_normal`] sum it.
#[inline(always)]
fn newell_term(prev: DVec3, p: DVec3) -> DVec3 {
    DVec3::new(
        (prev.y - p.y) * (prev.z + p.z),
        (prev.z - p.z) * (prev.x + p.x),
        (prev.x - p.x) * (prev.y + p.y),
    )
}

/// [`face_normals`]'s unit normal of a face whose outer loop `outer` has
/// four corners (most faces of a model), the same bits: its loop unrolled.
pub(crate) fn quad_normal(mesh: &Mesh, positions: &[DVec3], outer: Loop) -> Option<DVec3> {
    let s = outer.start as usize;
    let p: [DVec3; 4] = std::array::from_fn(|k| positions[mesh.corners[s + k] as usize]);
    let mut abs = DVec3::ZERO;
    let mut prev = p[3];
    for p in p {
        abs += newell_term(prev, p);
        prev = p;
    }
    let len = abs.length();
    (len > 0.0 && len.is_finite()).then(|| abs / len)
}

/// Whether every position, UV (set 0) and normal of the face is finite;
/// NaN or infinite values would make the written file invalid.
pub(crate) fn face_is_finite(
    mesh: &Mesh,
    positions: &[DVec3],
    normals: Option<&[DVec3]>,
    face: usize,
) -> bool {
    let uvs = mesh.uvs[0].as_deref();
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
            positions[mesh.corners[c] as usize].is_finite() && uv_ok && normal_ok
        })
    })
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
        let n = face_normal(&m, &m.positions, 0).unwrap();
        assert!((n - DVec3::Y).length() < 1e-12);
        let mut tris = Vec::new();
        cga_geometry::triangulate_face(&m, 0, &mut tris);
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
    fn face_normals_are_the_single_computations_bit_for_bit() {
        let mut m = Mesh::new();
        // Far from the origin, tilted, a non-planar quad, a concave
        // pentagon, a triangle, an edge and a collapsed quad.
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z) + DVec3::new(1e5, 3.25, -7e4);
        m.positions.extend([
            p(0.0, 0.0, 0.0),
            p(2.0, 0.1, 0.0),
            p(2.0, 1.0, -0.3),
            p(0.0, 1.1, 0.2),
            p(3.0, 0.0, 0.0),
            p(5.0, 0.0, 1.0),
            p(5.0, 2.0, 1.0),
            p(4.0, 0.5, 0.5),
            p(3.0, 2.0, 0.0),
        ]);
        m.add_face(&[&[0, 1, 2, 3]], 0);
        m.add_face(&[&[4, 5, 6, 7, 8]], 0);
        m.add_face(&[&[0, 5, 8]], 0);
        m.add_face(&[&[0, 1]], 0);
        m.add_face(&[&[0, 0, 0, 0]], 0);
        for f in 0..m.faces.len() {
            let (newell, normal) = face_normals(&m, &m.positions, m.outer_loop(f));
            let unit = cga_geometry::measure::unit_newell(newell);
            let want = cga_geometry::measure::face_normal_at(&m, &m.positions, f);
            assert_eq!(
                unit.to_array().map(f64::to_bits),
                want.to_array().map(f64::to_bits)
            );
            let want = face_normal(&m, &m.positions, f);
            assert_eq!(
                normal.map(|n| n.to_array().map(f64::to_bits)),
                want.map(|n| n.to_array().map(f64::to_bits))
            );
            let outer = m.outer_loop(f);
            if outer.len == 4 {
                let quad = quad_normal(&m, &m.positions, outer);
                assert_eq!(
                    quad.map(|n| n.to_array().map(f64::to_bits)),
                    want.map(|n| n.to_array().map(f64::to_bits))
                );
            }
            assert_eq!(normal.is_some(), f < 3, "face {f}");
        }
    }

    #[test]
    fn degenerate_face_gives_no_triangles() {
        let m = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0]);
        assert_eq!(face_normal(&m, &m.positions, 0), None);
        let mut tris = Vec::new();
        cga_geometry::triangulate_face(&m, 0, &mut tris);
        assert!(tris.is_empty());
    }
}
