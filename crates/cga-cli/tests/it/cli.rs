//! The `cga` command's contract (README, DESIGN): what goes to standard
//! output and error, exit statuses, lots, attributes, reports, limits.

use crate::common::*;

const BOX: &str = "version \"2023.0\"\n@StartRule\nLot --> extrude(10) Box.\n";

#[test]
fn prints_go_to_stdout_in_derivation_order_and_nothing_else() {
    let dir = temp_dir("prints");
    let rules = rule_file(
        &dir,
        "p.cga",
        "Lot --> print(\"first\") extrude(4) print(scope.sy) A(2) print(\"last\")\n\
         A(n) --> print(\"in A \" + n) X.\n",
    );
    let out = run(&["generate", rules.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    // A rule's own operations all run before the rules it calls: CityEngine
    // derives in generation (breadth-first) order.
    assert_eq!(stdout(&out), "first\n4\nlast\nin A 2\n");
}

#[test]
fn rules_are_derived_generation_by_generation() {
    // Measured with CityEngine's runtime: every rule of one generation prints
    // before any rule of the next, in the order the shapes were created.
    let dir = temp_dir("generations");
    let rules = rule_file(
        &dir,
        "g.cga",
        "Lot --> print(1) B1 B2\n\
         B1 --> print(10) C1\n\
         B2 --> print(11) C2\n\
         C1 --> print(20) D1 D2\n\
         C2 --> NIL\n\
         D1 --> print(100) E\n\
         D2 --> print(200)\n\
         E --> print(1000)\n",
    );
    let out = run(&["generate", rules.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "1\n10\n11\n20\n100\n200\n1000\n");
}

#[test]
fn default_lot_is_a_20_by_30_rectangle() {
    let dir = temp_dir("default-lot");
    let rules = rule_file(
        &dir,
        "d.cga",
        "Lot --> print(scope.sx) print(scope.sz) print(geometry.area)\n",
    );
    let out = run(&["generate", rules.to_str().unwrap()]);
    assert_eq!(stdout(&out), "20\n30\n600\n");
}

#[test]
fn start_rule_comes_from_the_annotation_then_lot_then_the_option() {
    let dir = temp_dir("start");
    let annotated = rule_file(
        &dir,
        "a.cga",
        "@StartRule\nInit --> print(\"init\")\nLot --> print(\"lot\")\n",
    );
    assert_eq!(
        stdout(&run(&["generate", annotated.to_str().unwrap()])),
        "init\n"
    );
    let plain = rule_file(
        &dir,
        "b.cga",
        "Init --> print(\"init\")\nLot --> print(\"lot\")\n",
    );
    assert_eq!(
        stdout(&run(&["generate", plain.to_str().unwrap()])),
        "lot\n"
    );
    let chosen = run(&["generate", plain.to_str().unwrap(), "--start-rule", "Init"]);
    assert_eq!(stdout(&chosen), "init\n");
    let missing = run(&["generate", plain.to_str().unwrap(), "--start-rule", "Nope"]);
    assert_eq!(missing.status.code(), Some(2));
    assert!(stderr(&missing).contains("Nope"));
}

#[test]
fn attributes_are_overridden_with_the_type_of_their_default() {
    let dir = temp_dir("attrs");
    let rules = rule_file(
        &dir,
        "a.cga",
        "attr h = 10\nattr name = \"x\"\nattr on = false\n\
         Lot --> print(h * 2) print(name + \"!\") print(on)\n",
    );
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--attr",
        "h=2.5",
        "--attr",
        "name=12",
        "--attr",
        "on=true",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "5\n12!\ntrue\n");
    let unknown = run(&["generate", rules.to_str().unwrap(), "--attr", "height=3"]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(stderr(&unknown).contains("no attribute `height`"));
}

#[test]
fn syntax_errors_give_file_line_column_source_line_and_exit_1() {
    let dir = temp_dir("syntax");
    let rules = rule_file(&dir, "bad.cga", "Lot -->\n    extrude(10\n    X.\n");
    for cmd in ["check", "generate"] {
        let out = run(&[cmd, rules.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{cmd}");
        let err = stderr(&out);
        assert!(err.contains("bad.cga:3:5"), "{err}");
        assert!(err.contains("expected"), "{err}");
        assert!(err.contains("    X."), "the source line is shown: {err}");
        assert!(stdout(&out).is_empty());
    }
}

#[test]
fn unknown_operation_names_the_closest_one() {
    let dir = temp_dir("typo");
    let rules = rule_file(&dir, "typo.cga", "Lot --> exturde(10) X.\n");
    let out = run(&["check", rules.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("typo.cga:1:9"), "{err}");
    assert!(err.contains("did you mean `extrude`?"), "{err}");
}

#[test]
fn check_accepts_a_valid_file() {
    let dir = temp_dir("check-ok");
    let rules = rule_file(&dir, "ok.cga", BOX);
    let out = run(&["check", rules.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stdout(&out).is_empty());
}

#[test]
fn runtime_errors_point_at_the_rule_and_keep_the_model() {
    let dir = temp_dir("runtime");
    let rules = rule_file(
        &dir,
        "rt.cga",
        "Lot --> extrude(10) A\nA --> print(\"before\") s(\"wide\", '1, '1) X.\n",
    );
    let obj = dir.join("m.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("rt.cga:2:25"), "{err}");
    assert!(err.contains("expected a float"), "{err}");
    assert_eq!(stdout(&out), "before\n");
    assert!(obj.exists(), "the model is written even when a lot fails");
}

#[test]
fn usage_errors_exit_2() {
    let dir = temp_dir("usage");
    let rules = rule_file(&dir, "u.cga", BOX);
    let r = rules.to_str().unwrap();
    for args in [
        vec!["generate", r, "--lot", "rect:20"],
        vec!["generate", r, "--lot", "rect:-1,3"],
        vec!["generate", r, "--lot", "nothing.shp"],
        vec!["generate", r, "--lot", "missing.obj"],
        vec!["generate", r, "-o", "model.xyz"],
        vec!["generate", "no-such-file.cga"],
        vec!["frobnicate"],
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", stderr(&out));
    }
}

#[test]
fn missing_asset_is_a_warning_and_the_model_is_still_written() {
    let dir = temp_dir("asset");
    let rules = rule_file(
        &dir,
        "a.cga",
        "Lot --> extrude(10) [ i(\"nowhere/window.obj\") W. ] Mass.\n",
    );
    let obj = dir.join("m.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("warning"));
    assert!(stderr(&out).contains("nowhere/window.obj"));
    let s = summarize(&obj);
    // Both the mass and the shape that kept its geometry: 2 boxes of 2200 m².
    assert_eq!(s.faces, 12);
    assert!((s.area - 4400.0).abs() < 1e-6, "{}", s.area);
}

#[test]
fn runaway_recursion_stops_at_the_depth_limit() {
    let dir = temp_dir("depth");
    let rules = rule_file(&dir, "r.cga", "Lot --> A\nA --> t(1, 0, 0) A\n");
    let out = run(&["generate", rules.to_str().unwrap(), "--max-depth", "50"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("depth limit (50)"), "{err}");
    assert!(err.contains("r.cga:2:18"), "{err}");
}

#[test]
fn shape_explosions_stop_at_the_shape_limit() {
    let dir = temp_dir("shapes");
    let rules = rule_file(&dir, "x.cga", "Lot --> A\nA --> A A\n");
    let out = run(&["generate", rules.to_str().unwrap(), "--max-shapes", "1000"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("shape limit (1000)"),
        "{}",
        stderr(&out)
    );
}

/// With the default limits, shapes that multiply without end are not
/// kept waiting by the million on the way to the shape limit (5 million:
/// gigabytes): past 65,536 waiting shapes the derivation goes depth
/// first and meets the depth limit (2^16 + 2^16 + 1000 shapes or so).
#[test]
fn shape_explosions_meet_the_depth_limit_early() {
    let dir = temp_dir("doubling");
    let rules = rule_file(&dir, "x.cga", "Lot --> A\nA --> A A\n");
    let glb = dir.join("x.glb");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("depth limit (1000)"), "{err}");
    // "wrote ...: 1 lots, N shapes, ..."
    let shapes: u64 = err
        .split(", ")
        .find_map(|part| part.strip_suffix(" shapes"))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no shape count in {err}"));
    assert!((131_072..140_000).contains(&shapes), "{shapes} shapes");
}

/// Found by fuzzing: a rule body runs on to the next line, so
/// `Lot --> extrude(5)` followed by a stray `Lot` makes the rule call
/// itself; each extrusion extrudes every face of the last one, so the
/// geometry grows sixfold per generation while the shape count stays
/// small. The geometry limit stops it.
#[test]
fn geometry_explosions_stop_at_the_face_limit() {
    let dir = temp_dir("faces");
    let rules = rule_file(
        &dir,
        "f.cga",
        "Lot --> extrude(5) color(1,1,1,0.75)\n\nLot // a comment -->",
    );
    let out = run(&["generate", rules.to_str().unwrap(), "--max-faces", "20000"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("geometry limit (20000 faces)"), "{err}");
    assert!(err.contains("f.cga:1:9"), "{err}");
}

/// An error in one lot does not stop the city: the lot is named with the
/// error's place, the other lots are generated and written, a summary
/// closes the run, and the exit status is 1.
#[test]
fn an_error_in_one_lot_does_not_stop_the_others() {
    let dir = temp_dir("perlot");
    let rules = rule_file(
        &dir,
        "p.cga",
        "Lot --> case scope.sx > 15 : A(1) else : extrude(3) X.\nA(n) --> print(n) B(n - \"x\")\nB(m) --> X.\n",
    );
    let obj = dir.join("city.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        "rect:20,30",
        "--lot",
        "rect:10,10",
        "--lot",
        "rect:5,5",
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("p.cga:2:21"), "{err}");
    assert!(err.contains("in lot `rect 20x30`"), "{err}");
    assert!(
        err.contains("1 of 3 lots stopped on an error; the others were generated"),
        "{err}"
    );
    // The two boxes of the other lots: 6 quads each.
    let text = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("f ")).count(), 12);
    assert_eq!(stdout(&out), "1\n");
}

/// The written model does not depend on the number of threads: GLB and
/// glTF are encoded in batches (on the deriving threads, or on the writing
/// thread for a single lot with more jobs than lots) and appended in lot
/// order, OBJ is written from
/// leaves on the writing thread. Lots of many leaves (more than one batch
/// each) and of different materials; with `--held-mib 1` the vertex data is
/// written out early many times, at the same points whatever the threads.
#[test]
fn written_models_do_not_depend_on_the_thread_count() {
    let dir = temp_dir("jobs-bytes");
    let rules = rule_file(
        &dir,
        "city.cga",
        "Lot --> extrude(6 + scope.sx / 10) comp(f) { side : Facade | top : color(\"#803020\") Roof. }\n\
         Facade --> split(y) { ~1 : Floor }*\n\
         Floor --> split(x) { ~0.7 : Tile }*\n\
         Tile --> case split.index % 2 == 0 : color(\"#cccccc\") X. else : color(0.2, 0.3, split.index / 40) extrude(0.2) Y.\n",
    );
    for (ext, held, granularity) in [
        ("glb", "64", "material"),
        ("glb", "1", "material"),
        ("gltf", "1", "material"),
        ("obj", "64", "material"),
        ("glb", "64", "lot"),
        ("obj", "64", "lot"),
    ] {
        let mut want: Option<Vec<u8>> = None;
        for jobs in ["1", "2", "3"] {
            let sub = dir.join(format!("{ext}-{held}-{granularity}-{jobs}"));
            std::fs::create_dir_all(&sub).unwrap();
            let model = sub.join(format!("city.{ext}"));
            let out = run(&[
                "generate",
                rules.to_str().unwrap(),
                "--lot",
                "grid:4x3",
                "--jobs",
                jobs,
                "--held-mib",
                held,
                "--granularity",
                granularity,
                "-o",
                model.to_str().unwrap(),
            ]);
            assert!(out.status.success(), "{}", stderr(&out));
            let mut bytes = std::fs::read(&model).unwrap();
            if ext != "obj" {
                assert_valid_gltf(&model);
                let json = gltf_json(&model);
                let meshes = json["meshes"].as_array().unwrap();
                let prims = meshes[0]["primitives"].as_array().unwrap().len();
                if granularity == "material" {
                    // Written early: several primitives per material.
                    assert_eq!(prims > 1, held == "1", "{ext} {held}: {prims} primitives");
                } else {
                    // A mesh per lot, a primitive per material (3 colours
                    // and the tiles' blues).
                    assert_eq!(meshes.len(), 12);
                    assert_eq!(json["nodes"][11]["extras"]["lot"], 11);
                }
            }
            if ext == "gltf" {
                bytes.extend(std::fs::read(model.with_extension("bin")).unwrap());
            }
            // 12 lots, each with hundreds of leaves.
            let err = stderr(&out);
            let leaves: usize = err
                .split(" leaf shapes")
                .next()
                .and_then(|s| s.rsplit(' ').next())
                .and_then(|n| n.parse().ok())
                .unwrap_or_else(|| panic!("no leaf count in {err}"));
            assert!(leaves > 12 * 512, "{leaves} leaves");
            match &want {
                None => want = Some(bytes),
                Some(w) => assert!(
                    *w == bytes,
                    "{ext}, --held-mib {held}: --jobs {jobs} wrote other bytes"
                ),
            }
        }
    }
}

/// The JSON of a glTF or GLB file.
fn gltf_json(path: &std::path::Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let json = if bytes.starts_with(b"glTF") {
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        bytes[20..20 + len].to_vec()
    } else {
        bytes
    };
    serde_json::from_slice(&json).unwrap()
}

/// Found by fuzzing: `extrude(888884) split(y) { 2 : X. }*` asks for
/// 444,442 slabs; with a small shape limit it stops before cutting them.
/// A split beyond a million parts is refused whatever the limits.
#[test]
fn huge_splits_stop_before_cutting() {
    let dir = temp_dir("slabs");
    let rules = rule_file(
        &dir,
        "s.cga",
        "Lot --> extrude(888884) split(y) { 2 : X. }*\n",
    );
    let out = run(&["generate", rules.to_str().unwrap(), "--max-shapes", "2000"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("shape limit (2000)"), "{err}");
    assert!(err.contains("s.cga:1:25"), "{err}");
    let rules = rule_file(
        &dir,
        "b.cga",
        "Lot --> extrude(1e12) split(y) { 1 : X. }*\n",
    );
    let out = run(&["generate", rules.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("split would create 1000000001000 parts, more than the limit of 1048576"),
        "{err}"
    );
}

/// Found by fuzzing: a shape attribute name with a two-byte letter where
/// a component is expected (`scope.ь`) was cut inside the letter (a
/// panic). It is an ordinary error now.
#[test]
fn non_ascii_attribute_names_are_errors_not_crashes() {
    let dir = temp_dir("non-ascii");
    let rules = rule_file(
        &dir,
        "n.cga",
        "Lot --> print(scope.\u{44c}) print(assetInfo(\"a.obj\", \"\u{44c}x\"))\n",
    );
    let out = run(&["check", rules.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("n.cga:1:15"), "{err}");
    assert!(!err.contains("internal error"), "{err}");
}

#[test]
fn reports_are_aggregated_per_key() {
    let dir = temp_dir("report");
    let rules = rule_file(
        &dir,
        "r.cga",
        "Lot --> report(\"area\", geometry.area) A(3) A(5) report(\"kind\", \"lot\")\n\
         A(x) --> report(\"x\", x) report(\"ok\", true)\n",
    );
    let json = dir.join("r.json");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--report",
        json.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["area_sum"], 600.0);
    assert_eq!(v["x_n"], 2.0);
    assert_eq!(v["x_sum"], 8.0);
    assert_eq!(v["x_avg"], 4.0);
    assert_eq!(v["x_min"], 3.0);
    assert_eq!(v["x_max"], 5.0);
    assert_eq!(v["ok_n"], 2.0);
    // Bools and strings: how often each value was reported.
    assert_eq!(v["ok_counts"], serde_json::json!({ "true": 2.0 }));
    assert_eq!(v["kind_counts"], serde_json::json!({ "lot": 1.0 }));
    assert_eq!(v["ok_sum"], true);
    assert_eq!(v["kind_avg"], "lot");
    // And each lot's own reports.
    let lots = v["lots"].as_array().unwrap();
    assert_eq!(lots.len(), 1);
    assert_eq!(lots[0]["id"], "rect 20x30");
    assert_eq!(lots[0]["reports"]["x_sum"], 8.0);
}

#[test]
fn obj_faces_and_geojson_features_give_one_initial_shape_each() {
    let dir = temp_dir("lots");
    let rules = rule_file(
        &dir,
        "l.cga",
        "attr height = 3\nLot --> print(initialShape.name + \" \" + geometry.area + \" \" + height)\n",
    );
    let obj = dir.join("lots.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 4 0 0\nv 4 0 -2\nv 0 0 -2\nv 10 0 0\nv 13 0 0\nv 13 0 -3\nf 1 2 3 4\nf 5 6 7\n",
    )
    .unwrap();
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let lines: Vec<String> = stdout(&out)
        .lines()
        .map(|l| l.rsplit_once(' ').unwrap().0.to_string())
        .collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[0].ends_with(" 8"), "{lines:?}");
    assert!(lines[1].ends_with(" 4.5"), "{lines:?}");

    let gj = dir.join("lots.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","id":"a","properties":{"height":12},"geometry":{"type":"Polygon",
           "coordinates":[[[0,0],[10,0],[10,10],[0,10],[0,0]],[[2,2],[2,4],[4,4],[4,2],[2,2]]]}},
          {"type":"Feature","id":"b","properties":{},"geometry":{"type":"MultiPolygon",
           "coordinates":[[[[20,0],[22,0],[22,2],[20,2],[20,0]]],[[[30,0],[31,0],[31,1],[30,0]]]]}}]}"#,
    )
    .unwrap();
    // Plain metres: GeoJSON is longitude/latitude unless told otherwise.
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        gj.to_str().unwrap(),
        "--crs",
        "local",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The MultiPolygon is one shape of two faces (4 + 0.5 m²).
    assert_eq!(stdout(&out), "a 96 12\nb 4.5 3\n");
    // Or a lot per polygon.
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        gj.to_str().unwrap(),
        "--crs",
        "local",
        "--split-multipolygons",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "a 96 12\nb 4 3\nb.1 0.5 3\n");
}

/// A MultiPolygon is one initial shape with a face per polygon, as
/// CityEngine imports it: an extrusion extrudes every face, comp(f) sees
/// them all, and a setback works on each face.
#[test]
fn a_multipolygon_is_one_shape_of_several_faces() {
    let dir = temp_dir("multipolygon");
    let gj = dir.join("two.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","id":"twin","properties":{},"geometry":{"type":"MultiPolygon",
           "coordinates":[[[[0,0],[10,0],[10,10],[0,10],[0,0]]],[[[20,0],[30,0],[30,10],[20,10],[20,0]]]]}}]}"#,
    )
    .unwrap();
    let rules = rule_file(
        &dir,
        "m.cga",
        r#"Lot --> print(geometry.nFaces) print(geometry.area) Mass
Mass --> extrude(5) print(geometry.nFaces) print(geometry.volume) comp(f) { top : Top }
Top --> print("top " + geometry.area)
"#,
    );
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        gj.to_str().unwrap(),
        "--crs",
        "local",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "2\n200\n12\n1000\ntop 100\ntop 100\n");
}

#[test]
fn glb_gltf_and_obj_outputs_are_written() {
    let dir = temp_dir("formats");
    let rules = rule_file(
        &dir,
        "f.cga",
        "Lot --> extrude(10) color(\"#ff0000\") Box.\n",
    );
    for ext in ["glb", "gltf", "obj"] {
        let path = dir.join(format!("m.{ext}"));
        let out = run(&[
            "generate",
            rules.to_str().unwrap(),
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{ext}: {}", stderr(&out));
        assert!(std::fs::metadata(&path).unwrap().len() > 100, "{ext}");
    }
    assert_valid_gltf(&dir.join("m.glb"));
    assert_valid_gltf(&dir.join("m.gltf"));
    let s = summarize(&dir.join("m.obj"));
    assert_eq!(
        s.by_appearance.get("1.000,0.000,0.000|-").copied(),
        Some(2200.0)
    );
    assert_eq!(s.min, [0.0, 0.0, -30.0]);
    assert_eq!(s.max, [20.0, 10.0, 0.0]);
}

#[test]
fn obj_lots_keep_their_texture_coordinates() {
    // A 60 m street segment whose u runs along it from 0 to 1: the seed
    // page's street bands (`split(u, unitSpace, 0)`) work on the lot itself.
    let dir = temp_dir("street");
    let street = dir.join("street.obj");
    std::fs::write(
        &street,
        "v 0 0 0\nv 60 0 0\nv 60 0 -10\nv 0 0 -10\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
    )
    .unwrap();
    let rules = rule_file(
        &dir,
        "s.cga",
        "Street --> print(geometry.du(0, unitSpace)) split(u, unitSpace, 0) { ~10 : NIL | ~3 : Band | ~10 : NIL }*\n\
         Band --> print(scope.sx) X.\n",
    );
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        street.to_str().unwrap(),
        "--start-rule",
        "Street",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let lines: Vec<f64> = stdout(&out).lines().map(|l| l.parse().unwrap()).collect();
    assert_eq!(lines.len(), 4, "{lines:?}");
    assert!((lines[0] - 60.0).abs() < 1e-9);
    // 3 repetitions of 69 m of pattern squeezed into 60 m: bands of 3 * 60/69.
    for w in &lines[1..] {
        assert!((w - 3.0 * 60.0 / 69.0).abs() < 1e-6, "{w}");
    }
}

#[test]
fn geographic_geojson_is_projected_to_metres() {
    // A block in Zurich given in longitude/latitude: 0.0004 deg of longitude
    // by 0.0002 deg of latitude at 47.37 N is about 30.1 m by 22.2 m.
    let dir = temp_dir("geographic");
    let rules = rule_file(&dir, "g.cga", "Lot --> print(geometry.area)\n");
    let gj = dir.join("zurich.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[{"type":"Feature","properties":{},"geometry":{"type":"Polygon",
           "coordinates":[[[8.5400,47.3700],[8.5404,47.3700],[8.5404,47.3702],[8.5400,47.3702],[8.5400,47.3700]]]}}]}"#,
    )
    .unwrap();
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        gj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("longitude/latitude"),
        "{}",
        stderr(&out)
    );
    let area: f64 = stdout(&out).trim().parse().unwrap();
    // On the WGS84 ellipsoid at 47.37 N: 0.0004 deg of longitude is
    // 30.21 m, 0.0002 deg of latitude 22.24 m (geodesic lengths).
    assert!((area - 30.21 * 22.24).abs() < 0.5, "{area}");
}

#[test]
fn geographic_origin_is_recorded_in_the_output_and_shared_by_all_files() {
    // Two blocks 0.001 deg of longitude apart, in two files: both are
    // projected about the first file's centre, and the output says where
    // that is so the model can be placed back on the globe.
    let dir = temp_dir("georef");
    let rules = rule_file(&dir, "g.cga", "Lot --> extrude(3) X.\n");
    let block = |name: &str, lon: f64| {
        let path = dir.join(name);
        std::fs::write(
            &path,
            format!(
                r#"{{"type":"FeatureCollection","features":[{{"type":"Feature","properties":{{}},"geometry":{{"type":"Polygon",
                   "coordinates":[[[{a},47.3700],[{b},47.3700],[{b},47.3702],[{a},47.3702],[{a},47.3700]]]}}}}]}}"#,
                a = lon,
                b = lon + 0.0004
            ),
        )
        .unwrap();
        path
    };
    let first = block("a.geojson", 8.5400);
    let second = block("b.geojson", 8.5410);
    let glb = dir.join("city.gltf");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        first.to_str().unwrap(),
        "--lot",
        second.to_str().unwrap(),
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_valid_gltf(&glb);
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&glb).unwrap()).unwrap();
    let g = &doc["asset"]["extras"]["georeference"];
    assert_eq!(g["crs"], "EPSG:4326");
    // The centre of both files' extent: 8.5400..8.5414 E, 47.3700..47.3702 N.
    let lon = g["origin"]["longitude"].as_f64().unwrap();
    let lat = g["origin"]["latitude"].as_f64().unwrap();
    assert!((lon - 8.5407).abs() < 1e-9, "{lon}");
    assert!((lat - 47.3701).abs() < 1e-9, "{lat}");
    let projection = g["projection"].as_str().unwrap();
    assert!(
        projection.starts_with(&format!("+proj=tmerc +lat_0={lat} +lon_0={lon} +k_0=1")),
        "{projection}"
    );
    // The blocks span 0.0014 deg of longitude: 105.74 m on the parallel
    // of 47.37 N (radius N cos(lat) = 4,327 km on the ellipsoid).
    let s = summarize_gltf_bounds(&glb);
    let frame = cga::GeoOrigin { lon, lat };
    let width = (frame.to_local(8.5414, 47.37).0 - frame.to_local(8.54, 47.37).0) as f32;
    assert!((s.1[0] - s.0[0] - width).abs() < 0.01, "{s:?} vs {width}");
    assert!((width - 105.74).abs() < 0.01, "{width}");

    let obj = dir.join("city.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        first.to_str().unwrap(),
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&obj).unwrap();
    let header = text.lines().nth(1).unwrap();
    // One file: its own centre.
    let origin: Vec<f64> = header
        .split(' ')
        .filter_map(|w| w.parse().ok())
        .take(2)
        .collect();
    assert!(
        (origin[0] - 8.5402).abs() < 1e-9 && (origin[1] - 47.3701).abs() < 1e-9,
        "{header}"
    );
    assert!(
        header.starts_with("# georeference: origin longitude ") && header.contains("+proj=tmerc"),
        "{header}"
    );
    // Lots in metres carry no georeference.
    let plain = dir.join("plain.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!std::fs::read_to_string(&plain)
        .unwrap()
        .contains("georeference"));
}

/// The (min, max) of the POSITION accessors of a glTF file.
fn summarize_gltf_bounds(path: &std::path::Path) -> ([f32; 3], [f32; 3]) {
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for m in doc["meshes"].as_array().unwrap() {
        for p in m["primitives"].as_array().unwrap() {
            let a = &doc["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(a["min"][k].as_f64().unwrap() as f32);
                hi[k] = hi[k].max(a["max"][k].as_f64().unwrap() as f32);
            }
        }
    }
    (lo, hi)
}

#[test]
fn flatgeobuf_lots_with_attributes() {
    use flatgeobuf::{ColumnType, FgbWriter, FgbWriterOptions, GeometryType};
    use geozero::{ColumnValue, PropertyProcessor};
    let dir = temp_dir("fgb");
    let path = dir.join("lots.fgb");
    let options = FgbWriterOptions {
        write_index: false,
        ..Default::default()
    };
    let mut fgb = FgbWriter::create_with_options("lots", GeometryType::Polygon, options).unwrap();
    fgb.add_column("height", ColumnType::Double, |_, _| {});
    for (x, h) in [(0.0, 12.0), (30.0, 7.5)] {
        let geometry = format!(
            r#"{{"type":"Polygon","coordinates":[[[{x},0],[{},0],[{},10],[{x},10],[{x},0]]]}}"#,
            x + 20.0,
            x + 20.0
        );
        fgb.add_feature_geom(geozero::geojson::GeoJson(&geometry), |feature| {
            feature
                .property(0, "height", &ColumnValue::Double(h))
                .unwrap();
        })
        .unwrap();
    }
    let mut file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    fgb.write(&mut file).unwrap();
    drop(file);
    let rules = rule_file(
        &dir,
        "f.cga",
        "attr height = 1\nLot --> extrude(height) print(geometry.volume)\n",
    );
    // Without a CRS in its header, numbers within longitude/latitude
    // ranges are taken for them (with a warning); --crs local says metres.
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        path.to_str().unwrap(),
        "--crs",
        "local",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "2400\n1500\n");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        path.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("declares no coordinate reference system; its coordinates are within longitude/latitude ranges"),
        "{}",
        stderr(&out)
    );
    let volumes: Vec<f64> = stdout(&out).lines().map(|l| l.parse().unwrap()).collect();
    assert!(volumes[0] > 1e12, "{volumes:?}");
}

#[test]
fn assets_are_found_from_a_relative_rule_path() {
    // A project: rules/ and assets/ side by side, run from inside rules/.
    let dir = temp_dir("relative");
    std::fs::create_dir_all(dir.join("rules")).unwrap();
    std::fs::create_dir_all(dir.join("assets/parts")).unwrap();
    std::fs::write(
        dir.join("assets/parts/tri.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("rules/r.cga"),
        "Lot --> i(\"parts/tri.obj\") print(geometry.nFaces)\n",
    )
    .unwrap();
    let out = cga()
        .current_dir(dir.join("rules"))
        .args(["generate", "r.cga"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("warning"), "{}", stderr(&out));
    assert_eq!(stdout(&out), "1\n");
}

#[test]
fn slow_lots_stop_at_the_time_limit() {
    let dir = temp_dir("time");
    let rules = rule_file(
        &dir,
        "t.cga",
        "Lot --> split(x) { ~0.01 : A }*\nA --> split(z) { ~0.5 : B. }*\n",
    );
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--max-seconds",
        "0.000001",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        stderr(&out).contains("time limit (0.000001 s)"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn assets_over_the_size_limit_are_a_warning() {
    let dir = temp_dir("asset-size");
    std::fs::write(
        dir.join("big.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".repeat(300),
    )
    .unwrap();
    let rules = rule_file(
        &dir,
        "a.cga",
        "Lot --> i(\"big.obj\") print(geometry.nFaces)\n",
    );
    let out = run(&["generate", rules.to_str().unwrap(), "--max-asset-mib", "0"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("larger than the asset size limit (0 MiB"),
        "{}",
        stderr(&out)
    );
    assert_eq!(stdout(&out), "1\n", "the lot keeps its own geometry");
    let out = run(&["generate", rules.to_str().unwrap()]);
    assert_eq!(stdout(&out), "300\n");
}

#[test]
fn crs_and_invalid_options() {
    let dir = temp_dir("gis-options");
    let rules = rule_file(
        &dir,
        "a.cga",
        "Lot --> print(initialShape.name + \" \" + geometry.area)\n",
    );
    let gj = dir.join("eight.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[
{"type":"Feature","id":"eight","properties":{},"geometry":{"type":"Polygon","coordinates":[[[0,0],[10,10],[10,0],[0,10],[0,0]]]}},
{"type":"Feature","id":"ok","properties":{},"geometry":{"type":"Polygon","coordinates":[[[20,0],[30,0],[30,10],[20,10],[20,0]]]}}]}"#,
    )
    .unwrap();
    let args = |extra: &[&str]| {
        let mut a = vec![
            "generate",
            rules.to_str().unwrap(),
            "--lot",
            gj.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        run(&a)
    };
    // Repaired by default: two triangles of 25 m², the faces of one lot,
    // with a warning.
    let out = args(&["--crs", "local"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "eight 50\nok 100\n");
    assert!(
        stderr(&out).contains("warning: ") && stderr(&out).contains("crosses itself at (5, 5)"),
        "{}",
        stderr(&out)
    );
    // Lots of their own with --split-multipolygons.
    let out = args(&["--crs", "local", "--split-multipolygons"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "eight 25\neight-1 25\nok 100\n");
    assert!(
        stderr(&out).contains("warning: ") && stderr(&out).contains("crosses itself at (5, 5)"),
        "{}",
        stderr(&out)
    );
    let out = args(&["--crs", "local", "--invalid", "skip"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(stdout(&out), "ok 100\n");
    let out = args(&["--crs", "local", "--invalid", "error"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("lot `eight` is invalid"),
        "{}",
        stderr(&out)
    );
    assert_eq!(stdout(&out), "");
    // Bad option values are usage errors.
    let out = args(&["--crs", "EPSG:99999999"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("EPSG:99999999"), "{}", stderr(&out));
    let out = args(&["--invalid", "ignore"]);
    assert_eq!(out.status.code(), Some(2));
    // Web Mercator at the equator: east-west metres are ground metres,
    // north-south ones are the sphere's, 1 - e² = 0.99331 of the ground's.
    let out = args(&["--crs", "EPSG:3857", "--invalid", "skip"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let area: f64 = stdout(&out)
        .trim()
        .rsplit_once(' ')
        .unwrap()
        .1
        .parse()
        .unwrap();
    assert!((area - 99.3306).abs() < 0.001, "{area}");
}

/// A rule package as CityEngine shares them (here a zip archive): `cga
/// generate` and `cga check` take it directly; its assets resolve inside it.
#[test]
fn rule_packages_are_read_directly() {
    let dir = temp_dir("rpk");
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut w = zip::ZipWriter::new(&mut out);
        let files: [(&str, &str); 3] = [
            (
                "rules/tower.cga",
                "attr floors = 3\n@StartRule\nTower --> extrude(floors * 3) print(scope.sy) i(\"block.obj\") X.\n",
            ),
            (
                "assets/block.obj",
                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
            ),
            ("bin/tower.cgb", "compiled"),
        ];
        for (name, text) in files {
            w.start_file(name, zip::write::SimpleFileOptions::default())
                .unwrap();
            std::io::Write::write_all(&mut w, text.as_bytes()).unwrap();
        }
        w.finish().unwrap();
    }
    let package = dir.join("tower.rpk");
    std::fs::write(&package, out.into_inner()).unwrap();
    let pkg = package.to_str().unwrap();
    let check = run(&["check", pkg]);
    assert_eq!(check.status.code(), Some(0), "{}", stderr(&check));
    assert!(stderr(&check).contains("ok (1 rule, 1 attribute, 0 functions and consts)"));
    let glb = dir.join("tower.glb");
    let o = run(&[
        "generate",
        pkg,
        "--attr",
        "floors=4",
        "-o",
        glb.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stdout(&o), "12\n");
    assert!(
        stderr(&o).contains("1 lots, 2 shapes, 1 leaf shapes, 1 faces, 2 triangles"),
        "{}",
        stderr(&o)
    );
    // A file that is not an archive is a rule error naming it.
    let bad = dir.join("bad.rpk");
    std::fs::write(&bad, "Lot --> X.").unwrap();
    let o = run(&["check", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("neither a 7z nor a zip archive"),
        "{}",
        stderr(&o)
    );
}

/// `--attr` values are read in the attribute's type: a float attribute
/// given text that is not a number is a usage error naming it; bools read
/// as the `bool` page converts; arrays in CGA's literal form; values outside
/// `@Range` or `@Enum` are a warning naming the lot.
#[test]
fn attribute_values_take_the_attribute_type_and_annotations_warn() {
    let dir = temp_dir("attr-types");
    let rules = rule_file(
        &dir,
        "a.cga",
        "@Range(min=1, max=20)\nattr floors = 3\nattr on = true\nattr heights = [1, 2]\n\
         @Enum(\"flat\", \"gable\")\nattr roof = \"flat\"\n\
         Lot --> print(floors) print(on) print(heights) print(roof)\n",
    );
    let r = rules.to_str().unwrap();
    let bad = run(&["generate", r, "--attr", "floors=abc"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        stderr(&bad).contains("attribute `floors` is a float: `abc` is not a number"),
        "{}",
        stderr(&bad)
    );
    let o = run(&[
        "generate",
        r,
        "--attr",
        "on=f",
        "--attr",
        "heights=[5,5]",
        "--attr",
        "floors=4",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(stdout(&o), "4\nfalse\n(2)[5,5]\nflat\n");
    let o = run(&["generate", r, "--attr", "floors=99", "--attr", "roof=dome"]);
    assert_eq!(o.status.code(), Some(0));
    let err = stderr(&o);
    assert!(
        err.contains("warning: 99 is outside the @Range of attribute `floors` (1 to 20), in lot `rect 20x30`"),
        "{err}"
    );
    assert!(
        err.contains("dome is not one of the @Enum values of attribute `roof` (flat, gable)"),
        "{err}"
    );
    assert!(err.contains("a.cga:2:6"), "{err}");
}

/// Each lot's seed: the run's seed for the first lot, a hash of the seed and
/// the lot's index for the others (so `--seed 1` is not `--seed 0` shifted
/// by a lot); a lot's own `seed` property, or `--attr seed=N`, sets it.
#[test]
fn every_seed_gives_another_city_and_lots_carry_their_own_seed() {
    let dir = temp_dir("seeds");
    let rules = rule_file(&dir, "s.cga", "Lot --> print(seedian) X.\n");
    let r = rules.to_str().unwrap();
    let seeds = |args: &[&str]| -> Vec<String> {
        let mut all = vec!["generate", r];
        all.extend_from_slice(args);
        let o = run(&all);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        stdout(&o).lines().map(str::to_string).collect()
    };
    let s0 = seeds(&["--lot", "grid:4x1", "--seed", "0"]);
    let s1 = seeds(&["--lot", "grid:4x1", "--seed", "1"]);
    assert_eq!(s0[0], "0");
    assert_eq!(s1[0], "1");
    assert_ne!(&s0[1..], &s1[..3], "not shifted by a lot");
    let all: std::collections::HashSet<_> = s0.iter().chain(&s1).collect();
    assert_eq!(all.len(), 8);
    // One lot with --seed 666 derives with seedian 666.
    assert_eq!(seeds(&["--seed", "666"]), vec!["666"]);
    // --attr seed=N: every lot's own seed.
    assert_eq!(
        seeds(&["--lot", "grid:2x1", "--attr", "seed=42"]),
        vec!["42", "42"]
    );
    // A GeoJSON property `seed` is the lot's seed.
    let geojson = dir.join("lots.geojson");
    std::fs::write(
        &geojson,
        r#"{"type":"FeatureCollection","features":[
        {"type":"Feature","properties":{"seed":7},"geometry":{"type":"Polygon","coordinates":[[[0,0],[10,0],[10,10],[0,10],[0,0]]]}},
        {"type":"Feature","properties":{"seed":9},"geometry":{"type":"Polygon","coordinates":[[[20,0],[30,0],[30,10],[20,10],[20,0]]]}}]}"#,
    )
    .unwrap();
    assert_eq!(seeds(&["--lot", geojson.to_str().unwrap()]), vec!["7", "9"]);
}

/// A rule file with a second and a third style (style.md): the height of
/// the building says which style generated it.
const STYLED: &str = "attr h = 10\n@StartRule\nLot --> extrude(h) print(h)\nBack --> X.\nstyle Modern\nattr h = 20\nstyle Tall extends Modern\nattr h = 30\n";

#[test]
fn style_chooses_the_style_a_file_generates_with() {
    let dir = temp_dir("style");
    let rules = rule_file(&dir, "styled.cga", STYLED);
    let printed = |extra: &[&str]| {
        let mut args = vec!["generate", rules.to_str().unwrap()];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        stdout(&out)
    };
    assert_eq!(printed(&[]), "10\n");
    assert_eq!(printed(&["--style", "Default"]), "10\n");
    assert_eq!(printed(&["--style", "Modern"]), "20\n");
    assert_eq!(printed(&["--style", "Tall"]), "30\n");

    // An unknown style is an error naming the styles that exist.
    let out = run(&["generate", rules.to_str().unwrap(), "--style", "Modrn"]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("unknown style `Modrn`"), "{err}");
    assert!(err.contains("Default, Modern, Tall"), "{err}");
}

#[test]
fn check_lists_styles_and_start_rules() {
    let dir = temp_dir("check-styles");
    let rules = rule_file(&dir, "styled.cga", STYLED);
    let out = run(&["check", rules.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("styles: Default, Modern, Tall\n"), "{err}");
    assert!(err.contains("start rules: Lot, Back\n"), "{err}");

    let out = run(&["check", rules.to_str().unwrap(), "--format", "json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let doc: serde_json::Value = serde_json::from_str(&stdout(&out)).unwrap();
    assert_eq!(
        doc["styles"],
        serde_json::json!(["Default", "Modern", "Tall"])
    );
    assert_eq!(doc["start_rules"], serde_json::json!(["Lot", "Back"]));

    let out = run(&["check", rules.to_str().unwrap(), "--style", "Nope"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr(&out).contains("unknown style `Nope`"));
}

#[test]
fn an_import_of_an_unknown_style_is_an_error() {
    let dir = temp_dir("import-style");
    rule_file(
        &dir,
        "imp.cga",
        "Lot --> extrude(10)\nstyle mystyle\nLot --> extrude(20)\n",
    );
    let main = rule_file(
        &dir,
        "main.cga",
        "import imp ( mystyl ) : \"imp.cga\"\nLot --> imp.Lot\n",
    );
    let out = run(&["check", main.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("main.cga:1:14"), "{err}");
    assert!(err.contains("unknown style `mystyl`"), "{err}");
    assert!(err.contains("defines the styles Default, mystyle"), "{err}");
}

/// An OBJ model can be taken apart: a group (`g`) per lot, named by its
/// feature id, and materials named by their colour or colour map.
#[test]
fn obj_groups_per_lot_and_material_names_say_what_they_are() {
    let dir = temp_dir("obj-groups");
    let gj = dir.join("two.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","id":"north house","properties":{},"geometry":{"type":"Polygon",
           "coordinates":[[[0,0],[10,0],[10,10],[0,10],[0,0]]]}},
          {"type":"Feature","id":"b","properties":{},"geometry":{"type":"Polygon",
           "coordinates":[[[20,0],[30,0],[30,10],[20,10],[20,0]]]}}]}"#,
    )
    .unwrap();
    let rules = rule_file(
        &dir,
        "g.cga",
        "Lot --> extrude(3) comp(f) { top : color(\"#ff8000\") Roof. | all : Wall. }\n",
    );
    let obj = dir.join("m.obj");
    let out = run(&[
        "generate",
        rules.to_str().unwrap(),
        "--lot",
        gj.to_str().unwrap(),
        "--crs",
        "local",
        "-o",
        obj.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&obj).unwrap();
    let groups: Vec<&str> = text.lines().filter(|l| l.starts_with("g ")).collect();
    assert_eq!(groups, ["g north_house", "g b"]);
    // Each group's faces: the 5 walls and the roof of one building.
    let faces_after = |g: &str| {
        text.split(g)
            .nth(1)
            .unwrap()
            .split("\ng ")
            .next()
            .unwrap()
            .lines()
            .filter(|l| l.starts_with("f "))
            .count()
    };
    assert_eq!(faces_after("g north_house\n"), 6);
    assert_eq!(faces_after("g b\n"), 6);
    let mtl = std::fs::read_to_string(dir.join("m.mtl")).unwrap();
    let names: Vec<&str> = mtl
        .lines()
        .filter_map(|l| l.strip_prefix("newmtl "))
        .collect();
    assert_eq!(names, ["color_ff8000", "color_ffffff"]);
}

/// A glTF model keeps its lots apart: a node per lot named by its feature
/// id, with the lot index and the feature's properties in `extras`;
/// `--granularity material` merges them by material.
#[test]
fn gltf_nodes_per_lot_carry_the_lot_and_its_attributes() {
    let dir = temp_dir("gltf-nodes");
    let gj = dir.join("two.geojson");
    std::fs::write(
        &gj,
        r#"{"type":"FeatureCollection","features":[
          {"type":"Feature","id":"n1","properties":{"height":12,"use":"office"},"geometry":{"type":"Polygon",
           "coordinates":[[[0,0],[10,0],[10,10],[0,10],[0,0]]]}},
          {"type":"Feature","id":"n2","properties":{"height":6,"use":"home"},"geometry":{"type":"Polygon",
           "coordinates":[[[20,0],[30,0],[30,10],[20,10],[20,0]]]}}]}"#,
    )
    .unwrap();
    let rules = rule_file(
        &dir,
        "n.cga",
        "attr height = 3\nLot --> extrude(height) comp(f) { top : color(\"#ff8000\") Roof. | all : Wall. }\n",
    );
    let gltf = dir.join("m.gltf");
    let generate = |extra: &[&str]| {
        let mut args = vec![
            "generate",
            rules.to_str().unwrap(),
            "--lot",
            gj.to_str().unwrap(),
            "--crs",
            "local",
            "-o",
            gltf.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = run(&args);
        assert!(out.status.success(), "{}", stderr(&out));
        let doc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&gltf).unwrap()).unwrap();
        doc
    };
    let doc = generate(&[]);
    let nodes = doc["nodes"].as_array().unwrap();
    assert_eq!(nodes.len(), 2);
    assert_eq!(nodes[0]["name"], "n1");
    assert_eq!(
        nodes[0]["extras"],
        serde_json::json!({"lot": 0, "attributes": {"height": 12.0, "use": "office"}})
    );
    assert_eq!(nodes[1]["name"], "n2");
    assert_eq!(nodes[1]["extras"]["lot"], 1);
    // Each lot's mesh: the roof and the walls.
    for n in nodes {
        let mesh = &doc["meshes"][n["mesh"].as_u64().unwrap() as usize];
        assert_eq!(mesh["primitives"].as_array().unwrap().len(), 2);
    }
    let names: Vec<&str> = doc["materials"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["color_ff8000", "color_ffffff"]);

    let doc = generate(&["--granularity", "material"]);
    let nodes: Vec<&str> = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n["name"].as_str().unwrap())
        .collect();
    assert_eq!(nodes, ["color_ff8000", "color_ffffff"]);
}

/// Generating again over the last output (GLB, glTF with its `.bin`, OBJ
/// with its `.mtl`) gives the same files, whose old versions are moved
/// aside and removed (no hidden file is left in the folder), and keeps
/// writing through a symbolic link to the file it names.
#[test]
fn generating_over_the_last_output_replaces_it() {
    let dir = temp_dir("regenerate");
    let rules = rule_file(&dir, "box.cga", BOX);
    let out_dir = dir.join("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    let listing = || {
        let mut n: Vec<String> = std::fs::read_dir(&out_dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    };
    for name in ["m.glb", "m.gltf", "m.obj"] {
        let path = out_dir.join(name);
        let generate = |lot: &str| {
            let out = run(&[
                "generate",
                rules.to_str().unwrap(),
                "--lot",
                lot,
                "-o",
                path.to_str().unwrap(),
            ]);
            assert!(out.status.success(), "{}", stderr(&out));
            std::fs::read(&path).unwrap()
        };
        let small = generate("rect:10,12");
        let large = generate("grid:3x3");
        assert!(large.len() > small.len(), "{name}");
        assert_eq!(generate("rect:10,12"), small, "{name}");
    }
    assert_eq!(
        listing(),
        ["m.bin", "m.glb", "m.gltf", "m.mtl", "m.obj"],
        "nothing hidden is left beside the outputs"
    );
    #[cfg(unix)]
    {
        let target = out_dir.join("m.glb");
        let link = dir.join("link.glb");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        let out = run(&[
            "generate",
            rules.to_str().unwrap(),
            "-o",
            link.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(
            std::fs::read(&link).unwrap(),
            std::fs::read(&target).unwrap()
        );
    }
}
