//! Deriving any rule file that resolves, on a small lot, never panics and
//! ends (tight limits keep each input fast; libFuzzer's `-timeout` catches
//! an operation that does not stop at the time limit).
#![no_main]

use libfuzzer_sys::fuzz_target;

use cga::{Limits, Options};

fuzz_target!(|data: &[u8]| {
    let text = cga::decode_text(data);
    let rules = cga::Engine::new(cga::MemoryWorld::new()).load_text("/fuzz/fuzz.cga", text);
    if rules.has_errors() || rules.start_rule(None).is_err() {
        return;
    }
    let options = Options {
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
        jobs: Some(1),
        ..Options::default()
    };
    // One lot per input (a building-sized one or a sliver, picked by the
    // input's length) keeps the executions per second high.
    let lot = if data.len() % 2 == 0 {
        cga::lots::rect(20.0, 30.0)
    } else {
        cga::lots::rect(0.5, 7.0)
    };
    let _ = rules.generate(&lot, &options);
});
