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
use std::fs::File;
use std::io::{BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use std::sync::Arc;

use cga_geometry::{DVec2, DVec3, Material, Mesh, UV_SETS};
use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use crate::materials::{srgb_to_linear, MaterialTable};
use crate::textures::{uri_encode, Textures};
use crate::{ExportError, ExportStats, FaceData};

/// Vertex data of one material, kept as the `f32` and `u32` values the
/// binary buffer holds (written as their little-endian bytes: on
/// little-endian machines the arrays' own memory).
#[derive(Default)]
struct Bucket {
    /// x, y, z per vertex (their number is the bucket's vertex count).
    positions: Vec<[f32; 3]>,
    /// x, y, z per vertex.
    normals: Vec<[f32; 3]>,
    /// The UV sets written as `TEXCOORD` arrays, set 0 first when present,
    /// and their coordinates (`f32` u and flipped v per vertex). A set a mesh
    /// lacks reads set 0 instead, as CGA does for texture layers; vertices
    /// without either get (0, 0). Set 0 is added when the first mesh with
    /// UVs comes (earlier vertices get (0, 0)); a textured material has it
    /// from the start, with one more set per other texture layer it uses.
    sets: Vec<usize>,
    coords: Vec<Vec<[f32; 2]>>,
    /// After [`Bucket::merge_equal_coords`]: the `TEXCOORD` index of each
    /// set (sets with equal coordinates share one array).
    tex_coords: Vec<u32>,
    /// `TANGENT` (x, y, z, w) per vertex, for normal-mapped materials.
    tangents: Option<Vec<[f32; 4]>>,
    /// Vertex indices per triangle.
    indices: Vec<[u32; 3]>,
    min: [f32; 3],
    max: [f32; 3],
}

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
    min: [f32; 3],
    max: [f32; 3],
}

/// Vertex data held before it is written out, by default (see the module
/// docs).
pub const DEFAULT_FLUSH_MIB: usize = 64;

/// GLB: bytes left at the start of the file for the header and the JSON
/// when data is written before the end (most models' JSON needs a few
/// kilobytes; one with thousands of materials may need more, and then the
/// binary data is moved up).
const GLB_JSON_ROOM: u64 = 1 << 20;

/// Writes values as the little-endian bytes glTF's binary buffer holds.
fn write_le<T: bytemuck::Pod>(w: &mut impl Write, values: &[T]) -> std::io::Result<()> {
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

/// The tangent written for a vertex with normal `n` given the face's
/// tangent: perpendicular to the normal, as glTF requires.
#[inline]
fn vertex_tangent(n: DVec3, (t, w): (DVec3, f64)) -> [f32; 4] {
    let t = (t - n * n.dot(t))
        .try_normalize()
        .unwrap_or_else(|| n.any_orthonormal_vector());
    let t = t.as_vec3();
    [t.x, t.y, t.z, w as f32]
}

fn too_many_vertices() -> ExportError {
    ExportError::TooLarge("more than 2^32 vertices with one material".into())
}

impl Bucket {
    /// Keeps one coordinate array per distinct content: a layer whose UV set
    /// no mesh had reads set 0's array.
    fn merge_equal_coords(&mut self) {
        let mut distinct: Vec<Vec<[f32; 2]>> = Vec::new();
        self.tex_coords.clear();
        for c in std::mem::take(&mut self.coords) {
            // Compared as numbers: 0 equals -0, NaN equals nothing.
            match distinct.iter().position(|d| *d == c) {
                Some(i) => self.tex_coords.push(i as u32),
                None => {
                    self.tex_coords.push(distinct.len() as u32);
                    distinct.push(c);
                }
            }
        }
        self.coords = distinct;
    }

    fn new() -> Bucket {
        Bucket {
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            ..Bucket::default()
        }
    }

    /// Bytes of vertex data held.
    fn bytes(&self) -> usize {
        self.positions.len() * 12
            + self.normals.len() * 12
            + self.coords.iter().map(|c| c.len() * 8).sum::<usize>()
            + self.tangents.as_ref().map_or(0, |t| t.len() * 16)
            + self.indices.len() * 12
    }

    /// Each UV set in an array of its own (no merging), as once anything
    /// was written early.
    fn unmerged_coords(&mut self) {
        self.tex_coords = (0..self.coords.len() as u32).collect();
    }

    /// What the accessors of this bucket's data as a primitive need.
    fn primitive(&self, material: u32) -> PrimitiveLayout {
        PrimitiveLayout {
            material,
            vertices: self.positions.len() as u64,
            positions: self.positions.len() * 12,
            normals: self.normals.len() * 12,
            coords: self.coords.iter().map(|c| c.len() * 8).collect(),
            tangents: self.tangents.as_ref().map(|t| t.len() * 16),
            indices: self.indices.len() * 12,
            min: self.min,
            max: self.max,
        }
    }

    /// The arrays in the order of the binary layout.
    fn write_arrays(&self, w: &mut impl Write) -> std::io::Result<()> {
        write_le(w, &self.positions)?;
        write_le(w, &self.normals)?;
        for coords in &self.coords {
            write_le(w, coords)?;
        }
        if let Some(tangents) = &self.tangents {
            write_le(w, tangents)?;
        }
        write_le(w, &self.indices)
    }

    /// Empties the arrays (keeping their room), as for a new primitive.
    fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.coords.iter_mut().for_each(Vec::clear);
        if let Some(t) = &mut self.tangents {
            t.clear();
        }
        self.indices.clear();
        self.min = [f32::INFINITY; 3];
        self.max = [f32::NEG_INFINITY; 3];
    }

    /// Room for `n` more vertices.
    fn reserve(&mut self, n: usize) {
        self.positions.reserve(n);
        self.normals.reserve(n);
        for c in &mut self.coords {
            c.reserve(n);
        }
        if let Some(t) = &mut self.tangents {
            t.reserve(n);
        }
    }

    /// Appends a vertex at `p` with normal `n`; `sources[k]` is where the
    /// `k`-th written UV set reads (see [`Bucket::sets`]), at `corner`.
    #[inline(always)]
    fn push_vertex(
        &mut self,
        p: DVec3,
        n: DVec3,
        sources: &[Option<&[DVec2]>],
        corner: usize,
        tangent: (DVec3, f64),
    ) -> Result<u32, ExportError> {
        let index = u32::try_from(self.positions.len()).map_err(|_| too_many_vertices())?;
        self.push_position(p);
        self.normals.push(n.as_vec3().to_array());
        for (src, coords) in sources.iter().zip(&mut self.coords) {
            coords.push(uv_at(*src, corner));
        }
        if let Some(tangents) = &mut self.tangents {
            tangents.push(vertex_tangent(n, tangent));
        }
        Ok(index)
    }

    /// Appends a position and widens the bounds.
    #[inline(always)]
    fn push_position(&mut self, p: DVec3) {
        let p = p.as_vec3().to_array();
        // `min` and `max` start at +inf and -inf (see `Bucket::new`) and are
        // never NaN, so plain comparisons keep what `f32::min` and `max`
        // would (a NaN coordinate changes nothing; of 0 and -0 the first
        // stays) without their NaN handling.
        for ((lo, hi), x) in self.min.iter_mut().zip(&mut self.max).zip(p) {
            if x < *lo {
                *lo = x;
            }
            if x > *hi {
                *hi = x;
            }
        }
        self.positions.push(p);
    }
}

/// The written texture coordinates of `corner` from a UV source: v flipped
/// (glTF puts v = 0 at the top of the image, CGA at the bottom); (0, 0)
/// without a source.
#[inline(always)]
fn uv_at(src: Option<&[DVec2]>, corner: usize) -> [f32; 2] {
    match src.and_then(|u| u.get(corner)) {
        Some(t) => [t.x as f32, (1.0 - t.y) as f32],
        None => [0.0, 0.0],
    }
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
fn face_tangent(f: &FaceData) -> (DVec3, f64) {
    let mesh = f.mesh;
    let Some(uvs) = mesh.uvs[5].as_deref().or(mesh.uvs[0].as_deref()) else {
        return (f.normal.any_orthonormal_vector(), 1.0);
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
            let w = if f.normal.cross(t).dot(-dpdv) < 0.0 {
                -1.0
            } else {
                1.0
            };
            return (t, w);
        }
    }
    (f.normal.any_orthonormal_vector(), 1.0)
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
struct MapUse {
    slot: Slot,
    texture: u32,
    channel: usize,
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

pub(crate) struct GltfWriter {
    path: PathBuf,
    out: BufWriter<File>,
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
    /// Output vertex of each corner of the mesh being added.
    corner_vertex: Vec<u32>,
    /// The output vertices made for each position of the mesh being added
    /// (per position the first entry in `shared`, chained by `next`): a
    /// position rarely has more than a few, so this is a short walk
    /// instead of hashing every corner.
    first_shared: Vec<u32>,
    shared: Vec<SharedVertex>,
    /// Vertex data held by all buckets, in bytes, and how much may be held
    /// before it is written out.
    held: usize,
    flush_bytes: usize,
    /// Primitives already written, in the order written, and their bytes.
    written: Vec<PrimitiveLayout>,
    written_bytes: u64,
    /// glTF: the `.bin` file, once data is written before the end.
    bin_out: Option<BufWriter<File>>,
}

impl GltfWriter {
    pub(crate) fn create(
        path: &Path,
        binary: bool,
        embed_images: bool,
        asset_extras: Option<serde_json::Value>,
        flush_mib: usize,
    ) -> Result<GltfWriter, ExportError> {
        // Readable too: a GLB's binary data may have to be moved up (see
        // `finish_early_glb`).
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .map_err(|e| ExportError::io(path, e))?;
        let stem = path
            .file_stem()
            .map_or("model".into(), |s| s.to_string_lossy());
        Ok(GltfWriter {
            path: path.to_path_buf(),
            out: BufWriter::with_capacity(1 << 16, file),
            binary,
            embed_images: binary && embed_images,
            asset_extras,
            bin_name: format!("{stem}.bin"),
            buckets: Vec::new(),
            maps: Vec::new(),
            alpha_maps: Vec::new(),
            uses_transform: false,
            corner_vertex: Vec::new(),
            first_shared: Vec::new(),
            shared: Vec::new(),
            held: 0,
            flush_bytes: flush_mib.saturating_mul(1 << 20),
            written: Vec::new(),
            written_bytes: 0,
            bin_out: None,
        })
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
        let mut maps = Vec::new();
        for (slot, channel) in [
            (Slot::BaseColor, 0),
            (Slot::Normal, 5),
            (Slot::Emissive, 6),
            (Slot::Occlusion, 7),
        ] {
            if let Some(texture) = usable(textures, warnings, &material.maps[channel].path) {
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
        if let Some(texture) =
            packed.and_then(|k| usable(textures, warnings, &material.maps[k].path))
        {
            maps.push(MapUse {
                slot: Slot::MetallicRoughness,
                texture,
                channel: 8,
            });
        }
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
        let mut bucket = Bucket::new();
        if !maps.is_empty() {
            // Textured: every vertex needs coordinates, set 0 first.
            bucket.sets.push(0);
            for m in &maps {
                if !bucket.sets.contains(&m.channel) {
                    bucket.sets.push(m.channel);
                }
            }
            bucket.coords = vec![Vec::new(); bucket.sets.len()];
        }
        if maps.iter().any(|m| m.slot == Slot::Normal) {
            bucket.tangents = Some(Vec::new());
        }
        if maps
            .iter()
            .any(|m| texture_transform(&material.maps[m.channel]).is_some())
        {
            self.uses_transform = true;
        }
        self.buckets.push(bucket);
        self.maps.push(maps);
        self.alpha_maps.push(alpha);
    }

    /// Starts a new input mesh; writes out the data held if it is more
    /// than allowed (between meshes, as vertex sharing is per mesh).
    pub(crate) fn begin_mesh(&mut self, mesh: &Mesh) -> Result<(), ExportError> {
        if self.held > self.flush_bytes {
            self.flush()?;
        }
        self.begin_mesh_data(mesh);
        Ok(())
    }

    /// Writes every bucket's data as a primitive and empties the buckets.
    fn flush(&mut self) -> Result<(), ExportError> {
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        let out: &mut BufWriter<File> = if self.binary {
            if self.written_bytes == 0 {
                self.out.seek(SeekFrom::Start(GLB_JSON_ROOM)).map_err(io)?;
            }
            &mut self.out
        } else {
            if self.bin_out.is_none() {
                let bin_path = self.path.with_file_name(&self.bin_name);
                let file = File::create(&bin_path).map_err(|e| ExportError::io(&bin_path, e))?;
                self.bin_out = Some(BufWriter::with_capacity(1 << 16, file));
            }
            self.bin_out.as_mut().expect("created above")
        };
        for (id, b) in self.buckets.iter_mut().enumerate() {
            if b.indices.is_empty() {
                continue;
            }
            b.unmerged_coords();
            b.write_arrays(out).map_err(io)?;
            let p = b.primitive(id as u32);
            self.written_bytes += b.bytes() as u64;
            self.written.push(p);
            b.clear();
        }
        self.held = 0;
        Ok(())
    }

    fn begin_mesh_data(&mut self, mesh: &Mesh) {
        self.corner_vertex.clear();
        self.corner_vertex.resize(mesh.corners.len(), 0);
        self.first_shared.clear();
        if mesh.normals.is_some() {
            self.first_shared.resize(mesh.positions.len(), NO_ENTRY);
        }
        self.shared.clear();
    }

    pub(crate) fn add_face(&mut self, f: &FaceData) -> Result<(), ExportError> {
        let GltfWriter {
            buckets,
            corner_vertex,
            first_shared,
            shared: made,
            held,
            ..
        } = self;
        let mesh = f.mesh;
        let bucket = &mut buckets[f.material as usize];
        let before = bucket.bytes();
        let uvs = mesh.uvs[0].as_deref();
        if uvs.is_some() && bucket.sets.is_empty() {
            bucket.sets.push(0);
            bucket.coords.push(vec![[0.0; 2]; bucket.positions.len()]);
        }
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
        let loops = mesh.face_loops(f.face);
        match f.normals {
            Some(normals) if shared => {
                bucket.reserve(loops.iter().map(|l| l.len as usize).sum());
                let corners = loops.iter().flat_map(|&l| mesh.loop_corners(l));
                for c in corners {
                    let position = mesh.corners[c] as usize;
                    let n = normals[c].try_normalize().unwrap_or(f.normal);
                    let uv = uvs.map_or([0; 2], |u| u[c].as_vec2().to_array().map(f32::to_bits));
                    let key = VertexKey {
                        material: f.material,
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
                        let v =
                            bucket.push_vertex(f.positions[position], n, sources, c, tangent)?;
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
                    mesh.loop_corners(*l),
                )?,
                _ => own_vertices(
                    bucket,
                    f,
                    sources,
                    tangent,
                    corner_vertex,
                    loops.iter().flat_map(|&l| mesh.loop_corners(l)),
                )?,
            },
        }
        bucket.indices.extend(
            f.triangles
                .iter()
                .map(|t| t.map(|c| corner_vertex[c as usize])),
        );
        *held += bucket.bytes() - before;
        Ok(())
    }

    pub(crate) fn finish(
        mut self,
        table: &MaterialTable,
        textures: &Textures,
        stats: &mut ExportStats,
    ) -> Result<(), ExportError> {
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
        let early = !self.written.is_empty();
        for b in &mut self.buckets {
            if early {
                b.unmerged_coords();
            } else {
                b.merge_equal_coords();
            }
        }
        let held: Vec<PrimitiveLayout> = self
            .buckets
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.indices.is_empty())
            .map(|(id, b)| b.primitive(id as u32))
            .collect();
        // Accessors in the order of the binary data; primitives by material.
        let mut primitives: Vec<Vec<json::mesh::Primitive>> = Vec::new();
        primitives.resize_with(self.buckets.len(), Vec::new);
        for p in self.written.iter().chain(&held) {
            let prim = primitive_accessors(&mut root, &mut layout, p);
            primitives[p.material as usize].push(prim);
            stats.vertices += p.vertices;
        }
        for (id, prims) in primitives.into_iter().enumerate() {
            if prims.is_empty() {
                continue;
            }
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
            let material = root.push(gltf_material(
                material,
                name.clone(),
                infos,
                self.alpha_maps[id as usize],
            ));
            let primitives = prims
                .into_iter()
                .map(|p| json::mesh::Primitive {
                    material: Some(material),
                    ..p
                })
                .collect();
            let mesh = root.push(json::Mesh {
                extensions: None,
                extras: Default::default(),
                name: Some(name.clone()),
                primitives,
                weights: None,
            });
            nodes.push(root.push(json::Node {
                mesh: Some(mesh),
                name: Some(name),
                ..Default::default()
            }));
            stats.materials += 1;
        }
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
            self.write_glb(&root, bin_len, &embedded, textures)?;
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
                        let file =
                            File::create(&bin_path).map_err(|e| ExportError::io(&bin_path, e))?;
                        BufWriter::with_capacity(1 << 16, file)
                    }
                };
                write_bin(&mut w, &self.buckets, &[], textures, &bin_path)?;
                w.flush().map_err(|e| ExportError::io(&bin_path, e))?;
            }
        }
        if !self.embed_images {
            textures.copy_all(images.iter().copied())?;
        }
        Ok(())
    }

    fn write_glb(
        &mut self,
        root: &json::Root,
        bin_len: u64,
        images: &[u32],
        textures: &Textures,
    ) -> Result<(), ExportError> {
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        let mut json = root.to_vec().map_err(|e| io(e.into()))?;
        // Chunks are 4-byte aligned; JSON pads with spaces.
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        if self.written_bytes > 0 {
            return self.finish_early_glb(json, bin_len, images, textures);
        }
        let bin_chunk = if bin_len > 0 { 8 + bin_len } else { 0 };
        let total = glb_length(12 + 8 + json.len() as u64 + bin_chunk)?;
        let out = &mut self.out;
        write_glb_head(out, total, &json, bin_len).map_err(io)?;
        if bin_len > 0 {
            write_bin(out, &self.buckets, images, textures, &path)?;
        }
        out.flush().map_err(io)
    }

    /// GLB whose binary data was partly written early, from `GLB_JSON_ROOM` on:
    /// the rest of it follows, then the header and the JSON (padded with
    /// spaces to the room, or, if it does not fit, with the binary data
    /// moved up to make room) go before it.
    fn finish_early_glb(
        &mut self,
        mut json: Vec<u8>,
        bin_len: u64,
        images: &[u32],
        textures: &Textures,
    ) -> Result<(), ExportError> {
        let path = self.path.clone();
        let io = |e| ExportError::io(&path, e);
        write_bin(&mut self.out, &self.buckets, images, textures, &path)?;
        self.out.flush().map_err(io)?;
        // Header (12), JSON chunk header (8), JSON, BIN chunk header (8).
        let head = 12 + 8 + json.len() as u64 + 8;
        let start = if head <= GLB_JSON_ROOM {
            GLB_JSON_ROOM
        } else {
            let file = self.out.get_mut();
            move_up(file, GLB_JSON_ROOM, bin_len, head - GLB_JSON_ROOM).map_err(io)?;
            head
        };
        json.resize((start - 28) as usize, b' ');
        let total = glb_length(start + bin_len)?;
        self.out.seek(SeekFrom::Start(0)).map_err(io)?;
        write_glb_head(&mut self.out, total, &json, bin_len).map_err(io)?;
        self.out.flush().map_err(io)
    }
}

/// A GLB's total length, which the header holds as `u32`.
fn glb_length(total: u64) -> Result<u32, ExportError> {
    u32::try_from(total)
        .map_err(|_| ExportError::TooLarge(format!("GLB of {total} bytes exceeds 4 GiB")))
}

/// The GLB header, the JSON chunk and the BIN chunk's header (if there is
/// binary data).
fn write_glb_head(
    out: &mut impl Write,
    total: u32,
    json: &[u8],
    bin_len: u64,
) -> std::io::Result<()> {
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&total.to_le_bytes())?;
    out.write_all(&(json.len() as u32).to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(json)?;
    if bin_len > 0 {
        out.write_all(&(bin_len as u32).to_le_bytes())?;
        out.write_all(b"BIN\0")?;
    }
    Ok(())
}

/// Moves the `len` bytes of `file` at `start` up by `by` bytes, from the
/// end backwards so that nothing is overwritten before it is moved.
fn move_up(file: &mut File, start: u64, len: u64, by: u64) -> std::io::Result<()> {
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
    corners: impl Iterator<Item = usize> + Clone,
) -> Result<(), ExportError> {
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
                let n = normals[c].try_normalize().unwrap_or(f.normal);
                bucket.normals.push(n.as_vec3().to_array());
                if let Some(tangents) = &mut bucket.tangents {
                    tangents.push(vertex_tangent(n, tangent));
                }
            }
        }
        None => {
            let n = f.normal.as_vec3().to_array();
            bucket.normals.extend(std::iter::repeat_n(n, count));
            if let Some(tangents) = &mut bucket.tangents {
                let t = vertex_tangent(f.normal, tangent);
                tangents.extend(std::iter::repeat_n(t, count));
            }
        }
    }
    for (src, coords) in sources.iter().zip(&mut bucket.coords) {
        coords.extend(corners.clone().map(|c| uv_at(*src, c)));
    }
    Ok(())
}

/// Assigns buffer views and accessors their place in the binary buffer.
#[derive(Default)]
struct Layout {
    /// Bytes laid out so far (always a multiple of 4).
    len: u64,
}

impl Layout {
    fn view(
        &mut self,
        root: &mut json::Root,
        bytes: u64,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let view = root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64(bytes),
            byte_offset: Some(USize64(self.len)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        });
        self.len += bytes.next_multiple_of(4);
        view
    }

    /// A view holding `components` 4-byte values and an accessor on it.
    fn accessor(
        &mut self,
        root: &mut json::Root,
        components: usize,
        count: u64,
        type_: json::accessor::Type,
        component_type: json::accessor::ComponentType,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::Accessor> {
        let view = self.view(root, components as u64 * 4, target);
        root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64(count),
            component_type: Valid(json::accessor::GenericComponentType(component_type)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        })
    }
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
    );
    let accessor = &mut root.accessors[positions.value()];
    accessor.min = Some(p.min.to_vec().into());
    accessor.max = Some(p.max.to_vec().into());
    attributes.insert(Valid(json::mesh::Semantic::Positions), positions);
    let normals = layout.accessor(
        root,
        p.normals / 4,
        p.vertices,
        Type::Vec3,
        ComponentType::F32,
        vertex_data,
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
    );
    json::mesh::Primitive {
        attributes,
        extensions: None,
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
    let linear = m.color.map(|c| srgb_to_linear(c) as f32);
    let opacity = m.opacity.clamp(0.0, 1.0) as f32;
    let unit = |x: f64| {
        if x.is_finite() {
            x.clamp(0.0, 1.0) as f32
        } else {
            0.0
        }
    };
    let mut emissive = m.emissive.map(|c| srgb_to_linear(c) as f32);
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
    buckets: &[Bucket],
    images: &[u32],
    textures: &Textures,
    path: &Path,
) -> Result<(), ExportError> {
    let io = |e| ExportError::io(path, e);
    // The arrays hold the bytes to write; arrays larger than the output
    // buffer go to the file directly.
    for b in buckets.iter().filter(|b| !b.indices.is_empty()) {
        b.write_arrays(w).map_err(io)?;
    }
    for &t in images {
        let tex = textures.get(t);
        if let Some(data) = &tex.data {
            w.write_all(data).map_err(io)?;
            let pad = (tex.len.next_multiple_of(4) - tex.len) as usize;
            w.write_all(&[0u8; 3][..pad]).map_err(io)?;
            continue;
        }
        let file = File::open(&tex.source).map_err(|e| ExportError::io(&tex.source, e))?;
        let copied = std::io::copy(&mut file.take(tex.len), w).map_err(io)?;
        if copied != tex.len {
            let msg = format!(
                "texture changed while exporting ({copied} of {} bytes)",
                tex.len
            );
            return Err(ExportError::io(&tex.source, std::io::Error::other(msg)));
        }
        let pad = (tex.len.next_multiple_of(4) - tex.len) as usize;
        w.write_all(&[0u8; 3][..pad]).map_err(io)?;
    }
    Ok(())
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
