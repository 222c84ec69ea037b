//! Shared helpers of the export tests: test meshes, a fresh output folder per
//! test, the Khronos glTF validator, and readers for what was written.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use cga_export::{ExportOptions, ExportStats, Format, ModelWriter};
use cga_geometry::{DVec2, DVec3, Material, Mesh};

/// An empty folder for one test's output, under cargo's scratch folder.
pub fn out_dir(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cga-export-tests")
        .join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

pub fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

/// Writes `meshes` to `path` (format from the extension).
pub fn write(path: &Path, meshes: &[Mesh], options: ExportOptions) -> ExportStats {
    let format = Format::from_path(path).unwrap();
    let mut w = ModelWriter::create(path, format, options).unwrap();
    for m in meshes {
        w.add_mesh(m).unwrap();
    }
    w.finish().unwrap()
}

/// A material of one colour.
pub fn colored(name: &str, color: [f64; 3]) -> Material {
    Material {
        name: name.into(),
        color,
        ..Material::default()
    }
}

/// Axis-aligned box from `min` with size `s`: 8 positions, 6 outward quads.
pub fn box_mesh(min: DVec3, s: DVec3, material: Material) -> Mesh {
    let mut m = Mesh::new();
    m.materials[0] = material;
    for (x, y, z) in [
        (0., 0., 0.),
        (1., 0., 0.),
        (1., 0., 1.),
        (0., 0., 1.),
        (0., 1., 0.),
        (1., 1., 0.),
        (1., 1., 1.),
        (0., 1., 1.),
    ] {
        m.positions.push(min + DVec3::new(x, y, z) * s);
    }
    for quad in [
        [0, 1, 2, 3], // -y
        [4, 7, 6, 5], // +y
        [0, 4, 5, 1], // -z
        [3, 2, 6, 7], // +z
        [0, 3, 7, 4], // -x
        [1, 5, 6, 2], // +x
    ] {
        m.add_face(&[&quad], 0);
    }
    m
}

/// A quad in the x-y plane facing +z, `w` by `h` at `origin`, with UVs
/// (0,0) (1,0) (1,1) (0,1) when `uvs`.
pub fn quad(origin: DVec3, w: f64, h: f64, material: Material, uvs: bool) -> Mesh {
    let mut m = Mesh::polygon(&[
        origin,
        origin + DVec3::new(w, 0.0, 0.0),
        origin + DVec3::new(w, h, 0.0),
        origin + DVec3::new(0.0, h, 0.0),
    ]);
    m.materials[0] = material;
    if uvs {
        m.uvs[0] = Some(vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.0, 1.0),
        ]);
    }
    m
}

/// A 4x4 square in the x-z plane (facing +y) with a 2x2 square hole:
/// area 12.
pub fn square_with_hole(material: Material) -> Mesh {
    let mut m = Mesh::new();
    m.materials[0] = material;
    m.positions.extend([
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(4.0, 0.0, 0.0),
        DVec3::new(4.0, 0.0, -4.0),
        DVec3::new(0.0, 0.0, -4.0),
        DVec3::new(1.0, 0.0, -1.0),
        DVec3::new(1.0, 0.0, -3.0),
        DVec3::new(3.0, 0.0, -3.0),
        DVec3::new(3.0, 0.0, -1.0),
    ]);
    m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
    m
}

/// A 2x2 RGBA PNG (red, green, blue, half-transparent white).
pub fn tiny_png() -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, 2, 2);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[
            255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128,
        ])
        .unwrap();
    }
    bytes
}

/// Runs the Khronos glTF validator on `file` and asserts that it reports no
/// errors and no warnings. Without the validator installed the check is
/// skipped with a note, unless `CGA_REQUIRE_GLTF_VALIDATOR=1` (as in CI).
pub fn assert_valid_gltf(file: &Path) {
    let tool = workspace_root().join("tools/gltf-validator");
    if !tool.join("node_modules/gltf-validator").is_dir() {
        if std::env::var("CGA_REQUIRE_GLTF_VALIDATOR").as_deref() == Ok("1") {
            panic!(
                "the glTF validator is not installed: run `npm ci --prefix tools/gltf-validator`"
            );
        }
        eprintln!(
            "note: glTF validator not installed (npm ci --prefix tools/gltf-validator); \
             not validating {}",
            file.display()
        );
        return;
    }
    let out = Command::new("node")
        .arg(tool.join("validate.mjs"))
        .arg(file)
        .output()
        .expect("cannot run node for the glTF validator");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "validator printed no report ({e}); stderr: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let issues = &report["issues"];
    assert_eq!(issues["numErrors"], 0, "validator errors: {report:#}");
    assert_eq!(issues["numWarnings"], 0, "validator warnings: {report:#}");
    assert!(out.status.success(), "validator exit status {}", out.status);
}

/// A parsed glTF/GLB with its binary buffer.
pub struct Gltf {
    pub doc: gltf::Document,
    pub bin: Vec<u8>,
}

pub fn read_gltf(path: &Path) -> Gltf {
    let bytes = std::fs::read(path).unwrap();
    let g = gltf::Gltf::from_slice(&bytes).unwrap();
    let bin = match g.blob {
        Some(blob) => blob,
        None => match g.document.buffers().next().map(|b| b.source()) {
            Some(gltf::buffer::Source::Uri(uri)) => {
                std::fs::read(path.parent().unwrap().join(uri)).unwrap()
            }
            Some(gltf::buffer::Source::Bin) => panic!("BIN buffer without a blob"),
            None => Vec::new(),
        },
    };
    Gltf {
        doc: g.document,
        bin,
    }
}

/// Vertex data of one primitive.
pub struct Prim {
    pub material: Option<usize>,
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Vec<u32>,
    pub min: Vec<f32>,
    pub max: Vec<f32>,
}

impl Prim {
    /// Sum of the triangle areas.
    pub fn area(&self) -> f64 {
        self.indices
            .chunks_exact(3)
            .map(|t| {
                let p = |i: u32| DVec3::from(self.positions[i as usize].map(f64::from));
                0.5 * (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0])).length()
            })
            .sum()
    }
}

pub fn primitives(g: &Gltf) -> Vec<Prim> {
    let mut out = Vec::new();
    for mesh in g.doc.meshes() {
        for p in mesh.primitives() {
            let r = p.reader(|_| Some(&g.bin[..]));
            let bounds = p.get(&gltf::Semantic::Positions).unwrap();
            out.push(Prim {
                material: p.material().index(),
                positions: r.read_positions().unwrap().collect(),
                normals: r.read_normals().unwrap().collect(),
                uvs: r.read_tex_coords(0).map(|t| t.into_f32().collect()),
                indices: r.read_indices().unwrap().into_u32().collect(),
                min: serde_json::from_value(bounds.min().unwrap()).unwrap(),
                max: serde_json::from_value(bounds.max().unwrap()).unwrap(),
            });
        }
    }
    out
}

/// What an OBJ + MTL file pair holds, read back the simple way.
#[derive(Debug, Default)]
pub struct Obj {
    pub v: Vec<DVec3>,
    pub vt: Vec<DVec2>,
    pub vn: Vec<DVec3>,
    /// Faces as (material name, corners as (v, vt, vn) 1-based; 0 = none).
    pub faces: Vec<(String, Vec<[usize; 3]>)>,
    /// `usemtl` statements in order.
    pub usemtl: Vec<String>,
    /// MTL statements per material: keyword → rest of the line.
    pub mtl: BTreeMap<String, BTreeMap<String, String>>,
}

impl Obj {
    /// Area per material (Newell's method per polygon).
    pub fn area_by_material(&self) -> BTreeMap<String, f64> {
        let mut out = BTreeMap::new();
        for (mat, corners) in &self.faces {
            let pts: Vec<DVec3> = corners.iter().map(|c| self.v[c[0] - 1]).collect();
            *out.entry(mat.clone()).or_insert(0.0) += polygon_area(&pts);
        }
        out
    }
}

pub fn polygon_area(pts: &[DVec3]) -> f64 {
    let mut n = DVec3::ZERO;
    for (i, a) in pts.iter().enumerate() {
        let b = pts[(i + 1) % pts.len()];
        n += a.cross(b);
    }
    0.5 * n.length()
}

pub fn read_obj(path: &Path) -> Obj {
    let mut obj = Obj::default();
    let mut current = String::new();
    let text = std::fs::read_to_string(path).unwrap();
    let nums = |rest: &[&str]| -> Vec<f64> { rest.iter().map(|t| t.parse().unwrap()).collect() };
    for line in text.lines() {
        let parts: Vec<&str> = line.split_whitespace().collect();
        let Some((&kw, rest)) = parts.split_first() else {
            continue;
        };
        match kw {
            "v" => obj.v.push(DVec3::from_slice(&nums(rest))),
            "vt" => obj.vt.push(DVec2::from_slice(&nums(rest))),
            "vn" => obj.vn.push(DVec3::from_slice(&nums(rest))),
            "usemtl" => {
                current = rest.join(" ");
                obj.usemtl.push(current.clone());
            }
            "f" => {
                let corners = rest
                    .iter()
                    .map(|c| {
                        let mut it = c.split('/').map(|x| x.parse().unwrap_or(0));
                        [0; 3].map(|_| it.next().unwrap_or(0))
                    })
                    .collect();
                obj.faces.push((current.clone(), corners));
            }
            "mtllib" => {
                let mtl = std::fs::read_to_string(path.with_file_name(rest.join(" "))).unwrap();
                let mut mat = String::new();
                for l in mtl.lines() {
                    let l = l.trim();
                    if let Some(name) = l.strip_prefix("newmtl ") {
                        mat = name.to_string();
                        obj.mtl.insert(mat.clone(), BTreeMap::new());
                    } else if let Some((k, v)) = l.split_once(' ') {
                        obj.mtl.get_mut(&mat).unwrap().insert(k.into(), v.into());
                    }
                }
            }
            "#" => {}
            other => panic!("unexpected OBJ statement {other}"),
        }
    }
    obj
}

/// The oracle's `summary.py` (`../shared/prt-oracle`, outside the
/// repository), or `None`, saying the test is skipped.
pub fn prt_summary_script() -> Option<PathBuf> {
    cga_testkit::shared("prt-oracle/summary.py")
}
