//! Helpers shared by the `cga` command's tests: running the binary and
//! summarising an OBJ model the way the conformance goldens do.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn cga() -> Command {
    Command::new(env!("CARGO_BIN_EXE_cga"))
}

pub fn run(args: &[&str]) -> Output {
    cga().args(args).output().expect("the cga binary runs")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A fresh, empty directory for one test's files.
pub fn temp_dir(name: &str) -> TempDir {
    let dir = std::env::temp_dir().join(format!("cga-cli-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    TempDir(dir)
}

/// A test's directory, removed when the test is done with it, unless the
/// test failed (its files are then left to look at). The suite writes
/// about 150 MB of models a run.
pub struct TempDir(PathBuf);

impl std::ops::Deref for TempDir {
    type Target = PathBuf;

    fn deref(&self) -> &PathBuf {
        &self.0
    }
}

impl AsRef<Path> for TempDir {
    fn as_ref(&self) -> &Path {
        &self.0
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if !std::thread::panicking() {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// Writes a rule file into `dir` and returns its path.
pub fn rule_file(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

pub fn manifest_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The engine-neutral summary of an OBJ model: bounding box, face count,
/// total area and area per appearance (diffuse colour with 3 decimals and
/// the diffuse texture's file name, or `-`).
#[derive(Debug, Default)]
pub struct Summary {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub faces: usize,
    pub area: f64,
    pub by_appearance: BTreeMap<String, f64>,
}

pub fn summarize(obj: &Path) -> Summary {
    summarize_rounded(obj, None)
}

/// [`summarize`] with vertex coordinates rounded to `decimals` first, as
/// CityEngine's OBJ writer rounds them (3 decimals): comparing with its
/// goldens, both models are then measured from the same rounded points.
pub fn summarize_rounded(obj: &Path, decimals: Option<i32>) -> Summary {
    let scale = decimals.map(|d| 10f64.powi(d));
    let dir = obj.parent().unwrap();
    let text = std::fs::read_to_string(obj).expect("the OBJ file exists");
    let mut mats: BTreeMap<String, ([f64; 3], String)> = BTreeMap::new();
    let mut verts: Vec<[f64; 3]> = Vec::new();
    let mut s = Summary {
        min: [f64::INFINITY; 3],
        max: [f64::NEG_INFINITY; 3],
        ..Summary::default()
    };
    let mut look = "1.000,1.000,1.000|-".to_string();
    for line in text.lines() {
        let p: Vec<&str> = line.split_whitespace().collect();
        match p.first().copied() {
            Some("mtllib") => {
                let mtl = std::fs::read_to_string(dir.join(p[1..].join(" "))).unwrap_or_default();
                let mut cur = String::new();
                for l in mtl.lines() {
                    let q: Vec<&str> = l.split_whitespace().collect();
                    match q.first().copied() {
                        Some("newmtl") => {
                            cur = q[1..].join(" ");
                            mats.insert(cur.clone(), ([1.0; 3], "-".into()));
                        }
                        Some("Kd") if q.len() >= 4 => {
                            let e = mats.get_mut(&cur).unwrap();
                            for k in 0..3 {
                                e.0[k] = q[k + 1].parse().unwrap();
                            }
                        }
                        Some("map_Kd") => {
                            let name = Path::new(q.last().unwrap())
                                .file_name()
                                .unwrap()
                                .to_string_lossy()
                                .into_owned();
                            mats.get_mut(&cur).unwrap().1 = name;
                        }
                        _ => {}
                    }
                }
            }
            Some("v") => {
                let v = [0, 1, 2].map(|k| {
                    let x = p[k + 1].parse::<f64>().unwrap();
                    scale.map_or(x, |f| (x * f).round() / f)
                });
                for (k, x) in v.iter().enumerate() {
                    s.min[k] = s.min[k].min(*x);
                    s.max[k] = s.max[k].max(*x);
                }
                verts.push(v);
            }
            Some("usemtl") => {
                let (kd, map) = mats
                    .get(&p[1..].join(" "))
                    .cloned()
                    .unwrap_or(([1.0; 3], "-".into()));
                look = format!("{:.3},{:.3},{:.3}|{}", kd[0], kd[1], kd[2], map);
            }
            Some("f") => {
                let pts: Vec<[f64; 3]> = p[1..]
                    .iter()
                    .map(|t| {
                        let i: i64 = t.split('/').next().unwrap().parse().unwrap();
                        let i = if i > 0 {
                            i as usize - 1
                        } else {
                            (verts.len() as i64 + i) as usize
                        };
                        verts[i]
                    })
                    .collect();
                let mut n = [0.0; 3];
                for i in 0..pts.len() {
                    let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
                    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
                    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
                    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
                }
                let a = 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                s.faces += 1;
                s.area += a;
                *s.by_appearance.entry(look.clone()).or_default() += a;
            }
            _ => {}
        }
    }
    s
}

/// Reads a golden `summary.json`.
pub fn golden_summary(path: &Path) -> Summary {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let arr = |k: &str| {
        let a = v["bbox"][k].as_array().unwrap();
        [0, 1, 2].map(|i| a[i].as_f64().unwrap())
    };
    Summary {
        min: arr("min"),
        max: arr("max"),
        faces: v["totals"]["faces"].as_u64().unwrap() as usize,
        area: v["totals"]["area"].as_f64().unwrap(),
        by_appearance: v["area_by_appearance"]
            .as_object()
            .unwrap()
            .iter()
            .map(|(k, x)| (k.clone(), x.as_f64().unwrap()))
            .collect(),
    }
}

/// The differences between two summaries beyond a relative tolerance (the
/// comparison of `summary.py --compare`).
pub fn compare(golden: &Summary, ours: &Summary, tol: f64) -> Vec<String> {
    let mut bad = Vec::new();
    let close = |a: f64, b: f64| (a - b).abs() <= tol * 1f64.max(a.abs()).max(b.abs());
    for k in 0..3 {
        if !close(golden.min[k], ours.min[k]) || !close(golden.max[k], ours.max[k]) {
            bad.push(format!(
                "bbox {:?}..{:?} vs {:?}..{:?}",
                golden.min, golden.max, ours.min, ours.max
            ));
            break;
        }
    }
    if !close(golden.area, ours.area) {
        bad.push(format!("total area {} vs {}", golden.area, ours.area));
    }
    let keys: std::collections::BTreeSet<&String> = golden
        .by_appearance
        .keys()
        .chain(ours.by_appearance.keys())
        .collect();
    for k in keys {
        let a = golden.by_appearance.get(k).copied().unwrap_or(0.0);
        let b = ours.by_appearance.get(k).copied().unwrap_or(0.0);
        if !close(a, b) {
            bad.push(format!("area of {k}: {a} vs {b}"));
        }
    }
    bad
}

/// Runs the Khronos glTF validator (`tools/gltf-validator`) on `file` and
/// asserts no errors. Skipped with a note when the validator is not
/// installed, unless `CGA_REQUIRE_GLTF_VALIDATOR=1` (as in CI).
pub fn assert_valid_gltf(file: &Path) {
    let tool = manifest_dir().join("../../tools/gltf-validator");
    if !tool.join("node_modules/gltf-validator").is_dir() {
        assert!(
            std::env::var("CGA_REQUIRE_GLTF_VALIDATOR").as_deref() != Ok("1"),
            "the glTF validator is not installed: run `npm ci --prefix tools/gltf-validator`"
        );
        eprintln!(
            "note: glTF validator not installed; not validating {}",
            file.display()
        );
        return;
    }
    let out = Command::new("node")
        .arg(tool.join("validate.mjs"))
        .arg(file)
        .output()
        .expect("node runs the glTF validator");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("a JSON report");
    assert_eq!(
        report["issues"]["numErrors"], 0,
        "validator errors: {report:#}"
    );
}

/// The JSON and binary chunk of a GLB file.
pub fn glb_parts(path: &Path) -> (serde_json::Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    assert!(
        bytes.starts_with(b"glTF"),
        "{} is not a GLB",
        path.display()
    );
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let bin_len = u32::from_le_bytes(bytes[20 + len..24 + len].try_into().unwrap()) as usize;
    (json, bytes[28 + len..28 + len + bin_len].to_vec())
}

/// The bytes of accessor `a` (its index) of a GLB's `json` and `bin`: its
/// buffer view, as the engine writes accessors (one per view, packed).
pub fn accessor_bytes<'a>(
    json: &serde_json::Value,
    bin: &'a [u8],
    a: &serde_json::Value,
) -> &'a [u8] {
    let acc = &json["accessors"][a.as_u64().unwrap() as usize];
    assert!(acc.get("byteOffset").is_none());
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    assert!(view.get("byteStride").is_none());
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    &bin[start..start + view["byteLength"].as_u64().unwrap() as usize]
}

/// The 32-bit float components of accessor `a`.
pub fn accessor_f32(json: &serde_json::Value, bin: &[u8], a: &serde_json::Value) -> Vec<f64> {
    accessor_bytes(json, bin, a)
        .chunks(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()) as f64)
        .collect()
}

/// The 32-bit unsigned components of accessor `a` (indices).
pub fn accessor_u32(json: &serde_json::Value, bin: &[u8], a: &serde_json::Value) -> Vec<usize> {
    accessor_bytes(json, bin, a)
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as usize)
        .collect()
}
