//! Random and mutated inputs never make the parser or the evaluator panic: every outcome
//! is a value or a positioned error. (The coverage-guided version is `fuzz/`, which needs
//! a nightly toolchain; this one runs on stable in CI.)

use covtrace::path::{Path, PathError};
use proptest::prelude::*;

fn corpus() -> Vec<String> {
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/paths");
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("examples/paths")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().extension().is_some_and(|x| x == "ron"))
        .map(|e| std::fs::read_to_string(e.path()).expect("read"))
        .collect();
    v.sort();
    v
}

fn check(text: &str) {
    match Path::parse(text, &covtrace::registry()) {
        Ok(p) => {
            if let Err(e) = p.eval() {
                assert!(!e.to_string().is_empty());
            }
        }
        Err(PathError::Parse {
            line, col, message, ..
        }) => {
            assert!(line >= 1 && col >= 1, "position {line}:{col}");
            assert!(!message.is_empty());
        }
        Err(e) => panic!("parse returned a non-positioned error: {e}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn mutated_files_never_panic(file in 0usize..64, edits in prop::collection::vec((0usize..4096, 0u8..4, any::<char>(), -1e12f64..1e12), 1..6)) {
        let files = corpus();
        let mut text: Vec<char> = files[file % files.len()].chars().collect();
        for (pos, kind, ch, num) in edits {
            let p = pos % (text.len() + 1);
            match kind {
                0 if p < text.len() => { text.remove(p); }
                1 => text.insert(p, ch),
                2 if p < text.len() => text[p] = ch,
                _ => {
                    let s: Vec<char> = format!("{num}").chars().collect();
                    for (k, c) in s.into_iter().enumerate() {
                        text.insert((p + k).min(text.len()), c);
                    }
                }
            }
        }
        check(&text.into_iter().collect::<String>());
    }

    #[test]
    fn arbitrary_strings_never_panic(s in "\\PC{0,200}") {
        check(&s);
    }

    #[test]
    fn extreme_numbers_never_panic(d in prop::num::f64::ANY, k in prop::num::f64::ANY, e in prop::num::f64::ANY) {
        let text = format!(
            "Path(source: Gaussian(x: 0.1, y: 0.2), operators: [Travel(distance: {d:?}), Curvature(k: {k:?}), Brdf(lobe: Phong(exponent: {e:?}))])"
        );
        check(&text);
    }
}
