//! Benchmarks of the plane cut behind CGA's `split`:
//! `cargo bench -p cga-geometry --bench cut`.
//!
//! Wall times on the shared build machine are noisy; the repeatable measure
//! is the instruction count of one call under callgrind, taken with
//! `examples/cut_timing.rs` (see its docs), which runs the same workloads.
//!
//! Workloads (see `cut/cases.rs`): a building mass (a box of 6 quads and
//! 8 shared positions) into 4 floors, and into 12 with cuts at both ends as
//! CGA's `split` passes them; a facade quad with UVs into 10 tiles; a
//! 16-sided cylinder into 20 slabs; the 64 x 64 sphere (4,096 faces) into 50.
//!
//! The numbers before and after the allocation-free rewrite of the cutter
//! are in `docs/performance.md` ("The plane cut").
//!
//! What remains for the small cases is largely the output itself: each part
//! is a `Mesh` of five to seven vectors and a clone of the material list
//! (whose materials hold 13 reference-counted strings each), allocated here
//! and freed by the caller.

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

#[path = "cut/cases.rs"]
mod cases;

fn bench_cut(c: &mut Criterion) {
    let mut group = c.benchmark_group("split_along_axis");
    for case in cases::cases() {
        group.bench_function(case.name, |b| {
            b.iter(|| {
                cga_geometry::split_along_axis(
                    black_box(&case.mesh),
                    case.axis,
                    black_box(&case.cuts),
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_cut);
criterion_main!(benches);
