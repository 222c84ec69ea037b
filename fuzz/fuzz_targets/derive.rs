//! Deriving any rule file that resolves, on a small lot, never panics and
//! ends (tight limits keep each input fast; libFuzzer's `-timeout` catches
//! an operation that does not stop at the time limit).
#![no_main]

use libfuzzer_sys::fuzz_target;

use cga_engine::{generate_lot, lot, GenerateOptions, Limits};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data).into_owned();
    let mut sources = cga_syntax::SourceMap::new();
    let loaded = cga_engine::load_text(std::path::Path::new("fuzz.cga"), text, &mut sources);
    let Some(program) = loaded.program else { return };
    let Ok(rule) = program.start_rule(None) else { return };
    let assets = cga_engine::assets::Assets::new(&sources);
    let options = GenerateOptions {
        limits: Limits {
            max_depth: 64,
            max_shapes: 1000,
            // Tight: an input that needs long (Boolean operations, whose
            // BSP trees grow faster than their operands) is stopped soon,
            // keeping the executions per second high; that the limits
            // hold at all is what is checked.
            max_seconds: 0.05,
            max_faces: 500,
        },
        ..GenerateOptions::default()
    };
    // One lot per input (a building-sized one or a sliver, picked by the
    // input's length) keeps the executions per second high.
    let l = if data.len() % 2 == 0 {
        lot::rect(20.0, 30.0)
    } else {
        lot::rect(0.5, 7.0)
    };
    let _ = generate_lot(&program, &assets, rule, &l, 0, &options);
});
