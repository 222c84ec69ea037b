//! Helpers shared by the `ops_*` tests: derive a rule text (or a rule file)
//! on a lot through the library, as the `cga` command does, and measure what
//! came out (prints, leaf meshes, materials, reports).

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use cga_engine::assets::Assets;
use cga_engine::generate::parse_value;
use cga_engine::lot::{self, Lot};
use cga_engine::{generate_lot, GenerateOptions, LotOutput, RtError};
use cga_geometry::{measure, DVec3, Material, Mesh};
use cga_syntax::SourceMap;
use cga_value::Value;

/// The folder of the rule files and assets of these tests.
pub fn rules_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/rules/ops")
}

/// How to derive: lot, seed, start rule, attribute values.
#[derive(Clone)]
pub struct Opts {
    pub lots: Vec<Lot>,
    pub seed: u64,
    pub start: Option<String>,
    pub attrs: Vec<(String, Value)>,
}

impl Default for Opts {
    fn default() -> Self {
        Opts {
            lots: vec![lot::rect(20.0, 30.0)],
            seed: 0,
            start: None,
            attrs: Vec::new(),
        }
    }
}

impl Opts {
    /// On the lot `rect:W,D`: `(0,0,0) (W,0,0) (W,0,-D) (0,0,-D)`.
    pub fn rect(w: f64, d: f64) -> Opts {
        Opts {
            lots: vec![lot::rect(w, d)],
            ..Opts::default()
        }
    }

    /// On a lot given by its polygon (object coordinates).
    pub fn polygon(points: &[DVec3]) -> Opts {
        Opts {
            lots: vec![Lot {
                name: "polygon".into(),
                mesh: Mesh::polygon(points),
                attrs: Vec::new(),
                geo_origin: None,
            }],
            ..Opts::default()
        }
    }

    pub fn start(mut self, rule: &str) -> Opts {
        self.start = Some(rule.to_string());
        self
    }

    pub fn seed(mut self, seed: u64) -> Opts {
        self.seed = seed;
        self
    }

    /// `--attr name=value` (the value parsed as the command line does).
    pub fn attr(mut self, name: &str, value: &str) -> Opts {
        self.attrs.push((name.to_string(), parse_value(value)));
        self
    }
}

/// What one derivation (of every lot) produced.
pub struct Gen {
    /// One output per lot.
    pub lots: Vec<LotOutput>,
    pub errors: Vec<RtError>,
}

static COUNTER: AtomicUsize = AtomicUsize::new(0);

/// A fresh folder for one test's rule file, holding a copy of the test assets.
fn scratch_dir() -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("cga-ops-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let assets = rules_dir().join("assets");
    if let Ok(entries) = std::fs::read_dir(&assets) {
        for e in entries.flatten() {
            std::fs::copy(e.path(), dir.join(e.file_name())).unwrap();
        }
    }
    dir
}

/// Derives `src` (a complete rule file) on the default lot `rect:20,30`.
#[track_caller]
pub fn gen(src: &str) -> Gen {
    gen_with(src, &Opts::default())
}

#[track_caller]
pub fn gen_with(src: &str, opts: &Opts) -> Gen {
    let dir = scratch_dir();
    let path = dir.join("rules.cga");
    std::fs::write(&path, src).unwrap();
    let generated = gen_file(&path, opts);
    // Kept only when the test fails (above) for a look at its files.
    let _ = std::fs::remove_dir_all(&dir);
    generated
}

/// Loads and derives a rule file; a rule file that does not load fails the test.
#[track_caller]
pub fn gen_file(path: &Path, opts: &Opts) -> Gen {
    gen_file_seeds(path, opts, &[opts.seed]).pop().unwrap()
}

/// Derives `src` once per seed, loading it once.
#[track_caller]
pub fn gen_seeds(src: &str, opts: &Opts, seeds: &[u64]) -> Vec<Gen> {
    let dir = scratch_dir();
    let path = dir.join("rules.cga");
    std::fs::write(&path, src).unwrap();
    let generated = gen_file_seeds(&path, opts, seeds);
    let _ = std::fs::remove_dir_all(&dir);
    generated
}

#[track_caller]
fn gen_file_seeds(path: &Path, opts: &Opts, seeds: &[u64]) -> Vec<Gen> {
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, path, &mut sources);
    let errors = loaded.has_errors();
    let Some(program) = (!errors).then_some(loaded.program) else {
        let text: String = loaded
            .diagnostics
            .iter()
            .map(|d| d.render(&sources))
            .collect();
        panic!("{} does not load:\n{text}", path.display());
    };
    let rule = program
        .start_rule(opts.start.as_deref())
        .unwrap_or_else(|e| panic!("{e}"));
    let mut attrs = Vec::new();
    for (name, v) in &opts.attrs {
        let id = program
            .main_attr(name)
            .unwrap_or_else(|| panic!("no attribute {name}"));
        attrs.push((id, v.clone()));
    }
    let assets = Assets::on_disk(&sources);
    seeds
        .iter()
        .map(|&seed| {
            let options = GenerateOptions {
                seed,
                attrs: attrs.clone(),
                ..GenerateOptions::default()
            };
            let mut g = Gen {
                lots: Vec::new(),
                errors: Vec::new(),
            };
            for (i, l) in opts.lots.iter().enumerate() {
                let (out, err) = generate_lot(&program, &assets, rule, l, i, &options);
                g.lots.push(out);
                if let Some(e) = err {
                    g.errors.push(e);
                }
            }
            g
        })
        .collect()
}

impl Gen {
    /// Fails the test if the derivation stopped on an error.
    #[track_caller]
    pub fn ok(self) -> Gen {
        if let Some(e) = self.errors.first() {
            panic!("derivation failed: {} at {:?}", e.message, e.span);
        }
        self
    }

    /// The output of the first (usually only) lot.
    pub fn out(&self) -> &LotOutput {
        &self.lots[0]
    }

    /// Every printed line of every lot, in order.
    pub fn prints(&self) -> Vec<String> {
        self.lots.iter().flat_map(|o| o.prints.clone()).collect()
    }

    /// Warning messages of the first lot.
    pub fn warnings(&self) -> Vec<String> {
        self.out()
            .warnings
            .iter()
            .map(|d| d.message.clone())
            .collect()
    }

    /// The leaf meshes of the first lot (object coordinates).
    pub fn meshes(&self) -> &[Mesh] {
        &self.out().meshes
    }

    /// Bounds of all leaf geometry of the first lot.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds_of(self.meshes())
    }

    /// Total face area of the first lot's leaves.
    pub fn area(&self) -> f64 {
        self.meshes().iter().map(measure::mesh_area).sum()
    }

    /// Total enclosed volume of the first lot's leaves.
    pub fn volume(&self) -> f64 {
        self.meshes().iter().map(measure::volume).sum()
    }

    /// The materials of every face of every leaf, in order.
    pub fn face_materials(&self) -> Vec<&Material> {
        self.meshes()
            .iter()
            .flat_map(|m| m.faces.iter().map(|f| &m.materials[f.material as usize]))
            .collect()
    }
}

pub fn bounds_of(meshes: &[Mesh]) -> (DVec3, DVec3) {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for m in meshes {
        if let Some((a, b)) = measure::bounds(m) {
            lo = lo.min(a);
            hi = hi.max(b);
        }
    }
    (lo, hi)
}

/// Bounds of one mesh.
pub fn mesh_bounds(m: &Mesh) -> (DVec3, DVec3) {
    measure::bounds(m).expect("a mesh with faces")
}

/// The numbers in a printed line, in order (`"(3)[1,2.5,-3]"` gives the 3,
/// the 1, 2.5 and -3; callers skip what they do not need).
pub fn numbers(line: &str) -> Vec<f64> {
    let mut out = Vec::new();
    let bytes = line.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i] as char;
        let starts = c.is_ascii_digit()
            || (c == '-' && bytes.get(i + 1).is_some_and(|b| b.is_ascii_digit()));
        if starts {
            let start = i;
            i += 1;
            while i < bytes.len() {
                let d = bytes[i] as char;
                let exp_sign = (d == '-' || d == '+') && matches!(bytes[i - 1] as char, 'e' | 'E');
                if d.is_ascii_digit() || d == '.' || d == 'e' || d == 'E' || exp_sign {
                    i += 1;
                } else {
                    break;
                }
            }
            if let Ok(x) = line[start..i].parse::<f64>() {
                out.push(x);
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The elements of a printed 1D array `(n)[a,b,c]`.
#[track_caller]
pub fn array(line: &str) -> Vec<f64> {
    let inner = line
        .split_once('[')
        .and_then(|(_, r)| r.strip_suffix(']'))
        .unwrap_or_else(|| panic!("`{line}` is not a printed array"));
    if inner.is_empty() {
        return Vec::new();
    }
    inner
        .split(',')
        .map(|s| {
            s.parse::<f64>()
                .unwrap_or_else(|_| panic!("`{s}` in `{line}` is not a number"))
        })
        .collect()
}

#[track_caller]
pub fn assert_near(got: f64, expected: f64, eps: f64) {
    assert!(
        (got - expected).abs() <= eps,
        "expected {expected}, got {got} (tolerance {eps})"
    );
}

#[track_caller]
pub fn assert_all_near(got: &[f64], expected: &[f64], eps: f64) {
    let ok =
        got.len() == expected.len() && got.iter().zip(expected).all(|(g, e)| (g - e).abs() <= eps);
    assert!(
        ok,
        "expected {expected:?}\n     got {got:?} (tolerance {eps})"
    );
}

#[track_caller]
pub fn assert_vec_near(got: DVec3, expected: [f64; 3], eps: f64) {
    assert_all_near(&got.to_array(), &expected, eps);
}

/// A rule-file fragment that prints a shape's scope and pivot as one line of
/// 15 numbers: `t`, `r`, `s`, `pivot.p`, `pivot.o`. Call `Scope` where the
/// page shows a scope (the printing copy is deleted, it adds no geometry);
/// parse with [`scope_line`].
pub const SCOPE_PRINTER: &str = r#"
Scope --> print([scope.tx, scope.ty, scope.tz, scope.rx, scope.ry, scope.rz, scope.sx, scope.sy, scope.sz, pivot.px, pivot.py, pivot.pz, pivot.ox, pivot.oy, pivot.oz]) NIL
"#;

/// A printed scope line (see [`SCOPE_PRINTER`]).
#[derive(Clone, Copy, Debug)]
pub struct ScopeLine {
    pub t: DVec3,
    pub r: DVec3,
    pub s: DVec3,
    pub p: DVec3,
    pub o: DVec3,
}

#[track_caller]
pub fn scope_line(line: &str) -> ScopeLine {
    let v = array(line);
    assert_eq!(v.len(), 15, "`{line}` is not a scope line");
    let d = |i: usize| DVec3::new(v[i], v[i + 1], v[i + 2]);
    ScopeLine {
        t: d(0),
        r: d(3),
        s: d(6),
        p: d(9),
        o: d(12),
    }
}

/// The CGA rotation matrix of Euler angles in degrees, written out from the
/// reference page "CGA Euler Angles" (element `[row][col]`), independently of
/// the engine's own code: returned as rows.
pub fn euler_matrix(deg: [f64; 3]) -> [[f64; 3]; 3] {
    let [a, b, g] = deg.map(f64::to_radians);
    let (sa, ca, sb, cb, sg, cg) = (a.sin(), a.cos(), b.sin(), b.cos(), g.sin(), g.cos());
    [
        [cb * cg, sa * sb * cg - ca * sg, sa * sg + ca * sb * cg],
        [cb * sg, ca * cg + sa * sb * sg, ca * sb * sg - sa * cg],
        [-sb, sa * cb, ca * cb],
    ]
}

/// `m * v` for a matrix given as rows.
pub fn mat_mul(m: &[[f64; 3]; 3], v: DVec3) -> DVec3 {
    DVec3::new(
        m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
        m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
        m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z,
    )
}

/// The colour of a material as 0..255 integers (rounded).
pub fn rgb255(m: &Material) -> [u8; 3] {
    m.color.map(|c| (c * 255.0).round() as u8)
}

/// Points `(x, z)` of a lot in the ground plane.
pub fn pts(p: &[(f64, f64)]) -> Vec<DVec3> {
    p.iter().map(|&(x, z)| DVec3::new(x, 0.0, z)).collect()
}

/// The L-shaped lot of the reference examples: a 12 x 5 wing along x and a
/// 5 x 12 wing along z, counter-clockwise seen from above, first edge the
/// front.
pub fn l_lot() -> Vec<DVec3> {
    pts(&[
        (0.0, 0.0),
        (12.0, 0.0),
        (12.0, -5.0),
        (5.0, -5.0),
        (5.0, -12.0),
        (0.0, -12.0),
    ])
}
