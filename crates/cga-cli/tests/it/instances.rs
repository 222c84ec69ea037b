//! Repeated assets as instances (`EXT_mesh_gpu_instancing`): an asset
//! inserted many times and left unchanged is written once per file and
//! placed by translations, rotations and scales; the instanced and the
//! plain file (`--no-instances`) describe the same triangles.

use std::path::Path;

use serde_json::Value;

use crate::common::*;

/// A street of trees and lamps: two assets inserted over and over, turned,
/// scaled unevenly, coloured; one more inserted and then cut (no longer an
/// asset as loaded), and one mirrored (no TRS without a negative scale).
const STREET: &str = r##"
Lot --> split(x){~4: Slot}*
Slot --> split(z){~4: Cell}*
Cell --> Tree Lamp Bench Sign
Tree --> s(1.5, 5, 1.5) center(xz) i("builtin:cylinder") color("#2a6a2a")
Lamp --> t(0.2, 0, 0.2) s(0.2, 3, 0.2) r(0, 30, 0) i("builtin:cube") color("#444444")
Bench --> t(1, 0, 2) s(1.2, 0.5, 0.4) i("builtin:cube") split(x){~0.4: Plank}*
Plank --> color("#8a6a4a")
Sign --> t(3, 0, 1) s(-0.5, 2, 0.1) i("builtin:cube")
"##;

type Tri = [[i64; 3]; 3];

/// Rotates `v` by the unit quaternion `q` (x, y, z, w).
fn rotate(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
    let (u, w) = ([q[0], q[1], q[2]], q[3]);
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let c = cross(u, t);
    std::array::from_fn(|k| v[k] + w * t[k] + c[k])
}

/// Every triangle the file draws, in the scene's frame, as its corners in
/// tenths of millimetres (each triangle's corners sorted, the list
/// sorted), with the number of instanced nodes seen.
fn triangles(path: &Path) -> (Vec<Tri>, usize) {
    let (json, bin) = glb_parts(path);
    let mut out = Vec::new();
    let mut instanced = 0;
    let mut stack: Vec<(u64, [f64; 3])> = json["scenes"][0]["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| (n.as_u64().unwrap(), [0.0; 3]))
        .collect();
    while let Some((n, offset)) = stack.pop() {
        let node = &json["nodes"][n as usize];
        assert!(node.get("rotation").is_none() && node.get("scale").is_none());
        let t = node.get("translation").map_or([0.0; 3], |t| {
            std::array::from_fn(|k| t[k].as_f64().unwrap())
        });
        let at: [f64; 3] = std::array::from_fn(|k| offset[k] + t[k]);
        for c in node["children"].as_array().into_iter().flatten() {
            stack.push((c.as_u64().unwrap(), at));
        }
        let Some(mesh) = node.get("mesh") else {
            continue;
        };
        // Placements: one identity, or the instancing attributes.
        let placements: Vec<([f64; 3], [f64; 4], [f64; 3])> =
            match node.pointer("/extensions/EXT_mesh_gpu_instancing/attributes") {
                None => vec![([0.0; 3], [0.0, 0.0, 0.0, 1.0], [1.0; 3])],
                Some(a) => {
                    instanced += 1;
                    let t = accessor_f32(&json, &bin, &a["TRANSLATION"]);
                    let r = accessor_f32(&json, &bin, &a["ROTATION"]);
                    let s = accessor_f32(&json, &bin, &a["SCALE"]);
                    (0..t.len() / 3)
                        .map(|i| {
                            (
                                [t[3 * i], t[3 * i + 1], t[3 * i + 2]],
                                [r[4 * i], r[4 * i + 1], r[4 * i + 2], r[4 * i + 3]],
                                [s[3 * i], s[3 * i + 1], s[3 * i + 2]],
                            )
                        })
                        .collect()
                }
            };
        let mesh = &json["meshes"][mesh.as_u64().unwrap() as usize];
        for prim in mesh["primitives"].as_array().unwrap() {
            let p = accessor_f32(&json, &bin, &prim["attributes"]["POSITION"]);
            let idx = accessor_u32(&json, &bin, &prim["indices"]);
            for (tr, rot, sc) in &placements {
                let place = |v: usize| -> [i64; 3] {
                    let local = [p[3 * v] * sc[0], p[3 * v + 1] * sc[1], p[3 * v + 2] * sc[2]];
                    let r = rotate(*rot, local);
                    std::array::from_fn(|k| ((r[k] + tr[k] + at[k]) * 1e4).round() as i64)
                };
                for t in idx.chunks(3) {
                    let mut tri = [place(t[0]), place(t[1]), place(t[2])];
                    tri.sort();
                    out.push(tri);
                }
            }
        }
    }
    out.sort();
    (out, instanced)
}

/// Whether two sorted triangle lists agree corner by corner to `tol`
/// tenths of millimetres (float rounding differs between placing in
/// double precision and on the GPU's terms).
fn same_triangles(a: &[Tri], b: &[Tri], tol: i64) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.iter()
                .zip(y)
                .all(|(p, q)| p.iter().zip(q).all(|(u, v)| (u - v).abs() <= tol))
        })
}

fn generate(dir: &Path, out: &str, lot: &str, extra: &[&str]) -> std::path::PathBuf {
    let rules = rule_file(dir, "street.cga", STREET);
    let path = dir.join(out);
    let mut args = vec![
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        lot,
        "-o",
        path.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    path
}

#[test]
fn instanced_and_plain_files_describe_the_same_triangles() {
    let dir = temp_dir("instances");
    for (granularity, lot) in [("lot", "grid:3x2"), ("material", "rect:80,60")] {
        let g = ["--granularity", granularity];
        let inst = generate(&dir, &format!("i-{granularity}.glb"), lot, &g);
        let plain = generate(
            &dir,
            &format!("p-{granularity}.glb"),
            lot,
            &[&g[..], &["--no-instances"]].concat(),
        );
        assert_valid_gltf(&inst);
        let (a, instanced) = triangles(&inst);
        let (b, none) = triangles(&plain);
        assert_eq!(none, 0);
        assert!(instanced >= 2, "{granularity}: {instanced} instanced nodes");
        assert!(
            same_triangles(&a, &b, 3),
            "{granularity}: {} and {} triangles differ",
            a.len(),
            b.len()
        );
        // The trees and lamps are written once: the file is smaller by
        // them (the benches and signs stay geometry of their own).
        let (si, sp) = (
            std::fs::metadata(&inst).unwrap().len(),
            std::fs::metadata(&plain).unwrap().len(),
        );
        assert!(si * 3 < sp * 2, "{granularity}: {si} vs {sp} bytes");
        let (json, _) = glb_parts(&inst);
        assert_eq!(json["extensionsRequired"][0], "EXT_mesh_gpu_instancing");
        // Two assets as loaded (the cylinder and the lamp's cube with
        // their colours); the cut bench and the mirrored sign are plain.
        let asset_meshes = json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|m| m["name"].as_str().unwrap().starts_with("asset "))
            .count();
        assert_eq!(asset_meshes, 2, "{granularity}");
    }
}

#[test]
fn each_lot_keeps_its_instances() {
    // Per lot, a lot's instances are children of its node: six lots of
    // 20 x 30 m, 5 x 8 cells each, each cell one tree and one lamp.
    let dir = temp_dir("instances-lots");
    let inst = generate(&dir, "lots.glb", "grid:3x2", &["--jobs", "2"]);
    // The same file however many threads derive and encode.
    let one = generate(&dir, "one.glb", "grid:3x2", &["--jobs", "1"]);
    assert_eq!(std::fs::read(&inst).unwrap(), std::fs::read(&one).unwrap());
    let (json, bin) = glb_parts(&inst);
    let lots: Vec<&Value> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n.pointer("/extras/lot").is_some())
        .collect();
    assert_eq!(lots.len(), 6);
    for lot in lots {
        let children = lot["children"].as_array().unwrap();
        assert_eq!(children.len(), 2);
        for c in children {
            let node = &json["nodes"][c.as_u64().unwrap() as usize];
            let t = &node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["TRANSLATION"];
            assert_eq!(accessor_f32(&json, &bin, t).len(), 3 * 5 * 8);
        }
    }
}

#[test]
fn tiles_place_instances_with_feature_ids() {
    let dir = temp_dir("instances-tiles");
    let tileset = generate(&dir, "t/tileset.json", "grid:3x2", &[]);
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&tileset).unwrap()).unwrap();
    let tile = dir
        .join("t")
        .join(t["root"]["content"]["uri"].as_str().unwrap());
    assert_valid_gltf(&tile);
    let (json, bin) = glb_parts(&tile);
    let instanced: Vec<&Value> = json["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n.pointer("/extensions/EXT_mesh_gpu_instancing").is_some())
        .collect();
    // Merged by material: one node per asset for the whole tile, each
    // placement with its lot's feature id.
    assert_eq!(instanced.len(), 2);
    for node in instanced {
        let ids = accessor_f32(
            &json,
            &bin,
            &node["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["_FEATURE_ID_0"],
        );
        let mut per_lot = [0usize; 6];
        for id in ids {
            per_lot[id as usize] += 1;
        }
        assert_eq!(per_lot, [5 * 8; 6]);
        let f = &node["extensions"]["EXT_instance_features"]["featureIds"][0];
        assert_eq!(f["featureCount"], 6);
        assert_eq!(f["propertyTable"], 0);
    }
}
