//! Turning leaf meshes into glTF vertex data, on any thread.
//!
//! Placing, triangulating and converting a mesh's faces is most of the
//! work of writing a model. An [`Encoder`] does it where the meshes are
//! made (a worker thread deriving lots) into a batch of per-material
//! vertex arrays, [`Encoded`]; the writing thread only appends batches, in
//! order, to the model ([`ModelWriter::append`](crate::ModelWriter::append)),
//! so the output does not depend on which thread encoded what. A batch
//! names its materials by value; the writer gives them their ids, in the
//! order of first appearance, as if it had seen the faces itself.

use std::sync::Arc;

use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DVec2, DVec3, Material, Mesh, UV_SETS};

use crate::array_pool::ArrayPool;
use crate::bucket::{too_many_vertices, Bucket};
use crate::gltf::{bucket_layout, face_tangent, texture_uses};
use crate::instances::{decompose, Pending};
use crate::materials::MaterialTable;
use crate::prepare::{FacePrep, SlotIds};
use crate::textures::TextureProbe;
use crate::{check_mesh, ExportError, ExportOptions, FaceData};

/// Meshes encoded into vertex data, ready for [`ModelWriter::append`]
/// (crate::ModelWriter::append).
#[derive(Default)]
pub struct Encoded {
    /// The batch's materials, in order of first use by a written face.
    pub(crate) materials: Vec<Material>,
    /// Vertex data per material of `materials`.
    pub(crate) buckets: Vec<Bucket>,
    pub(crate) faces: u64,
    pub(crate) triangles: u64,
    /// Faces left out for non-finite values.
    pub(crate) skipped_non_finite: u64,
    /// Bytes of vertex data held.
    pub(crate) bytes: usize,
    /// The first invalid mesh given, which fails the model.
    pub(crate) error: Option<ExportError>,
    /// Assets placed as instances, in order (see `instances`).
    pub(crate) instances: Vec<Pending>,
    /// Where the batch's arrays go once written (its encoder's pool, which
    /// its next batches take from): the writer, any of them, hands them
    /// back.
    pub(crate) pool: Option<Arc<ArrayPool>>,
    /// In an encoder's working batch: emptied buckets of its earlier
    /// batches, with the material each held, whose room new materials
    /// take: the same material's bucket where there is one (its arrays are
    /// the size that material needs; a lot's materials come again in every
    /// batch), else the last.
    spare: Vec<(Material, Bucket)>,
}

/// Spare buckets up to which a new material looks for its own.
const MATCHED_SPARES: usize = 32;

impl Encoded {
    /// Whether nothing was encoded (and nothing failed).
    pub fn is_empty(&self) -> bool {
        self.faces == 0
            && self.skipped_non_finite == 0
            && self.error.is_none()
            && self.instances.is_empty()
    }

    /// A bucket for a new material of the batch, in the room of an old one
    /// if there is one.
    fn new_bucket(&mut self, material: &Material, sets: Vec<usize>, tangents: bool) {
        // A batch of many materials (a colour per building) would compare
        // each new one with every spare: beyond a few, any bucket does.
        let same = (self.spare.len() <= MATCHED_SPARES)
            .then(|| {
                self.spare
                    .iter()
                    .rposition(|(m, _)| crate::materials::same_material(m, material))
            })
            .flatten();
        let spare = match same {
            Some(k) => Some(self.spare.swap_remove(k)),
            None => self.spare.pop(),
        };
        let bucket = match spare.map(|(_, b)| b) {
            Some(mut b) => {
                b.relayout(sets, tangents);
                b
            }
            None => Bucket::with_layout(sets, tangents),
        };
        self.buckets.push(bucket);
    }

    /// The batch's data in its own arrays, leaving the batch empty with
    /// arrays of room for as much from `pool` (arrays the writer wrote out,
    /// where the batch's go back too; each bucket kept with `materials`,
    /// the materials of its buckets in order).
    ///
    /// Batches wait to be appended (a worker's lot waits for the lots
    /// before it), so their arrays are what the model holds in flight; the
    /// writer keeps them as they are until it writes them (see
    /// `Bucket::append`). A batch is about as large as the one before it,
    /// so its arrays (with a quarter more room, see
    /// `Bucket::take_leaving_room`) seldom grow past the room they start
    /// with. (Copying each batch into arrays of its exact size, as before,
    /// cost a copy of every encoded byte; reusing the arrays of appended
    /// batches, before that, made every array in flight grow to the most
    /// any material ever needed.)
    fn take_batch(&mut self, materials: Vec<Material>, pool: &Arc<ArrayPool>) -> Encoded {
        let out = Encoded {
            buckets: self
                .buckets
                .iter_mut()
                .map(|b| b.take_leaving_room(pool))
                .collect(),
            materials,
            faces: std::mem::take(&mut self.faces),
            triangles: std::mem::take(&mut self.triangles),
            skipped_non_finite: std::mem::take(&mut self.skipped_non_finite),
            bytes: std::mem::take(&mut self.bytes),
            error: self.error.take(),
            instances: std::mem::take(&mut self.instances),
            pool: Some(pool.clone()),
            spare: Vec::new(),
        };
        let kept = out.materials.iter().cloned().zip(self.buckets.drain(..));
        self.spare.extend(kept.map(|(m, mut b)| {
            b.clear();
            (m, b)
        }));
        out
    }
}

/// What the encoders of one writer share.
pub(crate) struct EncoderShared {
    /// Which textures the writer will find usable: that decides which UV
    /// sets and tangents a material's vertices carry.
    pub probe: TextureProbe,
    /// What every encoder writes positions relative to.
    pub origin: Option<DVec3>,
    /// Whether assets are placed as instances (`ExportOptions::instances`).
    pub instancing: bool,
    /// Arrays the writer wrote out, for the encoders' next batches.
    pub pool: Arc<ArrayPool>,
}

impl EncoderShared {
    pub(crate) fn new(
        probe: TextureProbe,
        origin: Option<DVec3>,
        instancing: bool,
    ) -> EncoderShared {
        EncoderShared {
            probe,
            origin,
            instancing,
            pool: Arc::default(),
        }
    }
}

/// Where encoded faces go: vertex data by material id.
pub(crate) trait Buckets {
    /// The id of material `m`, with a bucket made for it if it is new.
    fn id_of(&mut self, m: &Material) -> u32;
    fn bucket(&mut self, id: u32) -> &mut Bucket;
}

/// What encoding a mesh added.
#[derive(Default, Clone, Copy)]
pub(crate) struct Counts {
    pub faces: u64,
    pub triangles: u64,
    /// Faces left out for non-finite values.
    pub skipped_non_finite: u64,
    /// Bytes of vertex data.
    pub bytes: usize,
}

/// Scratch room for encoding meshes, kept from one mesh to the next.
#[derive(Default)]
pub(crate) struct MeshEncoder {
    /// Positions are written relative to this point (see
    /// [`ExportOptions::origin`](crate::ExportOptions::origin)).
    pub origin: Option<DVec3>,
    prep: FacePrep,
    slots: SlotIds,
    vertices: VertexSharing,
    /// Where a bucket's arrays grow from (an [`Encoder`]'s batches: the
    /// arrays its writer wrote out); `None`: from the allocator.
    pub pool: Option<Arc<ArrayPool>>,
}

impl MeshEncoder {
    /// Encodes one shape's geometry into `store`: given in its own
    /// coordinates, placed by `transform`, with `materials` for its slots
    /// (see [`ModelWriter::add_placed`](crate::ModelWriter::add_placed)).
    /// The ids `store` gives are remembered per material list until
    /// [`forget_ids`](MeshEncoder::forget_ids).
    pub fn encode(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
        store: &mut impl Buckets,
    ) -> Result<Counts, ExportError> {
        check_mesh(mesh, materials.len())?;
        let shifted;
        let transform = match self.origin {
            Some(o) => {
                shifted = DAffine3::from_translation(-o) * transform.copied().unwrap_or_default();
                Some(&shifted)
            }
            None => transform,
        };
        let MeshEncoder {
            origin: _,
            prep,
            slots,
            vertices,
            pool,
        } = self;
        let pool = pool.as_deref();
        slots.begin(materials);
        vertices.begin(mesh);
        let mut counts = Counts::default();
        let result = prep.faces(mesh, transform, |f| {
            let material = slots.id(f.material, || store.id_of(&materials[f.material as usize]));
            let bucket = store.bucket(material);
            counts.bytes += add_face(bucket, vertices, pool, f, material)?;
            counts.faces += 1;
            counts.triangles += f.triangles.len() as u64;
            Ok(())
        });
        slots.end(materials);
        counts.skipped_non_finite = result?;
        Ok(counts)
    }

    /// Forgets the ids of the material lists seen (the store's ids start
    /// again).
    pub fn forget_ids(&mut self) {
        self.slots.clear();
    }
}

/// The buckets of a batch: materials get ids of their own, in order of
/// first use, and buckets laid out as the writer will lay them out.
struct BatchBuckets<'a> {
    table: &'a mut MaterialTable,
    batch: &'a mut Encoded,
    probe: &'a TextureProbe,
}

impl Buckets for BatchBuckets<'_> {
    fn id_of(&mut self, m: &Material) -> u32 {
        let (id, new) = self.table.intern(m);
        if new {
            let uses = texture_uses(
                m,
                |path, _| self.probe.usable(path).then_some(0),
                &mut Vec::new(),
            );
            let (sets, tangents) = bucket_layout(&uses);
            self.batch.new_bucket(m, sets, tangents);
        }
        id
    }

    fn bucket(&mut self, id: u32) -> &mut Bucket {
        &mut self.batch.buckets[id as usize]
    }
}

/// Encodes meshes for a glTF or GLB [`ModelWriter`](crate::ModelWriter),
/// which makes it ([`ModelWriter::encoder`](crate::ModelWriter::encoder)).
/// One per thread; it keeps its scratch room from one mesh to the next.
pub struct Encoder {
    shared: Arc<EncoderShared>,
    mesh: MeshEncoder,
    /// The materials of the batch being filled.
    table: MaterialTable,
    batch: Encoded,
}

impl Encoder {
    pub(crate) fn new(shared: Arc<EncoderShared>) -> Encoder {
        Encoder {
            mesh: MeshEncoder {
                origin: shared.origin,
                pool: Some(shared.pool.clone()),
                ..MeshEncoder::default()
            },
            shared,
            table: MaterialTable::default(),
            batch: Encoded::default(),
        }
    }

    /// A new encoder for the same writer or export options (for another
    /// thread), with their origin (not one given by
    /// [`set_origin`](Encoder::set_origin)).
    pub fn another(&self) -> Encoder {
        Encoder::new(self.shared.clone())
    }

    /// An encoder for the glTF and GLB writers made with `options`, with
    /// no writer of its own: its batches can be appended to any of them
    /// whose origin is the encoder's ([`set_origin`](Encoder::set_origin);
    /// the tiles of a tileset, each with the origin of its lots).
    pub fn for_export(options: &ExportOptions) -> Encoder {
        let options = options.clone().exact_origin();
        Encoder::new(Arc::new(EncoderShared::new(
            TextureProbe::new(options.world.clone(), &options.texture_roots),
            options.origin,
            options.instances,
        )))
    }

    /// Writes the positions of the meshes added from now on relative to
    /// `origin` (see [`ExportOptions::origin`]), as a writer made with that
    /// origin does.
    pub fn set_origin(&mut self, origin: Option<DVec3>) {
        self.mesh.origin = origin.map(crate::exact);
    }

    /// Encodes one shape's geometry, given in its own coordinates and
    /// placed in the world by `transform`, with `materials` for its
    /// material slots (see [`ModelWriter::add_placed`]
    /// (crate::ModelWriter::add_placed), whose output this gives). An
    /// invalid mesh fails the batch: appending it returns the error.
    pub fn add_placed(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
    ) {
        let batch = &mut self.batch;
        if batch.error.is_some() {
            return;
        }
        let mut store = BatchBuckets {
            table: &mut self.table,
            batch: &mut *batch,
            probe: &self.shared.probe,
        };
        match self.mesh.encode(mesh, transform, materials, &mut store) {
            Ok(c) => {
                batch.faces += c.faces;
                batch.triangles += c.triangles;
                batch.skipped_non_finite += c.skipped_non_finite;
                batch.bytes += c.bytes;
            }
            Err(e) => batch.error = Some(e),
        }
    }

    /// An inserted asset as loaded (the engine's `Leaf::asset`), placed by
    /// `transform`: kept as an instance of its mesh when the writer writes
    /// instances and `transform` is a rotation and scale, else encoded as
    /// [`add_placed`](Encoder::add_placed) does.
    pub fn add_asset(
        &mut self,
        mesh: &Arc<Mesh>,
        transform: &DAffine3,
        materials: &SharedVec<Material>,
    ) {
        match instance(self.shared.instancing, mesh, transform, materials) {
            Some(p) => {
                self.batch.instances.push(p);
                // A placement is a few dozen bytes on its way.
                self.batch.bytes += 64;
            }
            None => self.add_placed(mesh, Some(transform), materials),
        }
    }

    /// Bytes of vertex data encoded since the last [`take`](Encoder::take).
    pub fn bytes(&self) -> usize {
        self.batch.bytes
    }

    /// The meshes encoded since the last call, as one batch; the encoder
    /// starts an empty one.
    pub fn take(&mut self) -> Encoded {
        let batch = self
            .batch
            .take_batch(self.table.take_materials(), &self.shared.pool);
        // Slot ids name this batch's materials.
        self.mesh.forget_ids();
        batch
    }
}

/// The placement of an asset as an instance, if instancing is on and
/// `transform` is a TRS.
pub(crate) fn instance(
    instancing: bool,
    mesh: &Arc<Mesh>,
    transform: &DAffine3,
    materials: &SharedVec<Material>,
) -> Option<Pending> {
    if !instancing || mesh.faces.is_empty() {
        return None;
    }
    let trs = decompose(transform)?;
    Some(Pending {
        mesh: mesh.clone(),
        materials: materials.clone(),
        transform: *transform,
        trs,
    })
}

/// Identifies a vertex at one position of an input mesh that carries its
/// own normals, so corners that share position, normal and UV (and
/// material) share one output vertex.
#[derive(Clone, Copy, PartialEq, Eq)]
struct VertexKey {
    material: u32,
    normal: [u32; 3],
    uv: [u32; 2],
}

/// An output vertex made for a position of the mesh being added: its key,
/// the vertex, and the next entry of the same position (`NO_ENTRY`: none).
#[derive(Clone, Copy)]
struct SharedVertex {
    key: VertexKey,
    vertex: u32,
    next: u32,
}

const NO_ENTRY: u32 = u32::MAX;

/// Which output vertex each corner of the mesh being encoded became.
#[derive(Default)]
struct VertexSharing {
    /// Output vertex of each corner.
    corner_vertex: Vec<u32>,
    /// The output vertices made for each position (per position the first
    /// entry in `shared`, chained by `next`): a position rarely has more
    /// than a few, so this is a short walk instead of hashing every corner.
    first_shared: Vec<u32>,
    shared: Vec<SharedVertex>,
    /// The written normal of the last corner, for the next.
    last_normal: LastNormal,
}

/// The unit normal written for the corner before, by the bits of its
/// placed normal. An asset's flat faces repeat one normal corner after
/// corner (Candler's sash window: 112 of its 148 corners, 62 % of a
/// building's faces), and the same bits normalise to the same normal: a
/// comparison instead of a square root and a division.
#[derive(Default)]
pub(crate) struct LastNormal(Option<([u64; 3], DVec3)>);

impl LastNormal {
    /// `n` made unit, else the face's normal (`f.normal()`, never
    /// remembered: it belongs to the face).
    #[inline(always)]
    pub fn unit(&mut self, n: DVec3, f: &FaceData) -> DVec3 {
        let bits = n.to_array().map(f64::to_bits);
        match self.0 {
            Some((b, unit)) if b == bits => unit,
            _ => match n.try_normalize() {
                Some(unit) => {
                    self.0 = Some((bits, unit));
                    unit
                }
                None => f.normal(),
            },
        }
    }
}

impl VertexSharing {
    fn begin(&mut self, mesh: &Mesh) {
        // Every corner of a face is given its vertex before the face's
        // triangles read it: the entries of earlier meshes need no reset.
        if self.corner_vertex.len() < mesh.corners.len() {
            self.corner_vertex.resize(mesh.corners.len(), 0);
        }
        self.first_shared.clear();
        if mesh.normals.is_some() {
            self.first_shared.resize(mesh.positions.len(), NO_ENTRY);
        }
        self.shared.clear();
        self.last_normal = LastNormal::default();
    }
}

/// Appends face `f` to `bucket`, that of its output material `material`
/// (`f.material` is the face's slot): its vertices and triangles. Corners
/// of a mesh with its own normals share vertices where position, normal
/// and UV agree; other faces get a vertex per corner.
///
/// The id comes apart from `f`, which is read as the preparation wrote it:
/// a copy of `f` with the id changed cost a stall per face (a wide load of
/// fields just stored one by one, which the processor cannot forward).
fn add_face(
    bucket: &mut Bucket,
    sharing: &mut VertexSharing,
    pool: Option<&ArrayPool>,
    f: &FaceData,
    material: u32,
) -> Result<usize, ExportError> {
    let VertexSharing {
        corner_vertex,
        first_shared,
        shared: made,
        last_normal,
    } = sharing;
    let mesh = f.mesh;
    let uvs = mesh.uvs[0].as_deref();
    // Bytes added (see `Bucket::own_bytes`): the coordinates of the
    // vertices before, when the material starts having them, then the
    // face's vertices and triangles.
    #[cfg(debug_assertions)]
    let own_before = bucket.own_bytes();
    let mut bytes = 0;
    if uvs.is_some() && bucket.sets.is_empty() {
        bucket.start_coords();
        bytes += bucket.positions.len() * 8;
    }
    if let Some(pool) = pool {
        let corners = f.loops.iter().map(|l| l.len as usize).sum();
        bucket.room_from(pool, corners, f.triangles.len());
    }
    let vertices_before = bucket.positions.len();
    // Vertices are shared only where one UV set is written (the key
    // holds set 0's coordinates) and no tangents (which are per face).
    let shared = bucket.sets.len() <= 1 && bucket.tangents.is_none();
    let tangent = match bucket.tangents {
        Some(_) => face_tangent(f),
        None => (DVec3::X, 1.0),
    };
    // Where each written UV set reads: the mesh's set, else set 0.
    let mut sources: [Option<&[DVec2]>; UV_SETS] = [None; UV_SETS];
    for (src, &set) in sources.iter_mut().zip(&bucket.sets) {
        *src = mesh.uvs[set].as_deref().or(uvs);
    }
    let sources = &sources[..bucket.sets.len()];
    let loops = f.loops;
    match f.normals {
        Some(normals) if shared => {
            let corners = loops.iter().flat_map(|&l| mesh.loop_corners(l));
            for c in corners {
                let position = mesh.corners[c] as usize;
                let n = last_normal.unit(normals[c], f);
                let uv = uvs.map_or([0; 2], |u| u[c].as_vec2().to_array().map(f32::to_bits));
                let key = VertexKey {
                    material,
                    normal: n.as_vec3().to_array().map(f32::to_bits),
                    uv,
                };
                let mut e = first_shared[position];
                while e != NO_ENTRY {
                    let s = &made[e as usize];
                    if s.key == key {
                        break;
                    }
                    e = s.next;
                }
                corner_vertex[c] = if e != NO_ENTRY {
                    made[e as usize].vertex
                } else {
                    let v = bucket.push_vertex(f.positions[position], n, sources, c, tangent)?;
                    made.push(SharedVertex {
                        key,
                        vertex: v,
                        next: first_shared[position],
                    });
                    first_shared[position] = made.len() as u32 - 1;
                    v
                };
            }
        }
        // Every corner its own vertex: the attributes are appended one
        // array at a time (a face's corners are mostly one range).
        _ => match loops {
            [l] => own_vertices(
                bucket,
                f,
                sources,
                tangent,
                corner_vertex,
                last_normal,
                mesh.loop_corners(*l),
            )?,
            _ => own_vertices(
                bucket,
                f,
                sources,
                tangent,
                corner_vertex,
                last_normal,
                loops.iter().flat_map(|&l| mesh.loop_corners(l)),
            )?,
        },
    }
    bucket.indices.extend(
        f.triangles
            .iter()
            .map(|t| t.map(|c| corner_vertex[c as usize])),
    );
    let vertex_bytes = 24 + bucket.coords.len() * 8 + bucket.tangents.as_ref().map_or(0, |_| 16);
    bytes += (bucket.positions.len() - vertices_before) * vertex_bytes + f.triangles.len() * 12;
    #[cfg(debug_assertions)]
    debug_assert_eq!(bytes, bucket.own_bytes() - own_before);
    Ok(bytes)
}

/// Appends one vertex per corner of face `f` (`corners`, in order) to
/// `bucket`, recording each corner's vertex in `corner_vertex`: the values
/// `Bucket::push_vertex` would append corner by corner, written one
/// attribute array at a time. Without normals of its own every vertex has
/// the face normal (flat shading), so the normal and tangent are converted
/// once for the face.
fn own_vertices(
    bucket: &mut Bucket,
    f: &FaceData,
    sources: &[Option<&[DVec2]>],
    tangent: (DVec3, f64),
    corner_vertex: &mut [u32],
    last_normal: &mut LastNormal,
    corners: impl Iterator<Item = usize> + Clone,
) -> Result<(), ExportError> {
    use crate::bucket::{uv_at, vertex_tangent};
    let mesh = f.mesh;
    let count = corners.clone().count();
    let first = bucket.positions.len();
    // Vertex indices are u32: the last one must fit.
    if first + count > u32::MAX as usize + 1 {
        return Err(too_many_vertices());
    }
    bucket.reserve(count);
    for (v, c) in (first as u32..).zip(corners.clone()) {
        bucket.push_position(f.positions[mesh.corners[c] as usize]);
        corner_vertex[c] = v;
    }
    match f.normals {
        Some(normals) => {
            for c in corners.clone() {
                let n = last_normal.unit(normals[c], f);
                bucket.normals.push(n.as_vec3().to_array());
                if let Some(tangents) = &mut bucket.tangents {
                    tangents.push(vertex_tangent(n, tangent));
                }
            }
        }
        None => {
            let normal = f.normal();
            let n = normal.as_vec3().to_array();
            bucket.normals.extend(std::iter::repeat_n(n, count));
            if let Some(tangents) = &mut bucket.tangents {
                let t = vertex_tangent(normal, tangent);
                tangents.extend(std::iter::repeat_n(t, count));
            }
        }
    }
    for (src, coords) in sources.iter().zip(&mut bucket.coords) {
        coords.extend(corners.clone().map(|c| uv_at(*src, c)));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ExportOptions;

    fn material(name: &str, r: f64) -> SharedVec<Material> {
        let m = Material {
            name: name.into(),
            color: [r, 0.5, 0.5],
            ..Material::default()
        };
        SharedVec::from(vec![m])
    }

    /// The address and room of the positions of the encoder's bucket for
    /// material `id` of the batch being filled.
    fn room(e: &Encoder, id: usize) -> (*const [f32; 3], usize) {
        let p = &e.batch.buckets[id].positions;
        (p.as_ptr(), p.capacity())
    }

    /// A batch takes the encoder's arrays as they are (no copy); the
    /// encoder starts fresh ones with room for as much, each material in
    /// the bucket it had before (here the materials come in the other
    /// order the second time), so that a batch like the last reallocates
    /// nothing.
    #[test]
    fn batches_take_their_arrays_and_each_material_keeps_its_room() {
        let mut e = Encoder::for_export(&ExportOptions::default());
        let big = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let small = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Z]);
        let (wall, roof) = (material("wall", 0.25), material("roof", 0.75));
        for _ in 0..20 {
            e.add_placed(&big, None, &wall);
        }
        e.add_placed(&small, None, &roof);
        let wall_data = room(&e, 0).0;
        let batch = e.take();
        assert_eq!(batch.materials.len(), 2);
        assert_eq!(batch.faces, 20 * 6 + 1);
        assert_eq!(batch.buckets[0].positions.as_ptr(), wall_data, "not copied");
        assert_eq!(batch.buckets[0].positions.len(), 20 * 24);
        assert_eq!(batch.buckets[1].indices.len(), 1);
        assert_eq!(e.bytes(), 0);
        // The spare buckets: room for what each material held and a
        // quarter more.
        let spare_room = |name: &str| {
            let (_, b) = e
                .batch
                .spare
                .iter()
                .find(|(m, _)| &*m.name == name)
                .unwrap();
            assert!(b.positions.is_empty() && b.indices.is_empty());
            (b.positions.as_ptr(), b.positions.capacity())
        };
        let (wall_room, roof_room) = (spare_room("wall"), spare_room("roof"));
        assert!(wall_room.1 >= 20 * 24 * 5 / 4 && wall_room.0 != wall_data);
        assert!((3..20 * 24).contains(&roof_room.1), "{roof_room:?}");

        e.add_placed(&small, None, &roof);
        for _ in 0..20 {
            e.add_placed(&big, None, &wall);
        }
        assert_eq!(room(&e, 0), roof_room, "roof in the roof's bucket");
        assert_eq!(room(&e, 1), wall_room, "wall in the wall's bucket");
        let again = e.take();
        assert_eq!(again.buckets[1].positions, batch.buckets[0].positions);
    }

    /// Arrays the writer wrote out go round: a lot's data is written when
    /// the next lot begins, its arrays go back to its encoder's pool, and the
    /// encoder's next batch takes them (with their room) instead of new
    /// ones. The model is the same as without the pool.
    #[test]
    fn written_arrays_come_back_to_the_encoder() {
        use crate::ModelWriter;
        let glb = |pooled: bool| {
            let out = std::io::Cursor::new(Vec::new());
            let mut w = ModelWriter::glb_into(out, "m.glb", ExportOptions::default()).unwrap();
            let mut e = w.encoder().unwrap();
            let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
            let wall = material("wall", 0.25);
            let mut arrays = Vec::new();
            for lot in 0..3 {
                w.begin_lot(&format!("lot {lot}"), None).unwrap();
                e.add_placed(&cube, None, &wall);
                e.add_placed(&cube, None, &wall);
                if !pooled {
                    e.shared.pool.clear();
                }
                let batch = e.take();
                let b = &batch.buckets[0];
                assert_eq!(b.positions.len(), 48);
                arrays.push([b.positions.as_ptr(), b.normals.as_ptr()]);
                w.append(batch).unwrap();
            }
            let bytes = w.finish_into().unwrap().1.unwrap();
            (arrays, bytes)
        };
        let (arrays, with_pool) = glb(true);
        // Lot 0's arrays were written when lot 1 began; lot 1's batch left
        // the encoder arrays from the pool (room for 60 vertices, which
        // lot 0's have), which lot 2's batch took.
        assert!(arrays[0].contains(&arrays[2][0]), "{arrays:?}");
        assert!(arrays[0].contains(&arrays[2][1]), "{arrays:?}");
        assert!(!arrays[0].contains(&arrays[1][0]), "{arrays:?}");
        let (_, without) = glb(false);
        let bytes = |out: Box<dyn crate::Output>| {
            out.into_any()
                .downcast::<std::io::Cursor<Vec<u8>>>()
                .unwrap()
                .into_inner()
        };
        assert_eq!(bytes(with_pool), bytes(without));
    }

    /// An array of a batch that outgrows its room grows into an array the
    /// writer wrote out (from the pool: already touched memory), not into
    /// fresh memory from the allocator, and the short array goes to the
    /// pool; the data is as pushes alone would give.
    #[test]
    fn short_arrays_grow_from_the_pool() {
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        let wall = material("wall", 0.25);
        let mut plain = Encoder::for_export(&ExportOptions::default());
        plain.add_placed(&cube, None, &wall);
        let mut e = Encoder::for_export(&ExportOptions::default());
        let written: Vec<[f32; 3]> = Vec::with_capacity(1000);
        let written_at = written.as_ptr();
        e.shared.pool.vectors.give(written);
        e.add_placed(&cube, None, &wall);
        // The first face needed room for 4 vertices: the positions took the
        // written array (the least room that fits) and kept it; the
        // normals, with nothing else kept, grew 4 -> 8 -> 16 -> 32, each
        // from a new array, each short one given to the pool.
        assert_eq!(room(&e, 0), (written_at, 1000));
        let normals = &e.batch.buckets[0].normals;
        assert_eq!((normals.len(), normals.capacity()), (24, 32));
        for n in [4, 8, 16] {
            assert_eq!(e.shared.pool.vectors.take(n).capacity(), n);
        }
        let (a, b) = (e.take(), plain.take());
        assert_eq!(a.buckets[0].positions, b.buckets[0].positions);
        assert_eq!(a.buckets[0].normals, b.buckets[0].normals);
        assert_eq!(a.buckets[0].indices, b.buckets[0].indices);
    }

    /// Normals of its own repeated corner after corner are placed and made
    /// unit once (`LastNormal`): every corner gets what its own would give,
    /// a zero normal the face's normal, even between repeats and across
    /// faces, and a normal that differs only in the sign of a zero its own.
    #[test]
    fn repeated_normals_of_its_own_are_written_as_each_would_be() {
        let s = DVec3::new(1.5, 2.0, 0.5);
        let mut mesh = Mesh::new();
        mesh.positions.extend([
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::Y,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 1.0, 0.0),
        ]);
        mesh.add_face(&[&[0, 1, 2, 3]], 0);
        mesh.add_face(&[&[1, 4, 5, 2]], 0);
        let up = DVec3::new(0.0, 0.0, 3.0);
        let tilted = DVec3::new(0.0, -0.0, 3.0);
        let own = [up, up, DVec3::ZERO, up, up, tilted, up, up];
        mesh.normals = Some(own.to_vec());
        let turn = DAffine3::from_rotation_x(0.4) * DAffine3::from_scale(s);
        let mut e = Encoder::for_export(&ExportOptions {
            instances: false,
            ..ExportOptions::default()
        });
        e.add_placed(&mesh, Some(&turn), &material("m", 0.5));
        let batch = e.take();
        let bucket = &batch.buckets[0];
        // Each corner on its own: placed by the inverse transpose, made
        // unit twice (placed, then written), else the face normal.
        let nm = cga_geometry::transform::normal_matrix(&turn);
        let face_normal = (turn.matrix3 * DVec3::Z).normalize();
        let want: Vec<[f32; 3]> = own
            .iter()
            .map(|&n| match (nm * n).normalize_or_zero().try_normalize() {
                Some(n) => n.as_vec3().to_array(),
                None => face_normal.as_vec3().to_array(),
            })
            .collect();
        let written: Vec<u32> = bucket.indices.iter().flatten().copied().collect();
        assert_eq!(batch.faces, 2);
        // Face 1's first corner shares face 0's second vertex (same
        // position, normal and UV); the others are vertices of their own
        // unless their written normals agree.
        assert_eq!(written[6], written[1]);
        assert!((6..=7).contains(&bucket.normals.len()));
        let got = |v: u32| bucket.normals[v as usize];
        // Face 0 is cut 0-1-2, 0-2-3; face 1 likewise from its corner 4.
        let corners = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
        for (&v, &c) in written.iter().zip(&corners) {
            let (g, w) = (got(v), want[c]);
            assert!(
                (0..3).all(|k| (g[k] - w[k]).abs() < 1e-6),
                "corner {c}: {g:?} against {w:?}"
            );
            assert_eq!(g.map(f32::to_bits), w.map(f32::to_bits), "corner {c}");
        }
        assert!((got(written[2])[2] - face_normal.z as f32).abs() < 1e-6);
    }

    /// The bytes an encoder counts are those its batch holds: faces with
    /// and without texture coordinates of one untextured material (the
    /// first with coordinates gives the vertices before theirs), and
    /// meshes whose corners share vertices.
    #[test]
    fn the_bytes_counted_are_the_bytes_held() {
        let mut e = Encoder::for_export(&ExportOptions::default());
        let wall = material("wall", 0.25);
        let plain = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]);
        let mut textured = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        assert!(textured.uvs[0].is_some());
        e.add_placed(&plain, None, &wall);
        e.add_placed(&textured, None, &wall);
        textured.normals = Some(vec![DVec3::Y; textured.corners.len()]);
        e.add_placed(&textured, None, &wall);
        let counted = e.bytes();
        let batch = e.take();
        let held: usize = batch.buckets.iter().map(Bucket::own_bytes).sum();
        assert_eq!(counted, held);
        // 4 + 24 vertices, then the cube's 24 corners on 8 positions with
        // one normal, but their own UVs.
        let b = &batch.buckets[0];
        assert!(
            b.positions.len() > 28 && b.positions.len() < 52,
            "{}",
            b.positions.len()
        );
        assert_eq!(held, b.positions.len() * 32 + b.indices.len() * 12);
    }
}
