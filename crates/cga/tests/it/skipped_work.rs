//! Work a generation skips because nobody keeps its result: texture
//! coordinates of sets the target does not write and the rules do not
//! read, and leaves that a report table only counts. What the caller gets
//! (reports, prints, warnings, shape and leaf counts, the meshes kept) is
//! the same as when everything is computed.

use cga::{Engine, LotResult, MemoryWorld, ModelWriter, Options, Target};

/// Facades with coordinates in sets 0 and 2, tiled, scaled, rotated and
/// copied; reports read set 2 and set 0, a print asks whether set 3 is
/// there, and the roof copies set 4 (read nowhere else) into set 0.
const RULES: &str = "\
Lot --> extrude(10) comp(f) { side : Facade | top : Roof }
Facade --> setupProjection(0, scope.xy, 2, 2) projectUV(0)
    setupProjection(2, scope.xy, '1, '1) projectUV(2) tileUV(2, 5, 5)
    report(\"u2\", geometry.uMax(2)) report(\"du0\", geometry.du(0, uvSpace))
    split(x) { ~4 : Tile }*
Tile --> scaleUV(0, 2, 1) rotateUV(2, 90) translateUV(2, 1, 0)
    setupProjection(3, scope.xy, 1, 1) projectUV(3) print(geometry.hasUVs(3)) T.
Roof --> setupProjection(4, scope.xy, 4, 4) projectUV(4) copyUV(4, 0) R.
";

fn results(rules: &cga::Rules, target: Target<'_>) -> (Vec<LotResult>, cga::Summary) {
    let lots = [cga::lots::rect(20.0, 30.0), cga::lots::rect(12.0, 8.0)];
    let mut out = Vec::new();
    let summary = rules
        .generate_lots(&lots, &Options::default().jobs(1), target, |r| out.push(r))
        .unwrap();
    (out, summary)
}

/// What a caller sees of a lot apart from its geometry.
fn seen(r: &LotResult) -> (Vec<String>, String, Vec<String>, usize, usize) {
    (
        r.prints.clone(),
        format!("{:?}", r.reports),
        r.warnings.iter().map(|w| w.message.clone()).collect(),
        r.shapes,
        r.leaf_count,
    )
}

#[test]
fn reports_and_plain_meshes_match_a_generation_that_computes_every_set() {
    let rules = Engine::new(MemoryWorld::new()).load_text("/p/rules/r.cga", RULES);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let (nothing, nothing_sum) = results(&rules, Target::Nothing);
    let (meshes, meshes_sum) = results(&rules, Target::Meshes);
    let mut writer = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    let (written, written_sum) = results(&rules, Target::Writer(&mut writer));
    let (_, stats) = writer.finish_bytes().unwrap();

    for (a, b) in [(&nothing, &written), (&meshes, &written)] {
        let a: Vec<_> = a.iter().map(seen).collect();
        let b: Vec<_> = b.iter().map(seen).collect();
        assert_eq!(a, b);
    }
    // 20 x 30 lot: four facades of 5 and 4 tiles, a roof; 12 x 8: 3 and 2.
    assert_eq!(nothing_sum.leaves, 2 * (5 + 8) + 1 + 2 * (3 + 2) + 1);
    assert_eq!(nothing_sum.leaves, written_sum.leaves);
    assert_eq!(meshes_sum.leaves, written_sum.leaves);
    assert_eq!(nothing_sum.shapes, written_sum.shapes);
    // Set 2 is read: tiled by 5 m, the facades span 4 and 6 (and 2.4, 1.6)
    // in u. Set 0 projected 2 m to the unit: 10 m high is 5 in v, and du
    // is the width over 2.
    let numbers = |r: &LotResult, key: &str| -> Vec<f64> {
        let mut v: Vec<f64> = r
            .reports
            .iter()
            .filter(|(k, _)| k == key)
            .map(|(_, v)| match v {
                cga::Value::Float(x) => (x * 1e9).round() / 1e9,
                other => panic!("{key}: {other:?}"),
            })
            .collect();
        v.sort_by(f64::total_cmp);
        v
    };
    assert_eq!(numbers(&nothing[0], "u2"), [4.0, 4.0, 6.0, 6.0]);
    assert_eq!(numbers(&nothing[1], "u2"), [1.6, 1.6, 2.4, 2.4]);
    assert_eq!(numbers(&nothing[0], "du0"), [10.0, 10.0, 15.0, 15.0]);
    // Set 3 is read (hasUVs), so it is there in every tile.
    assert!(
        nothing[0].prints.iter().all(|p| p == "true"),
        "{:?}",
        nothing[0].prints
    );
    assert_eq!(nothing[0].prints.len(), 2 * (5 + 8));

    // The plain meshes hold set 0 as the model file does: the roof's
    // coordinates come from set 4 (copied), so set 4 is computed.
    assert_eq!(
        meshes.iter().map(|r| r.model.triangles()).sum::<usize>() as u64,
        stats.triangles
    );
    let lot = &meshes[0];
    let roof_uvs: Vec<[f64; 2]> = lot
        .model
        .meshes
        .iter()
        .flat_map(|m| {
            m.indices
                .iter()
                .zip(&m.triangle_leaf)
                .filter(|(_, &leaf)| &*lot.leaves[leaf as usize].shape == "R")
                .flat_map(|(t, _)| t.map(|v| m.uvs[v as usize]))
        })
        .collect();
    // The roof's two triangles.
    assert_eq!(roof_uvs.len(), 6);
    let (lo, hi) = roof_uvs
        .iter()
        .fold(([f64::MAX; 2], [f64::MIN; 2]), |(lo, hi), t| {
            (
                [lo[0].min(t[0]), lo[1].min(t[1])],
                [hi[0].max(t[0]), hi[1].max(t[1])],
            )
        });
    // 20 x 30 m projected 4 m to the unit.
    let mut spans = [hi[0] - lo[0], hi[1] - lo[1]];
    spans.sort_by(f64::total_cmp);
    assert!(
        (spans[0] - 5.0).abs() < 1e-9 && (spans[1] - 7.5).abs() < 1e-9,
        "{lo:?} {hi:?}"
    );
}

#[test]
fn a_report_table_of_candler_counts_what_its_model_holds() {
    let Some(rule) = cga_testkit::oracle_rule("candler", "candler.cga") else {
        return;
    };
    let Some(oracle) = cga_testkit::oracle() else {
        return;
    };
    let rules = Engine::new(cga::DiskWorld).load(&rule);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let spec = oracle.join("lots/candler_footprint.obj");
    let lots = cga::lots::read(&[spec.to_str().unwrap()]).unwrap().lots;
    let options = Options::default();
    let nothing = rules
        .generate_lots(&lots, &options, Target::Nothing, |_| {})
        .unwrap();
    let mut plain = Vec::new();
    let meshes = rules
        .generate_lots(&lots, &options, Target::Meshes, |r| plain.push(r))
        .unwrap();
    let mut writer = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    let written = rules
        .generate_lots(&lots, &options, Target::Writer(&mut writer), |_| {})
        .unwrap();
    let (_, stats) = writer.finish_bytes().unwrap();
    assert_eq!(nothing.shapes, written.shapes);
    assert_eq!(nothing.leaves, written.leaves);
    assert_eq!(meshes.leaves, written.leaves);
    assert!(nothing.leaves > 4000, "{}", nothing.leaves);
    assert_eq!(plain[0].model.triangles() as u64, stats.triangles);
}

/// The rule text's lots generated without a model and into a GLB: what a
/// caller sees of each lot, and the shape and leaf counts, are the same.
/// Gives the lots and the summary without a model.
fn alike_with_and_without_a_model(text: &str) -> (Vec<LotResult>, cga::Summary) {
    let rules = Engine::new(MemoryWorld::new()).load_text("/p/rules/r.cga", text);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let (nothing, nothing_sum) = results(&rules, Target::Nothing);
    let mut writer = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    let (written, written_sum) = results(&rules, Target::Writer(&mut writer));
    let a: Vec<_> = nothing.iter().map(seen).collect();
    let b: Vec<_> = written.iter().map(seen).collect();
    assert_eq!(a, b);
    assert_eq!(nothing_sum.leaves, written_sum.leaves);
    assert_eq!(nothing_sum.shapes, written_sum.shapes);
    (nothing, nothing_sum)
}

/// Cubes inserted on the facades, wider than their tiles, mitred at the
/// corners by the trim planes of the component split; some moved past the
/// corner so that nothing is left of them; some measured after the insert.
const TRIMMED: &str = "\
Lot --> extrude(6) comp(f) { side : Side }
Side --> split(x) { 2 : Piece }* Beyond Measured
Piece --> s('1.5, '1, 0.5) center(x) i(\"builtin:cube\") color(\"#808080\") T.
Beyond --> t(scope.sx + 5, 0, 0) s(1, '1, 0.5) i(\"builtin:cube\") B.
Measured --> s('1.2, 1, 1) center(x) i(\"builtin:cube\") report(\"area\", geometry.area) M.
";

#[test]
fn trimmed_inserts_count_and_measure_alike_with_and_without_a_model() {
    let (nothing, nothing_sum) = alike_with_and_without_a_model(TRIMMED);
    // 20 x 30: 10 + 15 pieces per pair of sides, one measured cube per
    // side; 12 x 8: 6 + 4 and one per side. The cubes past the corners are
    // trimmed away and not counted.
    assert_eq!(nothing_sum.leaves, 2 * (10 + 15) + 4 + 2 * (6 + 4) + 4);
    // The measured cubes are trimmed (their geometry is read).
    let areas: Vec<f64> = nothing[0]
        .reports
        .iter()
        .map(|(_, v)| match v {
            cga::Value::Float(a) => *a,
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(areas.len(), 4);
    let mut areas = areas;
    areas.sort_by(f64::total_cmp);
    // Untrimmed, 24 x 1 x 1 and 36 x 1 x 1 boxes have 98 and 146; mitred
    // at both corners and open there, 84 and 124.
    let want = [84.0, 84.0, 124.0, 124.0];
    assert!(
        areas.iter().zip(want).all(|(a, w)| (a - w).abs() < 1e-9),
        "{areas:?}"
    );
}

/// Facades split into windows and walls; the windows' openings broken into
/// faces. Walls, jambs and glass only take a colour, a texture and a
/// report: without a model their parts are not built.
const UNBUILT: &str = "\
Lot --> extrude(9) comp(f) { side : Facade | top : Roof. }
Facade --> split(y) { 3 : Floor }*
Floor --> split(x) { 2 : Wall | 3 : Win }*
Win --> extrude(-0.3) comp(f) { front : reverseNormals Glass | side = color(\"#888888\") Jamb. }
Glass --> texture(\"glass.png\") color(\"#99aaff\") report(\"glass\", comp.index) G.
Wall --> color(\"#ffffff\") report(\"walls\", split.index) W.
";

#[test]
fn parts_nothing_reads_count_and_report_alike_with_and_without_a_model() {
    let (nothing, _) = alike_with_and_without_a_model(UNBUILT);
    // 20 x 30 lot, three floors: per floor, a 20 m facade has 4 walls
    // and 4 windows, a 30 m one 6 and 6; each window a glass and one jamb
    // (its four sides in one part).
    let count = |r: &LotResult, key: &str| r.reports.iter().filter(|(k, _)| k == key).count();
    assert_eq!(count(&nothing[0], "glass"), 3 * 2 * (4 + 6));
    assert_eq!(count(&nothing[0], "walls"), 3 * 2 * (4 + 6));
    // Walls, glass, jambs and the roof.
    assert_eq!(nothing[0].leaf_count, 60 + 60 + 60 + 1);
}

/// Facades of windows: each window a sill wider than its tile, mitred at
/// the building's corners by the trim planes, an opening broken into
/// faces, and a pane inserted 4 m further along the facade, cut away by
/// the corner's trim plane where that is past the facade's end. Without a
/// model the windows that repeat are derived once
/// (`cga_engine::subtree_memo`), but not where a trim plane comes close
/// enough to cut what the first window kept.
const WINDOWS: &str = "\
Lot --> extrude(7) comp(f) { side : Facade }
Facade --> split(y) { 3.5 : Floor }*
Floor --> split(x) { 0.5 : Wall | { ~2.5 : Tile }* | 0.5 : Wall }
Tile --> split(x) { 0.4 : Wall | ~1 : Window | 0.4 : Wall }
Window --> Sill Opening Pane
Sill --> s('1 + 2.2, 0.1, 0.2) center(x) i(\"builtin:cube\") S.
Opening --> extrude(-0.2) comp(f) { front : G. | side : J. }
Pane --> t(4, 0, 0) s('1, '1, 0.1) i(\"builtin:cube\") P.
Wall --> color(\"#ffffff\") W.
";

#[test]
fn repeated_windows_count_alike_with_and_without_a_model() {
    let (nothing, sum) = alike_with_and_without_a_model(WINDOWS);
    // 20 x 30 lot: two floors; tiles of about 2.5 m in 19 and 29 m: 8 and
    // 12 (2.375 and 2.417 m wide). Per window: the sill, the glass and
    // three jambs (the front is the glass), and the pane unless it starts
    // past the corner (it starts 4.9 m + a tile per window along): the
    // last window's on each facade.
    let windows = 2 * 2 * (8 + 12);
    // Two end walls a floor on four facades, two beside each window.
    let walls = 2 * 4 * 2 + 2 * windows;
    let panes = 2 * 2 * (7 + 11);
    assert_eq!(nothing[0].leaf_count, walls + 5 * windows + panes);
    assert_eq!(sum.leaves, nothing[0].leaf_count + nothing[1].leaf_count);
}

/// Tiles whose splits depend on the random stream, on the split index and
/// on a parameter: each must be derived for what it reads.
const VARIED: &str = "\
Lot --> extrude(7) comp(f) { side : Facade }
Facade --> split(x) { ~3 : Tile(split.index % 3) }*
Tile(k) --> split(y) { ~1 : Row(k) }*
Row(k) --> split(x) { rand(0.5, 1.5) : A. | ~1 : Cells(k) }
Cells(k) --> case k == 0 : split(x) { 1 : C. }* else : split(x) { ~1 : D. | 0.5 : E. }
";

#[test]
fn random_and_indexed_tiles_count_alike_with_and_without_a_model() {
    let (_, sum) = alike_with_and_without_a_model(VARIED);
    assert!(sum.leaves > 100, "{}", sum.leaves);
}

/// Missing assets deep in the facades' repeated tiles and on the roof:
/// the roof's warning comes first (a generation earlier), with a model
/// and without, where the tiles are counted from memory.
const WARNING: &str = "\
Lot --> extrude(6) comp(f) { side : Facade | top : Roof }
Facade --> split(x) { 2 : Tile }*
Tile --> split(y) { 1 : Deep }*
Deep --> i(\"missing_deep.obj\") D.
Roof --> Later
Later --> i(\"missing_roof.obj\") R.
";

#[test]
fn warnings_of_repeated_subtrees_come_in_their_order_with_and_without_a_model() {
    let (nothing, _) = alike_with_and_without_a_model(WARNING);
    let messages: Vec<&str> = nothing[0]
        .warnings
        .iter()
        .map(|w| w.message.as_str())
        .collect();
    assert_eq!(messages.len(), 2, "{messages:?}");
    assert!(messages[0].contains("missing_roof.obj"), "{messages:?}");
    assert!(messages[1].contains("missing_deep.obj"), "{messages:?}");
    // 20 x 30 lot, 6 m high: 10 + 15 tiles of 6 rows per pair of sides,
    // each row a leaf (the shape keeps its geometry), and the roof.
    assert_eq!(nothing[0].leaf_count, 2 * (10 + 15) * 6 + 1);
}

/// `alike_with_and_without_a_model` on lots of its own, comparing the
/// lots' errors too; gives the lots without a model.
fn alike_on(text: &str, lots: &[cga::Lot]) -> Vec<LotResult> {
    alike_with(text, lots, &Options::default().jobs(1))
}

/// [`alike_on`] with `options`.
fn alike_with(text: &str, lots: &[cga::Lot], options: &Options) -> Vec<LotResult> {
    let rules = Engine::new(MemoryWorld::new()).load_text("/p/rules/r.cga", text);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let run = |target: Target<'_>| {
        let mut out = Vec::new();
        rules
            .generate_lots(lots, options, target, |r| out.push(r))
            .unwrap();
        out
    };
    let nothing = run(Target::Nothing);
    let mut writer = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    let written = run(Target::Writer(&mut writer));
    let seen_all = |r: &LotResult| (seen(r), r.error.as_ref().map(|e| e.message.clone()));
    let a: Vec<_> = nothing.iter().map(seen_all).collect();
    let b: Vec<_> = written.iter().map(seen_all).collect();
    assert_eq!(a, b, "{text}");
    nothing
}

/// Lots whose sizes are not round, at the origin and away from it.
fn odd_lots() -> Vec<cga::Lot> {
    let sizes = [(22.9, 30.0), (101.3, 30.0), (20.0, 30.0)];
    let mut lots: Vec<cga::Lot> = sizes.iter().map(|&(w, d)| cga::lots::rect(w, d)).collect();
    for &(w, d) in &sizes {
        let mut lot = cga::lots::rect(w, d);
        for p in lot.mesh.positions.iter_mut() {
            p.x += 1234.567;
            p.z -= 765.4321;
        }
        lots.push(lot);
    }
    lots
}

#[test]
fn tiles_that_meet_a_threshold_exactly_count_alike_wherever_they_stand() {
    // Widths set to 3 m, extruded, then compared with 3 m; areas of
    // 3 x 30 m compared with 90 m²: measured and extruded around the
    // scope's origin, every tile gives the same answer wherever it stands
    // (in object coordinates some gave 3 m less a last bit).
    for text in [
        "Lot --> split(x) { ~1 : W }*\nW --> s(3, '1, '1) extrude(world.y, 1) Q\nQ --> case scope.sx < 3 : B. else : split(x) { 1 : A. }*\n",
        "Lot --> split(x) { ~1 : W }*\nW --> s(3, '1, '1) Q\nQ --> case geometry.area < 90 : B. else : split(x) { 0.5 : A. }*\n",
    ] {
        let lots = alike_on(text, &odd_lots());
        // About a metre a tile (23, 101 and 20 of them), each made 3 m
        // wide: none is less than 3 m wide, or than 90 m², so each is split
        // into 3 (or 6) leaves, at the origin and away from it.
        let leaves: Vec<usize> = lots.iter().map(|r| r.leaf_count).collect();
        let k = if text.contains("0.5") { 6 } else { 3 };
        assert_eq!(leaves, [23 * k, 101 * k, 20 * k, 23 * k, 101 * k, 20 * k], "{text}");
    }
}

#[test]
fn random_values_that_can_fail_or_warn_count_alike_with_and_without_a_model() {
    // A random colour that is sometimes no colour, a random opacity that
    // is sometimes a string, a projection that only some tiles set up: the
    // tiles are derived for their own draws, and warn or fail as they do
    // with a model.
    for text in [
        "Lot --> split(x) { ~1 : A }*\nA --> color(case rand < 0.5 : \"#ff0000\" else : \"bogus\") split(z) { 1 : X. }*\n",
        "Lot --> split(x) { ~1 : A }*\nA --> set(material.opacity, case rand < 0.7 : 1 else : \"x\") split(z) { 1 : X. }*\n",
        "Lot --> split(x) { 10 : P | 10 : W }\nP --> setupProjection(0, scope.xz, 1, 1) W\nW --> projectUV(0) split(z) { 1 : X. }*\n",
        // A texture size of 0 for some draws.
        "Lot --> split(x) { 1 : W }*\nW --> setupProjection(0, scope.xy, floor(rand * 10), 1) B\nB --> X.\n",
        // The repeated part warns: the copy of the whole that saw it first
        // is dropped, and so is what it remembered of the parts.
        "Lot --> split(x) { 1 : A }*\nA --> i(\"missing.obj\") B\nB --> X.\n",
    ] {
        alike_on(text, &odd_lots());
    }
}

#[test]
fn a_lot_that_meets_the_shape_limit_stops_where_it_does_with_a_model() {
    // Remembered subtrees count their leaves at once, where their root
    // is: a lot that fails is derived again without them, so its partial
    // counts are those of the model (2,999 shapes, no leaf yet).
    let text = "Lot --> extrude(12) split(x) { 1 : R1(4) }*\n\
        R1(d) --> case d <= 0 : NIL else : split(x) { ~2 : R2(d - 1) }\n\
        R2(d) --> case d <= 0 : Y. else : split(y) { 2 : extrude(1) R2(d - 1) }*\n";
    let limits = cga::Limits {
        max_shapes: 3000,
        ..cga::Limits::default()
    };
    let lots = [cga::lots::rect(22.9, 30.7)];
    let r = alike_with(text, &lots, &Options::default().jobs(1).limits(limits));
    assert_eq!((r[0].shapes, r[0].leaf_count), (2999, 0));
    assert!(r[0]
        .error
        .as_ref()
        .unwrap()
        .message
        .starts_with("shape limit (3000)"));
}
