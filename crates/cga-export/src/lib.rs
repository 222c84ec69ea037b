//! Model export: GLB, glTF (+ `.bin`) and OBJ + MTL.
//!
//! [`ModelWriter`] streams: the engine hands it one leaf shape's mesh at a
//! time ([`ModelWriter::add_mesh`]) and the writer keeps only what the output
//! needs, never the input meshes. Geometry is merged per distinct material
//! (materials compared by value), giving one glTF mesh (with one primitive)
//! or one OBJ `usemtl` group per material, so a city of thousands of
//! buildings has as many draw calls as it has materials, not shapes.
//!
//! Coordinates stay `f64` until written: glTF stores `f32`, OBJ stores
//! decimal text with six decimals.
//!
//! ```no_run
//! use cga_export::{ExportOptions, Format, ModelWriter};
//! # fn meshes() -> Vec<cga_geometry::Mesh> { Vec::new() }
//! let path = std::path::Path::new("city.glb");
//! let format = Format::from_path(path).unwrap();
//! let mut writer = ModelWriter::create(path, format, ExportOptions::default())?;
//! for mesh in meshes() {
//!     writer.add_mesh(&mesh)?;
//! }
//! let stats = writer.finish()?;
//! for w in &stats.warnings {
//!     eprintln!("warning: {w}");
//! }
//! # Ok::<(), cga_export::ExportError>(())
//! ```

pub mod builtin;
mod faces;
mod gltf;
mod hash;
mod materials;
mod obj;
mod textures;

use std::fmt;
use std::path::{Path, PathBuf};

use cga_geometry::{DVec3, Material, Mesh};

use crate::faces::{face_is_finite, face_normal};
use crate::materials::MaterialTable;
use crate::textures::Textures;

/// The triangulation every writer uses.
use cga_geometry::triangulate_face;

/// Output file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Binary glTF: one self-contained file.
    Glb,
    /// glTF JSON with its binary data in a `.bin` file beside it.
    Gltf,
    /// Wavefront OBJ with an `.mtl` material library beside it.
    Obj,
}

impl Format {
    /// The format an output path asks for by its extension (`.glb`, `.gltf`,
    /// `.obj`, in any case); `None` for anything else.
    pub fn from_path(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "glb" => Some(Format::Glb),
            "gltf" => Some(Format::Gltf),
            "obj" => Some(Format::Obj),
            _ => None,
        }
    }
}

/// How a model is written.
#[derive(Clone, Debug)]
pub struct ExportOptions {
    /// Folders in which texture paths that are not existing absolute paths
    /// are looked up, in order (typically the rule file's project folder).
    /// Empty: the current directory.
    pub texture_roots: Vec<PathBuf>,
    /// Make the output self-contained: GLB embeds texture images in its
    /// binary chunk; glTF and OBJ copy texture files next to the output and
    /// refer to them by file name. When `false`, the output refers to the
    /// texture files where they were found, by a path relative to the output
    /// folder.
    pub embed_textures: bool,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            texture_roots: Vec::new(),
            embed_textures: true,
        }
    }
}

/// What [`ModelWriter::finish`] wrote.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ExportStats {
    /// Vertices written (glTF: vertex count of all primitives; OBJ: `v` lines).
    pub vertices: u64,
    /// Triangles of the triangulated faces.
    pub triangles: u64,
    /// Input faces written (faces with at least 3 corners and non-zero area).
    pub faces: u64,
    /// Distinct materials written.
    pub materials: u64,
    /// Texture files embedded, copied or referenced.
    pub textures: u64,
    /// Problems that did not stop the export (missing textures, skipped
    /// faces), one line each.
    pub warnings: Vec<String>,
}

/// Why an export failed.
#[derive(Debug)]
pub enum ExportError {
    /// Reading or writing a file failed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A mesh's indices are inconsistent (out of range, attribute arrays of
    /// the wrong length).
    InvalidMesh(String),
    /// The model exceeds a limit of the format (glTF: 2^32 vertices per
    /// material, 4 GiB per GLB file; OBJ: 2^32 vertices).
    TooLarge(String),
}

impl ExportError {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> ExportError {
        ExportError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

impl fmt::Display for ExportError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExportError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            ExportError::InvalidMesh(msg) => write!(f, "invalid mesh: {msg}"),
            ExportError::TooLarge(msg) => write!(f, "model too large: {msg}"),
        }
    }
}

impl std::error::Error for ExportError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ExportError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// One face on its way to a writer: the triangulation and the normal are
/// computed once, by [`ModelWriter`], for every format.
pub(crate) struct FaceData<'a> {
    pub mesh: &'a Mesh,
    pub face: usize,
    /// Output material id.
    pub material: u32,
    /// Unit face normal (flat shading when the mesh has no normals).
    pub normal: DVec3,
    /// Triangles as indices into `mesh.corners`.
    pub triangles: &'a [[u32; 3]],
}

enum Sink {
    Gltf(gltf::GltfWriter),
    Obj(obj::ObjWriter),
}

/// Streams meshes into a GLB, glTF or OBJ file; see the crate docs.
///
/// Nothing is complete on disk until [`finish`](ModelWriter::finish)
/// returns: GLB and glTF are written there, OBJ writes its vertices as meshes
/// come and its faces and materials there.
pub struct ModelWriter {
    table: MaterialTable,
    textures: Textures,
    sink: Sink,
    /// Output material id of each material slot of the mesh being added
    /// (`UNSEEN` until a face uses the slot).
    slot_ids: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    stats: ExportStats,
    skipped_non_finite: u64,
}

const UNSEEN: u32 = u32::MAX;

impl ModelWriter {
    /// Creates the output file (and, for glTF and OBJ, claims the names of
    /// the `.bin` / `.mtl` files beside it, which `finish` writes).
    pub fn create(
        path: &Path,
        format: Format,
        options: ExportOptions,
    ) -> Result<ModelWriter, ExportError> {
        let out_dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let (sink, reserved) = match format {
            Format::Glb | Format::Gltf => {
                let w =
                    gltf::GltfWriter::create(path, format == Format::Glb, options.embed_textures)?;
                let reserved = w.file_names();
                (Sink::Gltf(w), reserved)
            }
            Format::Obj => {
                let w = obj::ObjWriter::create(path)?;
                let reserved = w.file_names();
                (Sink::Obj(w), reserved)
            }
        };
        let reserved: Vec<&str> = reserved.iter().map(String::as_str).collect();
        // GLB embeds images instead of copying them.
        let copy_textures = options.embed_textures && format != Format::Glb;
        let textures = Textures::new(&options.texture_roots, copy_textures, &out_dir, &reserved);
        Ok(ModelWriter {
            table: MaterialTable::default(),
            textures,
            sink,
            slot_ids: Vec::new(),
            triangles: Vec::new(),
            stats: ExportStats::default(),
            skipped_non_finite: 0,
        })
    }

    /// Adds one shape's geometry, in world coordinates. Faces with fewer
    /// than 3 corners (edges, points) and faces of zero area are left out;
    /// faces with non-finite coordinates are left out with a warning.
    pub fn add_mesh(&mut self, mesh: &Mesh) -> Result<(), ExportError> {
        check_mesh(mesh)?;
        self.slot_ids.clear();
        self.slot_ids.resize(mesh.materials.len(), UNSEEN);
        match &mut self.sink {
            Sink::Gltf(w) => w.begin_mesh(mesh),
            Sink::Obj(w) => w.begin_mesh(mesh),
        }
        for face in 0..mesh.faces.len() {
            if mesh.outer_loop(face).len < 3 {
                continue;
            }
            if !face_is_finite(mesh, face) {
                self.skipped_non_finite += 1;
                continue;
            }
            self.triangles.clear();
            triangulate_face(mesh, face, &mut self.triangles);
            if self.triangles.is_empty() {
                continue;
            }
            // No normal means zero area: nothing to see, and no valid normal
            // to write.
            let Some(normal) =
                face_normal(mesh, face).or_else(|| triangles_normal(mesh, &self.triangles))
            else {
                continue;
            };
            let slot = mesh.faces[face].material as usize;
            if self.slot_ids[slot] == UNSEEN {
                self.slot_ids[slot] = self.intern(&mesh.materials[slot]);
            }
            let data = FaceData {
                mesh,
                face,
                material: self.slot_ids[slot],
                normal,
                triangles: &self.triangles,
            };
            match &mut self.sink {
                Sink::Gltf(w) => w.add_face(&data)?,
                Sink::Obj(w) => w.add_face(&data)?,
            }
            self.stats.faces += 1;
            self.stats.triangles += self.triangles.len() as u64;
        }
        Ok(())
    }

    fn intern(&mut self, material: &Material) -> u32 {
        let (id, new) = self.table.intern(material);
        if new {
            let warnings = &mut self.stats.warnings;
            match &mut self.sink {
                Sink::Gltf(w) => w.new_material(material, &mut self.textures, warnings),
                Sink::Obj(w) => w.new_material(material, &mut self.textures, warnings),
            }
        }
        id
    }

    /// Writes everything that is still pending and closes the files.
    pub fn finish(mut self) -> Result<ExportStats, ExportError> {
        if self.skipped_non_finite > 0 {
            self.stats.warnings.push(format!(
                "{} face(s) with non-finite coordinates left out",
                self.skipped_non_finite
            ));
        }
        match self.sink {
            Sink::Gltf(w) => w.finish(&self.table, &self.textures, &mut self.stats)?,
            Sink::Obj(w) => w.finish(&self.table, &self.textures, &mut self.stats)?,
        }
        Ok(self.stats)
    }
}

/// Area-weighted normal of triangles, for faces whose outer loop alone is
/// degenerate.
fn triangles_normal(mesh: &Mesh, triangles: &[[u32; 3]]) -> Option<DVec3> {
    let p = |c: u32| mesh.positions[mesh.corners[c as usize] as usize];
    let n: DVec3 = triangles
        .iter()
        .map(|&[a, b, c]| (p(b) - p(a)).cross(p(c) - p(a)))
        .sum();
    n.try_normalize()
}

/// Rejects meshes whose indices would make a writer read out of bounds.
fn check_mesh(mesh: &Mesh) -> Result<(), ExportError> {
    let bad = |msg: String| Err(ExportError::InvalidMesh(msg));
    let corners = mesh.corners.len();
    if let Some(c) = mesh
        .corners
        .iter()
        .position(|&p| p as usize >= mesh.positions.len())
    {
        return bad(format!(
            "corner {c} refers to position {} of {}",
            mesh.corners[c],
            mesh.positions.len()
        ));
    }
    for (set, uvs) in mesh.uvs.iter().enumerate() {
        if let Some(uvs) = uvs {
            if uvs.len() != corners {
                return bad(format!(
                    "UV set {set} has {} entries for {corners} corners",
                    uvs.len()
                ));
            }
        }
    }
    if let Some(n) = &mesh.normals {
        if n.len() != corners {
            return bad(format!("{} normals for {corners} corners", n.len()));
        }
    }
    for (i, l) in mesh.loops.iter().enumerate() {
        if l.start as u64 + l.len as u64 > corners as u64 {
            return bad(format!("loop {i} runs past the {corners} corners"));
        }
    }
    for (i, f) in mesh.faces.iter().enumerate() {
        if f.loop_count == 0 || f.first_loop as u64 + f.loop_count as u64 > mesh.loops.len() as u64
        {
            return bad(format!("face {i} has loops out of range"));
        }
        if f.material as usize >= mesh.materials.len() {
            return bad(format!(
                "face {i} uses material slot {} of {}",
                f.material,
                mesh.materials.len()
            ));
        }
    }
    Ok(())
}
