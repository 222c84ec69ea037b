//! GLB and glTF (+ `.bin`) output.
//!
//! One glTF mesh per material, each referenced by its own node of the
//! default scene. Per material the writer keeps the vertex attributes as
//! `f32` (that is the output itself: nothing of the input meshes is kept)
//! and writes the JSON at the end, when every accessor's size is known.
//!
//! Memory stays bounded for large models: once the vertex data held
//! exceeds [`ExportOptions::flush_mib`](crate::ExportOptions), every
//! material's data so far is written out as a primitive of its own and the
//! arrays start again empty (between two input meshes). A material's mesh
//! then has several primitives. The `.bin` of glTF is written as it comes;
//! GLB, whose JSON chunk comes first, leaves room for it at the start of
//! the file and fills the room with the JSON and spaces at the end (moving
//! the binary data up if the JSON does not fit). A model that fits in
//! memory is written at the end, in one primitive per material.
//!
//! Binary layout: for each primitive in the order written (those written
//! early first, then one per material in order of first appearance),
//! positions, normals, texture coordinates (when present: one array per
//! distinct UV set its textures read; per UV set once anything was written
//! early, so that all primitives of a material read the same sets),
//! tangents (normal-mapped materials) and `u32` indices, each in its own
//! buffer view; then the embedded images (GLB only).
//!
//! Textures: the colour map is the base colour texture (with the alpha when
//! the opacity map is the same image), the normal, emissive and occlusion
//! maps are glTF's, roughness and metallic maps its packed
//! metallic-roughness texture; each reads its own UV set (set 0 where a mesh
//! lacks it) and carries its `su sv tu tv rw` as `KHR_texture_transform`.
//! The dirt, bump and specular maps have no glTF counterpart. Everything is 4-byte
//! aligned because every component is 4 bytes.

use std::collections::HashMap;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use std::sync::Arc;

use cga_geometry::{DAffine3, DVec3, Material};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use crate::array_pool::ArrayPool;
use crate::bucket::Bucket;
use crate::encode::Buckets;
use crate::instances::{Instances, Pending, Placement, Trs};
use crate::json_spool::{self, GlbJson, Spool};
use crate::materials::{color_to_linear, MaterialTable};
use crate::output_file::OutputFile;
use crate::textures::{uri_encode, Textures};
use crate::{ExportError, ExportStats, FaceData};

/// The sizes (in bytes) of a primitive's arrays, in the order of the binary
/// layout, with its material and bounds: what its accessors need.
struct PrimitiveLayout {
    material: u32,
    vertices: u64,
    positions: usize,
    normals: usize,
    coords: Vec<usize>,
    tangents: Option<usize>,
    indices: usize,
    /// With per-lot features (EXT_mesh_features): a feature id per vertex
    /// (the position of its lot in the model), written after the indices.
    features: bool,
    min: [f32; 3],
    max: [f32; 3],
}

impl PrimitiveLayout {
    /// How many accessors (each with its buffer view) the primitive has.
    fn accessor_count(&self) -> usize {
        3 + self.coords.len() + usize::from(self.tangents.is_some()) + usize::from(self.features)
    }
}

/// Vertex data held before it is written out, by default (see the module
/// docs).
pub const DEFAULT_FLUSH_MIB: usize = 64;

/// GLB: bytes left at the start of the file for the header and the JSON
/// when data is written before the end (most models' JSON needs a few
/// kilobytes; one with thousands of materials may need more, and then the
/// binary data is moved up).
const GLB_JSON_ROOM: u64 = 1 << 20;

/// The least room left when the number of lots is known (see
/// `GltfWriter::estimated_json_room`).
const MIN_ESTIMATED_ROOM: u64 = 16 << 10;

/// Writes values as the little-endian bytes glTF's binary buffer holds.
fn write_le<T: bytemuck::Pod>(w: &mut (impl Write + ?Sized), values: &[T]) -> std::io::Result<()> {
    if cfg!(target_endian = "little") {
        return w.write_all(bytemuck::cast_slice(values));
    }
    // Every component is 4 bytes: swap each.
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in bytemuck::cast_slice::<T, [u8; 4]>(values).chunks(1 << 14) {
        buf.clear();
        buf.extend(
            chunk
                .iter()
                .flat_map(|b| u32::from_ne_bytes(*b).to_le_bytes()),
        );
        w.write_all(&buf)?;
    }
    Ok(())
}

impl Bucket {
    /// Keeps one coordinate array per distinct content: a layer whose UV set
    /// no mesh had reads set 0's array. (Every segment holds the same sets:
    /// two sets are equal where they are in each.)
    fn merge_equal_coords(&mut self) {
        let mut distinct: Vec<usize> = Vec::new();
        let mut tex_coords = Vec::with_capacity(self.coords.len());
        for k in 0..self.coords.len() {
            // Compared as numbers: 0 equals -0, NaN equals nothing.
            let equal = |d: usize| self.segments().all(|s| s.coords[d] == s.coords[k]);
            match distinct.iter().position(|&d| equal(d)) {
                Some(i) => tex_coords.push(i as u32),
                None => {
                    tex_coords.push(distinct.len() as u32);
                    distinct.push(k);
                }
            }
        }
        self.tex_coords = tex_coords;
        self.each_segment_mut(|s| {
            let mut all = std::mem::take(&mut s.coords);
            s.coords = distinct
                .iter()
                .map(|&d| std::mem::take(&mut all[d]))
                .collect();
        });
    }

    /// Each UV set in an array of its own (no merging), as once anything
    /// was written early.
    fn unmerged_coords(&mut self) {
        self.tex_coords = (0..self.coords.len() as u32).collect();
    }

    /// What the accessors of this bucket's data as a primitive need.
    fn primitive(&self, material: u32) -> PrimitiveLayout {
        let sum = |len: &dyn Fn(&Bucket) -> usize| self.segments().map(len).sum::<usize>();
        let vertices = sum(&|s| s.positions.len());
        PrimitiveLayout {
            material,
            vertices: vertices as u64,
            positions: vertices * 12,
            normals: sum(&|s| s.normals.len()) * 12,
            coords: (0..self.coords.len())
                .map(|k| sum(&|s| s.coords[k].len()) * 8)
                .collect(),
            tangents: self
                .tangents
                .as_ref()
                .map(|_| sum(&|s| s.tangents.as_ref().map_or(0, Vec::len)) * 16),
            indices: sum(&|s| s.indices.len()) * 12,
            features: self.segments().any(|s| !s.features.is_empty()),
            min: self.min,
            max: self.max,
        }
    }

    /// The arrays in the order of the binary layout, each attribute's
    /// segments one after another.
    fn write_arrays(&self, w: &mut (impl Write + ?Sized)) -> std::io::Result<()> {
        for s in self.segments() {
            write_le(w, &s.positions)?;
        }
        for s in self.segments() {
            write_le(w, &s.normals)?;
        }
        for k in 0..self.coords.len() {
            for s in self.segments() {
                write_le(w, &s.coords[k])?;
            }
        }
        if self.tangents.is_some() {
            for s in self.segments() {
                write_le(w, s.tangents.as_deref().unwrap_or_default())?;
            }
        }
        for s in self.segments() {
            write_le(w, &s.indices)?;
        }
        // Feature ids as floats: exact below 2^24 lots per model.
        for s in self.segments() {
            write_le(w, &s.features)?;
        }
        Ok(())
    }
}

/// The model's buckets, for meshes encoded on the writing thread: a
/// material's id is its output id in the model's table, and a new one gets
/// its glTF material and bucket at once.
pub(crate) struct ModelBuckets<'a> {
    pub writer: &'a mut GltfWriter,
    pub table: &'a mut MaterialTable,
    pub textures: &'a mut Textures,
    pub warnings: &'a mut Vec<String>,
}

impl Buckets for ModelBuckets<'_> {
    fn id_of(&mut self, m: &Material) -> u32 {
        let (id, new) = self.table.intern(m);
        if new {
            self.writer
                .new_material(self.table.get(id), self.textures, self.warnings);
        }
        id
    }

    fn bucket(&mut self, id: u32) -> &mut Bucket {
        self.writer.bucket_for_pushes(id)
    }
}

/// An instanced asset's buckets, for encoding its mesh once: materials
/// get their model ids (and glTF materials) as for [`ModelBuckets`], and
/// buckets of their own laid out as the model's of the same material.
pub(crate) struct GroupBuckets<'a> {
    pub writer: &'a mut GltfWriter,
    pub table: &'a mut MaterialTable,
    pub textures: &'a mut Textures,
    pub warnings: &'a mut Vec<String>,
    pub buckets: Vec<(u32, Bucket)>,
}

impl Buckets for GroupBuckets<'_> {
    fn id_of(&mut self, m: &Material) -> u32 {
        let (id, new) = self.table.intern(m);
        if new {
            self.writer
                .new_material(self.table.get(id), self.textures, self.warnings);
        }
        if !self.buckets.iter().any(|(i, _)| *i == id) {
            let model = &self.writer.buckets[id as usize];
            let bucket = Bucket::with_layout(model.sets.clone(), model.tangents.is_some());
            self.buckets.push((id, bucket));
        }
        id
    }

    fn bucket(&mut self, id: u32) -> &mut Bucket {
        let k = self
            .buckets
            .iter()
            .position(|(i, _)| *i == id)
            .expect("id_of made it");
        &mut self.buckets[k].1
    }
}

/// The textures a material uses in glTF, with `find` telling which of its
/// texture paths are usable and their texture ids; `find` and the layers
/// glTF cannot hold put their warnings into `warnings`, in order.
pub(crate) fn texture_uses(
    material: &Material,
    mut find: impl FnMut(&Arc<str>, &mut Vec<String>) -> Option<u32>,
    warnings: &mut Vec<String>,
) -> Vec<MapUse> {
    let mut maps = Vec::new();
    for (slot, channel) in [
        (Slot::BaseColor, 0),
        (Slot::Normal, 5),
        (Slot::Emissive, 6),
        (Slot::Occlusion, 7),
    ] {
        if let Some(texture) = find(&material.maps[channel].path, warnings) {
            maps.push(MapUse {
                slot,
                texture,
                channel,
            });
        }
    }
    // glTF packs roughness (green) and metalness (blue) into one image.
    // The same image for both layers is exactly that; a roughness map
    // alone works too when the material is not metallic (the factor
    // zeroes the blue channel). Other combinations cannot be written.
    let (rough, metal) = (&material.maps[8].path, &material.maps[9].path);
    let packed = match (rough.is_empty(), metal.is_empty()) {
        (false, false) if rough == metal => Some(8),
        (false, true) if material.metallic == 0.0 => Some(8),
        (true, true) => None,
        _ => {
            warnings.push(format!(
                "roughness map '{rough}' and metallic map '{metal}' are not one image, as glTF requires; written without them"
            ));
            None
        }
    };
    if let Some(texture) = packed.and_then(|k| find(&material.maps[k].path, warnings)) {
        maps.push(MapUse {
            slot: Slot::MetallicRoughness,
            texture,
            channel: 8,
        });
    }
    maps
}

/// The UV sets and whether tangents are written for a material with these
/// textures: a textured material's vertices all need coordinates, set 0
/// first, then each other set a texture reads; a normal map needs
/// tangents.
pub(crate) fn bucket_layout(maps: &[MapUse]) -> (Vec<usize>, bool) {
    let mut sets = Vec::new();
    if !maps.is_empty() {
        sets.push(0);
        for m in maps {
            if !sets.contains(&m.channel) {
                sets.push(m.channel);
            }
        }
    }
    (sets, maps.iter().any(|m| m.slot == Slot::Normal))
}

/// The texture `path` names if it was found and glTF can use it (PNG or
/// JPEG), else `None` with a warning.
fn usable(textures: &mut Textures, warnings: &mut Vec<String>, path: &Arc<str>) -> Option<u32> {
    textures.resolve(path, warnings).filter(|&t| {
        let ok = textures.get(t).mime.is_some();
        if !ok {
            warnings.push(format!(
                "texture '{path}' is neither PNG nor JPEG, which glTF requires; written without it"
            ));
        }
        ok
    })
}

/// The tangent (direction of growing u) and bitangent sign of a face for
/// its normal map, whose coordinates are UV set 5 or else set 0. glTF's
/// bitangent is `cross(normal, tangent) * w` and points along its own v,
/// which runs opposite to CGA's.
pub(crate) fn face_tangent(f: &FaceData) -> (DVec3, f64) {
    let mesh = f.mesh;
    let Some(uvs) = mesh.uvs[5].as_deref().or(mesh.uvs[0].as_deref()) else {
        return (f.normal().any_orthonormal_vector(), 1.0);
    };
    for t in f.triangles {
        let c = t.map(|c| c as usize);
        let p = c.map(|c| f.positions[mesh.corners[c] as usize]);
        let q = c.map(|c| uvs.get(c).copied().unwrap_or_default());
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (q[1] - q[0], q[2] - q[0]);
        let det = d1.perp_dot(d2);
        if det.abs() < 1e-300 {
            continue;
        }
        let dpdu = (e1 * d2.y - e2 * d1.y) / det;
        let dpdv = (e2 * d1.x - e1 * d2.x) / det;
        if let Some(t) = dpdu.try_normalize() {
            let w = if f.normal().cross(t).dot(-dpdv) < 0.0 {
                -1.0
            } else {
                1.0
            };
            return (t, w);
        }
    }
    (f.normal().any_orthonormal_vector(), 1.0)
}

/// Where a CGA texture layer goes in a glTF material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    BaseColor,
    Normal,
    Emissive,
    Occlusion,
    MetallicRoughness,
}

/// A texture a material uses: its glTF slot, the texture, and the CGA
/// texture layer it comes from (its transform, and its UV set).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MapUse {
    slot: Slot,
    texture: u32,
    channel: usize,
}

/// The lots' property table (EXT_structural_metadata): for each lot its
/// index, name and attributes (as text), in views after everything laid
/// out so far (8-byte aligned, as the extension asks); sets the feature
/// count of every primitive's feature ids. Returns the table's bytes,
/// padding first, as they follow the rest of the binary data.
fn property_table(root: &mut json::Root, layout: &mut Layout, lots: &[LotNode]) -> Vec<u8> {
    use serde_json::{json, Map, Value};
    let mut tail = Vec::new();
    let view = |root: &mut json::Root, layout: &mut Layout, tail: &mut Vec<u8>, bytes: &[u8]| {
        while !layout.len.is_multiple_of(8) {
            layout.len += 4;
            tail.extend([0u8; 4]);
        }
        let v = layout.view(root, bytes.len() as u64, None);
        tail.extend(bytes);
        tail.resize(tail.len().next_multiple_of(4), 0);
        v.value()
    };
    let strings =
        |values: Vec<String>, root: &mut json::Root, layout: &mut Layout, tail: &mut Vec<u8>| {
            let mut text = Vec::new();
            let mut offsets = vec![0u32];
            for v in values {
                text.extend(v.as_bytes());
                offsets.push(text.len() as u32);
            }
            let values = view(root, layout, tail, &text);
            let offsets: Vec<u8> = offsets.iter().flat_map(|o| o.to_le_bytes()).collect();
            let offsets = view(root, layout, tail, &offsets);
            json!({"values": values, "stringOffsets": offsets, "stringOffsetType": "UINT32"})
        };
    let index: Vec<u8> = lots
        .iter()
        .enumerate()
        .flat_map(|(k, l)| {
            let i = l
                .extras
                .as_ref()
                .and_then(|e| e["lot"].as_u64())
                .unwrap_or(k as u64);
            (i as u32).to_le_bytes()
        })
        .collect();
    let mut class = Map::new();
    let mut table = Map::new();
    class.insert(
        "index".into(),
        json!({"type": "SCALAR", "componentType": "UINT32"}),
    );
    table.insert(
        "index".into(),
        json!({"values": view(root, layout, &mut tail, &index)}),
    );
    class.insert("name".into(), json!({"type": "STRING"}));
    let names = lots.iter().map(|l| l.name.clone()).collect();
    table.insert("name".into(), strings(names, root, layout, &mut tail));
    // Attributes by name, in order of first appearance, as text.
    for key in keys_of(lots, "attributes") {
        let id = property_id("attr_", &key);
        if class.contains_key(&id) {
            continue;
        }
        let values = lots
            .iter()
            .map(|l| text_of(l.extras.as_ref().map(|e| &e["attributes"][&key])))
            .collect();
        class.insert(id.clone(), json!({"type": "STRING", "name": key}));
        table.insert(id, strings(values, root, layout, &mut tail));
    }
    // Reports by key: numbers (the sum of a lot's values) as FLOAT64, 0
    // where a lot reported nothing; other values as text.
    for key in keys_of(lots, "reports") {
        let id = property_id("report_", &key);
        if class.contains_key(&id) {
            continue;
        }
        let values: Vec<Option<&Value>> = lots
            .iter()
            .map(|l| l.extras.as_ref().map(|e| &e["reports"][&key]))
            .collect();
        let numbers = values
            .iter()
            .all(|v| matches!(v, None | Some(Value::Null) | Some(Value::Number(_))));
        if numbers {
            let bytes: Vec<u8> = values
                .iter()
                .flat_map(|v| v.and_then(Value::as_f64).unwrap_or(0.0).to_le_bytes())
                .collect();
            class.insert(
                id.clone(),
                json!({"type": "SCALAR", "componentType": "FLOAT64", "name": key}),
            );
            table.insert(id, json!({"values": view(root, layout, &mut tail, &bytes)}));
        } else {
            let values = values.into_iter().map(text_of).collect();
            class.insert(id.clone(), json!({"type": "STRING", "name": key}));
            table.insert(id, strings(values, root, layout, &mut tail));
        }
    }
    root.extensions = Some(json::extensions::Root {
        others: [(
            "EXT_structural_metadata".to_string(),
            json!({
                "schema": {"id": "cga", "classes": {"lot": {"properties": class}}},
                "propertyTables": [{"class": "lot", "count": lots.len(), "properties": table}],
            }),
        )]
        .into_iter()
        .collect(),
    });
    for name in ["EXT_mesh_features", "EXT_structural_metadata"] {
        root.extensions_used.push(name.to_string());
    }
    for mesh in &mut root.meshes {
        for p in &mut mesh.primitives {
            if let Some(f) = p
                .extensions
                .as_mut()
                .and_then(|e| e.others.get_mut("EXT_mesh_features"))
            {
                f["featureIds"][0]["featureCount"] = json!(lots.len());
            }
        }
    }
    tail
}

/// The keys of the objects under `field` of the lots' extras, in order of
/// first appearance.
fn keys_of(lots: &[LotNode], field: &str) -> Vec<String> {
    let mut keys: Vec<String> = Vec::new();
    for l in lots {
        if let Some(serde_json::Value::Object(a)) = l.extras.as_ref().map(|e| &e[field]) {
            for k in a.keys() {
                if !keys.contains(k) {
                    keys.push(k.clone());
                }
            }
        }
    }
    keys
}

/// A property table id: `prefix` and the name with what is not ASCII
/// alphanumeric as `_` (the name itself goes into the property's `name`).
fn property_id(prefix: &str, name: &str) -> String {
    let name: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    format!("{prefix}{name}")
}

/// A value of the lots' extras as the text of a STRING property.
fn text_of(v: Option<&serde_json::Value>) -> String {
    use serde_json::Value;
    match v {
        Some(Value::String(s)) => s.clone(),
        Some(Value::Null) | None => String::new(),
        // Whole numbers without a decimal point, as CGA prints them.
        Some(Value::Number(n)) => match n.as_f64() {
            Some(x) if x.fract() == 0.0 && x.abs() < 1e15 => format!("{}", x as i64),
            _ => n.to_string(),
        },
        Some(v) => v.to_string(),
    }
}

/// The instances' data laid out: each group's primitives (with their
/// material ids), and per node its lot (if per lot), group and
/// `EXT_mesh_gpu_instancing` attributes.
#[derive(Default)]
struct LaidOutInstances {
    group_primitives: Vec<Vec<(u32, json::mesh::Primitive)>>,
    nodes: Vec<(Option<u32>, u32, serde_json::Map<String, serde_json::Value>)>,
}

/// The instance nodes of each lot (its node's children), by lot position.
type NodesByLot = HashMap<u32, Vec<json::Index<json::Node>>>;

/// The box around two boxes.
fn union_bounds(a: Option<[[f64; 3]; 2]>, b: Option<[[f64; 3]; 2]>) -> Option<[[f64; 3]; 2]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([
            std::array::from_fn(|k| a[0][k].min(b[0][k])),
            std::array::from_fn(|k| a[1][k].max(b[1][k])),
        ]),
        (a, None) => a,
        (None, b) => b,
    }
}

/// The box around primitives (min, max), if there are any.
fn bounds_of(primitives: &[&PrimitiveLayout]) -> Option<[[f64; 3]; 2]> {
    let first = primitives.first()?;
    let mut b = [first.min.map(f64::from), first.max.map(f64::from)];
    for p in &primitives[1..] {
        for (k, (lo, hi)) in p.min.iter().zip(&p.max).enumerate() {
            b[0][k] = b[0][k].min(f64::from(*lo));
            b[1][k] = b[1][k].max(f64::from(*hi));
        }
    }
    Some(b)
}

/// A node to write: its name, extras and primitives (with their material
/// ids).
type NodeGroup = (
    Option<u32>,
    String,
    Option<serde_json::Value>,
    Vec<(u32, json::mesh::Primitive)>,
);

/// The primitives of each lot (in the order written) with the lot's
/// position, name and extras (the caller leaves out lots with neither
/// geometry nor instances); primitives added before the first lot are a
/// node `model`.
#[allow(clippy::type_complexity)]
fn lot_groups(lots: Vec<LotNode>, primitives: Vec<(u32, json::mesh::Primitive)>) -> Vec<NodeGroup> {
    let mut groups = Vec::with_capacity(lots.len() + 1);
    let mut rest = primitives.into_iter();
    let first = lots.first().map_or(0, |l| l.first);
    let before: Vec<_> = rest.by_ref().take(first).collect();
    if !before.is_empty() {
        groups.push((None, "model".to_string(), None, before));
    }
    let ends: Vec<Option<usize>> = lots
        .iter()
        .skip(1)
        .map(|l| Some(l.first))
        .chain([None])
        .collect();
    // Lots without primitives too: their instances still need a node.
    for (k, (lot, end)) in lots.into_iter().zip(ends).enumerate() {
        let prims: Vec<_> = match end {
            Some(end) => rest.by_ref().take(end - lot.first).collect(),
            None => rest.by_ref().collect(),
        };
        groups.push((Some(k as u32), lot.name, lot.extras, prims));
    }
    groups
}

/// Where a GLB or a glTF's JSON is written: a file, or any stream that can
/// also be read back and sought (a GLB's binary data may have to be moved
/// up: see `finish_early_glb`), such as a `Cursor<Vec<u8>>`.
pub trait Output: Read + Write + Seek + Send + 'static {
    /// The output as `Any`, to take the concrete stream back after writing.
    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any>;
}

impl<T: Read + Write + Seek + Send + 'static> Output for T {
    fn into_any(self: Box<Self>) -> Box<dyn std::any::Any> {
        self
    }
}

pub(crate) struct GltfWriter {
    /// The output's path (also the name of an in-memory output in messages).
    path: PathBuf,
    out: BufWriter<Box<dyn Output>>,
    binary: bool,
    /// GLB: put images into the binary chunk (else refer to them by URI).
    embed_images: bool,
    /// `asset.extras` (the georeference of geographic lots).
    asset_extras: Option<serde_json::Value>,
    /// `.gltf`: file name of the `.bin` beside it.
    bin_name: String,
    buckets: Vec<Bucket>,
    /// The textures of each material id.
    maps: Vec<Vec<MapUse>>,
    /// Whether each material takes its opacity from the colour map's alpha
    /// (its opacity map is the colour map).
    alpha_maps: Vec<bool>,
    /// Whether some material uses `KHR_texture_transform`.
    uses_transform: bool,
    /// Vertex data held by all buckets, in bytes, and how much may be held
    /// before it is written out.
    held: usize,
    flush_bytes: usize,
    /// Primitives already written, in the order written, and their bytes.
    written: Vec<PrimitiveLayout>,
    written_bytes: u64,
    /// glTF: the `.bin` file, once data is written before the end.
    bin_out: Option<BufWriter<OutputFile>>,
    /// A node per lot ([`Granularity::Lot`](crate::Granularity)): each
    /// lot's data is written out when the next begins.
    per_lot: bool,
    lots: Vec<LotNode>,
    /// How many lots the model will have, if known (see
    /// `estimated_json_room`).
    lots_hint: Option<usize>,
    /// GLB: where the binary data written early starts.
    json_room: u64,
    /// Per-lot features: a feature id per vertex and a property table of
    /// the lots (EXT_mesh_features, EXT_structural_metadata).
    features: bool,
    /// The property table's bytes, written after everything else.
    tail: Vec<u8>,
    /// With features: the box of each lot's vertices so far.
    feature_bounds: Vec<Option<[[f64; 3]; 2]>>,
    /// The point positions are relative to: every node's translation.
    origin: Option<DVec3>,
    /// Where arrays written out go for the encoders' next batches (see
    /// `array_pool`; the pool of the batches appended); without one they
    /// are freed.
    pool: Option<Arc<ArrayPool>>,
    /// Assets placed as instances, and the boxes of their placements
    /// (relative to the origin), over all and per lot.
    pub(crate) instances: Instances,
    instance_bounds: Option<[[f64; 3]; 2]>,
    instance_lot_bounds: Vec<Option<[[f64; 3]; 2]>>,
}

/// A lot's node: its name and `extras`, and the first of its primitives in
/// the order written.
#[derive(Clone)]
struct LotNode {
    name: String,
    extras: Option<serde_json::Value>,
    first: usize,
}

impl GltfWriter {
    pub(crate) fn create(
        path: &Path,
        binary: bool,
        embed_images: bool,
        asset_extras: Option<serde_json::Value>,
        flush_mib: usize,
        per_lot: bool,
    ) -> Result<GltfWriter, ExportError> {
        // Readable too: a GLB's binary data may have to be moved up (see
        // `finish_early_glb`).
        let mut file =
            crate::output_file::create(path, true).map_err(|e| ExportError::io(path, e))?;
        if binary {
            // A GLB is written from its start to its end, then its head.
            file.around_cache();
        }
        Ok(GltfWriter::new(
            Box::new(file),
            path,
            binary,
            embed_images,
            asset_extras,
            flush_mib,
            per_lot,
        ))
    }

    /// A writer into `out`, named `path` (glTF writes its `.bin` beside
    /// that path).
    pub(crate) fn new(
        out: Box<dyn Output>,
        path: &Path,
        binary: bool,
        embed_images: bool,
        asset_extras: Option<serde_json::Value>,
        flush_mib: usize,
        per_lot: bool,
    ) -> GltfWriter {
        let stem = path
            .file_stem()
            .map_or("model".into(), |s| s.to_string_lossy());
        GltfWriter {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 16, out),
            binary,
            embed_images: binary && embed_images,
            asset_extras,
            bin_name: format!("{stem}.bin"),
            buckets: Vec::new(),
            maps: Vec::new(),
            alpha_maps: Vec::new(),
            uses_transform: false,
            held: 0,
            flush_bytes: flush_mib.saturating_mul(1 << 20),
            written: Vec::new(),
            written_bytes: 0,
            bin_out: None,
            per_lot,
            lots: Vec::new(),
            lots_hint: None,
            json_room: GLB_JSON_ROOM,
            features: false,
            pool: None,
            tail: Vec::new(),
            feature_bounds: Vec::new(),
            origin: None,
            instances: Instances::default(),
            instance_bounds: None,
            instance_lot_bounds: Vec::new(),
        }
    }

    /// Places `group` as `p` says (in the model's frame), in the lot begun
    /// last.
    pub(crate) fn place_instance(&mut self, group: u32, p: &Pending) {
        let lot = if self.per_lot || self.features {
            self.lots.len().checked_sub(1).map(|l| l as u32)
        } else {
            None
        };
        let shifted = match self.origin {
            Some(o) => DAffine3::from_translation(-o) * p.transform,
            None => p.transform,
        };
        let trs = Trs {
            translation: shifted.translation,
            ..p.trs
        };
        let Some(b) = self
            .instances
            .place(group, lot, self.per_lot, &trs, &shifted)
        else {
            return;
        };
        self.instance_bounds = union_bounds(self.instance_bounds, Some(b));
        if let Some(lot) = lot {
            let lot = lot as usize;
            if self.instance_lot_bounds.len() <= lot {
                self.instance_lot_bounds.resize(lot + 1, None);
            }
            self.instance_lot_bounds[lot] = union_bounds(self.instance_lot_bounds[lot], Some(b));
        }
    }

    /// Positions come relative to `origin` (see
    /// [`ExportOptions::origin`](crate::ExportOptions::origin)): nodes are
    /// translated by it, and the bounds in the stats are moved back by it.
    pub(crate) fn set_origin(&mut self, origin: Option<DVec3>) {
        self.origin = origin;
    }

    /// Hands the arrays written out from now on to `pool` (that of the
    /// encoders whose batches come) instead of freeing them.
    pub(crate) fn return_arrays_to(&mut self, pool: &Arc<ArrayPool>) {
        if !self.pool.as_ref().is_some_and(|p| Arc::ptr_eq(p, pool)) {
            self.pool = Some(pool.clone());
        }
    }

    /// Gives each lot's vertices its feature id and writes a property
    /// table of the lots (for 3D Tiles viewers that pick buildings).
    pub(crate) fn with_features(&mut self) {
        self.features = true;
    }

    /// Says how many lots the model will have.
    pub(crate) fn expect_lots(&mut self, lots: usize) {
        self.lots_hint = Some(lots);
    }

    /// Sets `key` of the last lot's `extras` (its node's, and its row of
    /// the property table).
    pub(crate) fn annotate_lot(&mut self, key: &str, value: serde_json::Value) {
        if let Some(lot) = self.lots.last_mut() {
            let extras = lot.extras.get_or_insert_with(|| serde_json::json!({}));
            if let Some(map) = extras.as_object_mut() {
                map.insert(key.to_string(), value);
            }
        }
    }

    /// Starts a lot's node (see [`LotNode`]): what is held of the lot
    /// before is written out first, as its primitives.
    pub(crate) fn begin_lot(
        &mut self,
        name: &str,
        extras: Option<serde_json::Value>,
    ) -> Result<(), ExportError> {
        if !self.per_lot && !self.features {
            return Ok(());
        }
        // What was added so far belongs to the lot before.
        self.sync_features();
        if self.per_lot && self.buckets.iter().any(Bucket::has_triangles) {
            self.flush()?;
        }
        self.lots.push(LotNode {
            name: name.to_string(),
            extras,
            first: self.written.len(),
        });
        Ok(())
    }

    /// File names this writer creates next to the output.
    pub(crate) fn file_names(&self) -> Vec<String> {
        let own = self
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned());
        let mut names: Vec<String> = own.into_iter().collect();
        if !self.binary {
            names.push(self.bin_name.clone());
        }
        names
    }

    pub(crate) fn new_material(
        &mut self,
        material: &Material,
        textures: &mut Textures,
        warnings: &mut Vec<String>,
    ) {
        let maps = texture_uses(material, |path, w| usable(textures, w, path), warnings);
        // glTF has no opacity map of its own: opacity is the base colour
        // texture's alpha. An opacity map that is the colour map (what
        // `texture()` sets for images with alpha) is exactly that.
        let colormap = &material.maps[0].path;
        let opacity_map = &material.maps[4].path;
        let has_base = maps.iter().any(|m| m.slot == Slot::BaseColor);
        let alpha = has_base && !opacity_map.is_empty() && opacity_map == colormap;
        if !opacity_map.is_empty() && !alpha {
            warnings.push(format!(
                "opacity map '{opacity_map}' is not the colour map; glTF takes opacity from the colour map's alpha: written without it"
            ));
        }
        let (sets, tangents) = bucket_layout(&maps);
        if maps
            .iter()
            .any(|m| texture_transform(&material.maps[m.channel]).is_some())
        {
            self.uses_transform = true;
        }
        self.buckets.push(Bucket::with_layout(sets, tangents));
        self.maps.push(maps);
        self.alpha_maps.push(alpha);
    }

    /// Appends encoded vertex data of material `id` (see `encode`), first
    /// writing out the data held if it is more than allowed.
    pub(crate) fn append(&mut self, id: u32, data: &mut Bucket) -> Result<(), ExportError> {
        self.flush_if_full()?;
        self.held += data.bytes();
        self.buckets[id as usize].append(data)
    }

    /// The bucket of material `id`, ready for vertices pushed one by one
    /// (encoding on the writing thread): what was appended whole is copied
    /// into its own arrays first.
    pub(crate) fn bucket_for_pushes(&mut self, id: u32) -> &mut Bucket {
        let bucket = &mut self.buckets[id as usize];
        bucket.consolidate();
        bucket
    }

    /// Writes out the data held if it is more than allowed: between input
    /// meshes, or between the materials of a batch, never inside a mesh
    /// (whose vertices share one numbering).
    pub(crate) fn flush_if_full(&mut self) -> Result<(), ExportError> {
        if self.held > self.flush_bytes {
            self.flush()?;
        }
        Ok(())
    }

    /// Counts `bytes` of vertex data encoded into the buckets directly.
    pub(crate) fn hold(&mut self, bytes: usize) {
        self.held += bytes;
    }

    /// The room to leave for a GLB's header and JSON when data is first
    /// written early. With a node per lot and the number of lots known,
    /// the JSON grows with the lots: room for as many lots as the first,
    /// with a quarter more, so that the binary data seldom has to be moved
    /// up at the end (spaces pad what is left).
    fn estimated_json_room(&self) -> u64 {
        // Compact JSON of a primitive with its accessors and buffer views,
        // and of a lot's node and mesh, in bytes (measured on the example
        // city: about 2,500 bytes for a lot of four primitives).
        const PER_PRIMITIVE: u64 = 700;
        const PER_LOT: u64 = 200;
        let (Some(lots), true) = (self.lots_hint, self.per_lot) else {
            return GLB_JSON_ROOM;
        };
        let primitives = self.buckets.iter().filter(|b| b.has_triangles()).count() as u64;
        let extras = self
            .lots
            .last()
            .and_then(|l| l.extras.as_ref())
            .map_or(0, |e| e.to_string().len() as u64);
        // Feature ids add an accessor and a view per primitive, and the
        // property table a few views and the lots' names.
        let (per_primitive, per_lot) = match self.features {
            true => (PER_PRIMITIVE + 250, PER_LOT + 64),
            false => (PER_PRIMITIVE, PER_LOT),
        };
        // Instances: per lot a node per asset seen so far, with its
        // placements' accessors and views, and each asset's mesh once.
        const PER_INSTANCE_NODE: u64 = 1000;
        let groups = self.instances.groups.len() as u64;
        let per_lot = primitives * per_primitive + per_lot + extras + groups * PER_INSTANCE_NODE;
        let room = (lots as u64)
            .saturating_mul(per_lot)
            .saturating_add(groups * 2 * PER_PRIMITIVE)
            / 4
            * 5;
        // Small models (3D Tiles' tiles) get small room: should the JSON
        // not fit, moving a small file's data up costs little.
        room.clamp(MIN_ESTIMATED_ROOM, 256 << 20) / 4 * 4
    }

    /// Gives the vertices added since the last call the current lot's
    /// feature id (its position in the model) and takes them into the
    /// lot's box, when the model has per-lot features.
    fn sync_features(&mut self) {
        if !self.features {
            return;
        }
        let lot = self.lots.len().saturating_sub(1);
        let id = lot as f32;
        let mut bounds: Option<[[f64; 3]; 2]> = self.feature_bounds.get(lot).copied().flatten();
        for b in &mut self.buckets {
            b.each_segment_mut(|s| {
                let from = s.features.len();
                for p in &s.positions[from..] {
                    let p = p.map(f64::from);
                    bounds = Some(match bounds {
                        Some([lo, hi]) => [
                            std::array::from_fn(|k| lo[k].min(p[k])),
                            std::array::from_fn(|k| hi[k].max(p[k])),
                        ],
                        None => [p, p],
                    });
                }
                s.features.resize(s.positions.len(), id);
            });
        }
        if self.feature_bounds.len() <= lot {
            self.feature_bounds.resize(lot + 1, None);
        }
        self.feature_bounds[lot] = bounds;
    }

    /// Writes every bucket's data as a primitive and empties the buckets.
    fn flush(&mut self) -> Result<(), ExportError> {
        self.sync_features();
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        let out: &mut dyn Write = if self.binary {
            if self.written_bytes == 0 {
                self.json_room = self.estimated_json_room();
                self.out.seek(SeekFrom::Start(self.json_room)).map_err(io)?;
            }
            &mut self.out
        } else {
            if self.bin_out.is_none() {
                let bin_path = self.path.with_file_name(&self.bin_name);
                let file = crate::output_file::create(&bin_path, false)
                    .map_err(|e| ExportError::io(&bin_path, e))?;
                self.bin_out = Some(BufWriter::with_capacity(1 << 16, file));
            }
            self.bin_out.as_mut().expect("created above")
        };
        for (id, b) in self.buckets.iter_mut().enumerate() {
            if !b.has_triangles() {
                continue;
            }
            b.unmerged_coords();
            b.write_arrays(out).map_err(io)?;
            let p = b.primitive(id as u32);
            let features: usize = b.segments().map(|s| s.features.len()).sum();
            self.written_bytes += b.bytes() as u64 + features as u64 * 4;
            self.written.push(p);
            if let Some(pool) = &self.pool {
                b.sealed.drain(..).for_each(|s| pool.give_arrays(s));
            }
            b.clear();
        }
        self.held = 0;
        Ok(())
    }

    /// Writes what is pending and gives the output back.
    pub(crate) fn finish(
        mut self,
        table: &MaterialTable,
        textures: &Textures,
        stats: &mut ExportStats,
    ) -> Result<Box<dyn Output>, ExportError> {
        let mut root = json::Root {
            asset: json::Asset {
                generator: Some("CGA engine (cga-export)".into()),
                extras: self
                    .asset_extras
                    .as_ref()
                    .and_then(|v| serde_json::value::to_raw_value(v).ok()),
                ..Default::default()
            },
            ..Default::default()
        };
        let mut layout = Layout::default();
        // glTF texture index by texture id, in order of first use.
        let mut gltf_textures: HashMap<u32, json::Index<json::Texture>> = HashMap::new();
        let mut images: Vec<u32> = Vec::new();
        let mut nodes = Vec::new();

        // Once anything was written early, every primitive of a material
        // carries each of its UV sets (the material names the set to read).
        // Instances' primitives carry every UV set of their materials too.
        let early = !self.written.is_empty() || !self.instances.is_empty();
        for b in &mut self.buckets {
            if early {
                b.unmerged_coords();
            } else {
                b.merge_equal_coords();
            }
        }
        self.sync_features();
        let held: Vec<PrimitiveLayout> = self
            .buckets
            .iter()
            .enumerate()
            .filter(|(_, b)| b.has_triangles())
            .map(|(id, b)| b.primitive(id as u32))
            .collect();
        // Accessors in the order of the binary data, with their material.
        let mut primitives: Vec<(u32, json::mesh::Primitive)> =
            Vec::with_capacity(self.written.len() + held.len());
        let mut used = vec![false; self.buckets.len()];
        // A large GLB's primitives have their accessors and views written
        // out as JSON text (see `json_spool`); a smaller model's are
        // reserved at their final size in the document.
        let bulk = self.written.len() + held.len();
        match (self.binary && json_spool::spools(bulk))
            .then(Spool::create)
            .flatten()
        {
            Some(spool) => layout.start_spool(spool),
            None => {
                let accessors: usize = self
                    .written
                    .iter()
                    .chain(&held)
                    .map(PrimitiveLayout::accessor_count)
                    .sum();
                root.accessors.reserve_exact(accessors);
                root.buffer_views.reserve_exact(accessors);
            }
        }
        for p in self.written.iter().chain(&held) {
            let prim = primitive_accessors(&mut root, &mut layout, p);
            primitives.push((p.material, prim));
            used[p.material as usize] = true;
            stats.vertices += p.vertices;
        }
        let spool = layout.end_spool(&mut root);
        let laid_out = self.lay_out_instances(&mut root, &mut layout, &mut used, stats);
        let layouts: Vec<&PrimitiveLayout> = self.written.iter().chain(&held).collect();
        stats.bounds = bounds_of(&layouts);
        if self.features {
            stats.lot_bounds = self.feature_bounds.clone();
            stats.lot_bounds.resize(self.lots.len(), None);
        } else if self.per_lot {
            let starts: Vec<usize> = self.lots.iter().map(|l| l.first).collect();
            for (k, &start) in starts.iter().enumerate() {
                let end = starts.get(k + 1).copied().unwrap_or(layouts.len());
                stats.lot_bounds.push(bounds_of(&layouts[start..end]));
            }
        }
        stats.bounds = union_bounds(stats.bounds, self.instance_bounds);
        if self.per_lot || self.features {
            stats.lot_bounds.resize(self.lots.len(), None);
            for (b, i) in stats.lot_bounds.iter_mut().zip(&self.instance_lot_bounds) {
                *b = union_bounds(*b, *i);
            }
        }
        // The stats' boxes are in the model's frame.
        if let Some(o) = self.origin {
            let o = o.to_array();
            let moved = |b: &mut [[f64; 3]; 2]| {
                for corner in b.iter_mut() {
                    for (c, o) in corner.iter_mut().zip(o) {
                        *c += o;
                    }
                }
            };
            stats.bounds.iter_mut().for_each(moved);
            stats.lot_bounds.iter_mut().flatten().for_each(moved);
        }
        // The glTF material of each material id that has primitives.
        let mut gltf_materials: Vec<Option<json::Index<json::Material>>> =
            vec![None; self.buckets.len()];
        for id in (0..self.buckets.len()).filter(|&id| used[id]) {
            let bucket = &self.buckets[id];
            let id = id as u32;
            let name = table.name(id).to_string();
            let material = table.get(id);
            let mut infos: Vec<(Slot, json::texture::Info)> = Vec::new();
            for m in &self.maps[id as usize] {
                let index = *gltf_textures.entry(m.texture).or_insert_with(|| {
                    images.push(m.texture);
                    add_texture(&mut root, textures, m.texture, self.embed_images)
                });
                let set = if m.slot == Slot::BaseColor {
                    0
                } else {
                    m.channel
                };
                let k = bucket.sets.iter().position(|&s| s == set).unwrap_or(0);
                infos.push((
                    m.slot,
                    json::texture::Info {
                        index,
                        tex_coord: bucket.tex_coords.get(k).copied().unwrap_or(0),
                        extensions: texture_transform(&material.maps[m.channel]).map(|t| {
                            let mut others = serde_json::Map::new();
                            others.insert("KHR_texture_transform".into(), t);
                            json::extensions::texture::Info { others }
                        }),
                        extras: Default::default(),
                    },
                ));
            }
            gltf_materials[id as usize] = Some(root.push(gltf_material(
                material,
                name,
                infos,
                self.alpha_maps[id as usize],
            )));
            stats.materials += 1;
        }
        // Instances: a mesh per group, a node per lot (or per model) and
        // group; a lot's are children of its node.
        let (mut lot_children, root_instances) =
            self.instance_nodes(&mut root, laid_out, &gltf_materials);
        // Meshes and nodes: one per lot, or one per material.
        let groups: Vec<NodeGroup> = if self.per_lot && !self.lots.is_empty() {
            // The property table of per-lot features reads the lots below.
            let lots = match self.features {
                true => self.lots.clone(),
                false => std::mem::take(&mut self.lots),
            };
            lot_groups(lots, primitives)
        } else {
            let mut by_material: Vec<Vec<(u32, json::mesh::Primitive)>> = Vec::new();
            by_material.resize_with(self.buckets.len(), Vec::new);
            for (id, prim) in primitives {
                by_material[id as usize].push((id, prim));
            }
            by_material
                .into_iter()
                .enumerate()
                .filter(|(_, prims)| !prims.is_empty())
                .map(|(id, prims)| (None, table.name(id as u32).to_string(), None, prims))
                .collect()
        };
        for (lot, name, extras, prims) in groups {
            let children = lot.and_then(|l| lot_children.remove(&l));
            if prims.is_empty() && children.is_none() {
                continue;
            }
            let primitives: Vec<_> = prims
                .into_iter()
                .map(|(id, p)| json::mesh::Primitive {
                    material: gltf_materials[id as usize],
                    ..p
                })
                .collect();
            let mesh = (!primitives.is_empty()).then(|| {
                root.push(json::Mesh {
                    extensions: None,
                    extras: Default::default(),
                    name: Some(name.clone()),
                    primitives,
                    weights: None,
                })
            });
            nodes.push(root.push(json::Node {
                mesh,
                children,
                name: Some(name),
                extras: extras.and_then(|v| serde_json::value::to_raw_value(&v).ok()),
                // glTF's JSON holds the translation as f32; numbers in
                // JSON text are doubles, and readers that keep them so
                // (CesiumJS, three.js) place the model to the millimetre.
                translation: self.origin.map(|o| o.as_vec3().to_array()),
                ..Default::default()
            }));
        }
        nodes.extend(root_instances);
        stats.textures = images.len() as u64;
        if self.embed_images {
            // Images go after all geometry, in the order `write_bin` writes them.
            for (i, &t) in images.iter().enumerate() {
                let view = layout.view(&mut root, textures.get(t).len, None);
                root.images[i].buffer_view = Some(view);
            }
        }

        if self.uses_transform && !images.is_empty() {
            root.extensions_used
                .push("KHR_texture_transform".to_string());
        }
        if !nodes.is_empty() {
            let scene = root.push(json::Scene {
                extensions: None,
                extras: Default::default(),
                name: None,
                nodes,
            });
            root.scene = Some(scene);
        }
        if self.features && !self.lots.is_empty() {
            self.tail = property_table(&mut root, &mut layout, &self.lots);
        }
        let bin_len = layout.len;
        if bin_len > 0 {
            root.push(json::Buffer {
                byte_length: USize64(bin_len),
                name: None,
                uri: (!self.binary).then(|| uri_encode(&self.bin_name)),
                extensions: None,
                extras: Default::default(),
            });
        }

        let embedded: Vec<u32> = if self.embed_images {
            images.clone()
        } else {
            Vec::new()
        };
        if self.binary {
            self.write_glb(&root, spool, bin_len, &embedded, textures)?;
        } else {
            let json = root
                .to_vec_pretty()
                .map_err(|e| ExportError::io(&self.path, e.into()))?;
            self.out
                .write_all(&json)
                .and_then(|_| self.out.flush())
                .map_err(|e| ExportError::io(&self.path, e))?;
            if bin_len > 0 {
                let bin_path = self.path.with_file_name(&self.bin_name);
                // Appended to what was written early, if anything.
                let mut w = match self.bin_out.take() {
                    Some(w) => w,
                    None => {
                        let file = crate::output_file::create(&bin_path, false)
                            .map_err(|e| ExportError::io(&bin_path, e))?;
                        BufWriter::with_capacity(1 << 16, file)
                    }
                };
                let held = Held {
                    buckets: &self.buckets,
                    middle: &self.instances,
                    tail: &self.tail,
                };
                write_bin(&mut w, &held, &[], textures, &bin_path)?;
                w.flush().map_err(|e| ExportError::io(&bin_path, e))?;
            }
        }
        if !self.embed_images {
            textures.copy_all(images.iter().copied())?;
        }
        let path = self.path;
        self.out
            .into_inner()
            .map_err(|e| ExportError::io(&path, e.into_error()))
    }

    /// Lays out the instances' data after the held primitives (written
    /// after them by [`write_instances`]): each group's primitives, then per
    /// node the placements' translations, rotations, scales (and feature
    /// ids). Marks the groups' materials used.
    fn lay_out_instances(
        &mut self,
        root: &mut json::Root,
        layout: &mut Layout,
        used: &mut [bool],
        stats: &mut ExportStats,
    ) -> LaidOutInstances {
        use json::accessor::ComponentType;
        let mut out = LaidOutInstances::default();
        if self.instances.is_empty() {
            return out;
        }
        for group in &mut self.instances.groups {
            let mut prims = Vec::new();
            for (id, b) in group.buckets.iter_mut().filter(|(_, b)| b.has_triangles()) {
                b.unmerged_coords();
                let p = b.primitive(*id);
                prims.push((*id, primitive_accessors(root, layout, &p)));
                used[*id as usize] = true;
                stats.vertices += p.vertices;
            }
            out.group_primitives.push(prims);
        }
        let nodes = &self.instances.nodes;
        let accessors = nodes.len() * placement_attributes(self.features).len();
        root.accessors.reserve(accessors);
        root.buffer_views.reserve(accessors);
        for ((lot, group), placements) in nodes {
            let mut attributes = serde_json::Map::new();
            for &(name, width, type_, _) in placement_attributes(self.features) {
                let index = layout.accessor(
                    root,
                    placements.len() * width,
                    placements.len() as u64,
                    type_,
                    ComponentType::F32,
                    None,
                    None,
                );
                attributes.insert(name.into(), index.value().into());
            }
            out.nodes.push((*lot, *group, attributes));
        }
        self.instances.with_features = self.features;
        out
    }

    /// The instances' meshes and nodes: the nodes of each lot (its
    /// children) by lot position, and those of the whole model.
    fn instance_nodes(
        &self,
        root: &mut json::Root,
        laid_out: LaidOutInstances,
        gltf_materials: &[Option<json::Index<json::Material>>],
    ) -> (NodesByLot, Vec<json::Index<json::Node>>) {
        let mut by_lot = NodesByLot::new();
        let mut top = Vec::new();
        if laid_out.nodes.is_empty() {
            return (by_lot, top);
        }
        let meshes: Vec<Option<json::Index<json::Mesh>>> = laid_out
            .group_primitives
            .into_iter()
            .enumerate()
            .map(|(g, prims)| {
                (!prims.is_empty()).then(|| {
                    root.push(json::Mesh {
                        extensions: None,
                        extras: Default::default(),
                        name: Some(format!("asset {g}")),
                        primitives: prims
                            .into_iter()
                            .map(|(id, p)| json::mesh::Primitive {
                                material: gltf_materials[id as usize],
                                ..p
                            })
                            .collect(),
                        weights: None,
                    })
                })
            })
            .collect();
        for (lot, group, attributes) in laid_out.nodes {
            let Some(mesh) = meshes[group as usize] else {
                continue;
            };
            let mut others = serde_json::Map::new();
            others.insert(
                "EXT_mesh_gpu_instancing".into(),
                serde_json::json!({ "attributes": attributes }),
            );
            if self.features {
                others.insert(
                    "EXT_instance_features".into(),
                    serde_json::json!({"featureIds": [{
                        "featureCount": self.lots.len(), "attribute": 0, "propertyTable": 0,
                    }]}),
                );
            }
            let node = root.push(json::Node {
                mesh: Some(mesh),
                name: Some(format!("asset {group}")),
                extensions: Some(json::extensions::scene::Node { others }),
                // A lot's node carries the origin for its children.
                translation: match lot {
                    Some(_) => None,
                    None => self.origin.map(|o| o.as_vec3().to_array()),
                },
                ..Default::default()
            });
            match lot {
                Some(l) => by_lot.entry(l).or_default().push(node),
                None => top.push(node),
            }
        }
        // Without the extension a viewer would draw one placement of each.
        let name = "EXT_mesh_gpu_instancing";
        root.extensions_used.push(name.into());
        root.extensions_required.push(name.into());
        if self.features {
            root.extensions_used.push("EXT_instance_features".into());
        }
        (by_lot, top)
    }

    fn write_glb(
        &mut self,
        root: &json::Root,
        spool: Option<Spool>,
        bin_len: u64,
        images: &[u32],
        textures: &Textures,
    ) -> Result<(), ExportError> {
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        // A GLB written early has room for its JSON estimated.
        let early = self.written_bytes > 0;
        let room = if early { self.json_room as usize } else { 0 };
        let mut json = GlbJson::new(root, spool, room).map_err(io)?;
        if early {
            return self.finish_early_glb(&mut json, bin_len, images, textures);
        }
        // Chunks are 4-byte aligned; JSON pads with spaces.
        let chunk = json.len().next_multiple_of(4);
        let bin_chunk = if bin_len > 0 { 8 + bin_len } else { 0 };
        let total = glb_length(12 + 8 + chunk + bin_chunk)?;
        let out = &mut self.out;
        write_glb_head(out, total, &mut json, chunk, bin_len).map_err(io)?;
        if bin_len > 0 {
            let held = Held {
                buckets: &self.buckets,
                middle: &self.instances,
                tail: &self.tail,
            };
            write_bin(out, &held, images, textures, &path)?;
        }
        out.flush().map_err(io)
    }

    /// GLB whose binary data was partly written early, from `json_room` on:
    /// the rest of it follows, then the header and the JSON (padded with
    /// spaces to the room, or, if it does not fit, with the binary data
    /// moved up to make room) go before it.
    fn finish_early_glb(
        &mut self,
        json: &mut GlbJson,
        bin_len: u64,
        images: &[u32],
        textures: &Textures,
    ) -> Result<(), ExportError> {
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        let held = Held {
            buckets: &self.buckets,
            middle: &self.instances,
            tail: &self.tail,
        };
        write_bin(&mut self.out, &held, images, textures, &path)?;
        self.out.flush().map_err(io)?;
        // Header (12), JSON chunk header (8), JSON, BIN chunk header (8).
        let head = 12 + 8 + json.len().next_multiple_of(4) + 8;
        let room = self.json_room;
        let start = if head <= room {
            room
        } else {
            let file = self.out.get_mut();
            move_up(&mut **file, room, bin_len, head - room).map_err(io)?;
            head
        };
        let total = glb_length(start + bin_len)?;
        self.out.seek(SeekFrom::Start(0)).map_err(io)?;
        write_glb_head(&mut self.out, total, json, start - 28, bin_len).map_err(io)?;
        self.out.flush().map_err(io)
    }
}

/// A GLB's total length, which the header holds as `u32`.
fn glb_length(total: u64) -> Result<u32, ExportError> {
    u32::try_from(total)
        .map_err(|_| ExportError::TooLarge(format!("GLB of {total} bytes exceeds 4 GiB")))
}

/// The GLB header, the JSON chunk (`json`, padded with spaces to `chunk`
/// bytes) and the BIN chunk's header (if there is binary data).
fn write_glb_head(
    out: &mut impl Write,
    total: u32,
    json: &mut GlbJson,
    chunk: u64,
    bin_len: u64,
) -> std::io::Result<()> {
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(chunk as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    json.write_to(out)?;
    let pad = chunk - json.len();
    std::io::copy(&mut std::io::repeat(b' ').take(pad), out)?;
    if bin_len > 0 {
        out.write_all(&(bin_len as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
    }
    Ok(())
}

/// Moves the `len` bytes of `file` at `start` up by `by` bytes, from the
/// end backwards so that nothing is overwritten before it is moved.
fn move_up(file: &mut dyn Output, start: u64, len: u64, by: u64) -> std::io::Result<()> {
    let mut buf = vec![0u8; 1 << 20];
    let mut end = start + len;
    while end > start {
        let n = (end - start).min(buf.len() as u64);
        let from = end - n;
        file.seek(SeekFrom::Start(from))?;
        file.read_exact(&mut buf[..n as usize])?;
        file.seek(SeekFrom::Start(from + by))?;
        file.write_all(&buf[..n as usize])?;
        end = from;
    }
    Ok(())
}

/// Assigns buffer views and accessors their place in the binary buffer.
#[derive(Default)]
struct Layout {
    /// Bytes laid out so far (always a multiple of 4).
    len: u64,
    /// While laying out a large GLB's primitives: where their accessors and
    /// views go instead of the document (see `json_spool`).
    spool: Option<Spool>,
    /// Accessors and views spooled before the document's own, less the
    /// marker standing for them: added to the document's indices.
    accessor_base: usize,
    view_base: usize,
}

impl Layout {
    /// Accessors and views laid out from now on go to `spool`, until
    /// [`end_spool`](Layout::end_spool). Only for a document with none yet.
    fn start_spool(&mut self, spool: Spool) {
        self.spool = Some(spool);
    }

    /// Accessors and views go to the document again, after a marker for
    /// the spooled ones (if any); returns the spool.
    fn end_spool(&mut self, root: &mut json::Root) -> Option<Spool> {
        let spool = self.spool.take()?;
        debug_assert!(root.accessors.is_empty() && root.buffer_views.is_empty());
        if spool.accessors.count() > 0 {
            root.accessors.push(json_spool::accessor_marker());
            self.accessor_base = spool.accessors.count() - 1;
        }
        if spool.views.count() > 0 {
            root.buffer_views.push(json_spool::view_marker());
            self.view_base = spool.views.count() - 1;
        }
        Some(spool)
    }

    fn view(
        &mut self,
        root: &mut json::Root,
        bytes: u64,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let view = json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes),
            byte_offset: Some(USize64(self.len)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        };
        self.len += bytes.next_multiple_of(4);
        let spool = self.spool.as_mut().map(|s| &mut s.views);
        add_item(spool, &mut root.buffer_views, self.view_base, view)
    }

    /// A view holding `components` 4-byte values and an accessor on it
    /// (with the bounds `min_max`, if given).
    #[allow(clippy::too_many_arguments)]
    fn accessor(
        &mut self,
        root: &mut json::Root,
        components: usize,
        count: u64,
        type_: json::accessor::Type,
        component_type: json::accessor::ComponentType,
        target: Option<json::buffer::Target>,
        min_max: Option<([f32; 3], [f32; 3])>,
    ) -> json::Index<json::Accessor> {
        let view = self.view(root, components as u64 * 4, target);
        let accessor = json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count),
            component_type: Valid(json::accessor::GenericComponentType(component_type)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min: min_max.map(|m| m.0.to_vec().into()),
            max: min_max.map(|m| m.1.to_vec().into()),
            name: None,
            normalized: false,
            sparse: None,
        };
        let spool = self.spool.as_mut().map(|s| &mut s.accessors);
        add_item(spool, &mut root.accessors, self.accessor_base, accessor)
    }
}

/// Adds `item` to its spooled part while a spool is open, else to the
/// document's `list`, which follows `base` spooled items: its index.
fn add_item<T: serde::Serialize>(
    spooled: Option<&mut json_spool::Part>,
    list: &mut Vec<T>,
    base: usize,
    item: T,
) -> json::Index<T> {
    let index = match spooled {
        Some(part) => part.push(&item),
        None => {
            list.push(item);
            base + list.len() - 1
        }
    };
    json::Index::new(index as u32)
}

/// The accessors (and buffer views) of a primitive's arrays, laid out next
/// in the binary buffer, and the primitive reading them (its material is
/// set by the caller).
fn primitive_accessors(
    root: &mut json::Root,
    layout: &mut Layout,
    p: &PrimitiveLayout,
) -> json::mesh::Primitive {
    use json::accessor::{ComponentType, Type};
    let vertex_data = Some(json::buffer::Target::ArrayBuffer);
    let mut attributes = std::collections::BTreeMap::new();
    let positions = layout.accessor(
        root,
        p.positions / 4,
        p.vertices,
        Type::Vec3,
        ComponentType::F32,
        vertex_data,
        Some((p.min, p.max)),
    );
    attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
    let normals = layout.accessor(
        root,
        p.normals / 4,
        p.vertices,
        Type::Vec3,
        ComponentType::F32,
        vertex_data,
        None,
    );
    attributes.insert(Valid(json::mesh::Semantic::Normals), normals);
    for (n, &len) in p.coords.iter().enumerate() {
        let tex = layout.accessor(
            root,
            len / 4,
            p.vertices,
            Type::Vec2,
            ComponentType::F32,
            vertex_data,
            None,
        );
        attributes.insert(Valid(json::mesh::Semantic::TexCoords(n as u32)), tex);
    }
    if let Some(len) = p.tangents {
        let acc = layout.accessor(
            root,
            len / 4,
            p.vertices,
            Type::Vec4,
            ComponentType::F32,
            vertex_data,
            None,
        );
        attributes.insert(Valid(json::mesh::Semantic::Tangents), acc);
    }
    let indices = layout.accessor(
        root,
        p.indices / 4,
        p.indices as u64 / 4,
        Type::Scalar,
        ComponentType::U32,
        Some(json::buffer::Target::ElementArrayBuffer),
        None,
    );
    let extensions = p.features.then(|| {
        let acc = layout.accessor(
            root,
            p.vertices as usize,
            p.vertices,
            Type::Scalar,
            ComponentType::F32,
            vertex_data,
            None,
        );
        attributes.insert(Valid(json::mesh::Semantic::Extras("FEATURE_ID_0".into())), acc);
        let mut others = serde_json::Map::new();
        // The feature count is set when every lot is known (see `finish`).
        others.insert(
            "EXT_mesh_features".into(),
            serde_json::json!({"featureIds": [{"featureCount": 0, "attribute": 0, "propertyTable": 0}]}),
        );
        json::extensions::mesh::Primitive { others }
    });
    json::mesh::Primitive {
        attributes,
        extensions,
        extras: Default::default(),
        indices: Some(indices),
        material: None,
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    }
}

/// Adds the image, sampler (shared) and texture for texture `t`. An
/// embedded image gets its buffer view later, once all geometry is laid out.
fn add_texture(
    root: &mut json::Root,
    textures: &Textures,
    t: u32,
    embed: bool,
) -> json::Index<json::Texture> {
    let tex = textures.get(t);
    let name = Some(tex.out_name.clone());
    let image = if embed {
        json::Image {
            buffer_view: None,
            mime_type: tex.mime.map(|m| json::image::MimeType(m.to_string())),
            name,
            uri: None,
            extensions: None,
            extras: Default::default(),
        }
    } else {
        json::Image {
            buffer_view: None,
            mime_type: None,
            name,
            uri: Some(uri_encode(&textures.reference(t))),
            extensions: None,
            extras: Default::default(),
        }
    };
    let source = root.push(image);
    if root.samplers.is_empty() {
        // CGA textures tile (UVs beyond [0, 1] repeat); mipmaps keep
        // distant facades from shimmering.
        root.push(json::texture::Sampler {
            mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
            wrap_s: Valid(json::texture::WrappingMode::Repeat),
            wrap_t: Valid(json::texture::WrappingMode::Repeat),
            ..Default::default()
        });
    }
    root.push(json::Texture {
        name: None,
        sampler: Some(json::Index::new(0)),
        source,
        extensions: None,
        extras: Default::default(),
    })
}

/// The `KHR_texture_transform` of a texture channel's `su sv tu tv rw`, or
/// `None` for the identity.
///
/// CGA's channel transform maps texture coordinates as
/// `uv' = R(rw) * (su u, sv v) + (tu, tv)`, `rw` in degrees counter-clockwise
/// (the order glTF's extension uses too). glTF's coordinates are CGA's with
/// v flipped (`v_gltf = 1 - v`), which turns that map into: the same scale,
/// the rotation `rw` (the extension rotates clockwise in CGA's terms), and
/// the offset `(tu - sv sin rw, 1 - tv - sv cos rw)`.
fn texture_transform(ch: &cga_geometry::TextureChannel) -> Option<serde_json::Value> {
    let identity = ch.su == 1.0 && ch.sv == 1.0 && ch.tu == 0.0 && ch.tv == 0.0 && ch.rw == 0.0;
    let finite = [ch.su, ch.sv, ch.tu, ch.tv, ch.rw]
        .iter()
        .all(|x| x.is_finite());
    if identity || !finite {
        return None;
    }
    let (s, c) = ch.rw.to_radians().sin_cos();
    let offset = [ch.tu - ch.sv * s, 1.0 - ch.tv - ch.sv * c];
    Some(serde_json::json!({
        "offset": offset.map(|x| x as f32),
        "rotation": ch.rw.to_radians() as f32,
        "scale": [ch.su as f32, ch.sv as f32],
    }))
}

/// The glTF material for a CGA material with its textures. `alpha_map`:
/// the opacity comes from the colour map's alpha, blended, masked or
/// ignored as `material.opacitymap.mode` says. As in CityEngine, a texture
/// replaces the scalar it maps (emissive colour, metalness and roughness
/// become factors of 1), except the colour map, which multiplies the colour.
fn gltf_material(
    m: &Material,
    name: String,
    textures: Vec<(Slot, json::texture::Info)>,
    alpha_map: bool,
) -> json::Material {
    let linear = m.color.map(|c| color_to_linear(c) as f32);
    let opacity = m.opacity.clamp(0.0, 1.0) as f32;
    let unit = |x: f64| {
        if x.is_finite() {
            x.clamp(0.0, 1.0) as f32
        } else {
            0.0
        }
    };
    let mut emissive = m.emissive.map(|c| color_to_linear(c) as f32);
    let (mut metallic, mut roughness) = (unit(m.metallic), unit(m.roughness));
    let (alpha_mode, alpha_cutoff) = match (alpha_map, &*m.opacitymap_mode) {
        (true, "mask") => (
            json::material::AlphaMode::Mask,
            Some(json::material::AlphaCutoff(unit(m.opacitymap_cutoff))),
        ),
        (true, "opaque") if opacity >= 1.0 => (json::material::AlphaMode::Opaque, None),
        (true, _) => (json::material::AlphaMode::Blend, None),
        (false, _) if opacity < 1.0 => (json::material::AlphaMode::Blend, None),
        _ => (json::material::AlphaMode::Opaque, None),
    };
    let mut out = json::Material {
        alpha_mode: Valid(alpha_mode),
        alpha_cutoff,
        double_sided: m.double_sided,
        name: Some(name),
        ..Default::default()
    };
    let mut base_color_texture = None;
    let mut metallic_roughness_texture = None;
    for (slot, info) in textures {
        match slot {
            Slot::BaseColor => base_color_texture = Some(info),
            Slot::MetallicRoughness => {
                metallic_roughness_texture = Some(info);
                // A roughness map alone is only written for non-metals,
                // whose factor 0 keeps the image's blue channel out.
                if !m.maps[9].path.is_empty() {
                    metallic = 1.0;
                }
                roughness = 1.0;
            }
            Slot::Emissive => {
                emissive = [1.0; 3];
                out.emissive_texture = Some(info);
            }
            Slot::Normal => {
                out.normal_texture = Some(json::material::NormalTexture {
                    index: info.index,
                    scale: 1.0,
                    tex_coord: info.tex_coord,
                    extensions: info
                        .extensions
                        .map(|e| json::extensions::material::NormalTexture { others: e.others }),
                    extras: Default::default(),
                })
            }
            Slot::Occlusion => {
                out.occlusion_texture = Some(json::material::OcclusionTexture {
                    index: info.index,
                    strength: json::material::StrengthFactor(1.0),
                    tex_coord: info.tex_coord,
                    extensions: info
                        .extensions
                        .map(|e| json::extensions::material::OcclusionTexture { others: e.others }),
                    extras: Default::default(),
                })
            }
        }
    }
    out.pbr_metallic_roughness = json::material::PbrMetallicRoughness {
        base_color_factor: json::material::PbrBaseColorFactor([
            linear[0], linear[1], linear[2], opacity,
        ]),
        base_color_texture,
        metallic_factor: json::material::StrengthFactor(metallic),
        roughness_factor: json::material::StrengthFactor(roughness),
        metallic_roughness_texture,
        ..Default::default()
    };
    out.emissive_factor = json::material::EmissiveFactor(emissive);
    out
}

/// Writes the binary buffer in [`Layout`] order: per non-empty bucket its
/// positions, normals, UVs and indices, then the embedded `images`.
fn write_bin(
    w: &mut impl Write,
    held: &Held,
    images: &[u32],
    textures: &Textures,
    path: &Path,
) -> Result<(), ExportError> {
    let io = |e| ExportError::io(path, e);
    // The arrays hold the bytes to write; arrays larger than the output
    // buffer go to the file directly.
    for b in held.buckets.iter().filter(|b| b.has_triangles()) {
        b.write_arrays(w).map_err(io)?;
    }
    write_instances(w, held.middle).map_err(io)?;
    for &t in images {
        let tex = textures.get(t);
        textures.write_to(t, w)?;
        let pad = (tex.len.next_multiple_of(4) - tex.len) as usize;
        w.write_all(&[0u8; 3][..pad]).map_err(io)?;
    }
    w.write_all(held.tail).map_err(io)
}

/// What `finish` writes of the binary data: the buckets held, then the
/// instances' data, the images, and `tail` (the property table).
struct Held<'a> {
    buckets: &'a [Bucket],
    /// The instances, written as laid out.
    middle: &'a Instances,
    tail: &'a [u8],
}

/// The instances' data as `lay_out_instances` laid it out: each group's
/// arrays, then per node each placement attribute's values. Written
/// straight from the placements: gathered into one array first, the
/// model's last step (after its last lot) spent more time growing it in
/// fresh memory than writing it.
fn write_instances(w: &mut impl Write, instances: &Instances) -> std::io::Result<()> {
    for group in &instances.groups {
        for (_, b) in group.buckets.iter().filter(|(_, b)| b.has_triangles()) {
            b.write_arrays(w)?;
        }
    }
    // One attribute of a node at a time, in room kept between them; nodes
    // in the order `lay_out_instances` laid them out.
    let mut values: Vec<f32> = Vec::new();
    for placements in instances.nodes.values() {
        for &(_, width, _, value) in placement_attributes(instances.with_features) {
            values.clear();
            for p in placements {
                values.extend_from_slice(&value(p)[..width]);
            }
            write_le(w, &values)?;
        }
    }
    Ok(())
}

/// A placement attribute of an instance node: its name, values per
/// placement, accessor type, and its values (the first `width` of four).
type PlacementAttribute = (
    &'static str,
    usize,
    json::accessor::Type,
    fn(&Placement) -> [f32; 4],
);

/// The attributes of an instance node's placements, in the order of their
/// data: `EXT_mesh_gpu_instancing`'s, and with per-lot features each
/// placement's lot as its feature id (`EXT_instance_features`).
fn placement_attributes(features: bool) -> &'static [PlacementAttribute] {
    use json::accessor::Type;
    fn xyz(v: [f32; 3]) -> [f32; 4] {
        [v[0], v[1], v[2], 0.0]
    }
    const ALL: [PlacementAttribute; 4] = [
        ("TRANSLATION", 3, Type::Vec3, |p| xyz(p.translation)),
        ("ROTATION", 4, Type::Vec4, |p| p.rotation),
        ("SCALE", 3, Type::Vec3, |p| xyz(p.scale)),
        ("_FEATURE_ID_0", 1, Type::Scalar, |p| {
            [p.lot.unwrap_or(0) as f32, 0.0, 0.0, 0.0]
        }),
    ];
    match features {
        true => &ALL,
        false => &ALL[..3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_written_little_endian() {
        let mut out = Vec::new();
        write_le(&mut out, &[[1.5f32, -2.0]]).unwrap();
        write_le(&mut out, &[[7u32, 1, 256]]).unwrap();
        assert_eq!(
            out,
            [0, 0, 192, 63, 0, 0, 0, 192, 7, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]
        );
    }

    #[test]
    fn coordinate_arrays_compare_as_numbers() {
        // Sets with equal numbers share one array (0 equals -0); NaN equals
        // nothing.
        let mut b = Bucket::new();
        b.coords = vec![
            vec![[0.0, 0.5]],
            vec![[-0.0, 0.5]],
            vec![[1.0, 0.5]],
            vec![[f32::NAN, 0.5]],
            vec![[f32::NAN, 0.5]],
        ];
        b.merge_equal_coords();
        assert_eq!(b.tex_coords, [0, 0, 1, 2, 3]);
        assert_eq!(b.coords.len(), 4);
    }
}
