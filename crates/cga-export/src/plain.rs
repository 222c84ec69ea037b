//! Models as plain arrays, for programs that use the geometry themselves
//! (a Python user's numpy arrays) instead of a file, and the collector
//! they share with meshes to draw (`draw.rs`: a viewer's buffers).
//!
//! Faces are placed, triangulated and left out exactly as the file writers
//! do (`prepare`): a [`PlainModel`] holds the triangles a GLB of the same
//! leaves holds, in coordinates of `f64`, with each triangle's leaf.

use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DVec2, Material, Mesh};

use crate::draw::DrawMesh;
use crate::materials::MaterialTable;
use crate::prepare::{FacePrep, SlotIds};
use crate::{check_mesh, ExportError, FaceData};

/// The triangles of one material.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlainMesh {
    /// Index into [`PlainModel::materials`].
    pub material: usize,
    /// Vertex positions (object coordinates, metres; y up).
    pub positions: Vec<[f64; 3]>,
    /// Unit normal per vertex: the mesh's own, else its face's.
    pub normals: Vec<[f64; 3]>,
    /// Texture coordinates of UV set 0 per vertex, as CGA has them
    /// (v up); (0, 0) where the face has none.
    pub uvs: Vec<[f64; 2]>,
    /// Three vertex indices per triangle, counter-clockwise seen from the
    /// side the normal points to.
    pub indices: Vec<[u32; 3]>,
    /// Per triangle, the leaf it comes from (the number given to
    /// [`PlainCollector::add_placed`]).
    pub triangle_leaf: Vec<u32>,
}

/// Meshes by material: [`PlainMesh`]es, or [`DrawMesh`]es
/// ([`DrawModel`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PlainModel<M = PlainMesh> {
    /// Distinct materials, in order of first use.
    pub materials: Vec<Material>,
    /// One mesh per material, in the order of `materials`.
    pub meshes: Vec<M>,
    /// Faces written (before triangulation).
    pub faces: u64,
    /// Faces left out for non-finite coordinates.
    pub skipped_non_finite: u64,
}

impl<M> Default for PlainModel<M> {
    fn default() -> Self {
        PlainModel {
            materials: Vec::new(),
            meshes: Vec::new(),
            faces: 0,
            skipped_non_finite: 0,
        }
    }
}

impl PlainModel {
    /// Triangles over all meshes.
    pub fn triangles(&self) -> usize {
        self.meshes.iter().map(|m| m.indices.len()).sum()
    }
}

impl PlainModel<DrawMesh> {
    /// Triangles over all meshes.
    pub fn triangles(&self) -> usize {
        self.meshes.iter().map(DrawMesh::triangles).sum()
    }
}

/// What a collector needs of the arrays of one material's mesh: the
/// faces are found, placed and triangulated once (`Collector`), and each
/// kind of mesh stores them its way.
pub(crate) trait MeshArrays {
    /// An empty mesh of `material` with room for `vertices` and
    /// `triangles`.
    fn with_capacity(material: usize, vertices: usize, triangles: usize) -> Self;
    /// Vertices and triangles held.
    fn sizes(&self) -> (usize, usize);
    /// Adds face `f` of leaf `leaf`. `call` numbers the collector's calls
    /// (one per leaf added, whatever number the caller gives the leaf);
    /// `corner_vertex` is scratch room, at least a slot per corner of the
    /// mesh.
    fn push_face(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
        call: u32,
    );
    /// Arrays holding less than half of their room are copied into blocks
    /// of their size.
    fn fit(&mut self);
}

/// Meshes with a vertex per face corner (plain meshes, meshes to draw).
pub(crate) trait CornerArrays {
    /// Adds a face whose triangles are a fan (see [`fan_start`]) from the
    /// corner at `first` of its loop: its vertices are its corners in loop
    /// order from there, as `push_triangles` numbers them (in the order
    /// the triangles first use them).
    fn push_fan(&mut self, f: &FaceData, uvs: Option<&[DVec2]>, first: u32, leaf: u32);
    /// Adds a face's triangles, with a vertex per corner of the face in the
    /// order the triangles first use them (`corner_vertex` is scratch
    /// room, at least a slot per corner of the mesh).
    fn push_triangles(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
    );
}

/// [`MeshArrays::push_face`] for meshes of a vertex per corner: as a fan
/// where the face's triangles are one (see [`fan_start`]), else triangle
/// by triangle.
pub(crate) fn push_corners(
    m: &mut impl CornerArrays,
    f: &FaceData,
    uvs: Option<&[DVec2]>,
    corner_vertex: &mut [u32],
    leaf: u32,
) {
    match fan_start(f) {
        Some(first) => m.push_fan(f, uvs, first, leaf),
        None => m.push_triangles(f, uvs, corner_vertex, leaf),
    }
}

pub(crate) const NO_VERTEX: u32 = u32::MAX;

/// Shrinks `v` to its length if it holds less than half of its room.
pub(crate) fn fit<T>(v: &mut Vec<T>) {
    if v.capacity() > 2 * v.len() {
        v.shrink_to_fit();
    }
}

/// The place in its loop of the corner a face's triangles fan out from,
/// if they are the fan `(c[r], c[r + k + 1], c[r + k + 2])` over its one
/// loop `c` read from `r` on (round the loop): what the triangulation
/// makes of every convex face, nearly all faces of a model.
pub(crate) fn fan_start(f: &FaceData) -> Option<u32> {
    if f.fan.is_some() {
        return f.fan;
    }
    let &[outer] = f.loops else {
        return None;
    };
    let (s, n) = (outer.start, outer.len);
    // A quad (most faces): two triangles, checked as arrays.
    if n == 4 {
        let &[[a, b, c], [d, e, g]] = f.triangles else {
            return None;
        };
        let first = a.checked_sub(s).filter(|&k| k < 4)?;
        let at = |i: u32| s + (first + i) % 4;
        return ([b, c, d, e, g] == [at(1), at(2), at(0), at(2), at(3)]).then_some(first);
    }
    let first = f.triangles.first()?[0].checked_sub(s)?;
    if f.triangles.len() + 2 != n as usize || first >= n {
        return None;
    }
    // `first + i < 2n` here (`i < n`): a subtraction instead of `%` (an
    // integer division for every corner of nearly every face).
    let at = |i: u32| {
        let j = first + i;
        s + if j >= n { j - n } else { j }
    };
    f.triangles
        .iter()
        .zip(0..)
        .all(|(t, k)| *t == [s + first, at(k + 1), at(k + 2)])
        .then_some(first)
}

/// The corners of a face's loop from `first` on, round the loop: the
/// order [`CornerArrays::push_fan`] writes a fan's vertices in.
pub(crate) fn fan_corners(f: &FaceData, first: u32) -> impl Iterator<Item = usize> + Clone {
    let outer = f.loops[0];
    let (s, n) = (outer.start as usize, outer.len as usize);
    (first as usize..n)
        .chain(0..first as usize)
        .map(move |i| s + i)
}

/// The placed position of a face's corner `c`.
pub(crate) fn corner_position(f: &FaceData, c: usize) -> [f64; 3] {
    f.positions[f.mesh.corners[c] as usize].to_array()
}

/// The texture coordinates of corner `c` in `uvs` (the face's UV set 0),
/// (0, 0) where it has none.
pub(crate) fn corner_uv(uvs: Option<&[DVec2]>, c: usize) -> [f64; 2] {
    uvs.and_then(|u| u.get(c))
        .map_or([0.0; 2], |t| t.to_array())
}

/// Calls `vertex` for each corner of a triangle of `f` not seen before in
/// this face (its corner number), in the order the triangles first use
/// them, and `triangle` with each triangle's vertex numbers (`next` is
/// the number the first new vertex gets).
pub(crate) fn each_triangle(
    f: &FaceData,
    corner_vertex: &mut [u32],
    mut next: u32,
    mut vertex: impl FnMut(usize),
    mut triangle: impl FnMut([u32; 3]),
) {
    for l in f.loops {
        corner_vertex[f.mesh.loop_corners(*l)].fill(NO_VERTEX);
    }
    for tri in f.triangles {
        let mut ids = [0u32; 3];
        for (k, &c) in tri.iter().enumerate() {
            let v = &mut corner_vertex[c as usize];
            if *v == NO_VERTEX {
                vertex(c as usize);
                *v = next;
                next += 1;
            }
            ids[k] = *v;
        }
        triangle(ids);
    }
}

impl MeshArrays for PlainMesh {
    fn with_capacity(material: usize, vertices: usize, triangles: usize) -> PlainMesh {
        PlainMesh {
            material,
            positions: Vec::with_capacity(vertices),
            normals: Vec::with_capacity(vertices),
            uvs: Vec::with_capacity(vertices),
            indices: Vec::with_capacity(triangles),
            triangle_leaf: Vec::with_capacity(triangles),
        }
    }

    fn sizes(&self) -> (usize, usize) {
        (self.positions.len(), self.indices.len())
    }

    fn push_face(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
        _: u32,
    ) {
        push_corners(self, f, uvs, corner_vertex, leaf);
    }

    fn fit(&mut self) {
        fit(&mut self.positions);
        fit(&mut self.normals);
        fit(&mut self.uvs);
        fit(&mut self.indices);
        fit(&mut self.triangle_leaf);
    }
}

impl CornerArrays for PlainMesh {
    fn push_fan(&mut self, f: &FaceData, uvs: Option<&[DVec2]>, first: u32, leaf: u32) {
        let n = f.loops[0].len as usize;
        if n == 4 {
            return self.push_quad_fan(f, uvs, first, leaf);
        }
        let corners = fan_corners(f, first);
        let base = self.positions.len() as u32;
        self.positions
            .extend(corners.clone().map(|c| corner_position(f, c)));
        match f.normals {
            Some(normals) => self
                .normals
                .extend(corners.clone().map(|c| normals[c].to_array())),
            None => self
                .normals
                .extend(std::iter::repeat_n(f.normal().to_array(), n)),
        }
        self.uvs.extend(corners.map(|c| corner_uv(uvs, c)));
        self.indices
            .extend((1..n as u32 - 1).map(|k| [base, base + k, base + k + 1]));
        self.triangle_leaf.extend(std::iter::repeat_n(leaf, n - 2));
    }

    fn push_triangles(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
    ) {
        let PlainMesh {
            positions,
            normals,
            uvs: out_uvs,
            indices,
            triangle_leaf,
            ..
        } = self;
        each_triangle(
            f,
            corner_vertex,
            positions.len() as u32,
            |c| {
                positions.push(corner_position(f, c));
                normals.push(f.normals.map_or_else(|| f.normal(), |n| n[c]).to_array());
                out_uvs.push(corner_uv(uvs, c));
            },
            |ids| {
                indices.push(ids);
                triangle_leaf.push(leaf);
            },
        );
    }
}

impl PlainMesh {
    /// [`CornerArrays::push_fan`] for a quad (most faces): the same values,
    /// its four corners read as an array rather than round the loop.
    fn push_quad_fan(&mut self, f: &FaceData, uvs: Option<&[DVec2]>, first: u32, leaf: u32) {
        let s = f.loops[0].start as usize;
        let k = first as usize;
        let corners = [0, 1, 2, 3].map(|i| s + (k + i) % 4);
        let base = self.positions.len() as u32;
        self.positions
            .extend_from_slice(&corners.map(|c| corner_position(f, c)));
        match f.normals {
            Some(normals) => self
                .normals
                .extend_from_slice(&corners.map(|c| normals[c].to_array())),
            None => self.normals.extend_from_slice(&[f.normal().to_array(); 4]),
        }
        self.uvs
            .extend_from_slice(&corners.map(|c| corner_uv(uvs, c)));
        self.indices
            .extend_from_slice(&[[base, base + 1, base + 2], [base, base + 2, base + 3]]);
        self.triangle_leaf.extend_from_slice(&[leaf; 2]);
    }
}

/// The triangles of one material by their positions alone (see
/// [`PlainCollector::positions_only`]): a vertex per position of a leaf's
/// mesh that its faces of this material use, so that faces meeting at a
/// corner share it, as in the mesh; no normals, no texture coordinates.
pub(crate) struct SharedPositions {
    mesh: PlainMesh,
    /// Per position of the mesh being added: the collector's call that
    /// last gave it a vertex here (`NO_VERTEX`: none yet) and that vertex.
    vertex_of: Vec<(u32, u32)>,
}

impl SharedPositions {
    /// Adds the triangles of face `f` of leaf `leaf`, each corner the
    /// vertex of its position, made when the collector's call `call` (the
    /// leaf's) first uses it.
    fn push_shared(&mut self, f: &FaceData, leaf: u32, call: u32) {
        let SharedPositions { mesh, vertex_of } = self;
        if vertex_of.len() < f.positions.len() {
            vertex_of.resize(f.positions.len(), (NO_VERTEX, 0));
        }
        let corners = &f.mesh.corners;
        for tri in f.triangles {
            let ids = tri.map(|c| {
                let p = corners[c as usize] as usize;
                let slot = &mut vertex_of[p];
                if slot.0 != call {
                    *slot = (call, mesh.positions.len() as u32);
                    mesh.positions.push(f.positions[p].to_array());
                }
                slot.1
            });
            mesh.indices.push(ids);
        }
        mesh.triangle_leaf
            .extend(std::iter::repeat_n(leaf, f.triangles.len()));
    }
}

impl MeshArrays for SharedPositions {
    fn with_capacity(material: usize, vertices: usize, triangles: usize) -> SharedPositions {
        SharedPositions {
            mesh: PlainMesh {
                material,
                positions: Vec::with_capacity(vertices),
                normals: Vec::new(),
                uvs: Vec::new(),
                indices: Vec::with_capacity(triangles),
                triangle_leaf: Vec::with_capacity(triangles),
            },
            vertex_of: Vec::new(),
        }
    }

    fn sizes(&self) -> (usize, usize) {
        self.mesh.sizes()
    }

    fn push_face(
        &mut self,
        f: &FaceData,
        _: Option<&[DVec2]>,
        _: &mut [u32],
        leaf: u32,
        call: u32,
    ) {
        self.push_shared(f, leaf, call);
    }

    fn fit(&mut self) {
        self.mesh.fit();
    }
}

/// Gathers leaves into a [`PlainModel`]: all attributes, a vertex per
/// face corner ([`new`](PlainCollector::new),
/// [`with_room`](PlainCollector::with_room)), or positions alone, shared
/// within each leaf ([`positions_only`](PlainCollector::positions_only)).
pub struct PlainCollector(PlainKind);

enum PlainKind {
    Full(Collector<PlainMesh>),
    Positions(Collector<SharedPositions>),
}

impl Default for PlainCollector {
    fn default() -> Self {
        PlainCollector(PlainKind::Full(Collector::default()))
    }
}

impl PlainCollector {
    pub fn new() -> PlainCollector {
        PlainCollector::default()
    }

    /// A collector whose first model starts each mesh with the room given
    /// (vertices and triangles per material, in order of first use), as
    /// [`room`](Self::room) of an earlier collector tells it: a
    /// generation's first lot on a worker then does not grow its arrays by
    /// doubling (which cost a Candler building 16 M of its 70 M
    /// instructions of collection).
    pub fn with_room(room: Vec<(usize, usize)>) -> PlainCollector {
        PlainCollector(PlainKind::Full(Collector {
            last_sizes: room,
            ..Collector::default()
        }))
    }

    /// A collector of positions and triangles alone (what a program that
    /// measures or meshes the geometry needs): the same triangles as
    /// [`with_room`](Self::with_room) gives, but the faces of a leaf that
    /// meet at a position of its mesh share one vertex there (per
    /// material), and normals and texture coordinates are left empty.
    pub fn positions_only(room: Vec<(usize, usize)>) -> PlainCollector {
        PlainCollector(PlainKind::Positions(Collector {
            prep: FacePrep::without_normals(),
            last_sizes: room,
            ..Collector::default()
        }))
    }

    /// Vertices and triangles of each mesh of the model taken last, by
    /// material in order of first use.
    pub fn room(&self) -> &[(usize, usize)] {
        match &self.0 {
            PlainKind::Full(c) => &c.last_sizes,
            PlainKind::Positions(c) => &c.last_sizes,
        }
    }

    /// Adds one leaf's geometry given in its own coordinates, placed by
    /// `transform`, with `materials` for its slots (as
    /// [`ModelWriter::add_placed`](crate::ModelWriter::add_placed) takes
    /// them); its triangles are marked with `leaf`, a number no other leaf
    /// of the model has.
    pub fn add_placed(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
        leaf: u32,
    ) -> Result<(), ExportError> {
        match &mut self.0 {
            PlainKind::Full(c) => c.add_placed(mesh, transform, materials, leaf),
            PlainKind::Positions(c) => c.add_placed(mesh, transform, materials, leaf),
        }
    }

    /// The collector of all attributes (tests look at its room).
    #[cfg(test)]
    fn full(&self) -> &Collector<PlainMesh> {
        match &self.0 {
            PlainKind::Full(c) => c,
            PlainKind::Positions(_) => panic!("a collector of positions alone"),
        }
    }

    /// The model gathered so far; the collector starts a new one.
    pub fn take(&mut self) -> PlainModel {
        match &mut self.0 {
            PlainKind::Full(c) => c.take(),
            PlainKind::Positions(c) => {
                let m = c.take();
                PlainModel {
                    materials: m.materials,
                    meshes: m.meshes.into_iter().map(|s| s.mesh).collect(),
                    faces: m.faces,
                    skipped_non_finite: m.skipped_non_finite,
                }
            }
        }
    }
}

/// Gathers leaves into a [`DrawModel`].
#[derive(Default)]
pub struct DrawCollector(Collector<DrawMesh>);

/// Gathers leaves into meshes by material (see [`MeshArrays`]).
pub(crate) struct Collector<M> {
    prep: FacePrep,
    slots: SlotIds,
    table: MaterialTable,
    model: PlainModel<M>,
    /// The vertex of each corner of the mesh being added (`NO_VERTEX` for
    /// corners of the current face not yet given one): indexed, not
    /// hashed, since a street's collection visits millions of corners.
    corner_vertex: Vec<u32>,
    /// Vertices and triangles of each mesh of the model taken last (by
    /// material number, in order of first use).
    last_sizes: Vec<(usize, usize)>,
    /// Calls of `add_placed` so far (wrapping short of `NO_VERTEX`).
    calls: u32,
}

impl<M> Default for Collector<M> {
    fn default() -> Self {
        Collector {
            prep: FacePrep::default(),
            slots: SlotIds::default(),
            table: MaterialTable::default(),
            model: PlainModel::default(),
            corner_vertex: Vec::new(),
            last_sizes: Vec::new(),
            calls: 0,
        }
    }
}

impl DrawCollector {
    pub fn new() -> DrawCollector {
        DrawCollector::default()
    }

    /// As [`PlainCollector::with_room`].
    pub fn with_room(room: Vec<(usize, usize)>) -> DrawCollector {
        DrawCollector(Collector {
            last_sizes: room,
            ..Collector::default()
        })
    }

    /// As [`PlainCollector::room`].
    pub fn room(&self) -> &[(usize, usize)] {
        &self.0.last_sizes
    }

    /// As [`PlainCollector::add_placed`].
    pub fn add_placed(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
        leaf: u32,
    ) -> Result<(), ExportError> {
        self.0.add_placed(mesh, transform, materials, leaf)
    }

    /// The model gathered so far; the collector starts a new one.
    pub fn take(&mut self) -> PlainModel<DrawMesh> {
        self.0.take()
    }
}

impl<M: MeshArrays> Collector<M> {
    fn add_placed(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
        leaf: u32,
    ) -> Result<(), ExportError> {
        check_mesh(mesh, materials.len())?;
        let Collector {
            prep,
            slots,
            table,
            model,
            corner_vertex,
            last_sizes,
            calls,
        } = self;
        let call = *calls;
        *calls = (call + 1) % NO_VERTEX;
        slots.begin(materials);
        // Only long enough: each face marks its own corners before use.
        if corner_vertex.len() < mesh.corners.len() {
            corner_vertex.resize(mesh.corners.len(), NO_VERTEX);
        }
        let skipped = prep.faces(mesh, transform, |f| {
            let id = slots.id(f.material, || {
                let (id, new) = table.intern(&materials[f.material as usize]);
                if new {
                    model.materials.push(table.get(id).clone());
                    // Room for as much as the same mesh of the lot before
                    // had: lots of one street are much alike, and arrays
                    // grown by doubling were copied and faulted in again
                    // and again.
                    let (v, t) = last_sizes.get(id as usize).copied().unwrap_or_default();
                    model.meshes.push(M::with_capacity(id as usize, v, t));
                }
                id
            });
            let out = &mut model.meshes[id as usize];
            let uvs = f.mesh.uvs[0].as_deref();
            model.faces += 1;
            out.push_face(f, uvs, corner_vertex, leaf, call);
            Ok(())
        });
        slots.end(materials);
        model.skipped_non_finite += skipped?;
        Ok(())
    }

    fn take(&mut self) -> PlainModel<M> {
        self.table = MaterialTable::default();
        self.slots.clear();
        self.last_sizes.clear();
        self.last_sizes
            .extend(self.model.meshes.iter().map(MeshArrays::sizes));
        // A small lot after a large one started with the large one's room:
        // arrays holding less than half of their room are copied into
        // blocks of their size, so that a model its host keeps holds at
        // most about twice what it uses (as arrays grown by doubling do).
        for m in &mut self.model.meshes {
            m.fit();
        }
        std::mem::take(&mut self.model)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use cga_geometry::DVec3;

    #[test]
    fn a_quad_is_a_fan_from_any_of_its_corners_or_none() {
        let mut mesh = cga_geometry::primitive::quad(2.0, 3.0);
        // Corners 5..9 of a mesh whose first loop is elsewhere.
        mesh.corners.splice(0..0, [0; 5]);
        mesh.loops[0].start = 5;
        let fan = |triangles: &[[u32; 3]]| {
            fan_start(&FaceData {
                mesh: &mesh,
                positions: &mesh.positions,
                normals: None,
                loops: &mesh.loops,
                material: 0,
                known_normal: Some(DVec3::Y),
                triangles,
                fan: None,
            })
        };
        let c = |k: u32| 5 + k % 4;
        for first in 0..4 {
            let triangles = [
                [c(first), c(first + 1), c(first + 2)],
                [c(first), c(first + 2), c(first + 3)],
            ];
            assert_eq!(fan(&triangles), Some(first));
        }
        assert_eq!(fan(&[[5, 6, 8], [6, 7, 8]]), None);
        assert_eq!(fan(&[[5, 6, 7], [5, 8, 7]]), None);
        assert_eq!(fan(&[[9, 6, 7], [9, 7, 8]]), None);
        assert_eq!(fan(&[[5, 6, 7]]), None);
    }

    #[test]
    fn a_cube_gives_twelve_triangles_of_one_material() {
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let mut c = PlainCollector::new();
        let shift = DAffine3::from_translation(DVec3::new(10.0, 0.0, 0.0));
        c.add_placed(&cube, Some(&shift), &cube.materials, 7)
            .unwrap();
        let m = c.take();
        assert_eq!(m.materials.len(), 1);
        assert_eq!(m.faces, 6);
        let mesh = &m.meshes[0];
        assert_eq!(mesh.indices.len(), 12);
        assert_eq!(mesh.triangle_leaf, vec![7; 12]);
        // Each face has its own four corners (flat normals).
        assert_eq!(mesh.positions.len(), 24);
        let xs: Vec<f64> = mesh.positions.iter().map(|p| p[0]).collect();
        assert_eq!(xs.iter().cloned().fold(f64::INFINITY, f64::min), 10.0);
        assert_eq!(xs.iter().cloned().fold(f64::NEG_INFINITY, f64::max), 12.0);
        // Triangle areas add up to the cube's surface.
        let area: f64 = mesh
            .indices
            .iter()
            .map(|t| {
                let p = |i: u32| DVec3::from_array(mesh.positions[i as usize]);
                (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length() / 2.0
            })
            .sum();
        assert!((area - 2.0 * (6.0 + 8.0 + 12.0)).abs() < 1e-9);
        // Normals point out of the cube.
        for (t, _) in mesh.indices.iter().zip(0..) {
            let p = |i: u32| DVec3::from_array(mesh.positions[i as usize]);
            let geometric = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            let n = DVec3::from_array(mesh.normals[t[0] as usize]);
            assert!(geometric.dot(n) > 0.0);
        }
        assert!(c.take().meshes.is_empty());
    }

    /// The triangles of `m` as triples of positions, in order.
    fn triangles_by_position(m: &PlainModel) -> Vec<[[f64; 3]; 3]> {
        m.meshes
            .iter()
            .flat_map(|mesh| {
                mesh.indices
                    .iter()
                    .map(|t| t.map(|i| mesh.positions[i as usize]))
            })
            .collect()
    }

    /// Positions alone: the triangles all attributes give, on the same
    /// places, with a vertex per position a leaf's faces of one material
    /// use (a cube's 8 corners, not its 24 face corners), and no normals
    /// or texture coordinates.
    #[test]
    fn positions_alone_are_the_same_triangles_on_shared_vertices() {
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let mut faces = sample_faces();
        // The sample's last face (a triangle on positions the pentagon
        // uses) in a second material.
        let mut materials = faces.materials.clone();
        materials.push(Material {
            name: "second".into(),
            ..Material::default()
        });
        let last = faces.faces.len() - 1;
        faces.faces[last].material = 1;
        let shift = DAffine3::from_translation(DVec3::new(10.0, 0.0, 0.0));
        // A cube with normals of its own (an asset's), turned: its faces
        // are placed without them.
        let mut asset = cube.clone();
        asset.normals = Some(
            (0..asset.corners.len())
                .map(|c| DVec3::new(c as f64, 1.0, 0.5).normalize())
                .collect(),
        );
        let turn = DAffine3::from_rotation_y(0.3) * shift;
        let collect = |mut c: PlainCollector| {
            c.add_placed(&cube, Some(&shift), &cube.materials, 0)
                .unwrap();
            c.add_placed(&cube, None, &cube.materials, 1).unwrap();
            c.add_placed(&faces, Some(&shift), &materials, 2).unwrap();
            c.add_placed(&asset, Some(&turn), &asset.materials, 3)
                .unwrap();
            c.take()
        };
        let full = collect(PlainCollector::new());
        let alone = collect(PlainCollector::positions_only(Vec::new()));
        assert_eq!(triangles_by_position(&alone), triangles_by_position(&full));
        assert_eq!(alone.materials, full.materials);
        assert_eq!(alone.faces, full.faces);
        let [first, second] = &alone.meshes[..] else {
            panic!("two materials: {:?}", alone.materials);
        };
        // Two cubes of 8 vertices each (the same positions twice: each
        // leaf its own), then the sample's 25 positions; the triangle's
        // three (the pentagon's too) again in the second material.
        assert_eq!(first.positions.len(), 8 + 8 + 25 + 8);
        assert_eq!(second.positions.len(), 3);
        assert_eq!(second.indices, [[0, 1, 2]]);
        assert_eq!(first.indices.len(), 12 + 12 + 3 + 2 + 6 + 8 + 12);
        assert_eq!(first.triangle_leaf, full.meshes[0].triangle_leaf);
        assert_eq!(second.triangle_leaf, [2]);
        assert!(alone
            .meshes
            .iter()
            .all(|m| m.normals.is_empty() && m.uvs.is_empty()));
        // The first cube's corners, moved.
        assert_eq!(
            first.positions[..8]
                .iter()
                .map(|p| p[0])
                .fold(f64::INFINITY, f64::min),
            10.0
        );
        assert_eq!(full.meshes[0].positions.len(), 24 + 24 + 5 + 4 + 8 + 8 + 24);
        // Leaves their caller numbers alike still get vertices of their own.
        let mut c = PlainCollector::positions_only(Vec::new());
        c.add_placed(&cube, None, &cube.materials, 9).unwrap();
        c.add_placed(&cube, Some(&shift), &cube.materials, 9)
            .unwrap();
        let twice = c.take();
        assert_eq!(twice.meshes[0].positions.len(), 16);
        assert_eq!(twice.meshes[0].triangle_leaf, [9; 24]);
    }

    /// A convex pentagon (a fan from the corner the triangulation picks), a
    /// quad cut along its other diagonal (a fan from its second corner: its
    /// first three are in line), a U-shaped octagon, a square with a hole,
    /// a triangle; texture coordinates (corner number, 0.5).
    pub(crate) fn sample_faces() -> Mesh {
        let mut m = Mesh::new();
        let p = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        m.positions.extend([
            p(0.0, 0.0),
            p(2.0, 0.0),
            p(3.0, -1.0),
            p(1.0, -2.0),
            p(-1.0, -1.0),
            p(10.0, 0.0),
            p(11.0, 0.0),
            p(12.0, 0.0),
            p(11.0, -2.0),
            p(20.0, 0.0),
            p(26.0, 0.0),
            p(26.0, -4.0),
            p(24.0, -4.0),
            p(24.0, -1.0),
            p(22.0, -1.0),
            p(22.0, -4.0),
            p(20.0, -4.0),
            p(30.0, 0.0),
            p(34.0, 0.0),
            p(34.0, -4.0),
            p(30.0, -4.0),
            p(31.0, -1.0),
            p(31.0, -3.0),
            p(33.0, -3.0),
            p(33.0, -1.0),
        ]);
        m.add_face(&[&[0, 1, 2, 3, 4]], 0);
        m.add_face(&[&[5, 6, 7, 8]], 0);
        m.add_face(&[&[9, 10, 11, 12, 13, 14, 15, 16]], 0);
        m.add_face(&[&[17, 18, 19, 20], &[21, 22, 23, 24]], 0);
        m.add_face(&[&[0, 1, 3]], 0);
        m.uvs[0] = Some(
            (0..m.corners.len())
                .map(|c| DVec2::new(c as f64, 0.5))
                .collect(),
        );
        m
    }

    /// Faces whose triangles are fans take the short path, which gives
    /// exactly what the general one gives; other faces take the general.
    #[test]
    fn fans_are_collected_as_the_general_path_collects_them() {
        let m = sample_faces();
        let transform = DAffine3::from_translation(DVec3::new(5.0, 1.0, 2.0));
        let mut prep = FacePrep::default();
        let mut fans = PlainMesh::with_capacity(0, 0, 0);
        let mut general = PlainMesh::with_capacity(0, 0, 0);
        let mut scratch = vec![NO_VERTEX; m.corners.len()];
        let mut starts = Vec::new();
        prep.faces(&m, Some(&transform), |f| {
            let uvs = f.mesh.uvs[0].as_deref();
            let start = fan_start(f);
            // What the preparation knew of a quad's fan is what its
            // triangles say.
            assert_eq!(start, fan_start(&FaceData { fan: None, ..*f }));
            starts.push((start, f.fan));
            match start {
                Some(first) => fans.push_fan(f, uvs, first, 3),
                None => fans.push_triangles(f, uvs, &mut scratch, 3),
            }
            general.push_triangles(f, uvs, &mut scratch, 3);
            Ok(())
        })
        .unwrap();
        let hints: Vec<_> = starts.iter().map(|s| s.1).collect();
        let starts: Vec<_> = starts.iter().map(|s| s.0).collect();
        assert_eq!(starts, [Some(3), Some(1), None, None, Some(0)]);
        // The one quad has three corners in a line: the general
        // triangulation cuts it, whose fan is read from its triangles.
        assert_eq!(hints, [None; 5]);
        assert_eq!(fans, general);
        assert_eq!(general.indices.len(), 3 + 2 + 6 + 8 + 1);
        assert_eq!(general.positions[0], [6.0, 1.0, 0.0]);
        // The quad's vertices start at its second corner.
        assert_eq!(general.positions[5], [16.0, 1.0, 2.0]);
        assert_eq!(general.uvs[5], [6.0, 0.5]);
    }

    /// A quad cut along either diagonal comes with the corner its fan
    /// starts from, the one its triangles give.
    #[test]
    fn quads_come_with_their_fans() {
        let mut m = Mesh::new();
        let p = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        // Convex (cut from corner 0); reflex at corner 1 (cut from it);
        // reflex at corner 0.
        m.positions
            .extend([p(0.0, 0.0), p(2.0, 0.0), p(2.0, -2.0), p(0.0, -2.0)]);
        m.positions
            .extend([p(0.0, 0.0), p(1.5, 1.0), p(4.0, 0.0), p(0.0, 4.0)]);
        m.positions
            .extend([p(3.0, -3.0), p(4.0, 0.0), p(4.0, -4.0), p(0.0, -4.0)]);
        for q in 0..3 {
            m.add_face(&[&[4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3]], 0);
        }
        let mut hints = Vec::new();
        FacePrep::default()
            .faces(&m, None, |f| {
                assert_eq!(f.fan, fan_start(&FaceData { fan: None, ..*f }));
                hints.push(f.fan);
                Ok(())
            })
            .unwrap();
        assert_eq!(hints, [Some(0), Some(1), Some(0)]);
    }

    #[test]
    fn room_given_to_a_new_collector_changes_nothing_collected() {
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let mut c = PlainCollector::new();
        for leaf in 0..2 {
            c.add_placed(&cube, None, &cube.materials, leaf).unwrap();
        }
        let first = c.take();
        assert_eq!(c.room(), &[(48, 24)]);
        let mut next = PlainCollector::with_room(c.room().to_vec());
        next.add_placed(&cube, None, &cube.materials, 0).unwrap();
        // Collecting, the mesh has the room given.
        assert!(next.full().model.meshes[0].positions.capacity() >= 48);
        assert!(next.full().model.meshes[0].triangle_leaf.capacity() >= 24);
        let second = next.take();
        let mut fresh = PlainCollector::new();
        fresh.add_placed(&cube, None, &cube.materials, 0).unwrap();
        assert_eq!(second, fresh.take());
        assert_eq!(first.meshes[0].positions.len(), 48);
    }

    #[test]
    fn room_kept_from_the_lot_before_changes_nothing_collected() {
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let mut c = PlainCollector::new();
        for leaf in 0..4 {
            c.add_placed(&cube, None, &cube.materials, leaf).unwrap();
        }
        let first = c.take();
        // The next lot's mesh starts with room for the first one's...
        c.add_placed(&cube, None, &cube.materials, 0).unwrap();
        assert!(c.full().model.meshes[0].positions.capacity() >= 96);
        assert!(c.full().model.meshes[0].indices.capacity() >= 48);
        let second = c.take();
        // ...and, using a quarter of it, is handed over holding about what
        // it uses.
        let m = &second.meshes[0];
        assert!(
            m.positions.capacity() <= 2 * 24,
            "{}",
            m.positions.capacity()
        );
        assert!(m.normals.capacity() <= 2 * 24);
        assert!(m.uvs.capacity() <= 2 * 24);
        assert!(m.indices.capacity() <= 2 * 12);
        assert!(m.triangle_leaf.capacity() <= 2 * 12);
        assert_eq!(second.meshes[0].positions.len(), 24);
        assert_eq!(second.meshes[0].indices.len(), 12);
        // What a lot collects does not depend on the lot before.
        let mut fresh = PlainCollector::new();
        fresh.add_placed(&cube, None, &cube.materials, 0).unwrap();
        assert_eq!(second, fresh.take());
        assert_eq!(first.meshes[0].indices.len(), 48);
    }
}
