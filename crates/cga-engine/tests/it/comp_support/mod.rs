//! Running rule text through the library for the comp tests: write the
//! rules to a file, load, derive one lot, and read prints, warnings and
//! the generated meshes.

#![allow(dead_code)]

use std::path::PathBuf;

use cga_engine::assets::Assets;
use cga_engine::lot::{rect, Lot};
use cga_engine::{generate_lot, GenerateOptions};
use cga_geometry::{measure, DVec3, Mesh};
use cga_syntax::SourceMap;

pub struct Run {
    pub prints: Vec<String>,
    pub warnings: Vec<String>,
    pub error: Option<String>,
    pub meshes: Vec<Mesh>,
}

/// The folder of the test assets (absolute), for `i("{DIR}/x.obj")`.
pub fn assets_dir() -> String {
    format!("{}/tests/rules/comp", env!("CARGO_MANIFEST_DIR"))
}

/// Derives `lot` with the rules `text` (`{DIR}` is replaced by the assets
/// folder) from the start rule `start`. `name` names the rule file (unique
/// per test).
pub fn run_on(name: &str, text: &str, lot: &Lot, start: &str) -> Run {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("comp_tests");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("{name}.cga"));
    std::fs::write(&path, text.replace("{DIR}", &assets_dir())).expect("write rules");
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
    let errors: Vec<String> = loaded
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.message.clone())
        .collect();
    let Some(program) = errors.is_empty().then_some(loaded.program) else {
        panic!("rules do not load: {errors:?}");
    };
    let rule = program.start_rule(Some(start)).expect("start rule");
    let assets = Assets::on_disk(&sources);
    let (out, error) = generate_lot(&program, &assets, rule, lot, 0, &GenerateOptions::default());
    Run {
        prints: out.prints,
        warnings: out.warnings.iter().map(|d| d.message.clone()).collect(),
        error: error.map(|e| e.message),
        meshes: out.meshes,
    }
}

/// [`run_on`] with the lot `rect:20,30` and the start rule `Lot`.
pub fn run(name: &str, text: &str) -> Run {
    run_on(name, text, &rect(20.0, 30.0), "Lot")
}

/// The rule file `text` must not load; returns the error messages.
pub fn load_errors(name: &str, text: &str) -> Vec<String> {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("comp_tests");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(format!("{name}.cga"));
    std::fs::write(&path, text).expect("write rules");
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
    assert!(loaded.has_errors(), "rules should not load");
    loaded
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.message.clone())
        .collect()
}

impl Run {
    /// Fails with the error and warnings if the derivation failed.
    pub fn ok(self) -> Run {
        if let Some(e) = &self.error {
            panic!("derivation failed: {e}; warnings: {:?}", self.warnings);
        }
        self
    }

    /// The prints starting with `prefix`, without it.
    pub fn lines(&self, prefix: &str) -> Vec<String> {
        self.prints
            .iter()
            .filter_map(|p| p.strip_prefix(prefix))
            .map(|s| s.trim().to_string())
            .collect()
    }

    /// The prints starting with `prefix`, each parsed as numbers separated
    /// by spaces or commas.
    pub fn numbers(&self, prefix: &str) -> Vec<Vec<f64>> {
        self.lines(prefix)
            .iter()
            .map(|l| {
                l.split([' ', ','])
                    .filter(|t| !t.is_empty())
                    .map(|t| {
                        t.parse::<f64>()
                            .unwrap_or_else(|_| panic!("not a number: {t} in {l}"))
                    })
                    .collect()
            })
            .collect()
    }

    /// Total volume of the generated meshes (closed ones).
    pub fn volume(&self) -> f64 {
        self.meshes.iter().map(|m| measure::volume(m).abs()).sum()
    }

    /// Total area of the generated meshes.
    pub fn area(&self) -> f64 {
        self.meshes.iter().map(measure::mesh_area).sum()
    }
}

/// Asserts that two lists of numbers are equal within `tol`.
pub fn assert_close(actual: &[Vec<f64>], expected: &[&[f64]], tol: f64) {
    assert_eq!(
        actual.len(),
        expected.len(),
        "row count: {actual:?} vs {expected:?}"
    );
    for (a, e) in actual.iter().zip(expected) {
        assert_eq!(a.len(), e.len(), "{a:?} vs {e:?}");
        for (x, y) in a.iter().zip(e.iter()) {
            assert!((x - y).abs() <= tol, "{a:?} vs {e:?}");
        }
    }
}

/// Bounding box of a mesh's positions.
pub fn bbox(m: &Mesh) -> (DVec3, DVec3) {
    measure::bounds(m).expect("a mesh with vertices")
}

/// A lot of several faces (object coordinates), each a polygon.
pub fn multi_face_lot(faces: &[&[DVec3]]) -> Lot {
    let mut mesh = Mesh::new();
    for f in faces {
        let start = mesh.positions.len() as u32;
        mesh.positions.extend_from_slice(f);
        let idx: Vec<u32> = (start..start + f.len() as u32).collect();
        mesh.add_face(&[&idx], 0);
    }
    Lot {
        name: "multi".to_string(),
        mesh,
        attrs: Vec::new(),
        geo_origin: None,
    }
}

/// The 3 x 3 grid of unit squares on x in [0, 3], z in [-3, 0] (a
/// subdivided plane: 9 faces, 24 edges, 16 vertices).
pub fn grid_lot() -> Lot {
    let mut faces = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            let (x, z) = (i as f64, -(j as f64));
            faces.push(vec![
                DVec3::new(x, 0.0, z),
                DVec3::new(x + 1.0, 0.0, z),
                DVec3::new(x + 1.0, 0.0, z - 1.0),
                DVec3::new(x, 0.0, z - 1.0),
            ]);
        }
    }
    let refs: Vec<&[DVec3]> = faces.iter().map(|f| f.as_slice()).collect();
    multi_face_lot(&refs)
}
