//! The Candler building (CityEngine's example rule, in the shared oracle
//! folder) through the component split: its `comp` calls run without
//! warnings, and what depends on the split and its trim planes (the
//! ledges and cornices mitred at the corners, the window sills from
//! `comp(f) { front : ... }` of an inward extrusion, the shop window frames)
//! has the areas CityEngine's own runtime produced (`golden/*/summary.json`).

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::comp_support::Run;
use cga_engine::lot::{from_obj, rect, Lot};

/// The oracle folder `../shared/prt-oracle` (outside the repository).
fn oracle() -> Option<PathBuf> {
    cga_testkit::oracle()
}

fn run_candler(dir: &std::path::Path, lot: &Lot) -> Run {
    // Loaded in place, so that its assets resolve.
    let path = dir.join("rules/candler/rules/candler.cga");
    let mut sources = cga_syntax::SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
    let program = loaded.usable().expect("candler loads");
    let rule = program.start_rule(None).expect("start rule");
    let assets = cga_engine::assets::Assets::on_disk(&sources);
    let (out, error) = cga_engine::generate_lot(
        &program,
        &assets,
        rule,
        lot,
        0,
        &cga_engine::GenerateOptions::default(),
    );
    Run {
        prints: out.prints,
        warnings: out.warnings.iter().map(|d| d.message.clone()).collect(),
        error: error.map(|e| e.message),
        meshes: out.meshes,
    }
}

/// Area per appearance, keyed as the oracle's summary keys it: diffuse
/// colour with 3 decimals and the colour map's file name (or `-`).
fn areas(r: &Run) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    let mut tris = Vec::new();
    for m in &r.meshes {
        for f in 0..m.faces.len() {
            let mat = &m.materials[m.faces[f].material as usize];
            let map = mat.maps[0].path.rsplit('/').next().unwrap_or("");
            let key = format!(
                "{:.3},{:.3},{:.3}|{}",
                mat.color[0],
                mat.color[1],
                mat.color[2],
                if map.is_empty() { "-" } else { map }
            );
            // As exported: triangles (faces with holes, non-planar faces).
            tris.clear();
            cga_geometry::triangulate_face(m, f, &mut tris);
            let area: f64 = tris
                .iter()
                .map(|t| {
                    let p = t.map(|c| m.positions[m.corners[c as usize] as usize]);
                    0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
                })
                .sum();
            *out.entry(key).or_insert(0.0) += area;
        }
    }
    out
}

fn golden(dir: &std::path::Path, name: &str) -> BTreeMap<String, f64> {
    let text = std::fs::read_to_string(dir.join("golden").join(name).join("summary.json"))
        .expect("golden summary");
    let v: serde_json::Value = serde_json::from_str(&text).expect("json");
    v["area_by_appearance"]
        .as_object()
        .expect("areas")
        .iter()
        .map(|(k, v)| (k.clone(), v.as_f64().expect("number")))
        .collect()
}

fn check(lot: &Lot, golden_name: &str) {
    let Some(dir) = oracle() else { return };
    let r = run_candler(&dir, lot);
    assert!(r.error.is_none(), "{:?}", r.error);
    let comp_warnings: Vec<&String> = r
        .warnings
        .iter()
        .filter(|w| w.contains("comp") || w.contains("selector") || w.contains("trim"))
        .collect();
    assert!(comp_warnings.is_empty(), "{comp_warnings:?}");
    let ours = areas(&r);
    let theirs = golden(&dir, golden_name);
    for key in [
        "1.000,1.000,1.000|ledge.jpg",
        "1.000,1.000,1.000|sill.jpg",
        "0.067,0.067,0.067|-",
    ] {
        let (a, b) = (ours.get(key).copied().unwrap_or(0.0), theirs[key]);
        // The oracle's own tolerance (summary.py --compare): relative 1e-3.
        // Window and tile widths (the split's business) still differ by a
        // few hundredths of a percent; capped trims would add ~0.8 % to
        // the ledges, untrimmed ledges far more.
        assert!(
            (a - b).abs() <= 1e-3 * b.max(1.0),
            "{key}: {a} vs CityEngine's {b}; all: {ours:?}"
        );
    }
}

#[test]
fn candler_on_a_rectangle() {
    check(&rect(20.0, 30.0), "candler.rect20x30");
}

#[test]
fn candler_on_its_footprint() {
    let Some(dir) = oracle() else { return };
    let lots = from_obj(&dir.join("lots/candler_footprint.obj")).expect("footprint");
    check(&lots[0], "candler.candler_footprint");
}
