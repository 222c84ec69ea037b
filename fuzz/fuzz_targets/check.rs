//! Parsing and resolving (`cga check`) never panic, whatever the rule file.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = cga::decode_text(data);
    // In memory, over nothing: imports find no files, whatever they name.
    let rules = cga::Engine::new(cga::MemoryWorld::new()).load_text("/fuzz/fuzz.cga", text);
    let _ = rules.render_diagnostics();
    let _ = rules.attributes();
});
