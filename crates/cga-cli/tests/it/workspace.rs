//! Workspace paths on the command line: `--workspace DIR` (repeatable) and
//! `CGA_WORKSPACE` for `check` and `generate`, and the real rule files of
//! the shared corpus that need them (skipped when `../shared` is absent).

use std::path::{Path, PathBuf};

use crate::common::*;

/// A library project in its own workspace, and a rule file elsewhere that
/// imports from it and inserts its asset (in the second directory).
fn setup(name: &str) -> (TempDir, TempDir, PathBuf) {
    let ws = temp_dir(&format!("{name}-ws"));
    let lib = ws.join("Lib");
    std::fs::create_dir_all(lib.join("rules")).unwrap();
    std::fs::create_dir_all(lib.join("assets")).unwrap();
    std::fs::write(
        lib.join("rules/lib.cga"),
        "Post --> s(1, 4, 1) i(\"/Lib/assets/post.obj\") Post.\n",
    )
    .unwrap();
    std::fs::write(
        lib.join("assets/post.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nv 0 1 0\nv 1 1 0\nv 1 1 1\nv 0 1 1\n\
f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n",
    )
    .unwrap();
    let work = temp_dir(&format!("{name}-rules"));
    let rules = rule_file(
        &work,
        "main.cga",
        "import lib : \"/Lib/rules/lib.cga\"\nLot --> lib.Post\n",
    );
    (ws, work, rules)
}

#[test]
fn workspace_option_and_environment_find_other_projects() {
    let (ws, _work, rules) = setup("option");
    let rules_s = rules.to_str().unwrap();
    let ws_s = ws.to_str().unwrap();

    // Not found: exit 1, every place searched named.
    let o = run(&["check", rules_s]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(err.contains("cannot find the imported rule file \"/Lib/rules/lib.cga\""));
    assert!(err.contains("searched:"), "{err}");
    assert!(err.contains(
        &rules
            .parent()
            .unwrap()
            .join("Lib/rules/lib.cga")
            .display()
            .to_string()
    ));

    let o = run(&[
        "check",
        rules_s,
        "--workspace",
        "/nonexistent",
        "--workspace",
        ws_s,
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    let o = cga()
        .args(["check", rules_s])
        .env("CGA_WORKSPACE", ws_s)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    // The asset `/Lib/assets/post.obj` is found through the option too: a
    // 1 x 4 x 1 post.
    let out = rules.parent().unwrap().join("m.obj");
    let o = run(&[
        "generate",
        rules_s,
        "--workspace",
        ws_s,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let s = summarize(&out);
    assert_eq!(s.faces, 6);
    assert!((s.area - 18.0).abs() < 1e-6, "{}", s.area);
    assert!((s.max[1] - s.min[1] - 4.0).abs() < 1e-6);
}

/// The shared corpus of real rule files, when present.
fn corpus() -> Option<PathBuf> {
    let p = manifest_dir().join("../../../shared/corpus/workspace");
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!("skipped: ../shared/corpus is absent");
        None
    }
}

fn check_ok(file: &Path) {
    let o = run(&["check", file.to_str().unwrap()]);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}: {}",
        file.display(),
        stderr(&o)
    );
}

#[test]
fn corpus_files_with_workspace_imports_encodings_and_annotations_check() {
    let Some(ws) = corpus() else { return };
    // A workspace import of a Windows-1252 file of ESRI.lib.
    check_ok(&ws.join("Complete_Street_Rule/rules/Utils/Street_Text.cga"));
    // `^` and a string broken over a line in annotations.
    check_ok(&ws.join("Adapted-Complete-Street-Rule-to-a-Swiss-Standard/Swiss_Adaptions.cga"));
    // An annotation before `style`.
    check_ok(&ws.join("CGAShapeGrammar/cga/tutorial/complexpatterns_01.cga"));
    // Attributes with parameters in a file of version 2013.0.
    check_ok(&ws.join("ivis_data-visualisation/ivis/rules/bevschicht.cga"));
}
