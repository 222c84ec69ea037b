//! Bad input never panics and never loses work: every file under
//! `tests/bad_inputs/` with the diagnostic or warning it must give.

use std::path::PathBuf;

use crate::common::*;

fn file(name: &str) -> String {
    let p: PathBuf = manifest_dir().join("tests/bad_inputs").join(name);
    p.to_str().unwrap().to_string()
}

fn example() -> String {
    manifest_dir()
        .join("../../examples/building.cga")
        .to_str()
        .unwrap()
        .to_string()
}

/// Runs `cga generate` and checks the exit status and that stderr holds
/// every expected fragment.
fn expect(args: &[&str], status: i32, fragments: &[&str]) {
    let out = run(args);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(status), "{args:?}\n{err}");
    for f in fragments {
        assert!(err.contains(f), "{args:?}: missing `{f}` in\n{err}");
    }
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn rule_files_with_errors() {
    let cases: &[(&str, &[&str])] = &[
        (
            "unterminated_string.cga",
            &["unterminated_string.cga:1:15", "unterminated string"],
        ),
        (
            "missing_arrow.cga",
            &[
                "missing_arrow.cga:1:5",
                "expected `-->` (rule) or `=` (function)",
            ],
        ),
        (
            "unbalanced_brace.cga",
            &[
                "expected `}` to close the block",
                "opened at line 1, column 18",
            ],
        ),
        (
            "missing_import.cga",
            &[
                "missing_import.cga:1:12",
                "cannot find the imported rule file \"missing.cga\"",
            ],
        ),
        (
            "cycle_a.cga",
            &[
                "b.cga:1:12",
                "import cycle: cycle_a.cga imports b.cga imports cycle_a.cga",
            ],
        ),
        (
            "attr_cycle.cga",
            &["attr_cycle.cga:2:10", "attribute `a` depends on itself"],
        ),
    ];
    for (name, fragments) in cases {
        expect(&["generate", &file(name)], 1, fragments);
    }
}

/// What CityEngine generates anyway is a warning, and the model is made: a
/// rule called with a number of parameters no rule has becomes a leaf; an
/// operation given an infinite size is skipped.
#[test]
fn rule_files_that_generate_with_warnings() {
    let cases: &[(&str, &[&str])] = &[
        (
            "wrong_arity.cga",
            &[
                "warning: rule `Tile` takes 1 parameter(s), called with 2",
                "wrong_arity.cga:1:9",
            ],
        ),
        (
            "infinite_height.cga",
            &[
                "warning: `extrude` in rule `Lot` skipped: argument 1 is inf",
                "infinite_height.cga:2:17",
            ],
        ),
    ];
    for (name, fragments) in cases {
        let dir = temp_dir(&format!("warn-{name}"));
        let obj = dir.join("m.obj");
        expect(
            &["generate", &file(name), "-o", obj.to_str().unwrap()],
            0,
            fragments,
        );
        // The lot's face is kept.
        assert_eq!(summarize(&obj).faces, 1, "{name}");
    }
}

#[test]
fn broken_asset_is_a_warning_and_the_model_is_written() {
    let dir = temp_dir("broken-asset");
    let obj = dir.join("m.obj");
    expect(
        &[
            "generate",
            &file("broken_asset.cga"),
            "-o",
            obj.to_str().unwrap(),
        ],
        0,
        &[
            "warning: cannot load asset",
            "broken.obj: line 1",
            "the shape keeps its geometry",
        ],
    );
    assert_eq!(summarize(&obj).faces, 1);
}

/// A Boolean operation on operands of thousands of faces (each subtraction
/// leaves more for the next; found by fuzzing) took seconds to minutes in
/// one operation, past the time limit, which was only looked at between
/// rules. It stops at the limit now, with what was made so far written.
#[test]
fn boolean_operations_stop_at_the_time_limit() {
    let dir = temp_dir("boolean-blowup");
    let obj = dir.join("b.obj");
    expect(
        &[
            "generate",
            &file("boolean_blowup.cga"),
            "--lot",
            "rect:20,30",
            "--max-seconds",
            "0.5",
            "-o",
            obj.to_str().unwrap(),
        ],
        1,
        &[
            "time limit (0.5 s) reached",
            // Which subtraction runs out of time depends on the machine.
            "boolean_blowup.cga:",
            "subtract {",
        ],
    );
    assert!(summarize(&obj).faces > 0);
}

#[test]
fn bad_lot_files_are_usage_errors() {
    let ex = example();
    expect(
        &["generate", &ex, "--lot", &file("bad_vertex.obj")],
        2,
        &["bad_vertex.obj: line 3: expected three coordinates"],
    );
    expect(
        &["generate", &ex, "--lot", &file("no_faces.obj")],
        2,
        &["has no faces to use as lots"],
    );
    expect(
        &["generate", &ex, "--lot", &file("truncated.geojson")],
        2,
        &["truncated.geojson is not valid GeoJSON"],
    );
}

#[test]
fn degenerate_lots_are_skipped_with_a_warning_and_the_rest_generated() {
    let dir = temp_dir("degenerate");
    let obj = dir.join("m.obj");
    let rules = rule_file(&dir, "r.cga", "Lot --> extrude(3) Mass.\n");
    expect(
        &[
            "generate",
            rules.to_str().unwrap(),
            "--lot",
            &file("degenerate_lots.obj"),
            "-o",
            obj.to_str().unwrap(),
        ],
        0,
        &[
            "lot `",
            "face 0` is skipped: it has no area",
            "face 1` is skipped",
            "face 2` is skipped",
        ],
    );
    // The one good lot (20 x 30 at UTM-like coordinates) is generated.
    let s = summarize(&obj);
    assert_eq!(s.faces, 6);
    assert!(
        (s.area - (2.0 * 600.0 + 3.0 * 100.0)).abs() < 1.0,
        "{}",
        s.area
    );
}
