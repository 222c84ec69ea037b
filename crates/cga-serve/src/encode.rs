//! The model as the page reads it, and values as JSON.
//!
//! Binary model (`/api/model.bin`, `/api/lots.bin`, and the model being
//! made, `/api/live.bin`), little-endian: [`MAGIC`], then frames, each
//!
//! ```text
//! u32 header length H  u32 data length D
//! data (D bytes): per mesh, positions (u16 x 3 per vertex, quantised: see below),
//!       texture coordinates (only for textured meshes: u16 x 2 quantised,
//!       or f32 x 2: "uv_bytes"), normals (i8 x 3, x 127, per vertex or,
//!       "face_normals", per face), then either
//!       the corner counts of its faces (u8 per face: "fans", see below)
//!       or indices (u16 or u32 x 3 per triangle: "index_bytes");
//!       each array padded to 4 bytes
//! header (JSON, H bytes, padded with spaces to 4 bytes)
//! ```
//!
//! The frames: first `{"start": {"origin": [x, y, z], "lots"}}` (no data),
//! then one per lot as it is made, `{"lot": {"index", "name", "bounds",
//! "meshes": [{"mesh", "vertices", "triangles", "positions", "min",
//! "extent", "normals", "face_normals", "uvs", "uv_bytes", "uv_min",
//! "uv_extent", "indices", "index_bytes", "fans", "color", "opacity",
//! "material", "double_sided", "texture"}]}}` (offsets in bytes from the
//! start of the frame's data), and last `{"end": {"complete", "bounds",
//! "model_version"}}`: a model being made ends with `complete` false when a
//! newer edit made it obsolete or it failed. Lots come in frames so that
//! the page can fetch and build a lot while the next are derived.
//!
//! Coordinates are relative to `origin` (the lots' centre when they lie
//! far from the frame's origin, else zero). A vertex is at `min + q /
//! 65535 * extent` for its three 16-bit numbers `q`: one scale for all axes (the mesh's largest side),
//! so that the page can draw the numbers as they are, scaled, without
//! bending the normals; a step is the largest side / 65535 (1.5 mm for a
//! building of 100 m). `bounds` are the lot's or the model's bounds (of
//! its positions as collected: `f32` relative to the origin). A frame's
//! header comes after its data because the boxes are known only once the
//! positions have been read: each mesh is measured and written in one
//! visit, while its arrays are in the cache. The meshes are the lots'
//! [`cga::DrawModel`]s, collected on the deriving threads relative to the origin (positions
//! and texture coordinates in `f32`, normals already bytes, convex faces
//! as corner counts: 23 bytes a vertex to read instead of the plain
//! meshes' 64). `mesh` is the mesh's number in the lot's drawing, which
//! [`cga::LotResult::provenance`] takes with a triangle number. The page
//! builds its three.js geometry from these arrays directly, with no glTF
//! parsing, and keeps the numbers a click needs for provenance.
//!
//! Faces as fans: each face has its own run of vertices, and a convex
//! face (nearly all: every rectangle) is cut into the triangles `(b, b +
//! i, b + i + 1)` of its run starting at `b`. A mesh whose faces are all
//! such fans ([`cga::DrawFaces::Fans`]) sends the number of corners of
//! each face (`"fans"`: how many faces; `"index_bytes"` 0) and the page
//! makes the same triangles from them: a byte a face instead of 6 or 12
//! bytes a triangle (Candler's street: 9.1 of its 33.5 MB were indices).
//! Other meshes send their indices. A mesh of fans whose faces are all
//! flat ([`cga::DrawNormals::PerFace`]) sends a normal per face
//! (`"face_normals": true`) and the page gives it to the face's
//! vertices: 3 bytes a quad instead of 12 (Candler's street: about 4 of
//! its 25 MB).
//!
//! Texture coordinates with 2 bytes are `uv_min + q / 65535 * uv_extent` per
//! axis, for meshes whose coordinates span at most [`UV_SPAN`] (a step
//! is then at most a thousandth of the texture); others are sent as
//! 32-bit floats.
//!
//! Bytes are what a model costs on its way to the picture (the browser
//! takes about 2.5 ms per megabyte to fetch it), hence the quantised
//! positions and texture coordinates and byte normals (9 to 13 bytes a
//! vertex instead of 32) and no texture coordinates where no texture
//! reads them. (Flat meshes sent without normals, shaded flat from their
//! positions, were tried: 9 % fewer bytes for Candler's street, but
//! software WebGL took 40 ms more to draw a building filling the view.)

use cga::{LotResult, Value};
use serde_json::{json, Value as Json};

/// A model's first four bytes.
pub const MAGIC: &[u8; 4] = b"CGAF";

/// Largest quantised coordinate.
const STEPS: f64 = 65535.0;

/// Texture coordinates spanning at most this many repeats of a texture
/// are sent as 16-bit steps.
const UV_SPAN: f64 = 64.0;

/// Points taken at a time by the loops below: their coordinates, read as
/// one flat run of `f64`, go through the same steps lane by lane, which
/// the compiler turns into vector instructions (these loops are most of
/// the encoding's time: a street is millions of vertices).
const RUN: usize = 4;

/// The corner and far corner of the box around `points` (infinite and
/// inverted for none; NaN coordinates are passed over).
fn bounds<const N: usize>(points: &[[f32; N]]) -> ([f64; N], [f64; N]) {
    // Lane `i` of a run holds coordinate `i % N` of a point.
    let mut lo = [[f32::INFINITY; N]; RUN];
    let mut hi = [[f32::NEG_INFINITY; N]; RUN];
    let runs = points.chunks_exact(RUN);
    let rest = runs.remainder();
    for run in runs {
        for k in 0..RUN {
            for a in 0..N {
                // A comparison rather than `f32::min`, whose care for NaN
                // keeps the loop from being vectorised; NaN loses both.
                let v = run[k][a];
                lo[k][a] = if v < lo[k][a] { v } else { lo[k][a] };
                hi[k][a] = if v > hi[k][a] { v } else { hi[k][a] };
            }
        }
    }
    for p in rest {
        for a in 0..N {
            lo[0][a] = if p[a] < lo[0][a] { p[a] } else { lo[0][a] };
            hi[0][a] = if p[a] > hi[0][a] { p[a] } else { hi[0][a] };
        }
    }
    let mut min = lo[0];
    let mut max = hi[0];
    for k in 1..RUN {
        for a in 0..N {
            min[a] = min[a].min(lo[k][a]);
            max[a] = max[a].max(hi[k][a]);
        }
    }
    (min.map(f64::from), max.map(f64::from))
}

/// A coordinate as a 16-bit step: `(v - offset) * scale` rounded, within
/// 0 and [`STEPS`] (0 for NaN).
#[inline(always)]
fn step(v: f64, offset: f64, scale: f64) -> u16 {
    // Adding a half and cutting off rounds (without a call to `round`,
    // which this target does not inline); the comparisons keep the value
    // within the steps, NaN included, before the cut.
    let v = (v - offset) * scale + 0.5;
    let v = if v > 0.0 { v } else { 0.0 };
    let v = if v < STEPS { v } else { STEPS };
    // SAFETY: `v` is within 0 and STEPS (NaN became 0 above), which an
    // i32 holds. Unchecked, the conversion needs no test for NaN and
    // the range per value, and the loops over points are vectorised.
    (unsafe { v.to_int_unchecked::<i32>() }) as u16
}

/// Writes each of `points` as N 16-bit steps, `(p - offset) * scale`
/// rounded, into `out` (2 N bytes a point).
fn write_steps<const N: usize>(
    points: &[[f32; N]],
    offset: [f64; N],
    scale: [f64; N],
    out: &mut [u8],
) {
    // The arrays are padded: runs and the rest are cut from the points'
    // bytes alone, so that padding never passes for a run.
    let out = &mut out[..2 * N * points.len()];
    let runs = points.chunks_exact(RUN);
    let rest = runs.remainder();
    let mut outs = out.chunks_exact_mut(2 * N * RUN);
    for (run, q) in runs.zip(&mut outs) {
        let mut steps = [[0u16; N]; RUN];
        for k in 0..RUN {
            for a in 0..N {
                steps[k][a] = step(f64::from(run[k][a]), offset[a], scale[a]);
            }
        }
        for (s, b) in steps.as_flattened().iter().zip(q.chunks_exact_mut(2)) {
            b.copy_from_slice(&s.to_le_bytes());
        }
    }
    let q = outs.into_remainder();
    for (p, q) in rest.iter().zip(q.chunks_exact_mut(2 * N)) {
        for a in 0..N {
            let v = step(f64::from(p[a]), offset[a], scale[a]);
            q[2 * a..2 * a + 2].copy_from_slice(&v.to_le_bytes());
        }
    }
}

/// Writes the normals' signed bytes (`n * 127` rounded, made by the
/// collector: the page reads them as normalised) into `out`.
fn write_normals(normals: &[[i8; 3]], out: &mut [u8]) {
    for (n, b) in normals.as_flattened().iter().zip(out.iter_mut()) {
        *b = *n as u8;
    }
}

/// How a mesh's texture coordinates are sent.
#[derive(Clone, Copy, PartialEq)]
enum Uvs {
    /// Not at all (no texture reads them).
    None,
    /// As 16-bit steps across their box: `min`, and the box's sides.
    Steps { min: [f64; 2], extent: [f64; 2] },
    /// As 32-bit floats.
    Floats,
}

impl Uvs {
    /// How `uvs` are sent: as steps where their box is small.
    fn of(uvs: &[[f32; 2]]) -> Uvs {
        let (lo, hi) = bounds(uvs);
        let extent: [f64; 2] = std::array::from_fn(|a| hi[a] - lo[a]);
        if extent.iter().all(|e| e.is_finite() && *e <= UV_SPAN) {
            Uvs::Steps {
                min: lo,
                // A side of zero: every step is zero.
                extent: extent.map(|e| if e > 0.0 { e } else { 1.0 }),
            }
        } else {
            Uvs::Floats
        }
    }

    /// Bytes per vertex.
    fn bytes(&self) -> usize {
        match self {
            Uvs::None => 0,
            Uvs::Steps { .. } => 4,
            Uvs::Floats => 8,
        }
    }
}

/// Where one mesh's arrays go in the data, and how its positions are
/// quantised.
struct Placed<'a> {
    /// The mesh's number in its lot's drawing.
    number: usize,
    mesh: &'a cga::DrawMesh,
    material: Option<&'a cga::Material>,
    texture: Option<String>,
    /// Corner and far corner of the mesh's box (relative to the origin,
    /// as the positions are).
    min: [f64; 3],
    max: [f64; 3],
    uvs: Uvs,
    /// How many normals are sent: one per vertex, or per face.
    normals: usize,
    short: bool,
    /// The faces' corner counts, sent instead of indices (see
    /// [`cga::DrawFaces::Fans`]).
    fans: Option<&'a [u8]>,
    /// Offsets of positions, uvs, normals and indices (or fans), and the
    /// end.
    at: [usize; 5],
}

impl Placed<'_> {
    /// Bytes per index sent: 2 or 4, or 0 where the faces go as fans.
    fn index_bytes(&self) -> usize {
        match (&self.fans, self.short) {
            (Some(_), _) => 0,
            (None, true) => 2,
            (None, false) => 4,
        }
    }

    /// The box's largest side (1 for a point, or a box that is not finite).
    fn extent(&self) -> f64 {
        let e = (0..3)
            .map(|a| self.max[a] - self.min[a])
            .fold(0.0, f64::max);
        if e > 0.0 && e.is_finite() {
            e
        } else {
            1.0
        }
    }

    /// The mesh's part of its lot's header.
    fn header(&self) -> Json {
        let material = self.material;
        let [positions, uvs, normals, indices, _] = self.at;
        json!({
            "mesh": self.number,
            "vertices": self.mesh.positions.len(),
            "triangles": self.mesh.triangles(),
            "positions": positions,
            "min": self.min,
            "extent": self.extent(),
            "normals": normals,
            "face_normals": matches!(self.mesh.normals, cga::DrawNormals::PerFace(_)),
            "uvs": if self.uvs == Uvs::None { Json::Null } else { json!(uvs) },
            "uv_bytes": self.uvs.bytes() / 2,
            "uv_min": match self.uvs { Uvs::Steps { min, .. } => json!(min), _ => Json::Null },
            "uv_extent": match self.uvs { Uvs::Steps { extent, .. } => json!(extent), _ => Json::Null },
            "indices": indices,
            "index_bytes": self.index_bytes(),
            "fans": self.fans.map(<[u8]>::len),
            "texture": self.texture,
            "color": material.map(|m| m.color).unwrap_or([0.8, 0.8, 0.8]),
            "opacity": material.map(|m| m.opacity).unwrap_or(1.0),
            "material": material.map(|m| m.name.to_string()).unwrap_or_default(),
            "double_sided": material.map(|m| m.double_sided).unwrap_or(false),
        })
    }

    /// Measures the box, then writes the arrays into `out`, the bytes
    /// from `at[0]` to `at[4]`.
    fn write(&mut self, out: &mut [u8]) {
        (self.min, self.max) = bounds(&self.mesh.positions);
        let [positions, uvs, normals, indices, end] = self.at;
        let base = positions;
        // The buffer may hold an earlier model: the padding of the arrays
        // that have some is zeroed, their bytes written over it.
        for (from, to) in [(positions, uvs), (normals, indices), (indices, end)] {
            let region = &mut out[from - base..to - base];
            let n = region.len();
            region[n.saturating_sub(3)..].fill(0);
        }
        let scale = STEPS / self.extent();
        let mesh = self.mesh;
        write_steps(
            &mesh.positions,
            self.min,
            [scale; 3],
            &mut out[positions - base..uvs - base],
        );
        match self.uvs {
            Uvs::None => {}
            Uvs::Steps { min, extent } => {
                let scale = extent.map(|e| STEPS / e);
                write_steps(&mesh.uvs, min, scale, &mut out[uvs - base..normals - base]);
            }
            Uvs::Floats => {
                let f = out[uvs - base..normals - base].chunks_exact_mut(8);
                for (uv, b) in mesh.uvs.iter().zip(f) {
                    b[..4].copy_from_slice(&uv[0].to_le_bytes());
                    b[4..].copy_from_slice(&uv[1].to_le_bytes());
                }
            }
        }
        // Unit normals need no more than a byte per coordinate.
        let (cga::DrawNormals::PerFace(n) | cga::DrawNormals::PerVertex(n)) = &mesh.normals;
        write_normals(n, &mut out[normals - base..indices - base]);
        let out = &mut out[indices - base..end - base];
        match &mesh.faces {
            cga::DrawFaces::Fans(fans) => out[..fans.len()].copy_from_slice(fans),
            cga::DrawFaces::Triangles(t) if self.short => {
                for (i, b) in t.iter().flatten().zip(out.chunks_exact_mut(2)) {
                    b.copy_from_slice(&(*i as u16).to_le_bytes());
                }
            }
            cga::DrawFaces::Triangles(t) => {
                for (i, b) in t.iter().flatten().zip(out.chunks_exact_mut(4)) {
                    b.copy_from_slice(&i.to_le_bytes());
                }
            }
        }
    }
}

/// The lots generated into meshes to draw ([`cga::Target::Drawing`]),
/// positions relative to `origin`, in lot order.
pub fn drawn(
    rules: &cga::Rules,
    lots: &[cga::Lot],
    options: &cga::Options,
    origin: [f64; 3],
) -> Result<Vec<LotResult>, cga::Error> {
    let mut out = Vec::with_capacity(lots.len());
    rules.generate_lots(lots, options, cga::Target::Drawing(origin), |r| out.push(r))?;
    Ok(out)
}

/// A box: its corner and far corner.
pub type Bounds = ([f64; 3], [f64; 3]);

/// The smallest box around both (either may be none).
pub fn union(a: Option<Bounds>, b: Option<Bounds>) -> Option<Bounds> {
    match (a, b) {
        (Some((l, h)), Some((m, k))) => Some((
            std::array::from_fn(|i| l[i].min(m[i])),
            std::array::from_fn(|i| h[i].max(k[i])),
        )),
        (a, None) => a,
        (None, b) => b,
    }
}

fn bounds_json(b: Option<Bounds>) -> Json {
    b.map_or(Json::Null, |(min, max)| json!({"min": min, "max": max}))
}

/// Appends a frame to `out`: its lengths, then `data` bytes that `fill`
/// writes (all of them), then `header` padded to 4 bytes.
fn frame(out: &mut Vec<u8>, data: usize, fill: impl FnOnce(&mut [u8]) -> Json) {
    let at = out.len();
    out.resize(at + 8 + data, 0);
    out[at + 4..at + 8].copy_from_slice(&(data as u32).to_le_bytes());
    let header = fill(&mut out[at + 8..]);
    let mut header = serde_json::to_vec(&header).expect("JSON of plain data");
    // Padded with spaces (JSON reads them as nothing), so that the next
    // frame's arrays stay aligned.
    header.resize(header.len().next_multiple_of(4), b' ');
    out[at..at + 4].copy_from_slice(&(header.len() as u32).to_le_bytes());
    out.extend_from_slice(&header);
}

/// The model's first bytes: [`MAGIC`] and the frame that says the origin
/// and the number of lots to come.
pub fn start_frame(origin: [f64; 3], lots: usize) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    frame(
        &mut out,
        0,
        |_| json!({"start": {"origin": origin, "lots": lots}}),
    );
    out
}

/// The model's last frame: complete (with the model's bounds and, for
/// the preview's models, the number the page's state gives it), or
/// abandoned (a newer edit made it obsolete, or it failed: the page keeps
/// what it shows).
pub fn end_frame(complete: bool, bounds: Option<Bounds>, model_version: Option<u64>) -> Vec<u8> {
    let mut out = Vec::new();
    frame(
        &mut out,
        0,
        |_| json!({"end": {"complete": complete, "bounds": bounds_json(bounds), "model_version": model_version}}),
    );
    out
}

/// One lot's meshes to draw ([`LotResult::drawing`], made by [`drawn`]
/// relative to the origin) as a frame, written into `out` (its contents
/// replaced: a buffer of an earlier frame is written without the page
/// faults of fresh memory), with the box of its positions. `texture`
/// gives the URL of a colour map path as the rules wrote it (`None`: not
/// found, drawn without).
pub fn lot_frame(
    lot: &LotResult,
    texture: &mut dyn FnMut(&str) -> Option<String>,
    mut out: Vec<u8>,
) -> (Vec<u8>, Option<Bounds>) {
    // What each mesh sends and where it goes; then each mesh's box and
    // arrays, written in one visit while its arrays are in the cache, and
    // the header.
    let mut placed: Vec<Placed> = Vec::new();
    for (number, mesh) in lot.drawing.meshes.iter().enumerate() {
        if mesh.triangles() == 0 {
            continue;
        }
        let material = lot.drawing.materials.get(mesh.material);
        let texture = material
            .map(|m| m.colormap())
            .filter(|p| !p.is_empty())
            .and_then(&mut *texture);
        let vertices = mesh.positions.len();
        let uvs = if texture.is_some() && mesh.uvs.len() == vertices {
            Uvs::of(&mesh.uvs)
        } else {
            Uvs::None
        };
        placed.push(Placed {
            number,
            mesh,
            material,
            texture,
            min: [0.0; 3],
            max: [0.0; 3],
            uvs,
            normals: match &mesh.normals {
                cga::DrawNormals::PerFace(n) | cga::DrawNormals::PerVertex(n) => n.len(),
            },
            short: vertices <= 1 << 16,
            fans: match &mesh.faces {
                cga::DrawFaces::Fans(sizes) => Some(sizes),
                cga::DrawFaces::Triangles(_) => None,
            },
            at: [0; 5],
        });
    }
    let mut size = 0usize;
    for p in &mut placed {
        let vertices = p.mesh.positions.len();
        let positions = size;
        let uv_at = positions + (vertices * 6).next_multiple_of(4);
        let normal_at = uv_at + vertices * p.uvs.bytes();
        let index_at = normal_at + (p.normals * 3).next_multiple_of(4);
        let index_bytes = match &p.fans {
            Some(fans) => fans.len(),
            None => p.mesh.triangles() * 3 * p.index_bytes(),
        };
        size = index_at + index_bytes.next_multiple_of(4);
        p.at = [positions, uv_at, normal_at, index_at, size];
    }
    // A reused buffer has its pages already: the data is zeroed and then
    // written over (the padding by `Placed::write`). Room for the header
    // too, so that appending it does not copy the data.
    out.clear();
    out.reserve(8 + size + 512 * placed.len() + 1024);
    let mut bounds = None;
    frame(&mut out, size, |mut data| {
        for p in &mut placed {
            let (mine, rest) = std::mem::take(&mut data).split_at_mut(p.at[4] - p.at[0]);
            p.write(mine);
            data = rest;
        }
        let meshes: Vec<Json> = placed
            .iter()
            .map(|p| {
                bounds = union(bounds, Some((p.min, p.max)));
                p.header()
            })
            .collect();
        json!({"lot": {"index": lot.index, "name": lot.name, "bounds": bounds_json(bounds), "meshes": meshes}})
    });
    (out, bounds)
}

/// The lots' meshes to draw ([`LotResult::drawing`], made by [`drawn`]
/// relative to `origin`) as a whole model: the start frame, a frame per
/// lot and a complete end frame.
pub fn model(
    results: &[LotResult],
    origin: [f64; 3],
    texture: &mut dyn FnMut(&str) -> Option<String>,
) -> Vec<u8> {
    let mut out = start_frame(origin, results.len());
    let mut bounds = None;
    for lot in results {
        let (bytes, b) = lot_frame(lot, texture, Vec::new());
        out.extend_from_slice(&bytes);
        bounds = union(bounds, b);
    }
    out.extend_from_slice(&end_frame(true, bounds, None));
    out
}

/// A CGA value as JSON: numbers (non-finite ones as their text), booleans,
/// strings, arrays as (nested, for tables) arrays.
pub fn value(v: &Value) -> Json {
    match v {
        Value::Float(f) => number(*f),
        Value::Bool(b) => json!(b),
        Value::Str(s) => json!(s.as_ref()),
        _ => json!(cga::value_text(v)),
    }
}

fn number(f: f64) -> Json {
    serde_json::Number::from_f64(f)
        .map(Json::Number)
        .unwrap_or_else(|| json!(f.to_string()))
}

/// A value the page sent for an attribute of type `ty`, as the engine
/// takes it; `None` when it does not fit (the attribute keeps its
/// default).
pub fn attr_value(ty: Option<cga::ValueType>, v: &Json) -> Option<Value> {
    use cga::ValueType as T;
    match (ty, v) {
        (Some(T::Float), Json::Number(n)) => n.as_f64().map(Value::Float),
        (Some(T::Float), Json::String(s)) => s.trim().parse().ok().map(Value::Float),
        (Some(T::Bool), Json::Bool(b)) => Some(Value::Bool(*b)),
        (Some(T::Bool), Json::String(s)) => match s.as_str() {
            "true" => Some(Value::Bool(true)),
            "false" => Some(Value::Bool(false)),
            _ => None,
        },
        (Some(T::Str), Json::String(s)) => Some(Value::Str(s.as_str().into())),
        (Some(T::Str), Json::Number(n)) => Some(Value::Str(n.to_string().into())),
        (Some(T::FloatArray | T::BoolArray | T::StrArray), Json::String(s)) => {
            Some(cga::parse_value(s))
        }
        (None, Json::Number(n)) => n.as_f64().map(Value::Float),
        (None, Json::Bool(b)) => Some(Value::Bool(*b)),
        (None, Json::String(s)) => Some(cga::parse_value(s)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lots generated into meshes to draw (what the page gets), and
    /// into plain meshes (exact).
    fn both(
        rules: &cga::Rules,
        lots: &[cga::Lot],
        options: &cga::Options,
        origin: [f64; 3],
    ) -> (Vec<LotResult>, Vec<LotResult>) {
        let drawn = drawn(rules, lots, options, origin).unwrap();
        (drawn, rules.generate_all(lots, options).unwrap())
    }

    /// The frames of a binary model: their headers and data.
    fn frames(bytes: &[u8]) -> Vec<(Json, &[u8])> {
        assert_eq!(&bytes[..4], MAGIC);
        let mut at = 4;
        let mut out = Vec::new();
        while at < bytes.len() {
            let h = u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
            let d = u32::from_le_bytes(bytes[at + 4..at + 8].try_into().unwrap()) as usize;
            assert_eq!((h % 4, d % 4), (0, 0));
            let data = &bytes[at + 8..at + 8 + d];
            let header = serde_json::from_slice(&bytes[at + 8 + d..at + 8 + d + h]).unwrap();
            out.push((header, data));
            at += 8 + d + h;
        }
        assert_eq!(at, bytes.len());
        out
    }

    /// The header and the data of a model of one lot: the lot's frame,
    /// with the start's origin and the end's bounds.
    fn split(bytes: &[u8]) -> (Json, &[u8]) {
        let f = frames(bytes);
        assert_eq!(f.len(), 3);
        assert_eq!(f[0].0["start"]["lots"], 1);
        assert_eq!(f[2].0["end"]["complete"], true);
        assert_eq!(f[2].0["end"]["bounds"], f[1].0["lot"]["bounds"]);
        let header = json!({
            "origin": f[0].0["start"]["origin"],
            "bounds": f[2].0["end"]["bounds"],
            "lots": [f[1].0["lot"]],
        });
        (header, f[1].1)
    }

    /// A mesh's positions as the page computes them.
    fn decode_positions(mesh: &Json, data: &[u8]) -> Vec<[f64; 3]> {
        let at = mesh["positions"].as_u64().unwrap() as usize;
        let min: Vec<f64> = serde_json::from_value(mesh["min"].clone()).unwrap();
        let extent = mesh["extent"].as_f64().unwrap();
        (0..mesh["vertices"].as_u64().unwrap() as usize)
            .map(|i| {
                std::array::from_fn(|a| {
                    let o = at + 6 * i + 2 * a;
                    let q = u16::from_le_bytes([data[o], data[o + 1]]);
                    min[a] + q as f64 / STEPS * extent
                })
            })
            .collect()
    }

    /// Points from `k` on, a few of them NaN, infinite or outside the
    /// steps.
    fn points<const N: usize>(n: usize, k: usize) -> Vec<[f32; N]> {
        (0..n)
            .map(|i| {
                std::array::from_fn(|a| match (i * 7 + a * 3 + k) % 23 {
                    0 => f32::NAN,
                    1 => -5.0,
                    2 => 1e9,
                    3 => f32::INFINITY,
                    4 => f32::NEG_INFINITY,
                    j => (j as f32 * 0.37 - 2.0) * (a as f32 + 1.0),
                })
            })
            .collect()
    }

    #[test]
    fn run_wise_loops_give_the_pointwise_results() {
        // Every length up to a few runs, so that runs and remainders both
        // count: the box and the steps as one point at a time, with
        // `f64::min`/`max` and `clamp`, gives them.
        for n in 0..(3 * RUN + 2) {
            for k in 0..3 {
                let p3: Vec<[f32; 3]> = points(n, k);
                let (lo, hi) = bounds(&p3);
                for a in 0..3 {
                    let c = |p: &[f32; 3]| f64::from(p[a]);
                    let want_lo = p3.iter().map(c).fold(f64::INFINITY, f64::min);
                    let want_hi = p3.iter().map(c).fold(f64::NEG_INFINITY, f64::max);
                    assert_eq!(lo[a].to_bits(), want_lo.to_bits(), "n {n} axis {a}");
                    assert_eq!(hi[a].to_bits(), want_hi.to_bits(), "n {n} axis {a}");
                }
                let (offset, scale) = ([-1.5, 0.25, 2.0], [900.0, 3000.0, 17.5]);
                // Padded as in the model (to 4 bytes, and a run more):
                // the padding keeps its marker.
                let mut out = vec![0xAAu8; (6 * n).next_multiple_of(4) + 24];
                write_steps(&p3, offset, scale, &mut out);
                assert!(out[6 * n..].iter().all(|&b| b == 0xAA), "n {n}");
                for (i, p) in p3.iter().enumerate() {
                    for a in 0..3 {
                        let want = ((f64::from(p[a]) - offset[a]) * scale[a] + 0.5)
                            .clamp(0.0, STEPS) as u16;
                        let o = 6 * i + 2 * a;
                        assert_eq!(u16::from_le_bytes([out[o], out[o + 1]]), want);
                    }
                }
                let normals: Vec<[i8; 3]> = (0..n)
                    .map(|i| std::array::from_fn(|a| (i * 37 + a * 11) as i8))
                    .collect();
                let mut out = vec![0xAAu8; (3 * n).next_multiple_of(4) + 12];
                write_normals(&normals, &mut out);
                assert!(out[3 * n..].iter().all(|&b| b == 0xAA), "n {n}");
                for (n, b) in normals.iter().flatten().zip(&out) {
                    assert_eq!(*b as i8, *n);
                }
                let p2: Vec<[f32; 2]> = points(n, k);
                let (lo, hi) = bounds(&p2);
                for a in 0..2 {
                    let c = |p: &[f32; 2]| f64::from(p[a]);
                    let want_lo = p2.iter().map(c).fold(f64::INFINITY, f64::min);
                    let want_hi = p2.iter().map(c).fold(f64::NEG_INFINITY, f64::max);
                    assert_eq!((lo[a], hi[a]), (want_lo, want_hi), "n {n} axis {a}");
                }
            }
        }
    }

    /// Values outside the range, infinite or NaN are clamped before the
    /// unchecked conversions, as the checked `as` would have them.
    #[test]
    fn steps_clamp_whatever_comes() {
        let s = |v: f64| step(v, 0.0, 1.0);
        assert_eq!(
            [
                f64::NAN,
                -1e300,
                f64::NEG_INFINITY,
                0.0,
                0.49,
                0.5,
                1.0,
                65535.0,
                1e300,
                f64::INFINITY
            ]
            .map(s),
            [0, 0, 0, 0, 0, 1, 1, 65535, 65535, 65535]
        );
        assert_eq!(step(11.0, 10.0, 65535.0 / 2.0), 32768);
    }

    #[test]
    fn quantised_positions_stay_within_half_a_step() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text(
            "/p/a.cga",
            "Lot --> extrude(37.3) split(y) { 3.17 : X | ~1 : Y }\n",
        );
        let lots = [cga::lots::rect(23.7, 11.9)];
        let (results, exact) = both(&rules, &lots, &cga::Options::default(), [0.0; 3]);
        let bytes = model(&results, [0.0; 3], &mut |_| None);
        let (header, data) = split(&bytes);
        let mut checked = 0;
        for (m, mesh) in header["lots"][0]["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
        {
            let exact = &exact[0].model.meshes[m].positions;
            let step = mesh["extent"].as_f64().unwrap() / STEPS;
            for (got, want) in decode_positions(mesh, data).iter().zip(exact) {
                for a in 0..3 {
                    assert!(
                        // And the positions' rounding to `f32`.
                        (got[a] - want[a]).abs() <= step / 2.0 + 1e-5,
                        "{got:?} {want:?}"
                    );
                }
                checked += 1;
            }
        }
        assert!(checked >= 16, "{checked}");
    }

    /// The triangles of a mesh as the page makes them: from the faces'
    /// corner counts, or read from the indices.
    fn decode_triangles(mesh: &Json, data: &[u8]) -> Vec<[u32; 3]> {
        let at = mesh["indices"].as_u64().unwrap() as usize;
        let n = mesh["triangles"].as_u64().unwrap() as usize;
        if let Some(faces) = mesh["fans"].as_u64() {
            assert_eq!(mesh["index_bytes"], 0);
            let mut out = Vec::new();
            let mut base = 0u32;
            for &corners in &data[at..at + faces as usize] {
                for i in 1..u32::from(corners) - 1 {
                    out.push([base, base + i, base + i + 1]);
                }
                base += u32::from(corners);
            }
            return out;
        }
        let size = mesh["index_bytes"].as_u64().unwrap() as usize;
        let index = |i: usize| {
            let b = &data[at + i * size..at + (i + 1) * size];
            if size == 2 {
                u32::from(u16::from_le_bytes([b[0], b[1]]))
            } else {
                u32::from_le_bytes(b.try_into().unwrap())
            }
        };
        (0..n)
            .map(|t| std::array::from_fn(|k| index(t * 3 + k)))
            .collect()
    }

    /// Faces sent as fans give the plain meshes' triangles exactly, and
    /// meshes with other triangles (a concave face) send their indices.
    #[test]
    fn faces_sent_as_fans_give_the_same_triangles() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text(
            "/p/a.cga",
            "Lot --> extrude(9) comp(f) { top : color(\"#00ff00\") Top | all : Side }\n\
             Top --> X.\n\
             Side --> split(y) { 3 : X | ~1 : primitiveCylinder(40) }\n",
        );
        assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
        // An L-shaped lot: its top face is concave.
        let l_shape = cga::lots::polygon(
            "L",
            &[
                cga::DVec3::new(0.0, 0.0, 0.0),
                cga::DVec3::new(20.0, 0.0, 0.0),
                cga::DVec3::new(20.0, 0.0, -8.0),
                cga::DVec3::new(8.0, 0.0, -8.0),
                cga::DVec3::new(8.0, 0.0, -20.0),
                cga::DVec3::new(0.0, 0.0, -20.0),
            ],
        );
        let (results, exact) = both(&rules, &[l_shape], &cga::Options::default(), [0.0; 3]);
        let bytes = model(&results, [0.0; 3], &mut |_| None);
        let (header, data) = split(&bytes);
        let meshes = header["lots"][0]["meshes"].as_array().unwrap();
        let (mut fanned, mut indexed) = (0, 0);
        for mesh in meshes {
            let exact = &exact[0].model.meshes[mesh["mesh"].as_u64().unwrap() as usize];
            assert_eq!(decode_triangles(mesh, data), exact.indices);
            if mesh["fans"].is_null() {
                indexed += 1;
            } else {
                fanned += 1;
            }
        }
        // The sides and cylinders as fans; the concave top with indices.
        assert!(fanned >= 1 && indexed >= 1, "{fanned} {indexed}");
    }

    #[test]
    fn a_model_reads_back() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text("/p/a.cga", "Lot --> extrude(7) color(\"#ff0000\") X.\n");
        assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
        let lots = [cga::lots::rect(10.0, 20.0)];
        let (results, _) = both(&rules, &lots, &cga::Options::default(), [0.0; 3]);
        let bytes = model(&results, [0.0; 3], &mut |_| None);
        let (header, data) = split(&bytes);
        let mesh = &header["lots"][0]["meshes"][0];
        assert_eq!(mesh["color"], json!([1.0, 0.0, 0.0]));
        // A box without its bottom? extrude keeps the lot face: 6 quads.
        assert_eq!(mesh["triangles"], json!(12));
        let vertices = mesh["vertices"].as_u64().unwrap() as usize;
        let ys: Vec<f64> = decode_positions(mesh, data).iter().map(|p| p[1]).collect();
        let top = ys.iter().cloned().fold(f64::MIN, f64::max);
        // Within half a step of the largest side (20 m).
        assert!((top - 7.0).abs() <= 10.0 / STEPS, "{top}");
        assert_eq!(
            header["bounds"],
            json!({"min": [0.0, 0.0, -20.0], "max": [10.0, 7.0, 0.0]})
        );
        // No texture: no texture coordinates sent.
        assert_eq!(mesh["uvs"], Json::Null);
        let indices = mesh["indices"].as_u64().unwrap() as usize;
        // 12 triangles: the fans of 6 quads, a byte each (padded to 8).
        assert_eq!(mesh["index_bytes"], 0);
        assert_eq!(mesh["fans"], 6);
        assert_eq!(&data[indices..], &[4, 4, 4, 4, 4, 4, 0, 0]);
        // A normal per face: the six faces are flat.
        let normals = mesh["normals"].as_u64().unwrap() as usize;
        assert_eq!(mesh["face_normals"], json!(true));
        assert_eq!(normals, (vertices * 6).next_multiple_of(4));
        assert_eq!(indices, normals + (6 * 3usize).next_multiple_of(4));
        let n: Vec<i8> = data[normals..normals + 6 * 3]
            .iter()
            .map(|&b| b as i8)
            .collect();
        // Every normal a unit axis, scaled by 127, each axis both ways.
        let mut axes: Vec<Vec<i8>> = n.chunks(3).map(<[i8]>::to_vec).collect();
        axes.sort();
        axes.dedup();
        assert_eq!(axes.len(), 6, "{n:?}");
        for v in n.chunks(3) {
            assert_eq!(
                v.iter().map(|c| (*c as i32).abs()).sum::<i32>(),
                127,
                "{v:?}"
            );
        }
        assert_eq!(mesh["texture"], Json::Null);
    }

    /// A model written into a buffer of an earlier one is the model
    /// written anew: every byte, padding included, is written.
    #[test]
    fn a_model_written_into_a_used_buffer_is_the_same() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text(
            "/p/a.cga",
            "Lot --> extrude(7) comp(f) { top : primitiveSphere() X | all : Y }\n",
        );
        let lots = [cga::lots::rect(10.0, 20.0), cga::lots::rect(3.0, 5.0)];
        let (results, _) = both(&rules, &lots, &cga::Options::default(), [1.0, 0.0, 2.0]);
        let fresh = model(&results, [1.0, 0.0, 2.0], &mut |_| None);
        let frames = frames(&fresh);
        assert_eq!(frames.len(), 4);
        // The model's box holds both lots' boxes.
        let b = |f: &Json, k: &str, a: usize| f[k].as_array().unwrap()[a].as_f64().unwrap();
        let model_box = &frames[3].0["end"]["bounds"];
        for (lot, _) in &frames[1..3] {
            for a in 0..3 {
                assert!(b(model_box, "min", a) <= b(&lot["lot"]["bounds"], "min", a));
                assert!(b(model_box, "max", a) >= b(&lot["lot"]["bounds"], "max", a));
            }
        }
        // The padding after each array is zeros.
        let mut padded = 0;
        for (header, data) in &frames[1..3] {
            for m in header["lot"]["meshes"].as_array().unwrap() {
                let at = |k: &str| m[k].as_u64().unwrap() as usize;
                let vertices = at("vertices");
                let normals = if m["face_normals"] == json!(true) {
                    at("fans")
                } else {
                    vertices
                };
                let indices = match m["fans"].as_u64() {
                    Some(faces) => faces as usize,
                    None => at("triangles") * 3 * at("index_bytes"),
                };
                for (start, len) in [
                    (at("positions"), 6 * vertices),
                    (at("normals"), 3 * normals),
                    (at("indices"), indices),
                ] {
                    let pad = &data[start + len..start + len.next_multiple_of(4)];
                    assert!(pad.iter().all(|&b| b == 0), "{m}");
                    padded += pad.len();
                }
            }
        }
        assert!(padded > 0);
        // The model is its frames one after the other, and a frame
        // written into a used buffer is the frame written anew.
        let mut joined = start_frame([1.0, 0.0, 2.0], 2);
        let mut bounds = None;
        for result in &results {
            let (frame, b) = lot_frame(result, &mut |_| None, Vec::new());
            for used in [vec![0xAA; 10], vec![0x55; frame.len() * 2]] {
                assert_eq!(lot_frame(result, &mut |_| None, used).0, frame);
            }
            joined.extend_from_slice(&frame);
            bounds = union(bounds, b);
        }
        joined.extend_from_slice(&end_frame(true, bounds, None));
        assert_eq!(joined, fresh);
    }

    #[test]
    fn smooth_normals_are_sent_within_half_a_step() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text("/p/a.cga", "Lot --> primitiveSphere() X.\n");
        let lots = [cga::lots::rect(10.0, 10.0)];
        let (results, exact) = both(&rules, &lots, &cga::Options::default(), [0.0; 3]);
        let bytes = model(&results, [0.0; 3], &mut |_| None);
        let (header, data) = split(&bytes);
        let mesh = &header["lots"][0]["meshes"][0];
        let vertices = mesh["vertices"].as_u64().unwrap() as usize;
        let normals = mesh["normals"].as_u64().unwrap() as usize;
        // The sphere's own normals: one per vertex.
        assert_eq!(mesh["face_normals"], json!(false));
        assert_eq!(normals, (vertices * 6).next_multiple_of(4));
        let exact = &exact[0].model.meshes[0].normals;
        for (b, n) in data[normals..normals + vertices * 3].chunks(3).zip(exact) {
            for a in 0..3 {
                // Within half a step of 1/127.
                let got = b[a] as i8 as f64 / 127.0;
                assert!((got - n[a]).abs() <= 0.5 / 127.0 + 1e-9, "{got} {n:?}");
            }
        }
    }

    /// A mesh's texture coordinates as the page computes them.
    fn decode_uvs(mesh: &Json, data: &[u8]) -> Vec<[f64; 2]> {
        let at = mesh["uvs"].as_u64().unwrap() as usize;
        let vertices = mesh["vertices"].as_u64().unwrap() as usize;
        match mesh["uv_bytes"].as_u64().unwrap() {
            2 => {
                let min: Vec<f64> = serde_json::from_value(mesh["uv_min"].clone()).unwrap();
                let extent: Vec<f64> = serde_json::from_value(mesh["uv_extent"].clone()).unwrap();
                (0..vertices)
                    .map(|i| {
                        std::array::from_fn(|a| {
                            let o = at + 4 * i + 2 * a;
                            let q = u16::from_le_bytes([data[o], data[o + 1]]);
                            min[a] + q as f64 / STEPS * extent[a]
                        })
                    })
                    .collect()
            }
            4 => (0..vertices)
                .map(|i| {
                    std::array::from_fn(|a| {
                        let o = at + 8 * i + 4 * a;
                        f32::from_le_bytes(data[o..o + 4].try_into().unwrap()) as f64
                    })
                })
                .collect(),
            other => panic!("uv_bytes {other}"),
        }
    }

    #[test]
    fn texture_coordinates_are_sent_as_steps_across_a_small_box() {
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        // 23.7 m by 11.9 m in tiles of 2 m (spanning 11.85 by 5.95
        // repeats), then of 0.1 m (237 repeats: too many for steps).
        let rules = engine.load_text(
            "/p/a.cga",
            "attr tile = 2\n\
             Lot --> setupProjection(0, scope.xz, tile, tile) projectUV(0) texture(\"a.png\") X.\n",
        );
        let lot = cga::lots::rect(23.7, 11.9);
        for (tile, bytes_per_uv, span) in [(2.0, 2, 11.85), (0.1, 4, 237.0)] {
            let options = cga::Options {
                attrs: vec![("tile".into(), Value::Float(tile))],
                ..cga::Options::default()
            };
            let (results, exact) = both(&rules, std::slice::from_ref(&lot), &options, [0.0; 3]);
            let bytes = model(&results, [0.0; 3], &mut |p| Some(format!("/files/{p}")));
            let (header, data) = split(&bytes);
            let mesh = &header["lots"][0]["meshes"][0];
            assert_eq!(mesh["texture"], json!("/files/a.png"));
            assert_eq!(mesh["uv_bytes"], json!(bytes_per_uv));
            let exact = &exact[0].model.meshes[0].uvs;
            let got = decode_uvs(mesh, data);
            assert_eq!(got.len(), exact.len());
            let widest = exact.iter().map(|u| u[0]).fold(f64::MIN, f64::max)
                - exact.iter().map(|u| u[0]).fold(f64::MAX, f64::min);
            assert!((widest - span).abs() < 1e-9, "{widest}");
            // Steps: within half a step of the box's side; floats: 32 bits.
            // (And the coordinates' rounding to `f32`.)
            let tolerance = if bytes_per_uv == 2 {
                span / STEPS / 2.0 + 1e-5
            } else {
                1e-4
            };
            for (g, e) in got.iter().zip(exact) {
                for a in 0..2 {
                    assert!((g[a] - e[a]).abs() <= tolerance, "{g:?} {e:?}");
                }
            }
        }
    }

    #[test]
    fn far_lots_are_sent_relative_to_their_origin() {
        // A lot at 10,000 km: 32-bit floats there are a metre apart.
        let engine = cga::Engine::new(cga::MemoryWorld::new());
        let rules = engine.load_text("/p/a.cga", "Lot --> X.\n");
        let far = cga::DVec3::new(1e7, 0.0, -1e7);
        let corners = [0.0, 20.123].map(|x| far + cga::DVec3::new(x, 0.0, 0.0));
        let lot = cga::lots::polygon(
            "far",
            &[
                corners[0],
                corners[1],
                corners[1] - cga::DVec3::Z * 15.5,
                corners[0] - cga::DVec3::Z * 15.5,
            ],
        );
        let origin = cga::lots::local_origin(std::slice::from_ref(&lot)).unwrap();
        let (results, _) = both(&rules, &[lot], &cga::Options::default(), origin.to_array());
        let bytes = model(&results, origin.to_array(), &mut |_| None);
        let (header, data) = split(&bytes);
        assert_eq!(header["origin"], json!([1e7 + 10.0, 0.0, -1e7 - 8.0]));
        let mesh = &header["lots"][0]["meshes"][0];
        let xs: Vec<f64> = decode_positions(mesh, data).iter().map(|p| p[0]).collect();
        let width = xs.iter().cloned().fold(f64::MIN, f64::max)
            - xs.iter().cloned().fold(f64::MAX, f64::min);
        // The largest side as exact as `f32` near the origin holds it
        // (micrometres; at 10,000 km it would be a metre).
        assert!((width - 20.123).abs() < 1e-5, "{width}");
    }

    #[test]
    fn page_values_take_the_attribute_type() {
        use cga::ValueType as T;
        assert_eq!(
            attr_value(Some(T::Float), &json!(3.5)),
            Some(Value::Float(3.5))
        );
        assert_eq!(
            attr_value(Some(T::Float), &json!("12")),
            Some(Value::Float(12.0))
        );
        assert_eq!(attr_value(Some(T::Float), &json!("tall")), None);
        assert_eq!(
            attr_value(Some(T::Str), &json!("#ff0000")),
            Some(Value::Str("#ff0000".into()))
        );
        assert_eq!(
            attr_value(Some(T::Bool), &json!(true)),
            Some(Value::Bool(true))
        );
        assert_eq!(attr_value(Some(T::Bool), &json!(1)), None);
        assert_eq!(value(&Value::Float(f64::NAN)), json!("NaN"));
    }
}
