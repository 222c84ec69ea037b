//! Pieces of a mesh, as the component split (`comp`) takes it apart:
//! copying faces, holes, edges and vertices into new meshes with their
//! attributes, materials, groups and tags ([`SubmeshBuilder`]), connected
//! sets ([`UnionFind`]), corner navigation, and the frames components are
//! placed in (x along the first edge, z along the normal).

use crate::mesh::{Face, Loop, SharedVec};
use crate::{DMat3, DVec3, Mesh};

/// Union-find over `0..n`.
pub struct UnionFind(Vec<usize>);

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> UnionFind {
        UnionFind((0..n).collect())
    }
    /// The root of `i`'s set (the set's first member).
    pub fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    /// Joins the sets of `a` and `b`.
    pub fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        // The smaller root wins, so roots are first members.
        if a < b {
            self.0[b] = a;
        } else if b < a {
            self.0[a] = b;
        }
    }
}

/// The loop of `face` that holds `corner` (its outer loop if none does).
pub fn loop_of_corner(mesh: &Mesh, face: usize, corner: usize) -> Loop {
    mesh.face_loops(face)
        .iter()
        .copied()
        .find(|l| mesh.loop_corners(*l).contains(&corner))
        .unwrap_or(mesh.outer_loop(face))
}

/// The corner after `corner` in its loop.
pub fn next_corner(mesh: &Mesh, corner: usize) -> usize {
    let l = containing_loop(mesh, corner);
    let r = mesh.loop_corners(l);
    if corner + 1 == r.end {
        r.start
    } else {
        corner + 1
    }
}

/// The corner before `corner` in its loop.
pub fn prev_corner(mesh: &Mesh, corner: usize) -> usize {
    let l = containing_loop(mesh, corner);
    let r = mesh.loop_corners(l);
    if corner == r.start {
        r.end - 1
    } else {
        corner - 1
    }
}

/// The loop a corner belongs to (loops are sorted by their first corner).
fn containing_loop(mesh: &Mesh, corner: usize) -> Loop {
    let i = mesh
        .loops
        .partition_point(|l| l.start as usize <= corner)
        .saturating_sub(1);
    mesh.loops[i]
}

/// The face a corner belongs to.
pub fn face_of_corner(mesh: &Mesh, corner: usize) -> usize {
    let lp = mesh
        .loops
        .partition_point(|l| l.start as usize <= corner)
        .saturating_sub(1) as u32;
    mesh.faces
        .partition_point(|f| f.first_loop <= lp)
        .saturating_sub(1)
}

/// The normal stored on a corner, if the mesh carries normals.
pub fn stored_normal(mesh: &Mesh, corner: usize) -> Option<DVec3> {
    mesh.normals
        .as_ref()
        .and_then(|n| n.get(corner).copied())
        .and_then(|n| n.try_normalize())
}

/// Reverses a closed polygon keeping its first point first.
pub fn reverse_keep_first<T>(pts: &mut [T]) {
    if pts.len() > 2 {
        pts[1..].reverse();
    }
}

/// The unit part of `c` orthogonal to the unit vector `v`, unless `c` is
/// (nearly) parallel to `v` or zero.
fn orthogonal_part(c: DVec3, v: DVec3) -> Option<DVec3> {
    let r = c - v * c.dot(v);
    (r.length() > 1e-9 * c.length()).then(|| r.normalize())
}

/// A unit vector perpendicular to the unit vector `v`: the first candidate
/// not parallel to it, made orthogonal.
pub fn perpendicular(v: DVec3, candidates: &[DVec3]) -> DVec3 {
    candidates
        .iter()
        .find_map(|&c| orthogonal_part(c, v))
        .unwrap_or_else(|| v.any_orthonormal_vector())
}

/// The frame of a face: x along its first edge, z along `normal`.
/// (`pts` in loop order; an iterator, so that a face's loop is read in
/// place.)
pub fn face_frame(
    pts: impl IntoIterator<Item = DVec3>,
    normal: DVec3,
    stored: Option<DVec3>,
) -> (DVec3, DMat3) {
    let mut pts = pts.into_iter();
    let origin = pts.next().unwrap_or(DVec3::ZERO);
    // "The first edge": from the first vertex to the next distinct one.
    let x = pts
        .map(|p| p - origin)
        .find(|d| d.length_squared() > 1e-24)
        .unwrap_or(DVec3::X);
    let z = if normal != DVec3::ZERO {
        normal
    } else {
        stored.unwrap_or(DVec3::ZERO)
    };
    (origin, frame_from_x_z(x, z))
}

/// Right-handed axes with x along `x` and z as close to `z` as is
/// orthogonal to x.
pub fn frame_from_x_z(x: DVec3, z: DVec3) -> DMat3 {
    let x = x.try_normalize().unwrap_or(DVec3::X);
    let z =
        orthogonal_part(z, x).unwrap_or_else(|| perpendicular(x, &[DVec3::Z, DVec3::Y, DVec3::X]));
    DMat3::from_cols(x, z.cross(x), z)
}

/// Right-handed axes with x along `x` and y as close to `y` as is
/// orthogonal to x (z = x × y).
pub fn frame_from_x_y(x: DVec3, y: DVec3) -> DMat3 {
    let x = x.try_normalize().unwrap_or(DVec3::X);
    let y =
        orthogonal_part(y, x).unwrap_or_else(|| perpendicular(x, &[DVec3::Y, DVec3::Z, DVec3::X]));
    DMat3::from_cols(x, y, x.cross(y))
}

/// Right-handed axes with z along `z` and x as close to the current x axis
/// as is orthogonal to z (a vertex frame).
pub fn frame_from_z(z: DVec3) -> DMat3 {
    let z = z.try_normalize().unwrap_or(DVec3::Z);
    let x = perpendicular(z, &[DVec3::X, DVec3::Z, DVec3::Y]);
    DMat3::from_cols(x, z.cross(x), z)
}

/// Maps `mesh` (parent scope-local) into the frame `(origin, axes)`, then
/// moves it so that its bounding box starts at zero. Returns the bounding
/// box in the frame. Coordinates within rounding noise of zero are set to
/// zero so that flat components have exactly zero scope sizes.
pub fn to_frame(mesh: &mut Mesh, origin: DVec3, axes: DMat3) -> (DVec3, DVec3) {
    let inv = axes.transpose();
    let extent = mesh
        .positions
        .iter()
        .fold(0.0f64, |m, p| m.max((*p - origin).abs().max_element()));
    let snap = 1e-11 * extent.max(1.0);
    let clean = |v: f64| if v.abs() <= snap { 0.0 } else { v };
    for p in &mut mesh.positions {
        let q = inv * (*p - origin);
        *p = DVec3::new(clean(q.x), clean(q.y), clean(q.z));
    }
    if let Some(normals) = &mut mesh.normals {
        for n in normals {
            *n = inv * *n;
        }
    }
    let mut it = mesh.corners.iter().map(|&c| mesh.positions[c as usize]);
    let Some(first) = it.next() else {
        return (DVec3::ZERO, DVec3::ZERO);
    };
    let (lo, hi) = it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
    if lo != DVec3::ZERO {
        for p in &mut mesh.positions {
            *p -= lo;
        }
    }
    (lo, hi)
}

/// Copies parts of a mesh into new meshes, with their per-corner
/// attributes, materials and groups. The position map is reused between
/// components and reset after each, so that splitting a mesh of `n` faces
/// costs O(size of the mesh), not O(n × positions).
pub struct SubmeshBuilder {
    remap: Vec<u32>,
    touched: Vec<u32>,
    mat_remap: Vec<u32>,
    group_remap: Vec<u32>,
    /// The source slots the component uses, in order of first use: its
    /// material slots and groups (see `finish`).
    used_mats: Vec<u32>,
    used_groups: Vec<u32>,
    /// Edge and vertex components carry their normal on their corners.
    force_normals: bool,
}

impl SubmeshBuilder {
    /// A builder for components of `src`.
    pub fn new(src: &Mesh) -> SubmeshBuilder {
        SubmeshBuilder {
            remap: vec![u32::MAX; src.positions.len()],
            touched: Vec::new(),
            mat_remap: vec![u32::MAX; src.materials.len()],
            group_remap: vec![u32::MAX; src.groups.len()],
            used_mats: Vec::new(),
            used_groups: Vec::new(),
            force_normals: false,
        }
    }

    /// A new, empty component of `src`; `points` for edges and vertices,
    /// which carry their normal on their corners.
    pub fn begin(&mut self, src: &Mesh, points: bool) -> Mesh {
        // Material slots and groups are set by `finish`.
        let mut m = Mesh::new();
        for (dst, s) in m.uvs.iter_mut().zip(&src.uvs) {
            if s.is_some() {
                *dst = Some(Vec::new());
            }
        }
        self.force_normals = points;
        if src.normals.is_some() || self.force_normals {
            m.normals = Some(Vec::new());
        }
        // Components keep their tags: the source's tag table is shared.
        m.tags = src.tags.clone();
        if src.edge_tags.is_some() {
            m.edge_tags = Some(Vec::new());
        }
        if src.vertex_tags.is_some() {
            m.vertex_tags = Some(Vec::new());
        }
        m
    }

    fn position(&mut self, src: &Mesh, out: &mut Mesh, p: u32) -> u32 {
        let slot = &mut self.remap[p as usize];
        if *slot == u32::MAX {
            *slot = out.positions.len() as u32;
            out.positions.push(src.positions[p as usize]);
            self.touched.push(p);
        }
        *slot
    }

    fn slots(&mut self, src: &Mesh, face: usize) -> (u32, u32) {
        let f = src.faces[face];
        let m = f.material as usize;
        if self.mat_remap.get(m) == Some(&u32::MAX) {
            self.mat_remap[m] = self.used_mats.len() as u32;
            self.used_mats.push(m as u32);
        }
        let g = f.group as usize;
        if self.group_remap.get(g) == Some(&u32::MAX) {
            self.group_remap[g] = self.used_groups.len() as u32;
            self.used_groups.push(g as u32);
        }
        (
            self.mat_remap.get(m).copied().unwrap_or(0),
            self.group_remap.get(g).copied().unwrap_or(0),
        )
    }

    /// Appends corner `c` of `src` (position and attributes; `normal`
    /// replaces the stored normal if given).
    fn corner(&mut self, src: &Mesh, out: &mut Mesh, c: usize, normal: Option<DVec3>) {
        let p = self.position(src, out, src.corners[c]);
        out.corners.push(p);
        for (dst, s) in out.uvs.iter_mut().zip(&src.uvs) {
            if let (Some(dst), Some(s)) = (dst.as_mut(), s.as_ref()) {
                dst.push(s.get(c).copied().unwrap_or_default());
            }
        }
        if let Some(dst) = out.normals.as_mut() {
            let n = normal
                .or_else(|| src.normals.as_ref().and_then(|n| n.get(c).copied()))
                .unwrap_or(DVec3::ZERO);
            dst.push(n);
        }
        if let Some(dst) = out.edge_tags.as_mut() {
            dst.push(src.edge_tag_index(c));
        }
        if let Some(dst) = out.vertex_tags.as_mut() {
            dst.push(src.vertex_tag_index(c));
        }
    }

    /// Appends corners `run` of `src` in order, as [`corner`](Self::corner)
    /// would one by one (with their stored normals), each attribute array
    /// extended at once: a component's faces are runs of whole loops, and
    /// per-corner checks of ten UV sets cost more than the copying.
    fn run_of_corners(&mut self, src: &Mesh, out: &mut Mesh, run: std::ops::Range<usize>) {
        for c in run.clone() {
            let p = self.position(src, out, src.corners[c]);
            out.corners.push(p);
        }
        for (dst, s) in out.uvs.iter_mut().zip(&src.uvs) {
            if let (Some(dst), Some(s)) = (dst.as_mut(), s.as_ref()) {
                extend_from_run(dst, s, run.clone());
            }
        }
        if let Some(dst) = out.normals.as_mut() {
            extend_from_run(dst, src.normals.as_deref().unwrap_or_default(), run.clone());
        }
        let tags = [
            (&mut out.edge_tags, &src.edge_tags),
            (&mut out.vertex_tags, &src.vertex_tags),
        ];
        for (dst, s) in tags {
            if let Some(dst) = dst.as_mut() {
                extend_from_run(dst, s.as_deref().unwrap_or_default(), run.clone());
            }
        }
    }

    /// Appends face `face` of `src` with its holes.
    pub fn add_face(&mut self, src: &Mesh, out: &mut Mesh, face: usize) {
        let (material, group) = self.slots(src, face);
        let first_loop = out.loops.len() as u32;
        let loops = src.face_loops(face);
        for &l in loops {
            let start = out.corners.len() as u32;
            self.run_of_corners(src, out, src.loop_corners(l));
            out.loops.push(Loop { start, len: l.len });
        }
        out.faces.push(Face {
            first_loop,
            loop_count: loops.len() as u32,
            material,
            group,
            tags: src.faces[face].tags,
        });
    }

    /// A hole loop as a face of its own, facing like the face it is cut
    /// from (the clockwise hole loop reversed, first corner kept).
    pub fn add_hole(&mut self, src: &Mesh, out: &mut Mesh, face: usize, lp: usize) {
        let (material, group) = self.slots(src, face);
        let l = src.loops[lp];
        let mut corners: Vec<usize> = src.loop_corners(l).collect();
        reverse_keep_first(&mut corners);
        let start = out.corners.len() as u32;
        for c in corners {
            self.corner(src, out, c, None);
        }
        // Reversed keeping the first corner: the edges run in reverse order.
        let r = start as usize..out.corners.len();
        if let Some(e) = out.edge_tags.as_mut() {
            for (k, c) in src.loop_corners(l).enumerate() {
                e[r.end - 1 - k] = src.edge_tag_index(c);
            }
        }
        out.loops.push(Loop { start, len: l.len });
        out.faces.push(Face {
            first_loop: out.loops.len() as u32 - 1,
            loop_count: 1,
            material,
            group,
            tags: src.faces[face].tags,
        });
    }

    /// An edge (two corners) or a vertex (one corner) as a face, with
    /// `normal` stored on its corners.
    pub fn add_points(
        &mut self,
        src: &Mesh,
        out: &mut Mesh,
        corners: &[usize],
        face: usize,
        normal: DVec3,
    ) {
        let (material, group) = self.slots(src, face);
        let start = out.corners.len() as u32;
        for &c in corners {
            self.corner(src, out, c, Some(normal));
        }
        // Both corners of an edge shape stand for the one edge.
        if let (Some(e), [c0, _]) = (out.edge_tags.as_mut(), corners) {
            let t = src.edge_tag_index(*c0);
            let n = e.len();
            e[n - 2..].fill(t);
        }
        out.loops.push(Loop {
            start,
            len: corners.len() as u32,
        });
        out.faces.push(Face {
            first_loop: out.loops.len() as u32 - 1,
            loop_count: 1,
            material,
            group,
            tags: src.faces[face].tags,
        });
    }

    /// Resets the maps for the next component and completes `out`.
    pub fn finish(&mut self, src: &Mesh, out: &mut Mesh) {
        for p in self.touched.drain(..) {
            self.remap[p as usize] = u32::MAX;
        }
        for &m in &self.used_mats {
            self.mat_remap[m as usize] = u32::MAX;
        }
        for &g in &self.used_groups {
            self.group_remap[g as usize] = u32::MAX;
        }
        // The slots used, in order of first use. When that is the source's
        // whole list in order (a one-material mesh, the usual case), the
        // component shares the source's list: no copy, and the exporter
        // and the leaf material cache recognise it.
        out.materials = if self.used_mats.is_empty() {
            match src.materials.len() {
                0 => vec![crate::Material::default()].into(),
                1 => src.materials.clone(),
                _ => vec![src.materials[0].clone()].into(),
            }
        } else {
            pick(&src.materials, &self.used_mats)
        };
        if !self.used_groups.is_empty() {
            out.groups = pick(&src.groups, &self.used_groups);
        } // else: Mesh::new's one unnamed group
        self.used_mats.clear();
        self.used_groups.clear();
    }
}

/// Appends `src[run]` to `dst`, the default value where `src` is shorter
/// (as attributes missing on a corner are read).
fn extend_from_run<T: Copy + Default>(dst: &mut Vec<T>, src: &[T], run: std::ops::Range<usize>) {
    match src.get(run.clone()) {
        Some(values) => dst.extend_from_slice(values),
        None => dst.extend(run.map(|c| src.get(c).copied().unwrap_or_default())),
    }
}

/// The elements `used` of `src`, in that order: `src` itself (shared) when
/// that is all of it in order.
fn pick<T: Clone>(src: &SharedVec<T>, used: &[u32]) -> SharedVec<T> {
    let all = used.len() == src.len() && used.iter().enumerate().all(|(i, &k)| k as usize == i);
    if all {
        src.clone()
    } else {
        used.iter().map(|&k| src[k as usize].clone()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{face_area, mesh_area};
    use crate::primitive::cube;
    use crate::DVec2;

    #[test]
    fn union_find_keeps_the_first_member_as_root() {
        let mut sets = UnionFind::new(5);
        sets.union(3, 1);
        sets.union(4, 3);
        assert_eq!([0, 1, 2, 3, 4].map(|i| sets.find(i)), [0, 1, 2, 1, 1]);
    }

    #[test]
    fn faces_copied_one_by_one_keep_their_area_and_only_their_positions() {
        let src = cube(DVec3::new(2.0, 3.0, 4.0));
        let mut b = SubmeshBuilder::new(&src);
        let mut total = 0.0;
        for f in 0..src.faces.len() {
            let mut out = b.begin(&src, false);
            b.add_face(&src, &mut out, f);
            b.finish(&src, &mut out);
            assert_eq!(out.faces.len(), 1);
            assert_eq!(out.positions.len(), 4, "face {f}");
            assert!((face_area(&out, 0) - face_area(&src, f)).abs() < 1e-12);
            total += mesh_area(&out);
        }
        assert!((total - 2.0 * (6.0 + 8.0 + 12.0)).abs() < 1e-12);
    }

    #[test]
    fn faces_copy_every_corner_attribute_as_corner_by_corner() {
        let mut src = cube(DVec3::new(2.0, 3.0, 4.0));
        let n = src.corners.len();
        src.uvs[2] = Some((0..n).map(|c| DVec2::new(c as f64, -(c as f64))).collect());
        // Shorter than the corners: the missing ones read as zero.
        src.uvs[3] = Some(vec![DVec2::ONE; n - 3]);
        src.normals = Some((0..n).map(|c| DVec3::new(0.0, c as f64, 1.0)).collect());
        src.edge_tags = Some((0..n as u32).collect());
        src.vertex_tags = Some((0..n as u32).map(|c| 100 + c).collect());
        let mut b = SubmeshBuilder::new(&src);
        for f in 0..src.faces.len() {
            let mut out = b.begin(&src, false);
            b.add_face(&src, &mut out, f);
            b.finish(&src, &mut out);
            let mut reference = b.begin(&src, false);
            let first_loop = reference.loops.len() as u32;
            for &l in src.face_loops(f) {
                let start = reference.corners.len() as u32;
                for c in src.loop_corners(l) {
                    b.corner(&src, &mut reference, c, None);
                }
                reference.loops.push(Loop { start, len: l.len });
            }
            reference.faces.push(Face {
                first_loop,
                loop_count: src.face_loops(f).len() as u32,
                ..src.faces[f]
            });
            b.finish(&src, &mut reference);
            assert_eq!(out.positions, reference.positions, "face {f}");
            assert_eq!(out.corners, reference.corners);
            assert_eq!(out.uvs, reference.uvs);
            assert_eq!(out.normals, reference.normals);
            assert_eq!(out.edge_tags, reference.edge_tags);
            assert_eq!(out.vertex_tags, reference.vertex_tags);
            let last = src.loop_corners(src.outer_loop(f)).end - 1;
            let expected_uv3 = if last < n - 3 {
                DVec2::ONE
            } else {
                DVec2::ZERO
            };
            assert_eq!(out.uvs[3].as_ref().unwrap()[3], expected_uv3, "face {f}");
            assert_eq!(out.edge_tags.as_ref().unwrap()[3], last as u32);
        }
    }

    #[test]
    fn corners_run_around_their_loop() {
        let src = cube(DVec3::ONE);
        let r = src.loop_corners(src.outer_loop(2));
        let (first, last) = (r.start, r.end - 1);
        assert_eq!(next_corner(&src, last), first);
        assert_eq!(prev_corner(&src, first), last);
        assert_eq!(face_of_corner(&src, first), 2);
    }
}
