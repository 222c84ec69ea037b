//! Parses the given `.cga` files, prints their diagnostics and how long
//! parsing took (run with `--release` for meaningful timings), and with
//! `--tree` the syntax tree as S-expressions:
//!
//!     cargo run --release -p cga-syntax --example parse_files -- [--tree] a.cga b.cga

use std::time::Instant;

use cga_syntax::{parse, sexpr, SourceMap};

fn main() {
    let mut sources = SourceMap::new();
    let mut failed = false;
    let args: Vec<String> = std::env::args().skip(1).collect();
    let tree = args.iter().any(|a| a == "--tree");
    for path in args.into_iter().filter(|a| a != "--tree") {
        let text = match std::fs::read(&path) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                eprintln!("{path}: {e}");
                failed = true;
                continue;
            }
        };
        let file = sources.add(&path, text);
        let text = &sources.get(file).text;
        let rounds = 200;
        let t = Instant::now();
        for _ in 0..rounds {
            std::hint::black_box(parse(file, text));
        }
        let per_parse = t.elapsed() / rounds;
        let (module, diagnostics) = parse(file, text);
        println!(
            "{path}: {} items, {} diagnostics, {:.1} µs per parse",
            module.items.len(),
            diagnostics.len(),
            per_parse.as_secs_f64() * 1e6
        );
        if tree {
            print!("{}", sexpr::module(&module));
        }
        for d in &diagnostics {
            print!("{}", d.render(&sources));
            failed = true;
        }
    }
    if failed {
        std::process::exit(1);
    }
}
