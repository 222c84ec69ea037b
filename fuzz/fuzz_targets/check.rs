//! Parsing and resolving (`cga check`) never panic, whatever the rule file.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("cga-fuzz-check-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join("rules.cga");
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let mut sources = cga_syntax::SourceMap::new();
    let loaded = cga_engine::load(&path, &mut sources);
    for d in &loaded.diagnostics {
        let _ = d.render(&sources);
    }
});
