//! The library boundary itself: any host thread, cancellation, worlds,
//! programs of files with errors, caches across reloads.

use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use cga::{
    ConfinedWorld, DiskWorld, Engine, Error, Limits, MemoryWorld, Options, Severity, Target, Value,
    World,
};

fn memory_rules(text: &str) -> cga::Rules {
    Engine::new(MemoryWorld::new()).load_text("/p/rules/r.cga", text)
}

/// A plain thread of Rust's default size, as rayon, tokio and Python give.
fn on_small_thread<R: Send + 'static>(f: impl FnOnce() -> R + Send + 'static) -> R {
    std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(f)
        .unwrap()
        .join()
        .expect("the thread did not abort")
}

#[test]
fn deep_recursion_on_a_small_thread_stops_at_the_depth_limit() {
    let result = on_small_thread(|| {
        let rules = memory_rules(
            "f(n) = case n > 0 : f(n - 1) + 1 else : 0\n\
             Lot --> print(f(100000)) X.\n",
        );
        assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
        rules
            .generate(&cga::lots::rect(20.0, 30.0), &Options::default())
            .unwrap()
    });
    let error = result.error.expect("the depth limit stops the lot");
    assert!(
        error
            .message
            .starts_with("evaluation depth limit (1000) reached in function `f`"),
        "{}",
        error.message
    );
    assert_eq!(error.location.unwrap().line, 1);
    // Within the limit, the same function answers.
    let ok = on_small_thread(|| {
        memory_rules("f(n) = case n > 0 : f(n - 1) + 1 else : 0\nLot --> print(f(900)) X.\n")
            .generate(&cga::lots::rect(20.0, 30.0), &Options::default())
            .unwrap()
    });
    assert!(ok.error.is_none());
    assert_eq!(ok.prints, vec!["900"]);
}

#[test]
fn deep_rule_recursion_and_nesting_on_a_small_thread() {
    // Rules calling rules to the derivation depth limit, and an expression
    // nested sixty parentheses deep, on a 2 MiB thread.
    let nested = format!("{}1{}", "(".repeat(60), ")".repeat(60));
    let text = format!("A(n) --> A(n + 1)\nLot --> print({nested}) A(0)\n");
    let result = on_small_thread(move || {
        let rules = memory_rules(&text);
        assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
        rules
            .generate(&cga::lots::rect(20.0, 30.0), &Options::default())
            .unwrap()
    });
    assert_eq!(result.prints, vec!["1"]);
    let error = result.error.expect("the depth limit stops the lot");
    assert!(error
        .message
        .starts_with("derivation depth limit (1000) reached in rule `A`"));
    // Deeper nesting is a diagnostic, not an overflow.
    let deeper = format!(
        "Lot --> print({}1{}) X.\n",
        "(".repeat(50_000),
        ")".repeat(50_000)
    );
    let rules = on_small_thread(move || memory_rules(&deeper));
    assert!(rules.diagnostics()[0].message.contains("nested too deeply"));
}

#[test]
/// An endless generation stops when cancelled and says so. How soon is
/// not asserted (a loaded machine may hold the thread back); the engine
/// looks at the flag with every shape it counts, and the 5 s here only
/// tell a generation that stopped from one that never would.
fn a_cancelled_generation_stops_and_says_so() {
    // Endless: every generation doubles the shapes (each half scaled back
    // to the whole, so that they never get too small to split), under
    // generous limits.
    let rules = memory_rules("Lot --> s('2, '1, '1) split(x) { ~1 : Lot | ~1 : Lot }\n");
    let cancel = cga::Cancel::new();
    let options = Options::default().cancel(cancel.clone()).limits(Limits {
        max_depth: 1_000_000,
        max_shapes: usize::MAX,
        max_seconds: 600.0,
        max_faces: usize::MAX,
    });
    let lots: Vec<_> = (0..4).map(|_| cga::lots::rect(20.0, 30.0)).collect();
    let (tx, rx) = std::sync::mpsc::channel();
    let worker = std::thread::spawn(move || {
        let r = rules.generate_lots(&lots, &options, Target::Nothing, |_| {});
        tx.send(Instant::now()).unwrap();
        r
    });
    std::thread::sleep(Duration::from_millis(300));
    assert!(rx.try_recv().is_err(), "still generating before the cancel");
    let asked = Instant::now();
    cancel.cancel();
    let returned = rx
        .recv_timeout(Duration::from_secs(5))
        .expect("it stops once cancelled");
    assert!(returned >= asked);
    assert!(matches!(worker.join().unwrap(), Err(Error::Cancelled)));
}

#[test]
fn a_file_with_errors_still_gives_its_program() {
    let rules = memory_rules(
        "@Range(min=1, max=9)\nattr floors = 3\n\
         height(n) = n * 3\n\
         Lot --> extrude(height(floors)) Mass\n\
         Mass --> comp(f) { top : Roof. | side : Facde }\n\
         Broken --> split(x) { 2 : A | }\n",
    );
    assert!(rules.has_errors());
    let errors: Vec<_> = rules
        .diagnostics()
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert_eq!(
        errors[0].location.as_ref().unwrap().line,
        6,
        "{}",
        rules.render_diagnostics()
    );
    // What resolved is there: attributes with annotations, rules with places.
    let floors = rules.attribute("floors").expect("the attribute resolved");
    assert_eq!(floors.range().map(|r| r.max), Some(9.0));
    assert_eq!(floors.location.as_ref().unwrap().line, 2);
    assert_eq!(rules.start_rules()[0], "Lot");
    assert!(rules.size().rules >= 3 && rules.size().functions == 1);
    // It does not generate.
    assert!(matches!(
        rules.generate(&cga::lots::rect(5.0, 5.0), &Options::default()),
        Err(Error::Rules { errors: 1, .. })
    ));
}

#[test]
fn an_unreadable_file_is_a_diagnostic_not_a_failure() {
    let rules = Engine::new(MemoryWorld::new()).load("/nowhere/r.cga");
    assert!(rules.has_errors());
    assert_eq!(rules.diagnostics()[0].severity, Severity::Error);
    assert!(rules.diagnostics()[0]
        .message
        .starts_with("cannot read rule file /nowhere/r.cga"));
}

#[test]
fn imports_and_assets_come_from_the_world() {
    let world = MemoryWorld::new()
        .with("/p/rules/lib.cga", "Part --> color(\"#ff0000\") P.\n")
        .with("/p/assets/table.txt", "a;b\n1;2\n")
        .with(
            "/p/assets/box.obj",
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
        );
    let engine = Engine::new(world);
    let rules = engine.load_text(
        "/p/rules/main.cga",
        "import lib : \"lib.cga\"\n\
         Lot --> print(readTextFile(\"table.txt\")) print(fileExists(\"box.obj\")) i(\"box.obj\") lib.Part\n",
    );
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let r = rules
        .generate(&cga::lots::rect(4.0, 4.0), &Options::default())
        .unwrap();
    assert_eq!(r.prints, vec!["a;b\n1;2\n", "true"]);
    assert_eq!(r.model.materials.len(), 1);
    assert_eq!(r.model.materials[0].color, [1.0, 0.0, 0.0]);
    assert_eq!(r.model.triangles(), 2);
}

#[test]
fn a_confined_world_refuses_files_outside_its_roots() {
    let dir = std::env::temp_dir().join(format!("cga-facade-confined-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("project/rules")).unwrap();
    std::fs::create_dir_all(dir.join("private")).unwrap();
    std::fs::write(dir.join("private/secret.txt"), "secret").unwrap();
    std::fs::write(dir.join("project/rules/ok.txt"), "fine").unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(
        dir.join("private/secret.txt"),
        dir.join("project/rules/link.txt"),
    )
    .unwrap();
    let world = ConfinedWorld::new(Arc::new(DiskWorld), [dir.join("project")]);
    let engine = Engine::new(world);
    let secret = dir.join("private/secret.txt");
    let rules = engine.load_text(
        dir.join("project/rules/r.cga"),
        format!(
            "Lot --> print(readTextFile(\"ok.txt\")) print(readTextFile(\"{}\")) \
             print(readTextFile(\"../../private/secret.txt\")) print(readTextFile(\"/etc/passwd\")) \
             print(readTextFile(\"link.txt\")) X.\n",
            secret.display()
        ),
    );
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let r = rules
        .generate(&cga::lots::rect(4.0, 4.0), &Options::default())
        .unwrap();
    assert_eq!(r.prints[0], "fine");
    for (i, p) in r.prints.iter().enumerate().skip(1) {
        assert!(
            !p.contains("secret") && !p.contains("root:"),
            "print {i}: {p}"
        );
    }
    // Nor can rules import from outside.
    let outside = engine.load_text(
        dir.join("project/rules/r2.cga"),
        "import x : \"../../private/lib.cga\"\nLot --> X.\n",
    );
    std::fs::write(dir.join("private/lib.cga"), "A --> X.").unwrap();
    assert!(outside.has_errors());
    // Lot files are read through the world too: inside the roots, yes.
    std::fs::write(
        dir.join("project/lots.obj"),
        "v 0 0 0\nv 4 0 0\nv 4 0 -4\nv 0 0 -4\nf 1 2 3 4\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("private/lots.obj"),
        "v 0 0 0\nv 4 0 0\nv 4 0 -4\nf 1 2 3\n",
    )
    .unwrap();
    let inside = engine
        .read_lots(
            &[dir.join("project/lots.obj").display().to_string()],
            &Default::default(),
        )
        .unwrap();
    assert_eq!(inside.lots.len(), 1);
    let Err(Error::Lot(e)) = engine.read_lots(
        &[dir.join("private/lots.obj").display().to_string()],
        &Default::default(),
    ) else {
        panic!("a lot file outside the roots was read");
    };
    assert!(
        e.contains("outside the folders this engine may read"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Lots from files held in memory (an upload, a notebook's string): OBJ,
/// GeoJSON, FlatGeobuf and Shapefile go through the engine's world.
#[test]
fn lots_are_read_through_the_engines_world() {
    let world = MemoryWorld::new()
        .with(
            "/data/parcels.geojson",
            r#"{"type":"FeatureCollection","features":[
              {"type":"Feature","id":"p1","properties":{"floors":3},"geometry":{"type":"Polygon",
               "coordinates":[[[0,0],[10,0],[10,20],[0,20],[0,0]]]}}]}"#,
        )
        .with(
            "/data/lots.obj",
            "v 0 0 0\nv 5 0 0\nv 5 0 -5\nv 0 0 -5\nf 1 2 3 4\n",
        );
    let engine = Engine::new(world);
    let options = cga::LotOptions {
        crs: Some(cga::CrsOption::Local),
        ..Default::default()
    };
    let set = engine
        .read_lots(
            &[
                "/data/parcels.geojson",
                "/data/lots.obj",
                "grid:2x1:/data/lots.obj",
            ],
            &options,
        )
        .unwrap();
    let names: Vec<&str> = set.lots.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names.len(), 4, "{names:?}");
    assert_eq!(names[0], "p1");
    assert_eq!(
        set.lots[0].attrs,
        vec![("floors".into(), Value::Float(3.0))]
    );
    let area = |l: &cga::Lot| -> f64 {
        let rules = engine.load_text("/data/a.cga", "Lot --> print(geometry.area)\n");
        rules.generate(l, &Options::default()).unwrap().prints[0]
            .parse()
            .unwrap()
    };
    assert_eq!(area(&set.lots[0]), 200.0);
    assert_eq!(area(&set.lots[1]), 25.0);
    // Not on disk: the same names fail there.
    let Err(Error::Lot(e)) = cga::lots::read_with(&["/data/lots.obj"], &options) else {
        panic!("read from disk");
    };
    assert!(e.starts_with("cannot read lot file /data/lots.obj"), "{e}");
}

#[test]
fn assets_are_read_once_across_reloads_until_they_change() {
    /// Counts reads of each file.
    struct Counting(MemoryWorld, std::sync::Mutex<Vec<String>>);
    impl World for Counting {
        fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
            self.1.lock().unwrap().push(path.display().to_string());
            self.0.read(path)
        }
        fn metadata(&self, path: &Path) -> Option<cga::Metadata> {
            self.0.metadata(path)
        }
        fn read_dir(&self, path: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
            self.0.read_dir(path)
        }
        fn canonical(&self, path: &Path) -> std::path::PathBuf {
            self.0.canonical(path)
        }
    }
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let world = Arc::new(Counting(
        MemoryWorld::new().with("/p/assets/box.obj", obj),
        Default::default(),
    ));
    let engine = Engine::with_world(world.clone());
    let reads = || {
        world
            .1
            .lock()
            .unwrap()
            .iter()
            .filter(|p| p.ends_with("box.obj"))
            .count()
    };
    for round in 0..3 {
        let rules = engine.load_text("/p/rules/r.cga", "Lot --> i(\"box.obj\") X.\n");
        let r = rules
            .generate(&cga::lots::rect(2.0, 2.0), &Options::default())
            .unwrap();
        assert_eq!(r.model.triangles(), 2, "round {round}");
    }
    assert_eq!(reads(), 1, "read once for three loads");
    // An edited asset is read again.
    world
        .0
        .set("/p/assets/box.obj", format!("{obj}v 0 0 1\nf 1 2 5\n"));
    let rules = engine.load_text("/p/rules/r.cga", "Lot --> i(\"box.obj\") X.\n");
    let r = rules
        .generate(&cga::lots::rect(2.0, 2.0), &Options::default())
        .unwrap();
    assert_eq!(r.model.triangles(), 3);
    assert_eq!(reads(), 2);
}

#[test]
fn attributes_are_set_by_name_and_unknown_names_are_errors() {
    let rules = memory_rules("attr h = 3\nattr label = \"a\"\nLot --> print(h) print(label) X.\n");
    let lot = cga::lots::rect(2.0, 2.0);
    let r = rules
        .generate(&lot, &Options::default().attr("h", 7.5).attr("label", "b"))
        .unwrap();
    assert_eq!(r.prints, vec!["7.5", "b"]);
    match rules.generate(&lot, &Options::default().attr("height", 2.0)) {
        Err(Error::UnknownAttribute { name, known }) => {
            assert_eq!(name, "height");
            assert_eq!(known, vec!["h", "label"]);
        }
        other => panic!("{other:?}"),
    }
    let a = rules.attribute("label").unwrap();
    assert_eq!(a.default, Some(Value::from("a")));
    assert_eq!(a.ty, Some(cga::ValueType::Str));
}

#[test]
fn many_lots_come_in_order_whatever_the_threads() {
    let rules = memory_rules("Lot --> print(scope.sx) extrude(scope.sx) X.\n");
    let lots: Vec<_> = (1..=12).map(|i| cga::lots::rect(i as f64, 2.0)).collect();
    for jobs in [1, 2, 5] {
        let mut seen = Vec::new();
        let summary = rules
            .generate_lots(&lots, &Options::default().jobs(jobs), Target::Meshes, |r| {
                seen.push((r.index, r.prints.clone(), r.model.triangles()))
            })
            .unwrap();
        assert_eq!(summary.lots, 12);
        assert_eq!(summary.failed, 0);
        for (i, (index, prints, triangles)) in seen.iter().enumerate() {
            assert_eq!(*index, i);
            assert_eq!(prints, &vec![(i + 1).to_string()]);
            assert_eq!(*triangles, 12, "a box");
        }
    }
}

/// A zip archive of `files`, as a rule package.
fn zip_package(files: &[(&str, &[u8])]) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    {
        let mut w = zip::ZipWriter::new(&mut out);
        for (name, bytes) in files {
            w.start_file(*name, zip::write::SimpleFileOptions::default())
                .unwrap();
            std::io::Write::write_all(&mut w, bytes).unwrap();
        }
        w.finish().unwrap();
    }
    out.into_inner()
}

#[test]
fn a_zip_rule_package_loads_with_its_imports_and_assets() {
    let obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";
    let package = zip_package(&[
        ("bin/main.cgb", b"compiled"),
        ("bin/main$lib.cgb", b"compiled"),
        (
            "rules/main.cga",
            b"import lib : \"lib.cga\"\nattr n = 2\nLot --> print(readTextFile(\"notes.txt\")) i(\"box.obj\") lib.Part\n",
        ),
        ("rules/lib.cga", b"Part --> report(\"parts\", 1) P.\n"),
        ("assets/notes.txt", b"from the package"),
        ("assets/box.obj", obj),
    ]);
    let world = MemoryWorld::new().with("/pkgs/city.rpk", package);
    let rules = Engine::new(world).load("/pkgs/city.rpk");
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    assert_eq!(rules.path(), Path::new("/pkgs/city.rpk/rules/main.cga"));
    assert_eq!(rules.attributes()[0].name, "n");
    let r = rules
        .generate(&cga::lots::rect(3.0, 3.0), &Options::default())
        .unwrap();
    assert_eq!(r.prints, vec!["from the package"]);
    assert_eq!(r.reports, vec![("parts".to_string(), Value::Float(1.0))]);
    assert_eq!(r.model.triangles(), 2);
    // Not a package, and a missing one, are diagnostics.
    let world = MemoryWorld::new().with("/pkgs/bad.rpk", "Lot --> X.");
    let bad = Engine::new(world).load("/pkgs/bad.rpk");
    assert!(bad.diagnostics()[0]
        .message
        .contains("neither a 7z nor a zip"));
    let missing = Engine::new(MemoryWorld::new()).load("/pkgs/none.rpk");
    assert!(missing.diagnostics()[0]
        .message
        .starts_with("cannot read rule package"));
}

/// The rule packages of CityEngine's runtime (7z archives), in
/// `../shared/prt-oracle/rpk` outside the repository.
fn shared_package(name: &str) -> Option<std::path::PathBuf> {
    cga_testkit::shared(&format!("prt-oracle/rpk/{name}"))
}

#[test]
fn seven_zip_packages_of_cityengine_load_and_generate() {
    let Some(candler) = shared_package("candler.rpk") else {
        return;
    };
    let rules = Engine::on_disk().load(&candler);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    assert!(rules.path().ends_with("candler.rpk/rules/candler.cga"));
    let r = rules
        .generate(&cga::lots::rect(20.0, 30.0), &Options::default())
        .unwrap();
    assert!(r.error.is_none());
    assert!(r.warnings.is_empty(), "{:?}", r.warnings);
    // Its textures come from the package: materials name files inside it.
    assert!(r.model.materials.iter().any(|m| m.maps[0]
        .path
        .contains("candler.rpk/assets/facade/walls/bricks.jpg")));
    let Some(envelope) = shared_package("envelope2002.rpk") else {
        return;
    };
    let rules = Engine::on_disk().load(&envelope);
    assert!(rules
        .path()
        .ends_with("envelope2002.rpk/rules/typology/envelope2002.cga"));
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
}

/// A city generated in parts (tiles, partitions) is the city of one call:
/// `lot_indices` number the lots of a part as in the whole.
#[test]
fn parts_with_their_lot_indices_make_the_same_city() {
    let rules = memory_rules(
        "attr h = rand(5, 50)\nLot --> print(h + \" \" + rand(0, 1) + \" \" + initialShape.name) X.\n",
    );
    let lots: Vec<cga::Lot> = (0..5)
        .map(|k| {
            let mut lot = cga::lots::rect(10.0 + k as f64, 10.0);
            lot.name = format!("lot{k}");
            lot
        })
        .collect();
    let options = Options::default().seed(7);
    let whole: Vec<String> = rules
        .generate_all(&lots, &options)
        .unwrap()
        .into_iter()
        .flat_map(|r| r.prints)
        .collect();
    // Lots 3, 0 and 4, then 1 and 2: each part in any order.
    let mut parts = vec![String::new(); 5];
    for indices in [vec![3, 0, 4], vec![1, 2]] {
        let part: Vec<cga::Lot> = indices.iter().map(|&i| lots[i].clone()).collect();
        let options = Options {
            lot_indices: Some(indices.clone().into()),
            ..options.clone()
        };
        let results = rules.generate_all(&part, &options).unwrap();
        for (k, r) in results.into_iter().enumerate() {
            assert_eq!(r.index, indices[k]);
            parts[r.index] = r.prints[0].clone();
        }
    }
    assert_eq!(whole.len(), 5);
    assert_eq!(parts, whole);
    // Without it the second part would repeat the first lots' draws.
    let alone: Vec<String> = rules
        .generate_all(&lots[2..], &options)
        .unwrap()
        .into_iter()
        .flat_map(|r| r.prints)
        .collect();
    assert_ne!(alone, whole[2..]);
}

#[test]
fn lots_in_a_given_order_keep_their_indices() {
    let rules = memory_rules("Lot --> print(scope.sx) extrude(1) X.\n");
    let lots: Vec<_> = (1..=12).map(|i| cga::lots::rect(i as f64, 2.0)).collect();
    let order = [5, 0, 11, 3];
    for jobs in [1, 2] {
        let mut seen = Vec::new();
        let summary = rules
            .generate_lots_in_order(
                &lots,
                &order,
                &Options::default().jobs(jobs),
                Target::Meshes,
                |r| seen.push((r.index, r.prints.clone())),
            )
            .unwrap();
        assert_eq!(summary.lots, 4);
        let want: Vec<_> = order
            .iter()
            .map(|&i| (i, vec![(i + 1).to_string()]))
            .collect();
        assert_eq!(seen, want, "{jobs} jobs");
    }
    for order in [&[2, 12][..], &[2, 5, 2]] {
        let bad = rules.generate_lots_in_order(
            &lots,
            order,
            &Options::default(),
            Target::Nothing,
            |_| {},
        );
        assert!(matches!(bad, Err(Error::Value(_))), "{order:?}: {bad:?}");
    }
}

/// `count` squares of side `side`, the `i`-th moved `i * step` along x.
fn squares_along_x(count: usize, side: f64, step: f64) -> Vec<cga::Lot> {
    (0..count)
        .map(|i| {
            let mut lot = cga::lots::rect(side, side);
            for p in &mut lot.mesh.positions {
                p.x += step * i as f64;
            }
            lot
        })
        .collect()
}

#[test]
fn one_lot_in_order_sees_every_lot_of_the_call() {
    let rules =
        memory_rules("Lot --> label(\"lot\") print(contextCount(inter, \"lot\")) extrude(1) X.\n");
    let lots = squares_along_x(4, 4.0, 10.0);
    let mut prints = Vec::new();
    rules
        .generate_lots_in_order(&lots, &[2], &Options::default(), Target::Nothing, |r| {
            prints.extend(r.prints)
        })
        .unwrap();
    // The three other lots of the call, though only one is generated.
    assert_eq!(prints, ["3"]);
}

/// Lots of even index into one model, of odd index into another, each
/// written relative to an origin of its own.
struct EvenAndOdd {
    writers: [cga::ModelWriter; 2],
    origins: [cga::DVec3; 2],
}

impl cga::LotWriters for EvenAndOdd {
    fn encoder(&self) -> Option<cga::Encoder> {
        Some(cga::Encoder::for_export(&cga::ExportOptions::default()))
    }

    fn origin(&self, i: usize) -> Option<cga::DVec3> {
        Some(self.origins[i % 2])
    }

    fn writer(&mut self, i: usize) -> Result<&mut cga::ModelWriter, Error> {
        Ok(&mut self.writers[i % 2])
    }
}

#[test]
fn lots_go_to_the_writer_the_target_names() {
    let rules = memory_rules("Lot --> extrude(3) X.\n");
    // Unit squares 100 m apart along x.
    let lots = squares_along_x(6, 1.0, 100.0);
    let origins = [
        cga::DVec3::new(1000.0, 0.0, 0.0),
        cga::DVec3::new(-7.0, 0.0, 5.0),
    ];
    for jobs in [1, 2] {
        let writer = |o: cga::DVec3| {
            cga::ModelWriter::glb_in_memory(cga::ExportOptions {
                origin: Some(o),
                ..cga::ExportOptions::default()
            })
            .unwrap()
        };
        let mut out = EvenAndOdd {
            writers: origins.map(writer),
            origins,
        };
        rules
            .generate_lots(
                &lots,
                &Options::default().jobs(jobs),
                Target::PerLot(&mut out),
                |_| {},
            )
            .unwrap();
        let [even, odd] = out.writers.map(|w| w.finish_bytes().unwrap().1);
        // Three boxes each; the bounds are in world coordinates again.
        assert_eq!((even.triangles, odd.triangles), (36, 36), "{jobs} jobs");
        let [lo, hi] = even.bounds.unwrap();
        assert_eq!((lo[0], hi[0], hi[1]), (0.0, 401.0, 3.0), "{jobs} jobs");
        let [lo, hi] = odd.bounds.unwrap();
        assert_eq!((lo[0], hi[0]), (100.0, 501.0), "{jobs} jobs");
    }
}

/// Hosts generate off their own thread (the Python module releases the
/// interpreter's lock around a call): a target must travel with it.
#[test]
fn targets_can_be_sent_to_another_thread() {
    fn send<T: Send>(_: &T) {}
    let mut writers = EvenAndOdd {
        writers: [(); 2]
            .map(|_| cga::ModelWriter::glb_in_memory(cga::ExportOptions::default()).unwrap()),
        origins: [cga::DVec3::ZERO; 2],
    };
    send(&Target::PerLot(&mut writers));
    send(&Target::Meshes);
}

/// Plain meshes start with the room the last call's lots took; what a lot
/// collects does not depend on the calls before (a small lot after large
/// ones, a large one after small ones, one and many jobs).
#[test]
fn meshes_do_not_depend_on_earlier_calls() {
    const RULES: &str =
        "Lot --> extrude(10) comp(f) { side : split(x) { ~2 : Tile }* | all : color(\"#808080\") X. }\n\
         Tile --> split(y) { ~3 : color(\"#a04020\") Floor. }*\n";
    let rules = memory_rules(RULES);
    let big = squares_along_x(3, 100.0, 110.0);
    let small = squares_along_x(1, 4.0, 0.0);
    let fresh = |lots: &[cga::Lot]| {
        memory_rules(RULES)
            .generate_all(lots, &Options::default())
            .unwrap()
    };
    let models = |r: Vec<cga::LotResult>| r.into_iter().map(|r| r.model).collect::<Vec<_>>();
    let small_alone = models(fresh(&small));
    let big_alone = models(fresh(&big));
    assert_eq!(big_alone[0].triangles(), 1204);
    assert_eq!(small_alone[0].triangles(), 52);
    for jobs in [1, 2] {
        let options = Options::default().jobs(jobs);
        let first = models(rules.generate_all(&big, &options).unwrap());
        assert_eq!(first, big_alone);
        let after_big = models(rules.generate_all(&small, &options).unwrap());
        assert_eq!(after_big, small_alone);
        // Whatever room it started with (a large lot's, twenty times what
        // it needs), it holds about what it uses.
        for mesh in &after_big[0].meshes {
            assert!(mesh.positions.capacity() <= 2 * mesh.positions.len());
            assert!(mesh.indices.capacity() <= 2 * mesh.indices.len());
        }
        assert_eq!(
            models(rules.generate_all(&big, &options).unwrap()),
            big_alone
        );
    }
}
