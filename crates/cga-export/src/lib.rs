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

mod array_pool;
mod bucket;
pub mod builtin;
mod direct_write;
mod draw;
mod encode;
mod faces;
mod gltf;
mod hash;
mod instances;
mod json_spool;
mod materials;
mod obj;
mod output_file;
mod plain;
mod prepare;
mod textures;

use std::fmt;
use std::path::{Path, PathBuf};

use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DVec3, Material, Mesh};

use std::sync::Arc;

use cga_world::World;

pub use crate::draw::{normal_byte, DrawFaces, DrawMesh, DrawModel, DrawNormals};
pub use crate::encode::{Encoded, Encoder};
use crate::encode::{EncoderShared, MeshEncoder};
pub use crate::gltf::{Output, DEFAULT_FLUSH_MIB};
use crate::materials::MaterialTable;
pub use crate::plain::{DrawCollector, PlainCollector, PlainMesh, PlainModel};
use crate::prepare::{FacePrep, SlotIds};
use crate::textures::{TextureProbe, Textures};
/// The JSON values of a lot's node `extras` ([`ModelWriter::begin_lot`]).
pub use serde_json;

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
#[derive(Clone)]
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
    /// Where the model's local frame lies on the globe, when the lots were
    /// given in longitude/latitude and projected to metres. Written into the
    /// output (glTF `asset.extras.georeference`, an OBJ header comment) so
    /// that models can be placed back.
    pub georeference: Option<Georeference>,
    /// glTF and GLB: vertex data held in memory before it is written out,
    /// in MiB (see `gltf`'s module docs): bounds memory for large models.
    pub flush_mib: usize,
    /// Where texture files are read from.
    pub world: Arc<dyn World>,
    /// How lots are kept apart in the model (see [`Granularity`]).
    pub granularity: Granularity,
    /// glTF and GLB: positions are written relative to this point of the
    /// model's frame (y up), and every node is translated by it, so that
    /// far from the frame's origin (a national grid's millions of metres)
    /// the 32-bit floats of glTF keep their millimetres: the point itself
    /// stays in double precision in the node's `translation` and in
    /// `asset.extras.origin`. OBJ writes full coordinates (its numbers are
    /// text) and ignores it.
    pub origin: Option<DVec3>,
    /// glTF and GLB: assets inserted with `i()` and left unchanged are
    /// written once per (mesh, materials) and placed as instances
    /// (`EXT_mesh_gpu_instancing`, see [`ModelWriter::add_asset`]); off,
    /// every placement is written as geometry of its own.
    pub instances: bool,
}

impl ExportOptions {
    /// The options with the origin moved to the nearest point whose
    /// coordinates are 32-bit floats: glTF's node translation is one, and
    /// positions must be relative to exactly what it says (whole metres are
    /// such floats up to 16,777 km).
    pub(crate) fn exact_origin(self) -> ExportOptions {
        ExportOptions {
            origin: self.origin.map(exact),
            ..self
        }
    }
}

/// An origin as the model keeps it: a point that 32-bit floats hold
/// exactly, so that positions relative to it and the origin add up to
/// the same point however they are stored.
pub(crate) fn exact(origin: DVec3) -> DVec3 {
    origin.as_vec3().as_dvec3()
}

/// How the output keeps lots apart.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Granularity {
    /// A lot is a node of its own (glTF, GLB: named by the lot, its index
    /// and attributes in the node's `extras`, a mesh with a primitive per
    /// material) or a group (OBJ `g`): a building can be picked out of a
    /// city. Lots are those begun with [`ModelWriter::begin_lot`].
    #[default]
    Lot,
    /// Everything merged by material: one glTF mesh per material, no OBJ
    /// groups. The fewest draw calls, and the smallest glTF JSON for
    /// cities of many thousand lots.
    Material,
}

impl std::str::FromStr for Granularity {
    type Err = String;
    fn from_str(s: &str) -> Result<Granularity, String> {
        match s {
            "lot" => Ok(Granularity::Lot),
            "material" => Ok(Granularity::Material),
            _ => Err(format!(
                "unknown granularity `{s}`: expected lot or material"
            )),
        }
    }
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            texture_roots: Vec::new(),
            embed_textures: true,
            georeference: None,
            flush_mib: gltf::DEFAULT_FLUSH_MIB,
            world: Arc::new(cga_world::DiskWorld),
            granularity: Granularity::Lot,
            origin: None,
            instances: true,
        }
    }
}

/// The geographic origin of a model's local metric frame: x is east, y up
/// and -z north, in metres, of the point (`longitude`, `latitude`) (WGS84
/// degrees), by the transverse Mercator projection on the WGS84 ellipsoid
/// centred there (scale 1 on the central meridian), `projection` as a PROJ
/// string.
#[derive(Clone, Debug, PartialEq)]
pub struct Georeference {
    pub longitude: f64,
    pub latitude: f64,
    pub projection: String,
}

impl Georeference {
    /// The record written into glTF `asset.extras`.
    fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "georeference": {
                "crs": "EPSG:4326",
                "origin": { "longitude": self.longitude, "latitude": self.latitude },
                "projection": self.projection,
                "axes": "x = easting, -z = northing, y = up (metres in the projection)",
            }
        })
    }

    /// The comment line written at the top of an OBJ file.
    fn obj_comment(&self) -> String {
        format!(
            "# georeference: origin longitude {} latitude {} (EPSG:4326); x east, y up, -z north in metres of {}",
            self.longitude, self.latitude, self.projection
        )
    }
}

/// glTF's `asset.extras`: the georeference of geographic lots, and the
/// origin positions are written from (see [`ExportOptions::origin`]).
fn asset_extras(options: &ExportOptions) -> Option<serde_json::Value> {
    let mut extras = options.georeference.as_ref().map(Georeference::to_json);
    if let Some(o) = options.origin {
        let record = serde_json::json!({
            "x": o.x, "y": o.y, "z": o.z,
            "note": "positions are relative to this point of the model frame (y up); nodes are translated by it",
        });
        extras.get_or_insert_with(|| serde_json::json!({}))["origin"] = record;
    }
    extras
}

/// What [`ModelWriter::finish`] wrote.
#[derive(Clone, Debug, Default, PartialEq)]
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
    /// glTF and GLB: the box around everything written (min, max; y up),
    /// and around each lot begun with [`ModelWriter::begin_lot`] with
    /// [`Granularity::Lot`] (`None` for a lot without geometry).
    pub bounds: Option<[[f64; 3]; 2]>,
    pub lot_bounds: Vec<Option<[[f64; 3]; 2]>>,
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
    /// Something asked of a writer that its kind does not do.
    Unsupported(String),
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
            ExportError::Unsupported(msg) => write!(f, "{msg}"),
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
/// computed once (`prepare::FacePrep`), for every format.
#[derive(Clone, Copy)]
pub(crate) struct FaceData<'a> {
    pub mesh: &'a Mesh,
    /// Where the mesh's vertices are placed (world coordinates): the mesh's
    /// own positions, or the placed copies the writer made.
    pub positions: &'a [DVec3],
    /// The per-corner normals as placed, if the mesh has normals.
    pub normals: Option<&'a [DVec3]>,
    /// The face's loops, the outer one first (`Mesh::face_loops`).
    pub loops: &'a [cga_geometry::Loop],
    /// Output material id (from `FacePrep`: the face's material slot, which
    /// the writer maps to its id).
    pub material: u32,
    /// Unit face normal, when it was worth computing: see
    /// [`normal`](FaceData::normal).
    pub known_normal: Option<DVec3>,
    /// Triangles as indices into `mesh.corners`.
    pub triangles: &'a [[u32; 3]],
    /// The place in the face's one loop of the corner its triangles fan
    /// out from, where the preparation knows it (see
    /// `plain::fan_start`, which reads the triangles otherwise).
    pub fan: Option<u32>,
}

impl FaceData<'_> {
    /// Unit face normal (flat shading when the mesh has no normals; where
    /// one of its own normals is zero when it has them). `FacePrep` leaves
    /// it to be computed here when a face with normals of its own may not
    /// need it (`prepare::deferred_normal`).
    #[inline]
    pub fn normal(&self) -> DVec3 {
        match self.known_normal {
            Some(n) => n,
            None => crate::prepare::deferred_normal(self),
        }
    }
}

enum Sink {
    /// glTF's faces are encoded here (`add_placed`) or by encoders of
    /// other threads ([`ModelWriter::append`]).
    Gltf(gltf::GltfWriter, Box<MeshEncoder>),
    Obj(obj::ObjWriter, FacePrep, SlotIds),
}

/// Streams meshes into a GLB, glTF or OBJ file; see the crate docs.
///
/// Nothing is complete on disk until [`finish`](ModelWriter::finish)
/// returns: GLB and glTF are written there, OBJ writes its vertices and
/// faces as meshes come and its materials there.
pub struct ModelWriter {
    table: MaterialTable,
    textures: Textures,
    /// What this writer's encoders share (glTF).
    encoders: Arc<EncoderShared>,
    sink: Sink,
    stats: ExportStats,
    skipped_non_finite: u64,
    granularity: Granularity,
}

impl ModelWriter {
    /// Creates the output file (and, for glTF and OBJ, claims the names of
    /// the `.bin` / `.mtl` files beside it, which `finish` writes).
    pub fn create(
        path: &Path,
        format: Format,
        options: ExportOptions,
    ) -> Result<ModelWriter, ExportError> {
        let options = options.exact_origin();
        let out_dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let (sink, reserved) = match format {
            Format::Glb | Format::Gltf => {
                let w = gltf::GltfWriter::create(
                    path,
                    format == Format::Glb,
                    options.embed_textures,
                    asset_extras(&options),
                    options.flush_mib,
                    options.granularity == Granularity::Lot,
                )?;
                let reserved = w.file_names();
                (Sink::Gltf(w, Box::default()), reserved)
            }
            Format::Obj => {
                let w = obj::ObjWriter::create(
                    path,
                    options.georeference.as_ref().map(Georeference::obj_comment),
                )?;
                let reserved = w.file_names();
                (
                    Sink::Obj(w, FacePrep::default(), SlotIds::default()),
                    reserved,
                )
            }
        };
        let reserved: Vec<&str> = reserved.iter().map(String::as_str).collect();
        // GLB embeds images instead of copying them.
        let copy_textures = options.embed_textures && format != Format::Glb;
        Ok(ModelWriter::with_sink(
            sink,
            &options,
            copy_textures,
            &out_dir,
            &reserved,
        ))
    }

    /// A GLB written into `out` (a `Cursor<Vec<u8>>`, a file opened for
    /// reading and writing, ...) instead of a file of its own; textures are
    /// embedded whatever `options.embed_textures` says (there is nowhere
    /// else to put them). `name` names the output in error messages.
    pub fn glb_into(
        out: impl Output + 'static,
        name: &str,
        options: ExportOptions,
    ) -> Result<ModelWriter, ExportError> {
        let options = options.exact_origin();
        let w = gltf::GltfWriter::new(
            Box::new(out),
            Path::new(name),
            true,
            true,
            asset_extras(&options),
            options.flush_mib,
            options.granularity == Granularity::Lot,
        );
        Ok(ModelWriter::with_sink(
            Sink::Gltf(w, Box::default()),
            &options,
            false,
            Path::new("."),
            &[],
        ))
    }

    fn with_sink(
        mut sink: Sink,
        options: &ExportOptions,
        copy_textures: bool,
        out_dir: &Path,
        reserved: &[&str],
    ) -> ModelWriter {
        let encoders = Arc::new(EncoderShared::new(
            TextureProbe::new(options.world.clone(), &options.texture_roots),
            options.origin,
            options.instances,
        ));
        let textures = Textures::new(
            options.world.clone(),
            &options.texture_roots,
            copy_textures,
            out_dir,
            reserved,
        );
        if let Sink::Gltf(w, encoder) = &mut sink {
            w.set_origin(options.origin);
            encoder.origin = options.origin;
        }
        ModelWriter {
            table: MaterialTable::default(),
            textures,
            encoders,
            sink,
            stats: ExportStats::default(),
            skipped_non_finite: 0,
            granularity: options.granularity,
        }
    }

    /// Adds one shape's geometry, in world coordinates. Faces with fewer
    /// than 3 corners (edges, points) and faces of zero area are left out;
    /// faces with non-finite coordinates are left out with a warning.
    pub fn add_mesh(&mut self, mesh: &Mesh) -> Result<(), ExportError> {
        self.add_placed(mesh, None, &mesh.materials)
    }

    /// Adds one shape's geometry given in its own coordinates, placed in the
    /// world by `transform` (positions mapped by it, normals by its inverse
    /// transpose, and faces reversed if it mirrors, exactly as
    /// `cga_geometry::transform::transform` and `reverse_faces` would), with
    /// `materials` for its material slots instead of the mesh's own. The
    /// output is the same as adding the transformed mesh with those
    /// materials, without copying it: shapes that share one mesh (inserted
    /// assets, copies) are written from that one mesh.
    pub fn add_placed(
        &mut self,
        mesh: &Mesh,
        transform: Option<&DAffine3>,
        materials: &SharedVec<Material>,
    ) -> Result<(), ExportError> {
        match &mut self.sink {
            Sink::Gltf(w, encoder) => {
                w.flush_if_full()?;
                let mut store = gltf::ModelBuckets {
                    writer: w,
                    table: &mut self.table,
                    textures: &mut self.textures,
                    warnings: &mut self.stats.warnings,
                };
                let c = encoder.encode(mesh, transform, materials, &mut store)?;
                w.hold(c.bytes);
                self.stats.faces += c.faces;
                self.stats.triangles += c.triangles;
                self.skipped_non_finite += c.skipped_non_finite;
                Ok(())
            }
            Sink::Obj(w, prep, slots) => {
                check_mesh(mesh, materials.len())?;
                let (table, textures, stats) =
                    (&mut self.table, &mut self.textures, &mut self.stats);
                w.begin_mesh(mesh);
                slots.begin(materials);
                let result = prep.faces(mesh, transform, |f| {
                    let material = slots.id(f.material, || {
                        let (id, new) = table.intern(&materials[f.material as usize]);
                        if new {
                            w.new_material(
                                table.name(id),
                                table.get(id),
                                textures,
                                &mut stats.warnings,
                            );
                        }
                        id
                    });
                    w.add_face(&FaceData { material, ..*f })?;
                    stats.faces += 1;
                    stats.triangles += f.triangles.len() as u64;
                    Ok(())
                });
                slots.end(materials);
                self.skipped_non_finite += result?;
                Ok(())
            }
        }
    }

    /// Adds an inserted asset as loaded (the engine's `Leaf::asset`: a mesh
    /// shared by every insert of the asset), placed by `transform`, with
    /// `materials`. glTF and GLB with [`ExportOptions::instances`] write
    /// the mesh once per (mesh, materials) and each placement that is a
    /// rotation and scale as an instance (`EXT_mesh_gpu_instancing`); other
    /// placements, and OBJ, as [`add_placed`](Self::add_placed) does.
    pub fn add_asset(
        &mut self,
        mesh: &Arc<Mesh>,
        transform: &DAffine3,
        materials: &SharedVec<Material>,
    ) -> Result<(), ExportError> {
        let instancing = matches!(self.sink, Sink::Gltf(..)) && self.encoders.instancing;
        match encode::instance(instancing, mesh, transform, materials) {
            Some(p) => self.place(p),
            None => self.add_placed(mesh, Some(transform), materials),
        }
    }

    /// Places an instance: its group found, or made by encoding its mesh.
    fn place(&mut self, p: instances::Pending) -> Result<(), ExportError> {
        let Sink::Gltf(w, _) = &mut self.sink else {
            return self.add_placed(&p.mesh, Some(&p.transform), &p.materials);
        };
        let group = match w.instances.find(&p.mesh, &p.materials) {
            Some(g) => g,
            None => {
                check_mesh(&p.mesh, p.materials.len())?;
                let mut store = gltf::GroupBuckets {
                    writer: w,
                    table: &mut self.table,
                    textures: &mut self.textures,
                    warnings: &mut self.stats.warnings,
                    buckets: Vec::new(),
                };
                let c = MeshEncoder::default().encode(&p.mesh, None, &p.materials, &mut store)?;
                let buckets = store.buckets;
                self.skipped_non_finite += c.skipped_non_finite;
                w.instances.add_group(
                    p.mesh.clone(),
                    p.materials.clone(),
                    buckets,
                    c.faces,
                    c.triangles,
                )
            }
        };
        let g = &w.instances.groups[group as usize];
        self.stats.faces += g.faces;
        self.stats.triangles += g.triangles;
        w.place_instance(group, &p);
        Ok(())
    }

    /// Triangles added so far (instances counted per placement).
    pub fn triangles(&self) -> u64 {
        self.stats.triangles
    }

    /// Gives the vertices of each lot begun the lot's feature id (also
    /// when merged by material), and writes a property table of the lots (index,
    /// name, attributes): `EXT_mesh_features` and
    /// `EXT_structural_metadata`, with which 3D Tiles viewers pick a
    /// building and show what it is. glTF and GLB only.
    pub fn with_features(&mut self) {
        if let Sink::Gltf(w, _) = &mut self.sink {
            w.with_features();
        }
    }

    /// Says how many lots will be begun ([`begin_lot`](Self::begin_lot)):
    /// a GLB with a node per lot then leaves room for their JSON at the
    /// start, instead of moving its binary data up at the end.
    pub fn expect_lots(&mut self, lots: usize) {
        if let Sink::Gltf(w, _) = &mut self.sink {
            w.expect_lots(lots);
        }
    }

    /// Starts the output of a lot: what is added from now on belongs to it.
    /// With [`Granularity::Lot`] it is a glTF node named `name` with
    /// `extras` (for instance its index and attributes), or an OBJ group;
    /// with [`Granularity::Material`] nothing changes.
    pub fn begin_lot(
        &mut self,
        name: &str,
        extras: Option<serde_json::Value>,
    ) -> Result<(), ExportError> {
        match &mut self.sink {
            Sink::Obj(w, ..) if self.granularity == Granularity::Lot => w.begin_group(name),
            Sink::Obj(..) => Ok(()),
            // Merged by material, a lot still has its feature id when
            // features are on.
            Sink::Gltf(w, _) => w.begin_lot(name, extras),
        }
    }

    /// Sets `key` of the `extras` of the lot begun last (glTF and GLB: its
    /// node's `extras` with [`Granularity::Lot`], its row of the property
    /// table with features; `"reports"` there, an object of numbers or
    /// strings, becomes a property per key). OBJ ignores it.
    pub fn annotate_lot(&mut self, key: &str, value: serde_json::Value) {
        if let Sink::Gltf(w, _) = &mut self.sink {
            w.annotate_lot(key, value);
        }
    }

    /// An encoder for this writer's format, for another thread: it does the
    /// work of [`add_placed`](ModelWriter::add_placed) there, and
    /// [`append`](ModelWriter::append) adds its batches. `None` for OBJ,
    /// whose meshes are added here.
    pub fn encoder(&self) -> Option<Encoder> {
        match self.sink {
            Sink::Gltf(..) => Some(Encoder::new(self.encoders.clone())),
            Sink::Obj(..) => None,
        }
    }

    /// Adds a batch of meshes an [`Encoder`] of this writer encoded: the
    /// output is what adding the same meshes here, in the same order, gives.
    /// Fails if a mesh in it was invalid.
    pub fn append(&mut self, mut batch: Encoded) -> Result<(), ExportError> {
        if let Some(e) = batch.error.take() {
            return Err(e);
        }
        let Sink::Gltf(w, _) = &mut self.sink else {
            return Err(ExportError::InvalidMesh(
                "encoded glTF data given to an OBJ writer".into(),
            ));
        };
        if let Some(pool) = &batch.pool {
            w.return_arrays_to(pool);
        }
        // The batch's materials in their order of first use: interned in
        // that order, they get the ids the faces would have given them.
        for (material, data) in batch.materials.iter().zip(&mut batch.buckets) {
            let (id, new) = self.table.intern(material);
            if new {
                w.new_material(
                    self.table.get(id),
                    &mut self.textures,
                    &mut self.stats.warnings,
                );
            }
            w.append(id, data)?;
        }
        self.stats.faces += batch.faces;
        self.stats.triangles += batch.triangles;
        self.skipped_non_finite += batch.skipped_non_finite;
        for p in batch.instances.drain(..) {
            self.place(p)?;
        }
        Ok(())
    }

    /// Writes everything that is still pending and closes the files.
    pub fn finish(self) -> Result<ExportStats, ExportError> {
        Ok(self.finish_into()?.0)
    }

    /// [`finish`](ModelWriter::finish), giving back the stream a GLB was
    /// written into ([`glb_into`](ModelWriter::glb_into)); `None` for OBJ.
    pub fn finish_into(mut self) -> Result<(ExportStats, Option<Box<dyn Output>>), ExportError> {
        if self.skipped_non_finite > 0 {
            self.stats.warnings.push(format!(
                "{} face(s) with non-finite coordinates left out",
                self.skipped_non_finite
            ));
        }
        let out = match self.sink {
            Sink::Gltf(w, _) => Some(w.finish(&self.table, &self.textures, &mut self.stats)?),
            Sink::Obj(w, ..) => {
                w.finish(&self.table, &self.textures, &mut self.stats)?;
                None
            }
        };
        Ok((self.stats, out))
    }

    /// A GLB written into memory; [`finish_bytes`](ModelWriter::finish_bytes)
    /// gives its bytes.
    pub fn glb_in_memory(options: ExportOptions) -> Result<ModelWriter, ExportError> {
        ModelWriter::glb_into(std::io::Cursor::new(Vec::new()), "model.glb", options)
    }

    /// Finishes a writer made by [`glb_in_memory`](ModelWriter::glb_in_memory)
    /// and gives the GLB's bytes.
    pub fn finish_bytes(self) -> Result<(Vec<u8>, ExportStats), ExportError> {
        let (stats, out) = self.finish_into()?;
        let bytes = out
            .and_then(|o| o.into_any().downcast::<std::io::Cursor<Vec<u8>>>().ok())
            .map(|c| c.into_inner())
            .ok_or_else(|| {
                ExportError::Unsupported("the model was not written into memory".into())
            })?;
        Ok((bytes, stats))
    }
}

/// Rejects meshes whose indices would make a writer read out of bounds.
fn check_mesh(mesh: &Mesh, material_slots: usize) -> Result<(), ExportError> {
    let bad = |msg: String| Err(ExportError::InvalidMesh(msg));
    let corners = mesh.corners.len();
    // Every leaf is checked: the passes below look at all entries without
    // stopping early (which the compiler vectorises) and look for the
    // culprit only when one is out of range.
    let in_range = |max: Option<u32>, len: usize| max.is_none_or(|m| (m as usize) < len);
    if !in_range(mesh.corners.iter().copied().max(), mesh.positions.len()) {
        let c = mesh
            .corners
            .iter()
            .position(|&p| p as usize >= mesh.positions.len())
            .unwrap_or_default();
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
    let loop_past = |l: &cga_geometry::Loop| l.start as u64 + l.len as u64 > corners as u64;
    if mesh.loops.iter().fold(false, |bad, l| bad | loop_past(l)) {
        let i = mesh.loops.iter().position(loop_past).unwrap_or_default();
        return bad(format!("loop {i} runs past the {corners} corners"));
    }
    let loops_out = |f: &cga_geometry::Face| {
        f.loop_count == 0 || f.first_loop as u64 + f.loop_count as u64 > mesh.loops.len() as u64
    };
    let slot_out = |f: &cga_geometry::Face| f.material as usize >= material_slots;
    if mesh
        .faces
        .iter()
        .fold(false, |bad, f| bad | loops_out(f) | slot_out(f))
    {
        for (i, f) in mesh.faces.iter().enumerate() {
            if loops_out(f) {
                return bad(format!("face {i} has loops out of range"));
            }
            if slot_out(f) {
                return bad(format!(
                    "face {i} uses material slot {} of {material_slots}",
                    f.material,
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use cga_geometry::{DMat3, DVec2, TextureChannel};

    /// A mesh with a quad, a concave pentagon and a square with a hole,
    /// per-corner normals on one face's worth of corners and two UV sets.
    fn sample() -> Mesh {
        let mut m = Mesh::new();
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        m.positions.extend([
            p(0., 0., 0.),
            p(2., 0., 0.),
            p(2., 1., 0.),
            p(0., 1., 0.),
            p(3., 0., 0.),
            p(5., 0., 0.),
            p(5., 2., 0.),
            p(4., 0.5, 0.),
            p(3., 2., 0.),
            p(6., 0., 1.),
            p(10., 0., 1.),
            p(10., 4., 1.),
            p(6., 4., 1.),
            p(7., 1., 1.),
            p(7., 3., 1.),
            p(9., 3., 1.),
            p(9., 1., 1.),
        ]);
        m.add_face(&[&[0, 1, 2, 3]], 0);
        m.add_face(&[&[4, 5, 6, 7, 8]], 1);
        m.add_face(&[&[9, 10, 11, 12], &[13, 14, 15, 16]], 0);
        let n = m.corners.len();
        m.uvs[0] = Some(
            (0..n)
                .map(|i| DVec2::new(i as f64 * 0.25, 1.0 - i as f64 * 0.125))
                .collect(),
        );
        m.uvs[5] = Some((0..n).map(|i| DVec2::new(0.5, i as f64)).collect());
        m.normals = Some(
            (0..n)
                .map(|i| DVec3::new(0.1 * i as f64, 0.0, 1.0))
                .collect(),
        );
        let brick = Material {
            maps: std::array::from_fn(|k| TextureChannel {
                path: if k == 0 {
                    "missing.png".into()
                } else {
                    "".into()
                },
                ..TextureChannel::default()
            }),
            ..Material::default()
        };
        m.materials = vec![
            brick,
            Material {
                color: [0.2, 0.4, 0.6],
                ..Material::default()
            },
        ]
        .into();
        m
    }

    fn written(format: Format, name: &str, add: impl Fn(&mut ModelWriter)) -> Vec<u8> {
        // One name in separate folders: OBJ files name their MTL file.
        let dir = std::env::temp_dir().join(format!("cga-export-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ext = if format == Format::Obj { "obj" } else { "glb" };
        let path = dir.join(format!("model.{ext}"));
        let mut w = ModelWriter::create(&path, format, ExportOptions::default()).unwrap();
        add(&mut w);
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        bytes
    }

    #[test]
    fn placing_writes_what_the_transformed_mesh_writes() {
        let mesh = sample();
        let other: SharedVec<Material> = vec![
            Material {
                color: [0.9, 0.1, 0.1],
                ..Material::default()
            },
            Material {
                opacity: 0.5,
                ..Material::default()
            },
        ]
        .into();
        let turn = DMat3::from_rotation_y(0.7) * DMat3::from_diagonal(DVec3::new(1.5, 0.5, 2.0));
        for (k, t) in [
            DAffine3::from_mat3_translation(turn, DVec3::new(100.0, -3.0, 7.5)),
            // Mirrored: the faces must come out reversed.
            DAffine3::from_mat3_translation(
                DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0)) * turn,
                DVec3::new(-4.0, 2.0, 0.25),
            ),
        ]
        .iter()
        .enumerate()
        {
            for format in [Format::Glb, Format::Obj] {
                let baked = written(format, &format!("baked{k}"), |w| {
                    let mut m = mesh.clone();
                    cga_geometry::transform::transform(&mut m, t);
                    if t.matrix3.determinant() < 0.0 {
                        cga_geometry::transform::reverse_faces(&mut m);
                    }
                    w.add_mesh(&m).unwrap();
                    m.materials = other.clone();
                    w.add_mesh(&m).unwrap();
                });
                let placed = written(format, &format!("placed{k}"), |w| {
                    w.add_placed(&mesh, Some(t), &mesh.materials).unwrap();
                    w.add_placed(&mesh, Some(t), &other).unwrap();
                });
                assert!(baked.len() > 1000);
                assert!(baked == placed, "transform {k}, {format:?}: outputs differ");
            }
        }
    }

    #[test]
    fn an_origin_moves_positions_into_the_node_translation() {
        // A unit square far away, written from an origin that is not a
        // 32-bit float: the writer moves the origin to one first.
        let far = DVec3::new(5_000_000.3, 2.0, -7_000_000.7);
        let mut mesh = Mesh::polygon(&[
            far,
            far + DVec3::X,
            far + DVec3::new(1.0, 0.0, -1.0),
            far + DVec3::new(0.0, 0.0, -1.0),
        ]);
        mesh.materials = vec![Material::default()].into();
        let options = ExportOptions {
            origin: Some(DVec3::new(5_000_000.3, 0.0, -7_000_000.7)),
            ..ExportOptions::default()
        };
        let mut w = ModelWriter::glb_in_memory(options).unwrap();
        w.begin_lot("far", None).unwrap();
        w.add_mesh(&mesh).unwrap();
        let (bytes, stats) = w.finish_bytes().unwrap();
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
        let t: Vec<f64> = json["nodes"][0]["translation"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        // The translation is exactly the 32-bit float nearest the origin.
        assert_eq!(t, [5_000_000.5, 0.0, -7_000_000.5]);
        assert_eq!(json["asset"]["extras"]["origin"]["z"], -7_000_000.5);
        let min: Vec<f64> = json["accessors"][0]["min"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert!(
            (min[0] - -0.2).abs() < 1e-6 && (min[1] - 2.0).abs() < 1e-6,
            "{min:?}"
        );
        assert!((min[2] - -1.2).abs() < 1e-6, "{min:?}");
        // The stats' boxes are in the model's frame.
        let [lo, hi] = stats.bounds.unwrap();
        assert!(
            (lo[0] - far.x).abs() < 1e-6 && (hi[2] - far.z).abs() < 1e-6,
            "{lo:?} {hi:?}"
        );
        assert_eq!(stats.lot_bounds.len(), 1);
        assert_eq!(stats.lot_bounds[0], stats.bounds);
    }

    #[test]
    fn placing_checks_the_material_slots_given() {
        let dir = std::env::temp_dir().join(format!("cga-export-slots-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.glb");
        let mut w = ModelWriter::create(&path, Format::Glb, ExportOptions::default()).unwrap();
        let mesh = sample();
        let one: SharedVec<Material> = vec![Material::default()].into();
        let r = w.add_placed(&mesh, Some(&DAffine3::IDENTITY), &one);
        assert!(
            matches!(r, Err(ExportError::InvalidMesh(m)) if m.contains("material slot 1 of 1"))
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
