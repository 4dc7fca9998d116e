//! Coverage-guided fuzzing of the path parser and evaluator:
//! `cargo +nightly fuzz run parse_path` (needs cargo-fuzz and a nightly toolchain).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(path) = covtrace::path::Path::parse(text, &covtrace::registry()) {
            let _ = path.eval();
        }
    }
});
