//! Helpers of the texturing tests: running rule text on a lot, reading the
//! texture coordinates of what was generated.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use cga_engine::assets::Assets;
use cga_engine::lot::Lot;
use cga_engine::{generate_lot, GenerateOptions, LotOutput};
use cga_geometry::{DVec2, DVec3, Mesh};
use cga_syntax::SourceMap;

/// A fresh project folder for one test: `<dir>/rules/`, `<dir>/assets/`.
pub fn project(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("texturing")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("rules")).unwrap();
    std::fs::create_dir_all(dir.join("assets")).unwrap();
    dir
}

/// Writes `rules/main.cga` into the project `dir` and derives `lot` with its
/// start rule (`Lot`); panics on rule errors.
pub fn run_in(dir: &Path, text: &str, lot: &Lot) -> LotOutput {
    let path = dir.join("rules/main.cga");
    std::fs::write(&path, text).unwrap();
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
    let rendered: String = loaded
        .diagnostics
        .iter()
        .map(|d| d.render(&sources))
        .collect();
    let program = loaded
        .usable()
        .unwrap_or_else(|| panic!("rule errors: {rendered}"));
    let assets = Assets::on_disk(&sources);
    let rule = program.start_rule(Some("Lot")).unwrap();
    let (out, error) = generate_lot(&program, &assets, rule, lot, 0, &GenerateOptions::default());
    if let Some(e) = error {
        panic!("derivation error: {}", e.to_diagnostic().render(&sources));
    }
    out
}

/// Derives `lot` with rule text in a fresh project.
pub fn run(name: &str, text: &str, lot: &Lot) -> LotOutput {
    run_in(&project(name), text, lot)
}

pub fn rect(w: f64, d: f64) -> Lot {
    cga_engine::lot::rect(w, d)
}

/// The (position, uv) of every corner of every face of `mesh` for UV set `set`.
pub fn corners(mesh: &Mesh, set: usize) -> Vec<(DVec3, DVec2)> {
    let uvs = mesh.uvs[set]
        .as_ref()
        .unwrap_or_else(|| panic!("uv set {set} missing"));
    let mut out = Vec::new();
    for f in 0..mesh.faces.len() {
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                out.push((mesh.positions[mesh.corners[c] as usize], uvs[c]));
            }
        }
    }
    out
}

/// Asserts that every corner's uv equals `f(position)` within 1e-9.
pub fn assert_uvs(mesh: &Mesh, set: usize, f: impl Fn(DVec3) -> DVec2) {
    let cs = corners(mesh, set);
    assert!(!cs.is_empty(), "no corners");
    for (p, uv) in cs {
        let want = f(p);
        assert!(
            (uv - want).length() < 1e-9,
            "corner {p:?}: uv {uv:?}, expected {want:?}"
        );
    }
}

pub fn area(mesh: &Mesh) -> f64 {
    cga_geometry::measure::mesh_area(mesh)
}

/// The (min, max) of coordinate `axis` (0 = x) over the corners of `mesh`.
pub fn span(mesh: &Mesh, axis: usize) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &c in &mesh.corners {
        let x = mesh.positions[c as usize][axis];
        lo = lo.min(x);
        hi = hi.max(x);
    }
    (lo, hi)
}

pub fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

/// Writes `assets/street.obj` into the project `dir`: a street segment in
/// the x-z plane whose front edge runs from (0,0,0) to (`front`,0,0) and
/// whose back edge runs from (`back0`,0,-`w`) to (`back1`,0,-`w`), with u
/// along the street and v across it, both in [0, 1] as CityEngine gives
/// streets their coordinates. Inserted with `i("street.obj")` on the lot
/// `rect(front, w)` it keeps exactly these positions (the lot's scope is the
/// segment's bounding box).
pub fn street_asset(dir: &Path, front: f64, back0: f64, back1: f64, w: f64) {
    let obj = format!(
        "v 0 0 0\nv {front} 0 0\nv {back1} 0 {z}\nv {back0} 0 {z}\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n",
        z = -w
    );
    std::fs::write(dir.join("assets/street.obj"), obj).unwrap();
}
