//! How long making the page's model bytes takes (`encode::lot_frame` for
//! each lot, as the preview encodes each lot when it is made) for a set of
//! lots, best and median of several runs, after generating them once into
//! meshes to draw, and how long that generation took:
//!
//!     cargo run --release -p cga-serve --example encode_bench -- RULES.cga LOTSPEC [RUNS]

use std::time::Instant;

/// The allocator of the `cga` command, which serves the preview.
#[global_allocator]
static ALLOCATOR: cga_alloc::Allocator = cga_alloc::Allocator;

fn main() {
    // As the command: memory freed is kept for reuse.
    cga_alloc::keep_freed_memory(None);
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [rules, lots, rest @ ..] = &args[..] else {
        eprintln!("usage: encode_bench RULES.cga LOTSPEC [RUNS]");
        std::process::exit(2);
    };
    let runs: usize = rest
        .first()
        .map_or(9, |r| r.parse().expect("RUNS is a number"));
    let rules = cga::Engine::new(cga::DiskWorld).load(rules);
    let lots = cga::lots::read(&[lots]).expect("lots").lots;
    let t = Instant::now();
    let results = cga_serve::encode::drawn(&rules, &lots, &cga::Options::default(), [0.0; 3])
        .expect("generates");
    println!(
        "generated into meshes to draw in {:.1} ms (first call)",
        t.elapsed().as_secs_f64() * 1e3
    );
    let mut bytes = 0;
    let mut last: Vec<Vec<u8>> = Vec::new();
    let mut times: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            // Into the buffers of the run before, as the preview reuses
            // its frames' buffers.
            let mut spare = std::mem::take(&mut last);
            let frames: Vec<Vec<u8>> = results
                .iter()
                .map(|lot| {
                    let used = spare.pop().unwrap_or_default();
                    cga_serve::encode::lot_frame(lot, &mut |p| Some(p.to_string()), used).0
                })
                .collect();
            let took = t.elapsed().as_secs_f64() * 1e3;
            bytes = frames.iter().map(Vec::len).sum();
            last = frames;
            took
        })
        .collect();
    times.sort_by(f64::total_cmp);
    // FNV-1a of the bytes: a change of code that should not change them
    // shows here.
    let digest = last
        .iter()
        .flatten()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)
        });
    println!(
        "{} lots, {:.1} MB (digest {digest:016x}): best {:.1} ms, median {:.1} ms",
        lots.len(),
        bytes as f64 / 1e6,
        times[0],
        times[times.len() / 2]
    );
}
