//! 3D Tiles output (`-o tileset.json`): a tileset of valid GLB tiles over
//! a quadtree of the lots, placed on the globe when the lots are, checked
//! by a structural check of our own (the 3D Tiles validator is not in the
//! package registries reachable here) and the Khronos glTF validator.

use std::path::Path;

use serde_json::Value;

use crate::common::*;

/// The JSON of a GLB file.
fn glb_json(path: &Path) -> Value {
    glb_parts(path).0
}

/// The bytes of buffer view `v`, checking the 8-byte alignment that
/// `EXT_structural_metadata` asks of its views.
fn view_bytes<'a>(json: &Value, bin: &'a [u8], v: &Value) -> &'a [u8] {
    let view = &json["bufferViews"][v.as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    assert_eq!(offset % 8, 0);
    &bin[offset..offset + view["byteLength"].as_u64().unwrap() as usize]
}

/// The strings of a STRING property of a property table.
fn strings(json: &Value, bin: &[u8], property: &Value) -> Vec<String> {
    let text = view_bytes(json, bin, &property["values"]);
    let offsets: Vec<usize> = view_bytes(json, bin, &property["stringOffsets"])
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as usize)
        .collect();
    offsets
        .windows(2)
        .map(|w| String::from_utf8(text[w[0]..w[1]].to_vec()).unwrap())
        .collect()
}

/// A tile's property table (EXT_structural_metadata): the lots' indices and
/// names, and the strings of attribute `attr` if asked; checks that the
/// primitives' feature ids (EXT_mesh_features) are exactly the table's rows.
fn property_table(path: &Path, attr: Option<&str>) -> (Vec<u64>, Vec<String>, Vec<String>) {
    let (json, bin) = glb_parts(path);
    let used: Vec<&str> = json["extensionsUsed"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert!(used.contains(&"EXT_mesh_features") && used.contains(&"EXT_structural_metadata"));
    let table = &json["extensions"]["EXT_structural_metadata"]["propertyTables"][0];
    let count = table["count"].as_u64().unwrap() as usize;
    let index: Vec<u64> = view_bytes(&json, &bin, &table["properties"]["index"]["values"])
        .chunks(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()) as u64)
        .collect();
    let names = strings(&json, &bin, &table["properties"]["name"]);
    let attrs = attr.map_or(Vec::new(), |a| {
        strings(&json, &bin, &table["properties"][a])
    });
    assert_eq!((index.len(), names.len()), (count, count));
    let mut ids = std::collections::BTreeSet::new();
    for mesh in json["meshes"].as_array().unwrap() {
        for p in mesh["primitives"].as_array().unwrap() {
            let feature_ids = &p["extensions"]["EXT_mesh_features"]["featureIds"][0];
            assert_eq!(
                feature_ids["featureCount"].as_u64().unwrap() as usize,
                count
            );
            let acc =
                &json["accessors"][p["attributes"]["_FEATURE_ID_0"].as_u64().unwrap() as usize];
            let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
            let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let n = acc["count"].as_u64().unwrap() as usize;
            for c in bin[offset..offset + 4 * n].chunks(4) {
                let id = f32::from_le_bytes(c.try_into().unwrap());
                assert!(id.fract() == 0.0 && (id as usize) < count, "{id}");
                ids.insert(id as usize);
            }
        }
    }
    // Every lot of the table has vertices (every test building has some).
    assert_eq!(ids.len(), count);
    (index, names, attrs)
}

/// `n` x `n` lots of 20 x 30 m in longitude/latitude around 8.5 E, 47.3 N,
/// with a `height` property.
fn lonlat_lots(dir: &Path, n: usize) -> std::path::PathBuf {
    let (dlon, dlat) = (1.0 / 75_500.0, 1.0 / 111_200.0); // about a metre
    let mut features = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (x, y) = (
                8.5 + (i as f64 * 40.0) * dlon,
                47.3 + (j as f64 * 45.0) * dlat,
            );
            let ring = [
                (x, y),
                (x + 20.0 * dlon, y),
                (x + 20.0 * dlon, y + 30.0 * dlat),
                (x, y + 30.0 * dlat),
                (x, y),
            ];
            let coords: Vec<String> = ring.iter().map(|(a, b)| format!("[{a},{b}]")).collect();
            features.push(format!(
                r#"{{"type":"Feature","id":"b{i}_{j}","properties":{{"height":{}}},"geometry":{{"type":"Polygon","coordinates":[[{}]]}}}}"#,
                8 + (i * n + j) % 7 * 3,
                coords.join(",")
            ));
        }
    }
    let path = dir.join("lots.geojson");
    std::fs::write(
        &path,
        format!(
            r#"{{"type":"FeatureCollection","features":[{}]}}"#,
            features.join(",")
        ),
    )
    .unwrap();
    path
}

/// A box's corners' ranges: centre ± |half axes|.
fn box_range(b: &Value) -> [[f64; 2]; 3] {
    let v: Vec<f64> = b["box"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(v.len(), 12);
    std::array::from_fn(|k| {
        let r: f64 = (0..3).map(|a| v[3 + 3 * a + k].abs()).sum();
        [v[k] - r, v[k] + r]
    })
}

/// Checks a tile and its children; returns the lots in its leaves.
fn check_tile(dir: &Path, tile: &Value, parent: Option<([[f64; 2]; 3], f64)>, lots: &mut Vec<u64>) {
    let range = box_range(&tile["boundingVolume"]);
    let error = tile["geometricError"].as_f64().unwrap();
    assert!(error >= 0.0);
    if let Some((outer, parent_error)) = parent {
        assert!(error <= parent_error, "{error} > {parent_error}");
        for k in 0..3 {
            assert!(range[k][0] >= outer[k][0] - 1e-3 && range[k][1] <= outer[k][1] + 1e-3);
        }
    }
    let children = tile["children"].as_array().cloned().unwrap_or_default();
    if let Some(uri) = tile["content"]["uri"].as_str() {
        let glb = dir.join(uri);
        assert_valid_gltf(&glb);
        let (index, _, _) = property_table(&glb, None);
        if children.is_empty() {
            lots.extend(index);
        }
    }
    if children.is_empty() {
        assert_eq!(error, 0.0, "leaves are the full model");
    } else {
        assert_eq!(tile["refine"], "REPLACE");
    }
    for c in &children {
        check_tile(dir, c, Some((range, error)), lots);
    }
}

#[test]
fn a_georeferenced_city_as_a_tileset() {
    let dir = temp_dir("tiles");
    let lots = lonlat_lots(&dir, 12);
    let rules = rule_file(
        &dir,
        "city.cga",
        "attr height = 10\nLot --> report(\"footprint\", geometry.area) report(\"use\", \"housing\") extrude(height) comp(f) { top : color(\"#a04030\") Roof. | side : split(y) { ~3 : Floor }* }\n\
         Floor --> report(\"floors\", 1) print(\"floor \" + split.index) color(rand(0.5, 1), 0.8, 0.7) X.\n",
    );
    let tileset = dir.join("out/tileset.json");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        lots.to_str().unwrap(),
        "-o",
        tileset.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("144 lots"), "{}", stderr(&out));
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&tileset).unwrap()).unwrap();
    assert_eq!(t["asset"]["version"], "1.1");
    let root = &t["root"];
    assert!(t["geometricError"].as_f64().unwrap() >= root["geometricError"].as_f64().unwrap());
    // East-north-up at the frame's origin to ECEF: the origin is on the
    // WGS84 ellipsoid near 8.5 E, 47.3 N.
    let m: Vec<f64> = root["transform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(m.len(), 16);
    let (x, y, z) = (m[12], m[13], m[14]);
    let r = (x * x + y * y + z * z).sqrt();
    assert!((6_360_000.0..6_380_000.0).contains(&r), "{r}");
    let lon = y.atan2(x).to_degrees();
    assert!((lon - 8.5).abs() < 0.01, "{lon}");
    // Every lot in exactly one leaf; leaves hold at most 64 lots, so 144
    // lots make a parent with children.
    let mut seen = Vec::new();
    check_tile(&dir.join("out"), root, None, &mut seen);
    seen.sort();
    assert_eq!(seen, (0..144).collect::<Vec<u64>>());
    assert!(root["children"].as_array().is_some_and(|c| c.len() >= 2));
    // Per-building metadata in a leaf: a property table with the lot's
    // index, its feature id and its `height` property.
    let leaf = &root["children"][0];
    let leaf = if leaf["children"].is_array() {
        &leaf["children"][0]
    } else {
        leaf
    };
    let (index, names, heights) = property_table(
        &dir.join("out")
            .join(leaf["content"]["uri"].as_str().unwrap()),
        Some("attr_height"),
    );
    assert!(!index.is_empty());
    for ((index, name), height) in index.iter().zip(&names).zip(&heights) {
        let (i, j) = (*index as usize / 12, *index as usize % 12);
        assert_eq!(name, &format!("b{i}_{j}"));
        assert_eq!(height, &(8 + (i * 12 + j) % 7 * 3).to_string());
    }
    // The lots' reports: numbers summed per lot (FLOAT64), text as text.
    let leaf_glb = dir
        .join("out")
        .join(leaf["content"]["uri"].as_str().unwrap());
    let (json, bin) = glb_parts(&leaf_glb);
    let table = &json["extensions"]["EXT_structural_metadata"]["propertyTables"][0];
    let class = &json["extensions"]["EXT_structural_metadata"]["schema"]["classes"]["lot"];
    assert_eq!(
        class["properties"]["report_floors"]["componentType"],
        "FLOAT64"
    );
    assert_eq!(class["properties"]["report_floors"]["name"], "floors");
    let numbers = |key: &str| -> Vec<f64> {
        view_bytes(&json, &bin, &table["properties"][key]["values"])
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let (floors, footprint) = (numbers("report_floors"), numbers("report_footprint"));
    let uses = strings(&json, &bin, &table["properties"]["report_use"]);
    assert_eq!(
        (floors.len(), footprint.len(), uses.len()),
        (index.len(), index.len(), index.len())
    );
    for (k, i) in index.iter().enumerate() {
        // A height of 8 + 3k metres has 3 + k floors of about 3 m a side.
        assert_eq!(floors[k], 4.0 * (3 + *i % 7) as f64, "lot {i}");
        assert!(
            (footprint[k] - 600.0).abs() < 2.0,
            "lot {i}: {}",
            footprint[k]
        );
        assert_eq!(uses[k], "housing");
    }
    // The parent's massing: one mesh of every building's box (4 walls,
    // the top and the base: 12 triangles each).
    let massing = glb_json(
        &dir.join("out")
            .join(root["content"]["uri"].as_str().unwrap()),
    );
    assert_eq!(massing["nodes"].as_array().unwrap().len(), 1);
    let primitive = &massing["meshes"][0]["primitives"][0];
    let indices = &massing["accessors"][primitive["indices"].as_u64().unwrap() as usize];
    assert_eq!(indices["count"].as_u64().unwrap(), 144 * 12 * 3);
    // Its property table has the lots' attributes and reports as the
    // leaves' have them.
    let massing_glb = dir
        .join("out")
        .join(root["content"]["uri"].as_str().unwrap());
    let (index, _, heights) = property_table(&massing_glb, Some("attr_height"));
    assert_eq!(index.len(), 144);
    for (i, h) in index.iter().zip(&heights) {
        assert_eq!(h, &(8 + *i as usize % 7 * 3).to_string());
    }
    let (json, _) = glb_parts(&massing_glb);
    let class = &json["extensions"]["EXT_structural_metadata"]["schema"]["classes"]["lot"];
    assert_eq!(
        class["properties"]["report_floors"]["componentType"],
        "FLOAT64"
    );

    // The same city as one GLB prints the same lines in the same order.
    let glb = dir.join("out/city.glb");
    let one = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        lots.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(one.status.success());
    assert_eq!(stdout(&one), stdout(&out));
    // Its nodes carry the same reports in their extras.
    let json = glb_json(&glb);
    let reports = &json["nodes"][10]["extras"]["reports"];
    assert_eq!(json["nodes"][10]["extras"]["lot"], 10);
    assert_eq!(reports["floors"], 4.0 * (3 + 10 % 7) as f64);
    assert_eq!(reports["use"], "housing");
    assert!((reports["footprint"].as_f64().unwrap() - 600.0).abs() < 2.0);
}

#[test]
fn lots_in_metres_make_a_local_tileset() {
    let dir = temp_dir("tiles-local");
    let rules = rule_file(&dir, "b.cga", "Lot --> extrude(6) X.\n");
    let tileset = dir.join("tileset.json");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        "grid:3x2",
        "-o",
        tileset.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&tileset).unwrap()).unwrap();
    // Six lots: one leaf tile, no transform.
    assert!(t["root"].get("transform").is_none());
    assert!(t["root"].get("children").is_none());
    let mut seen = Vec::new();
    check_tile(&dir, &t["root"], None, &mut seen);
    // In the tile, lots are ordered along a Z curve.
    seen.sort();
    assert_eq!(seen, [0, 1, 2, 3, 4, 5]);
    // z up: the box's height is the extrusion (half axis 3 m).
    let b = box_range(&t["root"]["boundingVolume"]);
    assert!(
        (b[2][0] - 0.0).abs() < 1e-6 && (b[2][1] - 6.0).abs() < 1e-6,
        "{b:?}"
    );
}

/// Context queries between lots see the whole city, not one tile: on 100
/// lots (two leaf tiles at least), every part counts the 99 other lots, as
/// in a single model.
#[test]
fn context_queries_see_every_tile() {
    let dir = temp_dir("tiles-context");
    let rules = rule_file(
        &dir,
        "c.cga",
        "Lot --> label(\"lot\") print(contextCount(inter, \"lot\")) extrude(3) X.\n",
    );
    let generate = |out: &str| {
        let path = dir.join(out);
        let o = run(&[
            "generate",
            rules.to_str().unwrap(),
            "--lot",
            "grid:10x10",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let tiles = generate("t/tileset.json");
    assert_eq!(tiles, "99\n".repeat(100));
    assert_eq!(tiles, generate("one.glb"));
    let t: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("t/tileset.json")).unwrap())
            .unwrap();
    assert!(t["root"]["children"]
        .as_array()
        .is_some_and(|c| c.len() >= 2));
}

/// A leaf whose lots make more triangles than a content may hold is
/// written as several contents, each a child tile of lots close together.
#[test]
fn tiles_bound_their_triangles() {
    let dir = temp_dir("tiles-triangles");
    // A box of 12 triangles per lot; 16 lots fit one leaf by their number.
    let rules = rule_file(&dir, "b.cga", "Lot --> extrude(6) X.\n");
    let tileset = dir.join("tileset.json");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        "grid:4x4",
        "--tile-triangles",
        "50",
        "-o",
        tileset.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let t: Value = serde_json::from_str(&std::fs::read_to_string(&tileset).unwrap()).unwrap();
    let root = &t["root"];
    assert!(root.get("content").is_none());
    let children = root["children"].as_array().unwrap();
    // Four lots (48 triangles) per content.
    assert_eq!(children.len(), 4);
    for c in children {
        let json = glb_json(&dir.join(c["content"]["uri"].as_str().unwrap()));
        let triangles: u64 = json["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| m["primitives"].as_array().unwrap())
            .map(|p| {
                json["accessors"][p["indices"].as_u64().unwrap() as usize]["count"]
                    .as_u64()
                    .unwrap()
                    / 3
            })
            .sum();
        assert_eq!(triangles, 48);
    }
    let mut seen = Vec::new();
    check_tile(&dir, root, None, &mut seen);
    seen.sort();
    assert_eq!(seen, (0..16).collect::<Vec<u64>>());
    // Lots close together: each content's box is a 2 x 2 block of the grid,
    // a quarter of the lots' footprint and a third of the root's box
    // (which takes in the streets between).
    let area = |b: &Value| {
        let r = box_range(b);
        (r[0][1] - r[0][0]) * (r[1][1] - r[1][0])
    };
    let whole = area(&root["boundingVolume"]);
    for c in children {
        let a = area(&c["boundingVolume"]);
        assert!(a < whole * 0.4, "{a} of {whole}");
    }
}
