//! Textured models through the `cga` command: texture coordinates in the
//! OBJ, texture files beside it, images embedded in GLB files that the
//! Khronos validator accepts, built-in textures, the uv split.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::*;

/// Runs the Khronos glTF validator on `file`: no errors, no warnings.
/// Skipped with a note when it is not installed, unless
/// `CGA_REQUIRE_GLTF_VALIDATOR=1`.
fn assert_valid_gltf(file: &Path) {
    let tool = manifest_dir().join("../../tools/gltf-validator");
    if !tool.join("node_modules/gltf-validator").is_dir() {
        if std::env::var("CGA_REQUIRE_GLTF_VALIDATOR").as_deref() == Ok("1") {
            panic!("the glTF validator is not installed: npm ci --prefix tools/gltf-validator");
        }
        eprintln!("note: glTF validator not installed; not validating {}", file.display());
        return;
    }
    let out = std::process::Command::new("node")
        .arg(tool.join("validate.mjs"))
        .arg(file)
        .output()
        .expect("node runs");
    let report: serde_json::Value = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("no validator report ({e}): {}", stderr(&out)));
    assert_eq!(report["issues"]["numErrors"], 0, "{report:#}");
    assert_eq!(report["issues"]["numWarnings"], 0, "{report:#}");
}

/// A project folder with the Candler wall texture in `assets/`.
fn project(name: &str) -> PathBuf {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("assets/facade")).unwrap();
    std::fs::create_dir_all(dir.join("rules")).unwrap();
    std::fs::copy(
        manifest_dir().join("tests/oracle/candler/assets/facade/walls/bricks.jpg"),
        dir.join("assets/facade/bricks.jpg"),
    )
    .unwrap();
    dir
}

fn generate(rules: &Path, out: &Path, extra: &[&str]) {
    let mut args = vec![
        "generate".to_string(),
        rules.display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let o = cga().args(&args).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

/// OBJ faces with their material's `map_Kd` and their corners' (v, vt).
struct ObjModel {
    faces: Vec<(String, Vec<([f64; 3], [f64; 2])>)>,
}

fn read_obj(path: &Path) -> ObjModel {
    let text = std::fs::read_to_string(path).unwrap();
    let mtl_text = std::fs::read_to_string(path.with_extension("mtl")).unwrap();
    let mut maps = BTreeMap::new();
    let mut cur = String::new();
    for l in mtl_text.lines() {
        if let Some(n) = l.strip_prefix("newmtl ") {
            cur = n.to_string();
            maps.insert(cur.clone(), "-".to_string());
        } else if let Some(m) = l.strip_prefix("map_Kd ") {
            maps.insert(cur.clone(), m.to_string());
        }
    }
    let (mut v, mut vt, mut faces) = (Vec::new(), Vec::new(), Vec::new());
    let mut map = String::from("-");
    for l in text.lines() {
        let p: Vec<&str> = l.split_whitespace().collect();
        let nums = |r: &[&str]| r.iter().map(|t| t.parse::<f64>().unwrap()).collect::<Vec<_>>();
        match p.first() {
            Some(&"v") => {
                let n = nums(&p[1..]);
                v.push([n[0], n[1], n[2]]);
            }
            Some(&"vt") => {
                let n = nums(&p[1..]);
                vt.push([n[0], n[1]]);
            }
            Some(&"usemtl") => map = maps[p[1]].clone(),
            Some(&"f") => {
                let corners = p[1..]
                    .iter()
                    .map(|c| {
                        let mut it = c.split('/');
                        let vi: usize = it.next().unwrap().parse().unwrap();
                        let ti: usize = it.next().unwrap().parse().expect("a vt index");
                        (v[vi - 1], vt[ti - 1])
                    })
                    .collect();
                faces.push((map.clone(), corners));
            }
            _ => {}
        }
    }
    ObjModel { faces }
}

const WALL: &str = r#"
Lot --> setupProjection(0, scope.xz, 5, 5) split(x) { ~4 : Tile }*
Tile --> projectUV(0) texture("facade/bricks.jpg") X.
"#;

#[test]
fn projected_texture_in_obj_and_glb() {
    let dir = project("wall");
    let rules = rule_file(&dir.join("rules"), "wall.cga", WALL);
    let obj = dir.join("out/wall.obj");
    std::fs::create_dir_all(obj.parent().unwrap()).unwrap();
    generate(&rules, &obj, &["--lot", "rect:20,30"]);
    // The texture is copied beside the model.
    assert!(dir.join("out/bricks.jpg").is_file());
    let model = read_obj(&obj);
    assert_eq!(model.faces.len(), 5);
    for (map, corners) in &model.faces {
        assert_eq!(map, "bricks.jpg");
        for (p, t) in corners {
            // Continuous over the tiles: u = x / 5, v = (z + 30) / 5 (OBJ
            // writes six decimals).
            assert!((t[0] - p[0] / 5.0).abs() < 1e-6, "{p:?} {t:?}");
            assert!((t[1] - (p[2] + 30.0) / 5.0).abs() < 1e-6, "{p:?} {t:?}");
        }
    }

    let glb = dir.join("out/wall.glb");
    generate(&rules, &glb, &["--lot", "rect:20,30"]);
    assert_valid_gltf(&glb);
    let bytes = std::fs::read(&glb).unwrap();
    let jpeg = std::fs::read(dir.join("assets/facade/bricks.jpg")).unwrap();
    assert!(
        bytes.windows(jpeg.len()).any(|w| w == jpeg.as_slice()),
        "the GLB embeds the texture"
    );
}

#[test]
fn builtin_texture_and_uv_split() {
    let dir = project("uvsplit");
    let rules = rule_file(
        &dir.join("rules"),
        "split.cga",
        r#"Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0)
                   texture("builtin:uvtest.png")
                   split(u, unitSpace, 0) { 5 : X }*"#,
    );
    let obj = dir.join("split.obj");
    generate(&rules, &obj, &["--lot", "rect:20,30"]);
    assert!(dir.join("builtin_uvtest.png").is_file());
    let model = read_obj(&obj);
    assert_eq!(model.faces.len(), 4);
    let mut lefts: Vec<f64> = model
        .faces
        .iter()
        .map(|(map, c)| {
            assert_eq!(map, "builtin_uvtest.png");
            c.iter().map(|(p, _)| p[0]).fold(f64::INFINITY, f64::min)
        })
        .collect();
    lefts.sort_by(f64::total_cmp);
    assert_eq!(lefts, [0.0, 5.0, 10.0, 15.0]);
    for (_, corners) in &model.faces {
        for (p, t) in corners {
            assert!((t[0] - p[0] / 20.0).abs() < 1e-6);
        }
    }
    let glb = dir.join("split.glb");
    generate(&rules, &glb, &["--lot", "rect:20,30"]);
    assert_valid_gltf(&glb);
}
