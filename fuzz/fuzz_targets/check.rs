//! Parsing and resolving (`cga check`) never panic, whatever the rule file.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data).into_owned();
    let mut sources = cga_syntax::SourceMap::new();
    let loaded = cga_engine::load_text(std::path::Path::new("fuzz.cga"), text, &mut sources);
    for d in &loaded.diagnostics {
        let _ = d.render(&sources);
    }
});
