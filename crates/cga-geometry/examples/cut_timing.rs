//! Timing of the plane cut on the workloads of the `cut` benchmark.
//!
//! `cargo run --release --example cut_timing` prints the time per call of
//! each workload. `cut_timing CASE N` runs only workload `CASE`, `N` times:
//! the instruction count of one call is the difference between the counts
//! of two runs under `valgrind --tool=callgrind` with different `N`,
//! divided by the difference of the `N`s (setup cancels out). This is the
//! measure to compare on a shared machine, where wall times are noisy.
use cga_geometry::split_along_axis;
use std::hint::black_box;
use std::time::Instant;

#[path = "../benches/cut/cases.rs"]
mod cases;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let all = cases::cases();
    if let Some(name) = args.first() {
        let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
        let Some(case) = all.iter().find(|c| c.name == name.as_str()) else {
            let names: Vec<&str> = all.iter().map(|c| c.name).collect();
            eprintln!("unknown case {name}; cases: {}", names.join(", "));
            std::process::exit(2);
        };
        let mut faces = 0;
        for _ in 0..n {
            let parts = split_along_axis(black_box(&case.mesh), case.axis, black_box(&case.cuts));
            faces += parts.iter().map(|p| p.faces.len()).sum::<usize>();
        }
        println!("{name}: {faces} faces out in {n} calls");
        return;
    }
    for case in &all {
        // About 50 ms per workload.
        let t = Instant::now();
        let mut n = 0usize;
        let mut faces = 0;
        while n < 10 || t.elapsed().as_secs_f64() < 0.05 {
            let parts = split_along_axis(black_box(&case.mesh), case.axis, black_box(&case.cuts));
            faces = parts.iter().map(|p| p.faces.len()).sum::<usize>();
            n += 1;
        }
        println!(
            "{:>14} ({:>4} faces in, {:>4} out): {:>10.2} us per split",
            case.name,
            case.mesh.faces.len(),
            faces,
            t.elapsed().as_secs_f64() * 1e6 / n as f64
        );
    }
}
