//! Measures of meshes: normals, areas, volume, bounds, and the purely
//! geometric `geometry.*` functions of CGA.
//!
//! Functions whose CGA counterpart depends on the shape's scope or on the
//! world frame (`geometry.height`, `geometry.angle`, orientation selectors)
//! take the mesh in the frame they should measure in: the caller transforms
//! the mesh (or passes the right axis) first.

use glam::{DVec2, DVec3};

use crate::mesh::{Loop, Mesh};
use crate::topology::Topology;
use crate::triangulate::triangulate_face;

/// Twice the vector area of a loop (Newell's method): its direction is the
/// loop's normal (counter-clockwise), its length twice the enclosed area.
/// Exact for planar polygons, concave or not; a best-fit normal otherwise.
pub fn loop_newell(mesh: &Mesh, l: Loop) -> DVec3 {
    newell(&mesh.positions, mesh.loop_indices(l))
}

/// [`loop_newell`] of the polygon through `positions[i]` for `i` in `idx`.
pub fn newell(positions: &[DVec3], idx: &[u32]) -> DVec3 {
    let n = idx.len();
    let mut acc = DVec3::ZERO;
    if n < 3 {
        return acc;
    }
    // Relative to the first point, to keep precision for far-away geometry.
    let o = positions[idx[0] as usize];
    let mut prev = positions[idx[n - 1] as usize] - o;
    for &i in idx {
        let p = positions[i as usize] - o;
        acc += prev.cross(p);
        prev = p;
    }
    acc
}

/// The unit normal of a face (Newell normal of its outer loop), or zero for
/// faces without area (edge and vertex shapes, collapsed polygons).
pub fn face_normal(mesh: &Mesh, face: usize) -> DVec3 {
    face_normal_at(mesh, &mesh.positions, face)
}

/// [`face_normal`] with the mesh's vertices at `positions` instead of its
/// own (the same mesh moved, as the exporter places a shape's geometry).
pub fn face_normal_at(mesh: &Mesh, positions: &[DVec3], face: usize) -> DVec3 {
    unit_newell(newell(positions, mesh.loop_indices(mesh.outer_loop(face))))
}

/// A Newell vector ([`newell`]) made unit, or zero when it has no length or
/// its length is not finite: [`face_normal_at`] of the loop.
pub fn unit_newell(v: DVec3) -> DVec3 {
    let len = v.length();
    if len > 0.0 && len.is_finite() {
        v / len
    } else {
        DVec3::ZERO
    }
}

/// Area of a face: its outer loop's area minus its holes' areas, measured in
/// the plane of the outer loop (exact for planar polygons, convex or not).
pub fn face_area(mesh: &Mesh, face: usize) -> f64 {
    let loops = mesh.face_loops(face);
    let outer = loop_newell(mesh, loops[0]);
    let len = outer.length();
    if len == 0.0 {
        return 0.0;
    }
    let n = outer / len;
    let mut a = len;
    for &h in &loops[1..] {
        // Holes should be clockwise; take the magnitude so that a hole given
        // the other way round still subtracts.
        a -= loop_newell(mesh, h).dot(n).abs();
    }
    (0.5 * a).max(0.0)
}

/// Sum of the face areas.
pub fn mesh_area(mesh: &Mesh) -> f64 {
    // A fold from +0.0: `sum()` of nothing is -0.0, which prints as "-0".
    (0..mesh.faces.len())
        .map(|f| face_area(mesh, f))
        .fold(0.0, |a, b| a + b)
}

/// Sum of the areas of the faces for which `keep(face, unit_normal)` holds
/// (for `geometry.area(selector)`; the selector logic is the caller's).
pub fn mesh_area_where(mesh: &Mesh, mut keep: impl FnMut(usize, DVec3) -> bool) -> f64 {
    (0..mesh.faces.len())
        .filter(|&f| keep(f, face_normal(mesh, f)))
        .map(|f| face_area(mesh, f))
        .fold(0.0, |a, b| a + b)
}

/// Signed volume enclosed by the mesh (divergence theorem): positive for a
/// closed mesh whose normals point outwards. Every loop is fanned from the
/// vertex centroid of its face's outer loop, so the value is exact for
/// polyhedra, and a face and its reverse cancel exactly (cap faces shared by
/// two cut parts add up to nothing). Meaningless for open meshes.
pub fn volume(mesh: &Mesh) -> f64 {
    let mut six_v = 0.0;
    for face in 0..mesh.faces.len() {
        let outer = mesh.outer_loop(face);
        if outer.len < 3 {
            continue;
        }
        let c = mesh.loop_points(outer).sum::<DVec3>() / outer.len as f64;
        for &l in mesh.face_loops(face) {
            let idx = mesh.loop_indices(l);
            if idx.len() < 3 {
                continue;
            }
            let mut prev = mesh.positions[idx[idx.len() - 1] as usize];
            for &i in idx {
                let p = mesh.positions[i as usize];
                six_v += c.dot(prev.cross(p));
                prev = p;
            }
        }
    }
    six_v / 6.0
}

/// Axis-aligned bounds `(min, max)` of the positions used by faces, or
/// `None` if the mesh has no corners.
pub fn bounds(mesh: &Mesh) -> Option<(DVec3, DVec3)> {
    let mut it = mesh.corners.iter().map(|&i| mesh.positions[i as usize]);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// Extent of the geometry along a unit direction (`max - min` of `p · dir`);
/// zero for an empty mesh. `geometry.height()` is the extent along world y.
pub fn extent_along(mesh: &Mesh, dir: DVec3) -> f64 {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &i in &mesh.corners {
        let d = mesh.positions[i as usize].dot(dir);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    if lo <= hi {
        hi - lo
    } else {
        0.0
    }
}

/// `geometry.height()`: extent along y of a mesh given in world coordinates.
pub fn height(mesh: &Mesh) -> f64 {
    extent_along(mesh, DVec3::Y)
}

/// `geometry.boundaryLength()`: total length of the edges used by at most
/// one face.
pub fn boundary_length(mesh: &Mesh, topo: &Topology) -> f64 {
    (0..topo.edges.len())
        .filter(|&e| topo.is_border(e))
        .map(|e| {
            let [a, b] = topo.edges[e].p;
            mesh.positions[a as usize].distance(mesh.positions[b as usize])
        })
        .sum()
}

/// Unit normals of the corner's two edges' cross product at every corner of
/// a loop, skipping corners where the edges are collinear or of zero length.
fn corner_turns(mesh: &Mesh, l: Loop, mut f: impl FnMut(DVec3, DVec3, DVec3)) {
    let idx = mesh.loop_indices(l);
    let n = idx.len();
    if n < 3 {
        return;
    }
    for k in 0..n {
        let a = mesh.positions[idx[(k + n - 1) % n] as usize];
        let b = mesh.positions[idx[k] as usize];
        let c = mesh.positions[idx[(k + 1) % n] as usize];
        f(a, b, c);
    }
}

/// `geometry.isPlanar(tolerance)`: true if the mesh has at least one face and,
/// at every corner of every face, the cross product of the corner's two edges
/// is within `tol_degrees` of the face normal. The comparison ignores the
/// sign of the cross product, since it flips at the reflex corners of
/// concave faces without the face leaving its plane; collinear corners carry
/// no information and are skipped.
pub fn is_planar(mesh: &Mesh, tol_degrees: f64) -> bool {
    if mesh.faces.is_empty() {
        return false;
    }
    let cos_tol = tol_degrees.to_radians().cos();
    (0..mesh.faces.len()).all(|face| {
        let n = face_normal(mesh, face);
        if n == DVec3::ZERO {
            return true;
        }
        let mut ok = true;
        for &l in mesh.face_loops(face) {
            corner_turns(mesh, l, |a, b, c| {
                let local = (b - a).cross(c - b);
                let len = local.length();
                // Collinear (relative to the edge lengths): no direction.
                if len <= 1e-12 * (b - a).length() * (c - b).length() || len == 0.0 {
                    return;
                }
                if (local.dot(n) / len).abs() < cos_tol {
                    ok = false;
                }
            });
        }
        ok
    })
}

/// `geometry.isRectangular(tolerance)`: true if the mesh has at least one
/// face and every face has exactly four corners (no holes) whose angles all
/// lie within `[90 - tol, 90 + tol]` degrees.
pub fn is_rectangular(mesh: &Mesh, tol_degrees: f64) -> bool {
    if mesh.faces.is_empty() {
        return false;
    }
    (0..mesh.faces.len()).all(|face| {
        let f = mesh.faces[face];
        let outer = mesh.outer_loop(face);
        if f.loop_count != 1 || outer.len != 4 {
            return false;
        }
        let mut ok = true;
        corner_turns(mesh, outer, |a, b, c| {
            let u = a - b;
            let v = c - b;
            let denom = u.length() * v.length();
            if denom == 0.0 {
                ok = false;
                return;
            }
            let angle = (u.dot(v) / denom).clamp(-1.0, 1.0).acos().to_degrees();
            if (angle - 90.0).abs() > tol_degrees {
                ok = false;
            }
        });
        ok
    })
}

/// True if the face is not convex: its outer loop has a reflex corner, or it
/// has holes (a polygon with a hole is not convex).
pub fn is_face_concave(mesh: &Mesh, face: usize) -> bool {
    if mesh.faces[face].loop_count > 1 {
        return true;
    }
    let n = face_normal(mesh, face);
    if n == DVec3::ZERO {
        return false;
    }
    let mut concave = false;
    corner_turns(mesh, mesh.outer_loop(face), |a, b, c| {
        let turn = (b - a).cross(c - b).dot(n);
        // A tiny negative turn is a collinear corner, not a reflex one.
        if turn < -1e-12 * (b - a).length() * (c - b).length() {
            concave = true;
        }
    });
    concave
}

/// `geometry.isConcave()`: true if at least one face is concave.
pub fn is_concave(mesh: &Mesh) -> bool {
    (0..mesh.faces.len()).any(|f| is_face_concave(mesh, f))
}

/// `geometry.nHoles()`: number of holes of all faces.
pub fn hole_count(mesh: &Mesh) -> usize {
    mesh.faces
        .iter()
        .map(|f| f.loop_count.saturating_sub(1) as usize)
        .sum()
}

/// The counts behind `geometry.nVertices()`, `nEdges()`, `nFaces()` and
/// `nHoles()`. Vertices are welded positions referenced by faces (an
/// extruded rectangle has 8), edges are unique undirected edges between them
/// (12 for a box).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Counts {
    pub vertices: usize,
    pub edges: usize,
    pub faces: usize,
    pub holes: usize,
}

pub fn counts(mesh: &Mesh, topo: &Topology) -> Counts {
    Counts {
        vertices: topo.referenced_vertex_count(mesh),
        edges: topo.edges.len(),
        faces: mesh.faces.len(),
        holes: hole_count(mesh),
    }
}

/// `geometry.isClosedSurface()`, see [`Topology::is_closed`].
pub fn is_closed(mesh: &Mesh) -> bool {
    Topology::new(mesh).is_closed(mesh)
}

/// Which angle `geometry.angle(...)` measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AngleKind {
    /// Largest slope of a face against the xz-plane, in [0, 90] degrees.
    MaxSlope,
    /// Compass direction of the steepest face's normal, clockwise from north
    /// (world -z), in [0, 360).
    Azimuth,
    /// `90 - MaxSlope`.
    Zenith,
}

/// `geometry.angle(kind)` for a mesh given in world coordinates. Faces are
/// compared by the slope of their plane (a face facing down has the same
/// slope as one facing up); the azimuth is that of the steepest face's normal
/// projected on the ground, 0 if that face is horizontal.
pub fn angle(mesh: &Mesh, kind: AngleKind) -> f64 {
    let mut best: Option<(f64, DVec3)> = None;
    for f in 0..mesh.faces.len() {
        let n = face_normal(mesh, f);
        if n == DVec3::ZERO {
            continue;
        }
        let slope = n.y.abs().clamp(0.0, 1.0).acos().to_degrees();
        if best.is_none_or(|(s, _)| slope > s + 1e-12) {
            best = Some((slope, n));
        }
    }
    let Some((slope, n)) = best else {
        return 0.0;
    };
    match kind {
        AngleKind::MaxSlope => slope,
        AngleKind::Zenith => 90.0 - slope,
        AngleKind::Azimuth => {
            let h = DVec2::new(n.x, -n.z);
            if h.length() <= 1e-12 {
                return 0.0;
            }
            let a = h.x.atan2(h.y).to_degrees();
            if a < 0.0 {
                (a + 360.0) % 360.0
            } else {
                a
            }
        }
    }
}

/// Range `(min, max)` of the texture coordinates of UV set `set` over the
/// corners of all faces, or `None` if the set is absent or the mesh empty.
/// Behind `geometry.uMin/uMax/vMin/vMax` and `du/dv(set, uvSpace)`.
pub fn uv_bounds(mesh: &Mesh, set: usize) -> Option<(DVec2, DVec2)> {
    let uvs = mesh.uvs.get(set)?.as_ref()?;
    let mut it = uvs.iter().copied();
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

/// Average world length of one unit of u and of v in UV set `set`, weighted
/// by triangle area (the surface stretch `geometry.du/dv(set, unitSpace)`
/// multiplies the uv range with). `None` if the set is absent or no triangle
/// has a non-degenerate parameterisation.
pub fn uv_unit_scale(mesh: &Mesh, set: usize) -> Option<DVec2> {
    let uvs = mesh.uvs.get(set)?.as_ref()?;
    let mut tris = Vec::new();
    let mut acc = DVec2::ZERO;
    let mut weight = 0.0;
    for f in 0..mesh.faces.len() {
        tris.clear();
        triangulate_face(mesh, f, &mut tris);
        for t in &tris {
            let p = t.map(|c| mesh.positions[mesh.corners[c as usize] as usize]);
            let q = t.map(|c| uvs[c as usize]);
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let (d1, d2) = (q[1] - q[0], q[2] - q[0]);
            let det = d1.x * d2.y - d2.x * d1.y;
            let area = 0.5 * e1.cross(e2).length();
            if det.abs() < 1e-300 || area == 0.0 {
                continue;
            }
            // Solve [e1 e2] = [dP/du dP/dv] [d1 d2] for the two tangents.
            let dpdu = (e1 * d2.y - e2 * d1.y) / det;
            let dpdv = (e2 * d1.x - e1 * d2.x) / det;
            acc += DVec2::new(dpdu.length(), dpdv.length()) * area;
            weight += area;
        }
    }
    (weight > 0.0).then(|| acc / weight)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// The lot `rect:W,D` of the command line: counter-clockwise from above.
    fn rect(w: f64, d: f64) -> Mesh {
        Mesh::polygon(&[v(0., 0., 0.), v(w, 0., 0.), v(w, 0., -d), v(0., 0., -d)])
    }

    /// An axis-aligned box from faces with outward normals.
    fn cube(lo: DVec3, hi: DVec3) -> Mesh {
        let mut m = Mesh::new();
        for z in [lo.z, hi.z] {
            for y in [lo.y, hi.y] {
                for x in [lo.x, hi.x] {
                    m.positions.push(v(x, y, z));
                }
            }
        }
        // index = x + 2y + 4z
        for f in [
            [0, 4, 6, 2], // -x
            [1, 3, 7, 5], // +x
            [0, 1, 5, 4], // -y
            [2, 6, 7, 3], // +y
            [0, 2, 3, 1], // -z
            [4, 5, 7, 6], // +z
        ] {
            m.add_face(&[&f], 0);
        }
        m
    }

    #[test]
    fn rectangle_lot_measures() {
        let m = rect(20.0, 30.0);
        assert_eq!(face_normal(&m, 0), DVec3::Y);
        assert_eq!(face_area(&m, 0), 600.0);
        assert_eq!(mesh_area(&m), 600.0);
        assert_eq!(bounds(&m), Some((v(0., 0., -30.), v(20., 0., 0.))));
        let topo = Topology::new(&m);
        assert_eq!(boundary_length(&m, &topo), 100.0);
        assert!(!topo.is_closed(&m));
        assert!(is_planar(&m, 0.25));
        assert!(is_rectangular(&m, 0.0));
        assert!(!is_concave(&m));
        let c = counts(&m, &topo);
        assert_eq!(
            c,
            Counts {
                vertices: 4,
                edges: 4,
                faces: 1,
                holes: 0
            }
        );
    }

    #[test]
    fn concave_face_with_hole_area() {
        // An L shape (area 3) with a clockwise unit-square hole... placed in
        // the 2x1 arm: area 3 - 0.25.
        let mut m = Mesh::new();
        m.positions.extend([
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(2., 0., -1.),
            v(1., 0., -1.),
            v(1., 0., -2.),
            v(0., 0., -2.),
            // hole, clockwise seen from above
            v(0.25, 0., -0.25),
            v(0.25, 0., -0.75),
            v(0.75, 0., -0.75),
            v(0.75, 0., -0.25),
        ]);
        m.add_face(&[&[0, 1, 2, 3, 4, 5], &[6, 7, 8, 9]], 0);
        assert!((face_area(&m, 0) - 2.75).abs() < 1e-15);
        assert_eq!(face_normal(&m, 0), DVec3::Y);
        assert!(is_concave(&m));
        assert!(!is_rectangular(&m, 1.0));
        assert_eq!(hole_count(&m), 1);
        let topo = Topology::new(&m);
        assert_eq!(boundary_length(&m, &topo), 8.0 + 2.0);
        assert_eq!(counts(&m, &topo).vertices, 10);
        assert_eq!(counts(&m, &topo).edges, 10);
    }

    #[test]
    fn cube_volume_area_closed() {
        let m = cube(v(1., 2., 3.), v(3., 5., 7.));
        assert!((volume(&m) - 24.0).abs() < 1e-12);
        assert!((mesh_area(&m) - 2.0 * (6.0 + 8.0 + 12.0)).abs() < 1e-12);
        let topo = Topology::new(&m);
        assert!(topo.is_closed(&m));
        assert_eq!(boundary_length(&m, &topo), 0.0);
        let c = counts(&m, &topo);
        assert_eq!(
            c,
            Counts {
                vertices: 8,
                edges: 12,
                faces: 6,
                holes: 0
            }
        );
        assert!(is_rectangular(&m, 0.01));
        assert_eq!(height(&m), 3.0);
        assert_eq!(angle(&m, AngleKind::MaxSlope), 90.0);
    }

    #[test]
    fn closedness_survives_duplicated_positions_and_detects_flips() {
        let mut m = cube(v(0., 0., 0.), v(1., 1., 1.));
        // Give the last face its own copies of its positions (as an OBJ with
        // per-face vertices would): still closed after welding.
        let base = m.positions.len() as u32;
        let loop0 = m.outer_loop(5);
        let idx: Vec<u32> = m.loop_indices(loop0).to_vec();
        for (k, &i) in idx.iter().enumerate() {
            let p = m.positions[i as usize] + DVec3::splat(1e-12);
            m.positions.push(p);
            m.corners[loop0.start as usize + k] = base + k as u32;
        }
        assert!(is_closed(&m));
        assert_eq!(counts(&m, &Topology::new(&m)).vertices, 8);
        // Flip one face: edges are then used twice in the same direction.
        m.corners[0..4].reverse();
        assert!(!is_closed(&m));
        // Remove a face: open.
        let mut open = cube(v(0., 0., 0.), v(1., 1., 1.));
        open.faces.pop();
        assert!(!is_closed(&open));
        assert!(!is_closed(&Mesh::new()));
    }

    #[test]
    fn planarity_with_tolerance() {
        let mut m = rect(10.0, 10.0);
        assert!(is_planar(&m, 0.25));
        // Lift one corner by 0.1: the corner normals tilt by about 0.57°.
        m.positions[2].y = 0.1;
        assert!(!is_planar(&m, 0.25));
        assert!(is_planar(&m, 1.0));
        assert!(!is_planar(&Mesh::new(), 1.0));
    }

    #[test]
    fn rectangularity_tolerance() {
        // A parallelogram with 89° and 91° corners.
        let s = 1f64.to_radians().tan();
        let m = Mesh::polygon(&[
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10. + s, 0., -1.),
            v(s, 0., -1.),
        ]);
        assert!(!is_rectangular(&m, 0.5));
        assert!(is_rectangular(&m, 1.0 + 1e-9));
        let tri = Mesh::polygon(&[v(0., 0., 0.), v(1., 0., 0.), v(0., 0., -1.)]);
        assert!(!is_rectangular(&tri, 45.0));
    }

    #[test]
    fn slope_and_azimuth_of_a_roof_plane() {
        // A 30° roof plane facing south (+z).
        let t = 30f64.to_radians().tan();
        let m = Mesh::polygon(&[v(0., 0., 0.), v(1., 0., 0.), v(1., t, -1.), v(0., t, -1.)]);
        assert!((angle(&m, AngleKind::MaxSlope) - 30.0).abs() < 1e-9);
        assert!((angle(&m, AngleKind::Zenith) - 60.0).abs() < 1e-9);
        assert!((angle(&m, AngleKind::Azimuth) - 180.0).abs() < 1e-9);
        // Facing east (+x): azimuth 90.
        let e = Mesh::polygon(&[v(0., 0., 0.), v(1., -t, 0.), v(1., -t, -1.), v(0., 0., -1.)]);
        assert!((angle(&e, AngleKind::Azimuth) - 90.0).abs() < 1e-9);
    }

    #[test]
    fn uv_ranges_and_unit_scale() {
        let mut m = rect(20.0, 30.0);
        m.uvs[0] = Some(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(2.0, 0.0),
            DVec2::new(2.0, 0.5),
            DVec2::new(0.0, 0.5),
        ]);
        assert_eq!(uv_bounds(&m, 0), Some((DVec2::ZERO, DVec2::new(2.0, 0.5))));
        assert_eq!(uv_bounds(&m, 1), None);
        let s = uv_unit_scale(&m, 0).unwrap();
        // 20 m span 2 units of u (10 m per u), 30 m span 0.5 of v (60 m per v).
        assert!((s.x - 10.0).abs() < 1e-12 && (s.y - 60.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_faces_measure_zero() {
        let mut m = Mesh::new();
        m.positions.extend([v(0., 0., 0.), v(3., 4., 0.)]);
        m.add_face(&[&[0, 1]], 0);
        m.add_face(&[&[1]], 0);
        assert_eq!(face_area(&m, 0), 0.0);
        assert_eq!(face_normal(&m, 1), DVec3::ZERO);
        assert_eq!(volume(&m), 0.0);
        let topo = Topology::new(&m);
        assert_eq!(topo.edges.len(), 1);
        assert!(!topo.is_closed(&m));
        // The 2-corner loop uses its one edge twice: not a border edge.
        assert_eq!(boundary_length(&m, &topo), 0.0);
    }
}
