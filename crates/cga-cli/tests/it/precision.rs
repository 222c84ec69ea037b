//! Lots far from the frame's origin (a national grid's metres, GeoJSON
//! without longitude/latitude): glTF's 32-bit floats would round positions
//! there to a metre, so models are written relative to a local origin kept
//! in double precision (`--origin`), and every vertex comes out within a
//! millimetre of where it belongs.

use std::path::{Path, PathBuf};

use serde_json::Value;

use crate::common::*;

/// West, south corner of the first lot (metres, x east, y north), its
/// width and depth; the second lot lies 40 m east of it.
const X0: f64 = 10_000_000.123;
const Y0: f64 = 10_000_000.456;
const W: f64 = 20.123;
const D: f64 = 15.5;
/// The rule: 10 m high, split into parts of about 2.5 m along x (8 parts
/// of 20.123 / 8 m), each a closed box.
const RULES: &str = "Lot --> extrude(10) split(x){~2.5: X.}*\n";

fn lots(dir: &Path) -> PathBuf {
    let ring = |x: f64| {
        format!(
            "[[{x},{Y0}],[{},{Y0}],[{},{}],[{x},{}],[{x},{Y0}]]",
            x + W,
            x + W,
            Y0 + D,
            Y0 + D
        )
    };
    let feature = |x: f64| {
        format!(
            r#"{{"type":"Feature","properties":{{}},"geometry":{{"type":"Polygon","coordinates":[{}]}}}}"#,
            ring(x)
        )
    };
    let path = dir.join("far.geojson");
    std::fs::write(
        &path,
        format!(
            r#"{{"type":"FeatureCollection","features":[{},{}]}}"#,
            feature(X0),
            feature(X0 + 40.0)
        ),
    )
    .unwrap();
    path
}

/// How far a model point (y up, z = -north) is from the nearest place a
/// vertex belongs: x on a cut between parts, y at the ground or the top,
/// z on the front or back of a lot.
fn error(p: [f64; 3]) -> f64 {
    let near = |v: f64, candidates: &mut dyn Iterator<Item = f64>| {
        candidates
            .map(|c| (v - c).abs())
            .fold(f64::INFINITY, f64::min)
    };
    let ex = near(
        p[0],
        &mut [X0, X0 + 40.0]
            .into_iter()
            .flat_map(|x| (0..=8).map(move |k| x + W * k as f64 / 8.0)),
    );
    let ey = near(p[1], &mut [0.0, 10.0].into_iter());
    let ez = near(p[2], &mut [-Y0, -(Y0 + D)].into_iter());
    ex.max(ey).max(ez)
}

/// The positions of a GLB's meshes as placed by their nodes'
/// translations (read in double precision from the JSON), and how many.
fn placed_positions(path: &Path) -> Vec<[f64; 3]> {
    let (json, bin) = glb_parts(path);
    let mut out = Vec::new();
    for node in json["nodes"].as_array().unwrap() {
        assert!(node.get("rotation").is_none() && node.get("scale").is_none());
        let t: Vec<f64> = match node.get("translation") {
            Some(t) => t
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect(),
            None => vec![0.0; 3],
        };
        let mesh = &json["meshes"][node["mesh"].as_u64().unwrap() as usize];
        for prim in mesh["primitives"].as_array().unwrap() {
            let p = accessor_f32(&json, &bin, &prim["attributes"]["POSITION"]);
            out.extend(p.chunks(3).map(|c| [c[0] + t[0], c[1] + t[1], c[2] + t[2]]));
        }
    }
    out
}

fn worst(points: &[[f64; 3]]) -> f64 {
    points.iter().map(|&p| error(p)).fold(0.0, f64::max)
}

fn generate(dir: &Path, out: &str, extra: &[&str]) -> PathBuf {
    let rules = rule_file(dir, "far.cga", RULES);
    let lots = lots(dir);
    let path = dir.join(out);
    let mut args = vec![
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        lots.to_str().unwrap(),
        "-o",
        path.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    path
}

#[test]
fn glb_far_from_the_origin_keeps_millimetres() {
    let dir = temp_dir("precision-glb");
    let glb = generate(&dir, "far.glb", &[]);
    let points = placed_positions(&glb);
    // 2 lots x 8 boxes x 6 faces x 4 corners.
    assert_eq!(points.len(), 2 * 8 * 6 * 4);
    let e = worst(&points);
    assert!(e < 0.001, "a vertex is {e} m from where it belongs");
    // The origin: the lots' centre in whole metres, kept in the
    // translation and in asset.extras.
    let bytes = std::fs::read(&glb).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let (cx, cz) = ((X0 + (X0 + 40.0 + W)) / 2.0, -(Y0 + Y0 + D) / 2.0);
    assert_eq!(json["nodes"][0]["translation"][0], cx.round());
    assert_eq!(json["nodes"][0]["translation"][2], cz.round());
    assert_eq!(json["asset"]["extras"]["origin"]["x"], cx.round());
    assert_valid_gltf(&glb);

    // Without the origin the floats round to a metre: the check above
    // tells the difference.
    let raw = generate(&dir, "raw.glb", &["--origin", "none"]);
    let e = worst(&placed_positions(&raw));
    assert!(e > 0.01, "raw positions were {e} m off");

    // An origin given by hand (x east, y north) works the same.
    let given = generate(&dir, "given.glb", &["--origin", "10000000,10000000"]);
    let e = worst(&placed_positions(&given));
    assert!(e < 0.001, "{e}");
}

#[test]
fn gltf_and_obj_far_from_the_origin() {
    let dir = temp_dir("precision-obj");
    // OBJ keeps full coordinates (text with six decimals).
    let obj = generate(&dir, "far.obj", &[]);
    let text = std::fs::read_to_string(&obj).unwrap();
    let points: Vec<[f64; 3]> = text
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|n| n.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert!(!points.is_empty());
    let e = worst(&points);
    assert!(e < 0.001, "{e}");
    // glTF: the same node translation as GLB.
    let gltf = generate(&dir, "far.gltf", &[]);
    let json: Value = serde_json::from_str(&std::fs::read_to_string(&gltf).unwrap()).unwrap();
    assert_eq!(
        json["nodes"][1]["translation"][0].as_f64().unwrap(),
        ((X0 + X0 + 40.0 + W) / 2.0).round()
    );
}

#[test]
fn tiles_far_from_the_origin_keep_millimetres() {
    let dir = temp_dir("precision-tiles");
    let tileset = generate(&dir, "t/tileset.json", &[]);
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&tileset).unwrap()).unwrap();
    let uri = t["root"]["content"]["uri"].as_str().unwrap();
    let tile = dir.join("t").join(uri);
    let points = placed_positions(&tile);
    assert_eq!(points.len(), 2 * 8 * 6 * 4);
    let e = worst(&points);
    assert!(e < 0.001, "{e}");
    assert_valid_gltf(&tile);
    // The tileset's box is where the lots are (z up, y north).
    let b = &t["root"]["boundingVolume"]["box"];
    let cx = b[0].as_f64().unwrap();
    let cy = b[1].as_f64().unwrap();
    assert!((cx - (X0 + (40.0 + W) / 2.0)).abs() < 0.01, "{cx}");
    assert!((cy - (Y0 + D / 2.0)).abs() < 0.01, "{cy}");
    // An origin by hand is for single models.
    let rules = dir.join("far.cga");
    let o = run(&[
        "generate",
        rules.to_str().unwrap(),
        "-o",
        dir.join("u/tileset.json").to_str().unwrap(),
        "--origin",
        "1,2",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--origin X,Y is for GLB and glTF"));
}

#[test]
fn bad_origins_are_usage_errors() {
    for bad in ["1", "a,b", "1,inf", ""] {
        let o = run(&["generate", "x.cga", "--origin", bad]);
        assert_eq!(o.status.code(), Some(2), "--origin {bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("--origin"), "{}", stderr(&o));
    }
}
