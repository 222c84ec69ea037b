//! The Candler building (CityEngine's example rule, in the shared oracle
//! folder) through the roof and footprint operations: `offset`,
//! `convexify` and `envelope` run without warnings, and what depends on
//! them has the areas CityEngine's own runtime produced
//! (`golden/*/summary.json`): the roof surface (`offset(-0.8)` of the top,
//! its inside lowered), the ventilation boxes (`envelope` on the
//! rectangular pieces of the convexified roof, only on the footprint lot
//! whose roof is not one large rectangle) and the ventilators placed on
//! them along the envelope's scope.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use cga_engine::lot::{from_obj, rect, Lot};
use cga_geometry::{DVec3, Mesh};

/// The oracle folder `../shared/prt-oracle` (outside the repository).
fn oracle() -> Option<PathBuf> {
    cga_testkit::oracle()
}

struct Run {
    warnings: Vec<String>,
    meshes: Vec<Mesh>,
}

fn run_candler(dir: &Path, lot: &Lot) -> Run {
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
    assert!(error.is_none(), "{:?}", error.map(|e| e.message));
    Run {
        warnings: out.warnings.iter().map(|d| d.message.clone()).collect(),
        meshes: out.meshes,
    }
}

/// Area per appearance, keyed as the oracle's summary: diffuse colour with
/// three decimals and the colour map's file name (or `-`).
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

fn bounds(r: &Run) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for m in &r.meshes {
        if let Some((a, b)) = cga_geometry::measure::bounds(m) {
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    (lo, hi)
}

fn golden(dir: &Path, name: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("golden").join(name).join("summary.json"))
        .expect("golden summary");
    serde_json::from_str(&text).expect("json")
}

fn check(lot: &Lot, golden_name: &str, keys: &[&str]) {
    let Some(dir) = oracle() else { return };
    let r = run_candler(&dir, lot);
    let ours_warnings: Vec<&String> = r
        .warnings
        .iter()
        .filter(|w| {
            ["offset", "convexify", "envelope", "roof", "setback"]
                .iter()
                .any(|k| w.contains(k))
        })
        .collect();
    assert!(ours_warnings.is_empty(), "{ours_warnings:?}");
    let ours = areas(&r);
    let g = golden(&dir, golden_name);
    for key in keys {
        let theirs = g["area_by_appearance"][*key].as_f64().expect("golden key");
        let a = ours.get(*key).copied().unwrap_or(0.0);
        // The oracle's own tolerance (summary.py --compare): relative 1e-3.
        assert!(
            (a - theirs).abs() <= 1e-3 * theirs.max(1.0),
            "{key}: {a} vs CityEngine's {theirs}; all: {ours:?}"
        );
    }
    let (lo, hi) = bounds(&r);
    let gb = &g["bbox"];
    for k in 0..3 {
        let (gl, gh) = (
            gb["min"][k].as_f64().unwrap(),
            gb["max"][k].as_f64().unwrap(),
        );
        assert!((lo[k] - gl).abs() <= 1e-3 && (hi[k] - gh).abs() <= 1e-3);
    }
}

#[test]
fn candler_roof_on_a_rectangle() {
    check(
        &rect(20.0, 30.0),
        "candler.rect20x30",
        &["1.000,1.000,1.000|roof.jpg"],
    );
}

#[test]
fn candler_roof_on_its_footprint() {
    let Some(dir) = oracle() else { return };
    let lots = from_obj(&dir.join("lots/candler_footprint.obj")).expect("footprint");
    check(
        &lots[0],
        "candler.candler_footprint",
        &[
            "1.000,1.000,1.000|roof.jpg",
            "1.000,1.000,1.000|ventilator.jpg",
            "0.800,0.800,0.800|dirtmap.jpg",
        ],
    );
}
