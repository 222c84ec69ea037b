//! The indexed polygon mesh every shape's geometry is made of.
//!
//! Layout (flat arrays, no per-face allocation):
//! - `positions`: the vertices;
//! - `corners`: one entry per face corner, an index into `positions`;
//! - `loops`: ranges of `corners`; a face's first loop is its outer boundary
//!   (counter-clockwise seen from the side its normal points to), the others
//!   are holes (clockwise);
//! - `faces`: ranges of `loops`, each with a material slot and a group;
//! - `uvs[k]`, `normals`: per-corner attributes aligned with `corners`;
//! - `tags`: the component tag sets faces, edges and vertices refer to
//!   (see [`crate::tags`]): `Face::tags`, and per corner `edge_tags` (the
//!   edge from that corner to the next of its loop) and `vertex_tags`.

use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::material::Material;
use crate::tags::TagSet;

/// Number of texture coordinate sets a mesh can carry (CGA's UV sets 0..9).
pub const UV_SETS: usize = 10;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Loop {
    /// First corner (index into `Mesh::corners`).
    pub start: u32,
    pub len: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    /// First loop (index into `Mesh::loops`): the outer boundary.
    pub first_loop: u32,
    /// 1 + number of holes.
    pub loop_count: u32,
    /// Index into `Mesh::materials`.
    pub material: u32,
    /// Index into `Mesh::groups`.
    pub group: u32,
    /// Index into `Mesh::tags` (0: no tags).
    pub tags: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    pub corners: Vec<u32>,
    pub loops: Vec<Loop>,
    pub faces: Vec<Face>,
    /// Per-corner texture coordinates for each UV set; `None` if the set is absent.
    pub uvs: [Option<Vec<DVec2>>; UV_SETS],
    /// Per-corner normals, if the geometry carries its own (assets, `setNormals`).
    pub normals: Option<Vec<DVec3>>,
    /// Material slots referenced by `Face::material`; never empty. Shared
    /// between the meshes cut, extruded or copied from one another.
    pub materials: SharedVec<Material>,
    /// Group names referenced by `Face::group` (OBJ `g`); never empty.
    pub groups: SharedVec<String>,
    /// Component tag sets referenced by `Face::tags`, `edge_tags` and
    /// `vertex_tags`; entry 0 is the empty set. Shared like `materials`.
    pub tags: SharedVec<TagSet>,
    /// Per corner: the tags of the edge from that corner to the next corner
    /// of its loop (a face edge; an edge shared by two faces has the union
    /// of both face edges' tags). `None`: no edge tags.
    pub edge_tags: Option<Vec<u32>>,
    /// Per corner: the tags of the vertex at that corner (a welded vertex
    /// has the union of its corners' tags). `None`: no vertex tags.
    pub vertex_tags: Option<Vec<u32>>,
}

/// A vector shared between meshes until one of them changes it (copy on
/// write). Every piece of a cut, every extrusion and every copy of a mesh
/// keeps the material slots and groups of its source: sharing them makes
/// those copies one reference count each instead of an allocation and a
/// deep copy of every material, and lets the exporter recognise material
/// lists it has seen by their address.
///
/// Reads go through `Deref` to a slice (`m.materials[0]`, `.iter()`,
/// `.len()`); writes (`m.materials[0] = x`, `.push(x)`, `iter_mut()`) copy
/// the vector first if another mesh shares it.
#[derive(Debug, PartialEq)]
pub struct SharedVec<T>(Arc<Vec<T>>);

impl<T> Clone for SharedVec<T> {
    fn clone(&self) -> Self {
        SharedVec(self.0.clone())
    }
}

impl<T> Default for SharedVec<T> {
    fn default() -> Self {
        SharedVec(Arc::new(Vec::new()))
    }
}

impl<T: Clone> SharedVec<T> {
    /// The vector for writing (copied first if shared).
    pub fn make_mut(&mut self) -> &mut Vec<T> {
        Arc::make_mut(&mut self.0)
    }

    pub fn push(&mut self, value: T) {
        self.make_mut().push(value);
    }

    pub fn clear(&mut self) {
        if !self.0.is_empty() {
            match Arc::get_mut(&mut self.0) {
                Some(v) => v.clear(),
                None => *self = SharedVec::default(),
            }
        }
    }

    pub fn truncate(&mut self, len: usize) {
        if len < self.0.len() {
            self.make_mut().truncate(len);
        }
    }

    pub fn retain(&mut self, keep: impl FnMut(&T) -> bool) {
        self.make_mut().retain(keep);
    }

    /// The elements as an owned vector.
    pub fn into_vec(self) -> Vec<T> {
        Arc::try_unwrap(self.0).unwrap_or_else(|shared| (*shared).clone())
    }
}

impl<T> SharedVec<T> {
    /// Whether both share one vector (then they are equal without comparing).
    pub fn ptr_eq(a: &SharedVec<T>, b: &SharedVec<T>) -> bool {
        Arc::ptr_eq(&a.0, &b.0)
    }

    /// The address of the shared vector: an identity for caches (valid while
    /// this value, or a clone of it, lives).
    pub fn as_ptr(&self) -> *const Vec<T> {
        Arc::as_ptr(&self.0)
    }

    pub fn as_slice(&self) -> &[T] {
        &self.0
    }
}

impl<T> std::ops::Deref for SharedVec<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.0
    }
}

impl<T: Clone> std::ops::DerefMut for SharedVec<T> {
    fn deref_mut(&mut self) -> &mut [T] {
        self.make_mut()
    }
}

impl<T> From<Vec<T>> for SharedVec<T> {
    fn from(v: Vec<T>) -> Self {
        SharedVec(Arc::new(v))
    }
}

impl<T> FromIterator<T> for SharedVec<T> {
    fn from_iter<I: IntoIterator<Item = T>>(iter: I) -> Self {
        SharedVec(Arc::new(iter.into_iter().collect()))
    }
}

impl<T: Clone> Extend<T> for SharedVec<T> {
    fn extend<I: IntoIterator<Item = T>>(&mut self, iter: I) {
        self.make_mut().extend(iter);
    }
}

impl<'a, T> IntoIterator for &'a SharedVec<T> {
    type Item = &'a T;
    type IntoIter = std::slice::Iter<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.0.iter()
    }
}

impl<'a, T: Clone> IntoIterator for &'a mut SharedVec<T> {
    type Item = &'a mut T;
    type IntoIter = std::slice::IterMut<'a, T>;
    fn into_iter(self) -> Self::IntoIter {
        self.make_mut().iter_mut()
    }
}

impl<T: PartialEq> PartialEq<Vec<T>> for SharedVec<T> {
    fn eq(&self, other: &Vec<T>) -> bool {
        *self.0 == *other
    }
}

impl<T: PartialEq> PartialEq<[T]> for SharedVec<T> {
    fn eq(&self, other: &[T]) -> bool {
        self.0.as_slice() == other
    }
}

/// The material slots and groups of a new mesh (one default material, one
/// unnamed group), made once and shared by the meshes that have them.
///
/// Shared per thread, not by the whole process: every mesh and every piece
/// cut from it holds these, and one reference count changed by every
/// deriving thread at every cut made its cache line bounce between the
/// cores (half the time of building a cut's output). Lists from different
/// threads are equal by value, which is what merging and the writers
/// compare; their addresses serve only as cache keys.
fn default_slots() -> (SharedVec<Material>, SharedVec<String>) {
    fn make() -> (SharedVec<Material>, SharedVec<String>) {
        (vec![Material::default()].into(), vec![String::new()].into())
    }
    thread_local! {
        static SLOTS: (SharedVec<Material>, SharedVec<String>) = make();
    }
    // `try_with` fails only while the thread shuts down.
    SLOTS
        .try_with(|s| (s.0.clone(), s.1.clone()))
        .unwrap_or_else(|_| make())
}

/// The tag table of an untagged mesh (only the empty set), shared per
/// thread (see `default_slots`).
pub fn no_tags() -> SharedVec<TagSet> {
    fn make() -> SharedVec<TagSet> {
        vec![TagSet::default()].into()
    }
    thread_local! {
        static NONE: SharedVec<TagSet> = make();
    }
    NONE.try_with(|t| t.clone()).unwrap_or_else(|_| make())
}

impl Default for Mesh {
    fn default() -> Self {
        Mesh::new()
    }
}

impl Mesh {
    /// An empty mesh with one default material slot and one unnamed group.
    pub fn new() -> Mesh {
        let (materials, groups) = default_slots();
        Mesh {
            positions: Vec::new(),
            corners: Vec::new(),
            loops: Vec::new(),
            faces: Vec::new(),
            uvs: Default::default(),
            normals: None,
            materials,
            groups,
            tags: no_tags(),
            edge_tags: None,
            vertex_tags: None,
        }
    }

    /// Gives the mesh lists of material slots, groups and tags shared only
    /// on this thread: the thread's default lists where its lists are
    /// those, copies of its own otherwise. For a mesh every piece of a
    /// derivation descends from (a lot's), made on another thread: each
    /// piece holds its lists, and reference counts changed by two threads
    /// at every cut bounce between the cores.
    pub fn share_on_this_thread(&mut self) {
        fn local<T: Clone + PartialEq>(list: &SharedVec<T>, default: SharedVec<T>) -> SharedVec<T> {
            match **list == *default {
                true => default,
                false => list.to_vec().into(),
            }
        }
        let (materials, groups) = default_slots();
        self.materials = local(&self.materials, materials);
        self.groups = local(&self.groups, groups);
        self.tags = local(&self.tags, no_tags());
    }

    /// Room for `corners` more corners (and as many positions, a loop and
    /// a face per four corners) in the arrays, and in the per-corner
    /// attributes the mesh has.
    pub fn reserve(&mut self, corners: usize) {
        self.positions.reserve(corners);
        self.corners.reserve(corners);
        self.loops.reserve(corners.div_ceil(4));
        self.faces.reserve(corners.div_ceil(4));
        for set in self.uvs.iter_mut().flatten() {
            set.reserve(corners);
        }
        if let Some(n) = &mut self.normals {
            n.reserve(corners);
        }
        for t in [&mut self.edge_tags, &mut self.vertex_tags]
            .into_iter()
            .flatten()
        {
            t.reserve(corners);
        }
    }

    /// Makes `self` a copy of `src`, reusing `self`'s allocations (a
    /// scratch mesh refilled for every shape costs no allocation).
    pub fn copy_from(&mut self, src: &Mesh) {
        self.positions.clone_from(&src.positions);
        self.corners.clone_from(&src.corners);
        self.loops.clone_from(&src.loops);
        self.faces.clone_from(&src.faces);
        for (d, s) in self.uvs.iter_mut().zip(&src.uvs) {
            match (d.as_mut(), s) {
                (Some(d), Some(s)) => d.clone_from(s),
                (_, None) => *d = None,
                (None, Some(s)) => *d = Some(s.clone()),
            }
        }
        match (self.normals.as_mut(), &src.normals) {
            (Some(d), Some(s)) => d.clone_from(s),
            (_, None) => self.normals = None,
            (None, Some(s)) => self.normals = Some(s.clone()),
        }
        for (d, s) in [
            (&mut self.edge_tags, &src.edge_tags),
            (&mut self.vertex_tags, &src.vertex_tags),
        ] {
            match (d.as_mut(), s) {
                (Some(d), Some(s)) => d.clone_from(s),
                (_, None) => *d = None,
                (None, Some(s)) => *d = Some(s.clone()),
            }
        }
        self.materials = src.materials.clone();
        self.groups = src.groups.clone();
        self.tags = src.tags.clone();
    }

    /// Gives `self` the material slots, groups and tag sets of `src`
    /// (shared), so that faces copied from `src` keep their indices.
    pub fn share_slots(&mut self, src: &Mesh) {
        self.materials = src.materials.clone();
        self.groups = src.groups.clone();
        self.tags = src.tags.clone();
    }

    /// A mesh of one polygon face (no holes) through `points` in order.
    pub fn polygon(points: &[DVec3]) -> Mesh {
        let mut m = Mesh::new();
        m.positions.extend_from_slice(points);
        let idx: Vec<u32> = (0..points.len() as u32).collect();
        m.add_face(&[&idx], 0);
        m
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Adds a face from its loops (outer first, then holes) of position indices.
    /// Per-corner attributes present on the mesh get zero entries; fill them
    /// afterwards if needed. Returns the face index.
    pub fn add_face(&mut self, loops: &[&[u32]], material: u32) -> usize {
        let first_loop = self.loops.len() as u32;
        for l in loops {
            let start = self.corners.len() as u32;
            self.corners.extend_from_slice(l);
            self.loops.push(Loop {
                start,
                len: l.len() as u32,
            });
        }
        let n = self.corners.len();
        for set in self.uvs.iter_mut().flatten() {
            set.resize(n, DVec2::ZERO);
        }
        if let Some(normals) = &mut self.normals {
            normals.resize(n, DVec3::ZERO);
        }
        for t in [&mut self.edge_tags, &mut self.vertex_tags]
            .into_iter()
            .flatten()
        {
            t.resize(n, 0);
        }
        self.faces.push(Face {
            first_loop,
            loop_count: loops.len() as u32,
            material,
            group: 0,
            tags: 0,
        });
        self.faces.len() - 1
    }

    /// The loops of a face: outer boundary first, then holes.
    pub fn face_loops(&self, face: usize) -> &[Loop] {
        let f = &self.faces[face];
        &self.loops[f.first_loop as usize..(f.first_loop + f.loop_count) as usize]
    }

    /// The corner index range of a loop.
    pub fn loop_corners(&self, l: Loop) -> std::ops::Range<usize> {
        l.start as usize..(l.start + l.len) as usize
    }

    /// Position indices of a loop.
    pub fn loop_indices(&self, l: Loop) -> &[u32] {
        &self.corners[self.loop_corners(l)]
    }

    /// Positions of a loop, in order.
    pub fn loop_points(&self, l: Loop) -> impl Iterator<Item = DVec3> + '_ {
        self.loop_indices(l)
            .iter()
            .map(move |&i| self.positions[i as usize])
    }

    /// The outer boundary loop of a face.
    pub fn outer_loop(&self, face: usize) -> Loop {
        self.loops[self.faces[face].first_loop as usize]
    }

    /// Applies `f` to every position (normals are not touched).
    pub fn map_positions(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_lists_are_shared_per_thread() {
        let here = Mesh::new();
        let there = std::thread::spawn(Mesh::new).join().unwrap();
        // Equal lists, each thread's own.
        assert_eq!(here.materials, there.materials);
        assert_eq!(here.groups, there.groups);
        assert_eq!(here.tags, there.tags);
        assert!(!SharedVec::ptr_eq(&here.materials, &there.materials));
        assert!(!SharedVec::ptr_eq(&here.tags, &there.tags));
        // A mesh from another thread takes this thread's default lists, and
        // copies of lists of its own.
        let mut moved = there.clone();
        moved.share_on_this_thread();
        assert!(SharedVec::ptr_eq(&moved.materials, &here.materials));
        assert!(SharedVec::ptr_eq(&moved.groups, &here.groups));
        assert!(SharedVec::ptr_eq(&moved.tags, &here.tags));
        let mut red = std::thread::spawn(|| {
            let mut m = Mesh::new();
            m.materials[0].color = [1.0, 0.0, 0.0];
            m.groups[0] = "walls".into();
            m
        })
        .join()
        .unwrap();
        let theirs = red.materials.clone();
        red.share_on_this_thread();
        assert_eq!(red.materials, theirs);
        assert_eq!(red.materials[0].color, [1.0, 0.0, 0.0]);
        assert_eq!(&*red.groups, &["walls".to_string()][..]);
        assert!(!SharedVec::ptr_eq(&red.materials, &theirs));
    }

    #[test]
    fn shared_slots_copy_on_write() {
        let a = Mesh::new();
        let mut b = Mesh::new();
        // New meshes share one default slot list.
        assert!(SharedVec::ptr_eq(&a.materials, &b.materials));
        assert!(SharedVec::ptr_eq(&a.groups, &b.groups));
        let red = Material {
            color: [1.0, 0.0, 0.0],
            ..Material::default()
        };
        b.materials.push(red.clone());
        b.materials[0].opacity = 0.5;
        // `a` and every other new mesh keep the defaults.
        assert_eq!(a.materials, vec![Material::default()]);
        assert_eq!(Mesh::new().materials.len(), 1);
        assert_eq!(b.materials.len(), 2);
        assert_eq!(b.materials[0].opacity, 0.5);
        assert_eq!(b.materials[1], red);
        let c = b.clone();
        assert!(SharedVec::ptr_eq(&b.materials, &c.materials));
        let mut d = c.clone();
        for m in &mut d.materials {
            m.shininess = 7.0;
        }
        assert_eq!(c.materials[1].shininess, 1.0);
        assert_eq!(d.materials[1].shininess, 7.0);
        d.materials.clear();
        assert!(d.materials.is_empty());
        assert_eq!(c.materials.len(), 2);
        assert_eq!(d.groups.clone().into_vec(), vec![String::new()]);
    }

    #[test]
    fn copy_from_equals_clone() {
        let mut src = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 0.0, -1.0)]);
        src.uvs[2] = Some(vec![DVec2::new(0.5, 1.0); 3]);
        src.normals = Some(vec![DVec3::Y; 3]);
        // A scratch mesh with other attribute sets and larger buffers.
        let mut dst = Mesh::polygon(&[DVec3::ONE; 5]);
        dst.uvs[0] = Some(vec![DVec2::ONE; 5]);
        dst.copy_from(&src);
        assert_eq!(dst, src);
        let plain = Mesh::polygon(&[DVec3::ZERO, DVec3::Y, DVec3::Z]);
        dst.copy_from(&plain);
        assert_eq!(dst, plain);
    }

    #[test]
    fn polygon_has_one_face_one_loop() {
        let m = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 0.0, -1.0)]);
        assert_eq!(m.faces.len(), 1);
        assert_eq!(m.face_loops(0).len(), 1);
        assert_eq!(m.loop_indices(m.outer_loop(0)), &[0, 1, 2]);
    }
}
