//! Loading glTF 2.0 assets (`.gltf` with external or base64 buffers, and
//! `.glb`) into a [`Mesh`], with the `gltf` crate, as CGA's `i()` reads
//! them (op_i.md: "The full scene graph will be imported including
//! transformation nodes and multiple texture coordinate sets").
//!
//! What is read: the default scene (else the first; a file without scenes
//! inserts every mesh once), its nodes' transforms, the triangles of each
//! primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`; points and
//! lines are not surfaces), positions, normals, texture coordinates of set
//! 0 (flipped to CGA's bottom-left origin) and the base colour of each
//! material (its factor taken from glTF's linear values back to CGA's
//! colour with the curve the GLB writer uses, and its texture when it is an
//! image file next to the asset). glTF is in metres with +y up, as CGA.
//! Images stored inside the file are not read (a warning), as
//! CityEngine does not read base64 images either.

use std::path::Path;
use std::sync::Arc;

use base64::Engine as _;
use glam::{DAffine3, DMat4, DVec2, DVec3};
use gltf::mesh::Mode;

use crate::asset_mesh::{percent_decode, MeshBuilder, Placement, ReadFile};
use crate::material::Material;
use crate::obj::{ObjAsset, ObjError};

/// Node nesting followed at most (a malformed file may loop).
const MAX_DEPTH: usize = 64;

/// Loads a `.gltf` or `.glb` file from disk; external buffers and images
/// are read relative to its folder.
pub fn load_gltf(path: &Path) -> Result<ObjAsset, ObjError> {
    let bytes = std::fs::read(path).map_err(|e| ObjError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_gltf(&bytes, &dir, &|p: &Path| {
        std::fs::read(p).map_err(|e| format!("cannot read '{}': {e}", p.display()))
    })
}

/// Parses glTF JSON or GLB bytes; `dir` is the folder external buffers and
/// images are relative to, `read` reads external buffers.
pub fn parse_gltf(bytes: &[u8], dir: &Path, read: &ReadFile) -> Result<ObjAsset, ObjError> {
    let bad = |message: String| ObjError::Parse { line: 0, message };
    let gltf = gltf::Gltf::from_slice(bytes).map_err(|e| bad(format!("not a glTF file: {e}")))?;
    let mut warnings = Vec::new();
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in gltf.document.buffers() {
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => gltf.blob.clone().unwrap_or_default(),
            gltf::buffer::Source::Uri(uri) => read_uri(uri, dir, read).map_err(bad)?,
        };
        if data.len() < buffer.length() {
            return Err(bad(format!(
                "buffer {} holds {} bytes, fewer than its length {}",
                buffer.index(),
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    let mut r = Reader {
        buffers: &buffers,
        dir,
        b: MeshBuilder::new(),
        materials: Vec::new(),
        warnings: &mut warnings,
    };
    let doc = &gltf.document;
    match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => {
            for node in scene.nodes() {
                r.node(&node, DAffine3::IDENTITY, 0);
            }
        }
        None => {
            for mesh in doc.meshes() {
                let name = mesh.name().unwrap_or("").to_string();
                r.mesh(&mesh, DAffine3::IDENTITY, &name);
            }
        }
    }
    let mesh = r.b.finish();
    Ok(ObjAsset { mesh, warnings })
}

/// The bytes of a buffer URI: base64 data or a file next to the asset.
fn read_uri(uri: &str, dir: &Path, read: &ReadFile) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (_, data) = rest
            .split_once(";base64,")
            .ok_or_else(|| "a data URI that is not base64".to_string())?;
        return base64::engine::general_purpose::STANDARD
            .decode(data)
            .map_err(|e| format!("bad base64 buffer: {e}"));
    }
    read(&dir.join(percent_decode(uri)))
}

struct Reader<'a> {
    buffers: &'a [Vec<u8>],
    dir: &'a Path,
    b: MeshBuilder,
    /// Material slots by glTF material index (`None`: the default material).
    materials: Vec<(Option<usize>, u32)>,
    warnings: &'a mut Vec<String>,
}

impl Reader<'_> {
    fn node(&mut self, node: &gltf::Node, parent: DAffine3, depth: usize) {
        if depth > MAX_DEPTH {
            self.warnings.push(format!(
                "nodes nested deeper than {MAX_DEPTH}; the rest is skipped"
            ));
            return;
        }
        let m = node.transform().matrix();
        let local = DAffine3::from_mat4(DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from))));
        let xf = parent * local;
        if let Some(mesh) = node.mesh() {
            let name = node.name().or(mesh.name()).unwrap_or("").to_string();
            self.mesh(&mesh, xf, &name);
        }
        for c in node.children() {
            self.node(&c, xf, depth + 1);
        }
    }

    fn mesh(&mut self, mesh: &gltf::Mesh, xf: DAffine3, name: &str) {
        let place = Placement::new(xf);
        let group = self.b.group(name);
        for prim in mesh.primitives() {
            let mode = prim.mode();
            if !matches!(
                mode,
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                continue;
            }
            let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
            let Some(positions) = reader.read_positions() else {
                continue;
            };
            let pos: Vec<DVec3> = positions
                .map(|p| place.point(DVec3::from(p.map(f64::from))))
                .collect();
            let n = pos.len() as u32;
            let base = self.b.positions(pos);
            let normals: Option<Vec<DVec3>> = reader.read_normals().map(|it| {
                it.map(|v| place.normal(DVec3::from(v.map(f64::from))))
                    .collect()
            });
            let uvs: Option<Vec<DVec2>> = reader.read_tex_coords(0).map(|t| {
                t.into_f32()
                    .map(|[u, v]| DVec2::new(f64::from(u), 1.0 - f64::from(v)))
                    .collect()
            });
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..n).collect(),
            };
            let tris: Vec<[u32; 3]> = match mode {
                Mode::Triangles => indices
                    .chunks_exact(3)
                    .map(|t| [t[0], t[1], t[2]])
                    .collect(),
                Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                    .map(|k| {
                        let (a, b, c) = (indices[k], indices[k + 1], indices[k + 2]);
                        if k % 2 == 0 {
                            [a, b, c]
                        } else {
                            [b, a, c]
                        }
                    })
                    .collect(),
                _ => (1..indices.len().saturating_sub(1))
                    .map(|k| [indices[0], indices[k], indices[k + 1]])
                    .collect(),
            };
            let material = self.material_slot(&prim.material());
            let mut dropped = 0usize;
            for mut t in tris {
                if t.iter().any(|&i| i >= n) {
                    dropped += 1;
                    continue;
                }
                if place.mirrors() {
                    t.swap(1, 2);
                }
                let idx = t.map(|i| base + i);
                let nv = normals.as_ref().map(|v| t.map(|i| v[i as usize]));
                let tv = uvs
                    .as_ref()
                    .and_then(|v| (v.len() == n as usize).then(|| t.map(|i| v[i as usize])));
                if !self.b.polygon(
                    &idx,
                    tv.as_ref().map(|x| x.as_slice()),
                    nv.as_ref().map(|x| x.as_slice()),
                    material,
                    group,
                ) {
                    dropped += 1;
                }
            }
            if dropped > 0 {
                self.warnings.push(format!(
                    "mesh \"{name}\": {dropped} triangle(s) with indices out of range or repeated corners skipped"
                ));
            }
        }
    }

    fn material_slot(&mut self, m: &gltf::Material) -> u32 {
        if let Some(&(_, slot)) = self.materials.iter().find(|(i, _)| *i == m.index()) {
            return slot;
        }
        let pbr = m.pbr_metallic_roughness();
        let f = pbr.base_color_factor();
        // glTF holds linear values; CGA colours are non-linear (the GLB
        // writer raises them to the power 2.2).
        let to_cga = |c: f32| f64::from(c).clamp(0.0, 1.0).powf(1.0 / 2.2);
        let mut mat = Material {
            name: Arc::from(m.name().unwrap_or("")),
            color: [to_cga(f[0]), to_cga(f[1]), to_cga(f[2])],
            opacity: f64::from(f[3]).clamp(0.0, 1.0),
            metallic: f64::from(pbr.metallic_factor()).clamp(0.0, 1.0),
            roughness: f64::from(pbr.roughness_factor()).clamp(0.0, 1.0),
            double_sided: m.double_sided(),
            ..Material::default()
        };
        if let Some(info) = pbr.base_color_texture() {
            match info.texture().source().source() {
                gltf::image::Source::Uri { uri, .. } if !uri.starts_with("data:") => {
                    let p = self.dir.join(percent_decode(uri));
                    mat.maps[0].path = Arc::from(p.to_string_lossy().as_ref());
                }
                _ => self.warnings.push(format!(
                    "material \"{}\": its texture is stored inside the file, which is not read; the material keeps its colour",
                    m.name().unwrap_or("")
                )),
            }
        }
        let slot = self.b.material(mat);
        self.materials.push((m.index(), slot));
        slot
    }
}
