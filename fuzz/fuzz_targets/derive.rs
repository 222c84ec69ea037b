//! Deriving any rule file that resolves, on a small lot, never panics and
//! ends (tight limits keep each input fast).
#![no_main]

use libfuzzer_sys::fuzz_target;

use cga_engine::{generate_lot, lot, GenerateOptions, Limits};

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("cga-fuzz-derive-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("rules.cga");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let mut sources = cga_syntax::SourceMap::new();
    let loaded = cga_engine::load(&path, &mut sources);
    let Some(program) = loaded.program else { return };
    let Ok(rule) = program.start_rule(None) else { return };
    let assets = cga_engine::assets::Assets::new(&sources);
    let options = GenerateOptions {
        limits: Limits {
            max_depth: 64,
            max_shapes: 2000,
        },
        ..GenerateOptions::default()
    };
    for (i, l) in [lot::rect(20.0, 30.0), lot::rect(0.5, 7.0)].iter().enumerate() {
        let _ = generate_lot(&program, &assets, rule, l, i, &options);
    }
});
