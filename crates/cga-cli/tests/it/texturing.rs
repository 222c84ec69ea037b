//! Textured models through the `cga` command: texture coordinates in the
//! OBJ, texture files beside it, images embedded in GLB files that the
//! Khronos validator accepts, built-in textures, the uv split.

use std::collections::BTreeMap;
use std::path::Path;

use crate::common::*;

/// Runs the Khronos glTF validator on `file`: no errors, no warnings.
/// Skipped with a note when it is not installed, unless
/// `CGA_REQUIRE_GLTF_VALIDATOR=1`.
fn assert_valid_gltf(file: &Path) {
    let tool = manifest_dir().join("../../tools/gltf-validator");
    if !tool.join("node_modules/gltf-validator").is_dir() {
        if std::env::var("CGA_REQUIRE_GLTF_VALIDATOR").as_deref() == Ok("1") {
            panic!("the glTF validator is not installed: npm ci --prefix tools/gltf-validator");
        }
        eprintln!(
            "note: glTF validator not installed; not validating {}",
            file.display()
        );
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

/// A project folder with a wall texture, `assets/facade/bricks.png` (the
/// pixels of the built-in test pattern, as an ordinary file).
fn project(name: &str) -> TempDir {
    let dir = temp_dir(name);
    std::fs::create_dir_all(dir.join("assets/facade")).unwrap();
    std::fs::create_dir_all(dir.join("rules")).unwrap();
    let png = cga_export::builtin::builtin_texture("builtin:uvtest.png").unwrap();
    std::fs::write(dir.join("assets/facade/bricks.png"), &png.png[..]).unwrap();
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

/// A face corner: position and texture coordinates.
type Corner = ([f64; 3], [f64; 2]);

/// OBJ faces with their material's `map_Kd` and their corners' (v, vt).
struct ObjModel {
    faces: Vec<(String, Vec<Corner>)>,
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
        let nums = |r: &[&str]| {
            r.iter()
                .map(|t| t.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        };
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
Tile --> projectUV(0) texture("facade/bricks.png") X.
"#;

#[test]
fn projected_texture_in_obj_and_glb() {
    let dir = project("wall");
    let rules = rule_file(&dir.join("rules"), "wall.cga", WALL);
    let obj = dir.join("out/wall.obj");
    std::fs::create_dir_all(obj.parent().unwrap()).unwrap();
    generate(&rules, &obj, &["--lot", "rect:20,30"]);
    // The texture is copied beside the model.
    assert!(dir.join("out/bricks.png").is_file());
    let model = read_obj(&obj);
    assert_eq!(model.faces.len(), 5);
    for (map, corners) in &model.faces {
        assert_eq!(map, "bricks.png");
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
    let png = std::fs::read(dir.join("assets/facade/bricks.png")).unwrap();
    assert!(
        bytes.windows(png.len()).any(|w| w == png.as_slice()),
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

/// Faces of CityEngine's Candler building on `rect:20,30` (oracle OBJ
/// output: positions to 3 decimals, texture coordinates to 4), three per
/// texture and facade: facade walls and window reveals projected with the
/// facade's projection (u = (x - uw * depth) / 5), ledge and window assets
/// with their own coordinates (windows and shop fronts tiled into an atlas),
/// sills on `builtin:cube`. The atlas tile is chosen with `rand`, whose
/// stream differs from CityEngine's, so those compare modulo the tile.
// Recorded numbers: one of them (0.318) looks like 1/pi to clippy.
#[allow(clippy::approx_constant)]
const CANDLER_FACES: &[(&str, &[Corner])] = &[
    (
        "bricks.jpg",
        &[
            ([2.175, 8.867, -30.0], [3.565, 1.7735]),
            ([2.175, 10.917, -30.0], [3.565, 2.1835]),
            ([2.175, 10.917, -29.7], [3.625, 2.1835]),
            ([2.175, 8.867, -29.7], [3.625, 1.7735]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([4.55, 38.864, -30.0], [3.09, 7.7728]),
            ([3.375, 38.864, -30.0], [3.325, 7.7728]),
            ([3.375, 42.303, -30.0], [3.325, 8.4607]),
            ([4.55, 42.303, -30.0], [3.09, 8.4607]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([9.4, 31.553, -30.0], [2.12, 6.3106]),
            ([10.6, 31.553, -30.0], [1.88, 6.3106]),
            ([10.6, 31.553, -29.7], [1.94, 6.3106]),
            ([9.4, 31.553, -29.7], [2.18, 6.3106]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([11.075, 41.871, 0.0], [2.215, 8.3742]),
            ([8.925, 41.871, 0.0], [1.785, 8.3742]),
            ([8.925, 41.871, -0.3], [1.845, 8.3742]),
            ([11.075, 41.871, -0.3], [2.275, 8.3742]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([0.0, 52.621, -1.0], [5.8, 10.5243]),
            ([0.0, 52.621, 0.0], [6.0, 10.5243]),
            ([0.0, 56.061, 0.0], [6.0, 11.2121]),
            ([0.0, 56.061, -1.0], [5.8, 11.2121]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([11.775, 0.0, 0.0], [2.355, 0.0]),
            ([12.475, 0.0, 0.0], [2.495, 0.0]),
            ([12.475, 4.3, 0.0], [2.495, 0.86]),
            ([11.775, 4.3, 0.0], [2.355, 0.86]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([0.0, 55.628, -5.25], [4.95, 11.1257]),
            ([0.0, 55.628, -6.16], [4.768, 11.1257]),
            ([0.3, 55.628, -6.16], [4.828, 11.1257]),
            ([0.3, 55.628, -5.25], [5.01, 11.1257]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([0.0, 38.864, -1.7], [5.66, 7.7728]),
            ([0.0, 38.864, -1.0], [5.8, 7.7728]),
            ([0.0, 42.303, -1.0], [5.8, 8.4607]),
            ([0.0, 42.303, -1.7], [5.66, 8.4607]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([0.0, 19.185, -2.9], [5.42, 3.8371]),
            ([0.0, 21.235, -2.9], [5.42, 4.2471]),
            ([0.3, 21.235, -2.9], [5.48, 4.2471]),
            ([0.3, 19.185, -2.9], [5.48, 3.8371]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([20.0, 25.107, -10.79], [2.158, 5.0214]),
            ([20.0, 25.107, -11.49], [2.298, 5.0214]),
            ([20.0, 28.546, -11.49], [2.298, 5.7092]),
            ([20.0, 28.546, -10.79], [2.158, 5.7092]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([20.0, 50.139, -24.75], [4.95, 10.0278]),
            ([20.0, 52.189, -24.75], [4.95, 10.4378]),
            ([19.7, 52.189, -24.75], [5.01, 10.4378]),
            ([19.7, 50.139, -24.75], [5.01, 10.0278]),
        ],
    ),
    (
        "bricks.jpg",
        &[
            ([20.0, 38.864, -12.19], [2.438, 7.7728]),
            ([20.0, 38.864, -14.26], [2.852, 7.7728]),
            ([20.0, 39.821, -14.26], [2.852, 7.9642]),
            ([20.0, 39.821, -12.19], [2.438, 7.9642]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([1.7, 0.0, -0.6], [-0.125, 0.0]),
            ([3.85, 0.0, -0.6], [0.0, 0.0]),
            ([3.85, 4.3, -0.6], [0.0, 1.0]),
            ([1.7, 4.3, -0.6], [-0.125, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([16.15, 0.0, -0.6], [-0.125, 0.0]),
            ([18.3, 0.0, -0.6], [0.0, 0.0]),
            ([18.3, 4.3, -0.6], [0.0, 1.0]),
            ([16.15, 4.3, -0.6], [-0.125, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([5.25, 0.0, -0.6], [-0.25, 0.0]),
            ([7.525, 0.0, -0.6], [-0.125, 0.0]),
            ([7.525, 4.3, -0.6], [-0.125, 1.0]),
            ([5.25, 4.3, -0.6], [-0.25, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([0.6, 0.0, -7.32], [-0.75, 0.0]),
            ([0.6, 0.0, -5.25], [-0.625, 0.0]),
            ([0.6, 4.3, -5.25], [-0.625, 1.0]),
            ([0.6, 4.3, -7.32], [-0.75, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([0.6, 0.0, -28.3], [-0.875, 0.0]),
            ([0.6, 0.0, -26.15], [-0.75, 0.0]),
            ([0.6, 4.3, -26.15], [-0.75, 1.0]),
            ([0.6, 4.3, -28.3], [-0.875, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([0.6, 0.0, -24.75], [-0.5, 0.0]),
            ([0.6, 0.0, -22.68], [-0.375, 0.0]),
            ([0.6, 4.3, -22.68], [-0.375, 1.0]),
            ([0.6, 4.3, -24.75], [-0.5, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([19.4, 0.0, -5.25], [-0.5, 0.0]),
            ([19.4, 0.0, -7.32], [-0.375, 0.0]),
            ([19.4, 4.3, -7.32], [-0.375, 1.0]),
            ([19.4, 4.3, -5.25], [-0.5, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([18.8, 0.0, -15.66], [0.0, 0.0]),
            ([18.8, 0.0, -17.81], [0.125, 0.0]),
            ([18.8, 4.3, -17.81], [0.125, 1.0]),
            ([18.8, 4.3, -15.66], [0.0, 1.0]),
        ],
    ),
    (
        "groundFloorTiles_2048x256.jpg",
        &[
            ([19.4, 0.0, -12.19], [-0.125, 0.0]),
            ([19.4, 0.0, -14.26], [0.0, 0.0]),
            ([19.4, 4.3, -14.26], [0.0, 1.0]),
            ([19.4, 4.3, -12.19], [-0.125, 1.0]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([0.0, 58.8, -29.003], [0.4965, 0.0]),
            ([-0.177, 58.8, -29.296], [0.1714, 0.0]),
            ([0.0, 58.8, -29.296], [0.1714, 0.0]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([20.882, 61.24, -29.622], [0.9782, 0.9884]),
            ([20.828, 61.193, -29.496], [0.8816, 0.0128]),
            ([20.803, 61.193, -29.549], [0.9224, 0.0128]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([20.091, 59.034, -29.298], [0.8309, 0.0461]),
            ([20.0, 59.034, -29.298], [0.8309, 0.0461]),
            ([20.122, 59.593, -29.328], [0.8532, 0.2845]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([4.865, 59.581, 0.182], [0.8391, 0.2804]),
            ([4.834, 59.576, 0.207], [0.8062, 0.2786]),
            ([4.836, 59.034, 0.152], [0.8181, 0.0461]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([7.903, 58.859, 0.255], [0.1429, 0.0117]),
            ([7.929, 58.8, 0.177], [0.1714, 0.0]),
            ([8.222, 58.859, 0.318], [0.4964, 0.0117]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([0.623, 60.482, 0.435], [0.1599, 0.5883]),
            ([0.645, 60.074, 0.271], [0.1407, 0.4488]),
            ([0.679, 60.063, 0.295], [0.1758, 0.4452]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([-0.498, 60.482, -8.024], [0.4961, 0.5883]),
            ([-0.358, 60.063, -8.024], [0.4962, 0.4452]),
            ([-0.435, 60.482, -7.643], [0.8401, 0.5883]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([-0.255, 58.979, -25.123], [0.8629, 0.0352]),
            ([0.0, 58.979, -25.123], [0.8629, 0.0352]),
            ([-0.236, 58.992, -25.13], [0.855, 0.0379]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([-0.295, 60.063, -18.189], [0.8242, 0.4452]),
            ([-0.271, 60.074, -18.155], [0.8593, 0.4488]),
            ([-0.435, 60.482, -18.133], [0.8401, 0.5883]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([20.255, 58.859, -4.228], [0.1429, 0.0117]),
            ([20.0, 58.859, -4.228], [0.1429, 0.0117]),
            ([20.177, 58.8, -4.254], [0.1714, 0.0]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([20.829, 61.005, -8.489], [0.8604, 0.9987]),
            ([20.617, 60.803, -8.478], [0.8525, 0.6981]),
            ([20.802, 61.023, -8.541], [0.9011, 0.9991]),
        ],
    ),
    (
        "ledge.jpg",
        &[
            ([20.122, 59.593, -15.288], [0.8532, 0.2845]),
            ([20.271, 60.074, -15.315], [0.8593, 0.4488]),
            ([20.182, 59.581, -15.275], [0.8391, 0.2804]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([7.112, 29.243, -30.0], [0.0, 0.0]),
            ([7.112, 29.243, -30.1], [1.0, 0.0]),
            ([7.112, 29.503, -30.1], [1.0, 1.0]),
            ([7.112, 29.503, -30.0], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([10.725, 15.486, -30.1], [0.0, 0.0]),
            ([9.275, 15.486, -30.1], [1.0, 0.0]),
            ([9.275, 15.746, -30.1], [1.0, 1.0]),
            ([10.725, 15.746, -30.1], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([5.662, 36.122, -30.0], [0.0, 0.0]),
            ([7.112, 36.122, -30.0], [1.0, 0.0]),
            ([7.112, 36.382, -30.0], [1.0, 1.0]),
            ([5.662, 36.382, -30.0], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([14.875, 12.047, 0.0], [0.0, 0.0]),
            ([12.35, 12.047, 0.0], [1.0, 0.0]),
            ([12.35, 12.307, 0.0], [1.0, 1.0]),
            ([14.875, 12.307, 0.0], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([7.65, 46.44, 0.0], [0.0, 0.0]),
            ([5.125, 46.44, 0.0], [1.0, 0.0]),
            ([5.125, 46.7, 0.0], [1.0, 1.0]),
            ([7.65, 46.7, 0.0], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([12.35, 25.804, 0.0], [0.0, 0.0]),
            ([12.35, 25.804, 0.1], [1.0, 0.0]),
            ([12.35, 26.064, 0.1], [1.0, 1.0]),
            ([12.35, 26.064, 0.0], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([0.0, 56.758, -27.625], [0.0, 0.0]),
            ([0.0, 56.758, -28.425], [1.0, 0.0]),
            ([0.0, 57.018, -28.425], [1.0, 1.0]),
            ([0.0, 57.018, -27.625], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([0.0, 22.365, -24.875], [0.0, 0.0]),
            ([-0.1, 22.365, -24.875], [1.0, 0.0]),
            ([-0.1, 22.625, -24.875], [1.0, 1.0]),
            ([0.0, 22.625, -24.875], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([0.0, 15.486, -27.225], [0.0, 0.0]),
            ([0.0, 15.486, -28.425], [1.0, 0.0]),
            ([0.0, 15.746, -28.425], [1.0, 1.0]),
            ([0.0, 15.746, -27.225], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([20.1, 56.758, -13.225], [0.0, 0.0]),
            ([20.1, 56.758, -14.385], [1.0, 0.0]),
            ([20.1, 57.018, -14.385], [1.0, 1.0]),
            ([20.1, 57.018, -13.225], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([20.1, 56.758, -7.445], [0.0, 0.0]),
            ([20.0, 56.758, -7.445], [1.0, 0.0]),
            ([20.0, 57.018, -7.445], [1.0, 1.0]),
            ([20.1, 57.018, -7.445], [0.0, 1.0]),
        ],
    ),
    (
        "sill.jpg",
        &[
            ([20.0, 22.365, -14.385], [0.0, 0.0]),
            ([20.0, 22.365, -12.065], [1.0, 0.0]),
            ([20.0, 22.625, -12.065], [1.0, 1.0]),
            ([20.0, 22.625, -14.385], [0.0, 1.0]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([10.6, 36.382, -29.735], [-0.2805, 0.9743]),
            ([9.4, 36.382, -29.735], [-0.224, 0.9743]),
            ([9.4, 36.382, -29.85], [-0.224, 0.9743]),
            ([10.6, 36.382, -29.85], [-0.2805, 0.9743]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([14.164, 16.693, -29.771], [-0.5708, 0.9839]),
            ([13.059, 16.693, -29.771], [-0.5326, 0.9839]),
            ([13.059, 16.737, -29.771], [-0.5326, 0.9875]),
            ([14.164, 16.737, -29.771], [-0.5708, 0.9875]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([10.552, 51.13, -29.771], [-0.6708, 0.9875]),
            ([9.446, 51.13, -29.771], [-0.6326, 0.9875]),
            ([9.446, 51.13, -29.735], [-0.6326, 0.9875]),
            ([10.552, 51.13, -29.735], [-0.6708, 0.9875]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([3.784, 13.403, -0.264], [-0.8708, 0.9768]),
            ([3.784, 12.444, -0.264], [-0.8326, 0.9768]),
            ([3.813, 12.444, -0.264], [-0.8326, 0.9804]),
            ([3.813, 13.403, -0.264], [-0.8708, 0.9804]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([2.9, 12.307, -0.265], [-0.8805, 0.9743]),
            ([3.85, 12.307, -0.265], [-0.824, 0.9743]),
            ([3.85, 12.307, -0.15], [-0.824, 0.9743]),
            ([2.9, 12.307, -0.15], [-0.8805, 0.9743]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([16.218, 27.028, -0.286], [-0.5, 0.467]),
            ([16.218, 26.202, -0.286], [-0.5, 0.0]),
            ([17.036, 26.202, -0.286], [-0.4, 0.0]),
            ([17.036, 27.028, -0.286], [-0.4, 0.467]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([0.264, 44.356, -26.216], [-0.5708, 0.9768]),
            ([0.264, 43.398, -26.216], [-0.5326, 0.9768]),
            ([0.264, 43.398, -26.187], [-0.5326, 0.9804]),
            ([0.264, 44.356, -26.187], [-0.5708, 0.9804]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([0.254, 54.569, -24.686], [-0.8, 0.5125]),
            ([0.254, 54.569, -23.9], [-0.7, 0.5125]),
            ([0.286, 54.542, -23.901], [-0.7, 0.467]),
            ([0.286, 54.542, -24.685], [-0.8, 0.467]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([0.232, 45.21, -1.766], [-0.8708, 0.9768]),
            ([0.232, 44.251, -1.766], [-0.8326, 0.9768]),
            ([0.232, 44.251, -1.737], [-0.8326, 0.9804]),
            ([0.232, 45.21, -1.737], [-0.8708, 0.9804]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([19.771, 38.332, -19.293], [0.0292, 0.9964]),
            ([19.771, 38.332, -21.2], [0.0674, 0.9964]),
            ([19.771, 38.375, -21.2], [0.0674, 1.0]),
            ([19.771, 38.375, -19.293], [0.0292, 1.0]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([19.746, 58.966, -9.944], [-0.8, 0.9411]),
            ([19.746, 58.008, -9.944], [-0.8, 0.5125]),
            ([19.746, 58.008, -10.73], [-0.7, 0.5125]),
            ([19.746, 58.966, -10.73], [-0.7, 0.9411]),
        ],
    ),
    (
        "windowTiles_2000x256.jpg",
        &[
            ([19.798, 31.495, -3.813], [-0.82, 0.9896]),
            ([19.798, 31.495, -2.938], [-0.8845, 0.9896]),
            ([19.735, 31.495, -2.938], [-0.8845, 0.9896]),
            ([19.735, 31.495, -3.813], [-0.82, 0.9896]),
        ],
    ),
];

#[test]
fn candler_facades_carry_cityengines_textures_and_coordinates() {
    let Some(oracle) = cga_testkit::oracle() else {
        return;
    };
    let dir = temp_dir("candler_textured");
    let rules = oracle.join("rules/candler/rules/candler.cga");
    let obj = dir.join("candler.obj");
    let o = cga()
        .args([
            "generate",
            &rules.display().to_string(),
            "--lot",
            "rect:20,30",
            "-o",
        ])
        .arg(&obj)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let model = read_obj(&obj);
    for (name, corners) in CANDLER_FACES {
        let tile = match *name {
            "windowTiles_2000x256.jpg" => Some(0.1),
            "groundFloorTiles_2048x256.jpg" => Some(0.125),
            _ => None,
        };
        let near = |a: [f64; 3], b: [f64; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 2e-3);
        let face = model.faces.iter().find(|(map, cs)| {
            map == name
                && cs.len() == corners.len()
                && corners
                    .iter()
                    .all(|(p, _)| cs.iter().any(|(q, _)| near(*p, *q)))
        });
        let Some((_, ours)) = face else {
            panic!("no {name} face at {corners:?}");
        };
        let mut shift = None;
        for (p, want) in *corners {
            let (_, got) = ours.iter().find(|(q, _)| near(*p, *q)).unwrap();
            assert!(
                (got[1] - want[1]).abs() < 1e-3,
                "{name} at {p:?}: {got:?} vs {want:?}"
            );
            let du = got[0] - want[0];
            match tile {
                None => assert!(du.abs() < 1e-3, "{name} at {p:?}: {got:?} vs {want:?}"),
                Some(t) => {
                    // The same tile offset for all corners, a whole number of tiles.
                    let s = *shift.get_or_insert(du);
                    assert!(
                        (du - s).abs() < 1e-3,
                        "{name} at {p:?}: {got:?} vs {want:?}"
                    );
                    assert!(
                        ((s / t) - (s / t).round()).abs() < 1e-2,
                        "{name}: shift {s}"
                    );
                }
            }
        }
    }
    // The textured appearances of the facades, by area (`summary.py`):
    // ledges and sills as CityEngine has them; window tiles within the
    // rounding of CityEngine's 3-decimal OBJ coordinates.
    let ours = summarize(&obj);
    let golden = golden_summary(&oracle.join("golden/candler.rect20x30/summary.json"));
    for (look, tol) in [
        ("1.000,1.000,1.000|ledge.jpg", 1e-3),
        ("1.000,1.000,1.000|sill.jpg", 1e-3),
        ("1.000,1.000,1.000|windowTiles_2000x256.jpg", 5e-3),
    ] {
        let (a, b) = (ours.by_appearance[look], golden.by_appearance[look]);
        assert!((a - b).abs() <= tol * b, "{look}: {a} vs {b}");
    }
    for look in [
        "0.988,0.937,0.886|bricks.jpg",
        "1.000,1.000,1.000|groundFloorTiles_2048x256.jpg",
    ] {
        assert!(
            ours.by_appearance[look] > 0.9 * golden.by_appearance[look],
            "{look}"
        );
    }
    for tex in [
        "bricks.jpg",
        "ledge.jpg",
        "sill.jpg",
        "windowTiles_2000x256.jpg",
    ] {
        assert!(dir.join(tex).is_file(), "{tex} copied beside the model");
    }

    // The GLB embeds the five facade textures and passes the validator.
    let glb = dir.join("candler.glb");
    let o = cga()
        .args([
            "generate",
            &rules.display().to_string(),
            "--lot",
            "rect:20,30",
            "-o",
        ])
        .arg(&glb)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_valid_gltf(&glb);
    let bytes = std::fs::read(&glb).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let mut names: Vec<&str> = json["images"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["name"].as_str().unwrap())
        .collect();
    names.sort();
    assert!(names.len() >= 5, "{names:?}");
    for tex in [
        "bricks.jpg",
        "groundFloorTiles_2048x256.jpg",
        "ledge.jpg",
        "sill.jpg",
        "windowTiles_2000x256.jpg",
    ] {
        assert!(names.contains(&tex), "{names:?}");
    }
}
