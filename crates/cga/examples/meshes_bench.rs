//! How long generating lots into plain meshes takes (what the Python
//! package asks the library for; with `DRAWING=1` also into meshes to
//! draw, what the live preview asks for), against deriving them without
//! geometry, best and median of several runs:
//!
//!     cargo run --release -p cga --example meshes_bench -- RULES.cga LOTSPEC [RUNS]
//!
//! LOTSPEC as the `cga` command's `--lot` takes it (e.g.
//! `grid:5x4:lots/candler_footprint.obj`). `DIGEST=1` also prints a digest
//! of the meshes made (every coordinate's bits, the indices, the leaves'
//! numbers), to tell that a change to the collection left them the same.

use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

use cga::{Engine, Options, Target};

// The allocator of the `cga` command and the Python module.
#[global_allocator]
static ALLOCATOR: cga_alloc::Allocator = cga_alloc::Allocator;

fn main() {
    cga_alloc::keep_freed_memory(None);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [rules, lots, rest @ ..] = &args[..] else {
        eprintln!("usage: meshes_bench RULES.cga LOTSPEC [RUNS]");
        std::process::exit(2);
    };
    let runs: usize = rest
        .first()
        .map_or(5, |r| r.parse().expect("RUNS is a number"));
    let rules = Engine::new(cga::DiskWorld).load(rules);
    let lots = cga::lots::read(&[lots]).expect("lots").lots;
    // JOBS=n sets the number of threads (default: one per core).
    let options = match std::env::var("JOBS").ok().and_then(|j| j.parse().ok()) {
        Some(jobs) => Options::default().jobs(jobs),
        None => Options::default(),
    };
    // The lots' results are kept until the run ends, as a caller that
    // uses them does.
    let time = |target: &dyn Fn() -> Target<'static>| {
        let mut times: Vec<f64> = (0..runs)
            .map(|_| {
                let t = Instant::now();
                let mut out = Vec::new();
                rules
                    .generate_lots(&lots, &options, target(), |r| out.push(r))
                    .expect("generates");
                std::hint::black_box(out);
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        times.sort_by(f64::total_cmp);
        (times[0], times[times.len() / 2])
    };
    // MESHES_ONLY=1 skips the derivation-only runs (for a profiler).
    let meshes_only = std::env::var_os("MESHES_ONLY").is_some();
    let (best, median) = if meshes_only {
        (0.0, 0.0)
    } else {
        time(&|| Target::Nothing)
    };
    println!(
        "{} lots, derivation only: best {best:.1} ms, median {median:.1} ms",
        lots.len()
    );
    // DERIVATION_ONLY=1 skips the meshes runs (for a profiler).
    if std::env::var_os("DERIVATION_ONLY").is_some() {
        return;
    }
    // POSITIONS=1 times positions and triangles alone instead of plain
    // meshes (what `geometry="positions"` asks for in Python).
    let positions = std::env::var_os("POSITIONS").is_some();
    let kept = move || match positions {
        true => Target::Positions,
        false => Target::Meshes,
    };
    let (best, median) = time(&kept);
    let what = if positions {
        "positions"
    } else {
        "plain meshes"
    };
    println!(
        "{} lots, {what}: best {best:.1} ms, median {median:.1} ms",
        lots.len()
    );
    // DRAWING=1 also times meshes to draw (what the preview collects).
    let drawing = std::env::var_os("DRAWING").is_some();
    if drawing {
        let (best, median) = time(&|| Target::Drawing([0.0; 3]));
        println!(
            "{} lots, meshes to draw: best {best:.1} ms, median {median:.1} ms",
            lots.len()
        );
    }
    if std::env::var_os("DIGEST").is_some() {
        let digest = |target: Target<'static>| {
            let mut out = Vec::new();
            rules
                .generate_lots(&lots, &options, target, |r| out.push(r))
                .expect("generates");
            out.sort_by_key(|r| r.index);
            let mut h = DefaultHasher::new();
            for r in &out {
                digest_lot(r, &mut h);
            }
            h.finish()
        };
        println!("{what} digest: {:016x}", digest(kept()));
        if drawing {
            println!(
                "meshes to draw digest: {:016x}",
                digest(Target::Drawing([0.0; 3]))
            );
        }
    }
}

/// Feeds a lot's meshes to `h`: materials, every coordinate's bits,
/// indices and leaf numbers.
fn digest_lot(r: &cga::LotResult, h: &mut DefaultHasher) {
    let bits = |v: &[f64], h: &mut DefaultHasher| v.iter().for_each(|x| x.to_bits().hash(h));
    for m in &r.model.meshes {
        m.material.hash(h);
        m.positions.iter().for_each(|p| bits(p, h));
        m.normals.iter().for_each(|n| bits(n, h));
        m.uvs.iter().for_each(|t| bits(t, h));
        m.indices.hash(h);
        m.triangle_leaf.hash(h);
    }
    for m in &r.drawing.meshes {
        m.material.hash(h);
        m.positions
            .iter()
            .for_each(|p| p.iter().for_each(|x| x.to_bits().hash(h)));
        m.uvs
            .iter()
            .for_each(|t| t.iter().for_each(|x| x.to_bits().hash(h)));
        m.vertex_normals().hash(h);
        m.indices().hash(h);
        m.triangle_leaf.hash(h);
    }
    format!("{:?}", r.model.materials).hash(h);
    format!("{:?}", r.drawing.materials).hash(h);
    r.leaves.len().hash(h);
}
