//! cov-render's modules form no import circle: each refers only to modules that do not
//! refer back to it, directly or through others (read from the sources).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Module name → the modules of the crate its source names as `crate::m`.
fn graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files: Vec<_> = std::fs::read_dir(&src)
        .expect("src")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "rs") && !p.ends_with("lib.rs"))
        .collect();
    files.sort();
    let names: BTreeSet<String> = files
        .iter()
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect();
    let mut g = BTreeMap::new();
    for p in &files {
        let me = p.file_stem().expect("stem").to_string_lossy().into_owned();
        let text = std::fs::read_to_string(p).expect("read");
        let mut uses = BTreeSet::new();
        for (i, _) in text.match_indices("crate::") {
            let rest = &text[i + "crate::".len()..];
            let mut brace = rest.strip_prefix('{').map(|r| r.split('}').next().unwrap_or(""));
            let heads: Vec<&str> = match brace.take() {
                // `use crate::{a::X, b::Y}`
                Some(list) => list.split(',').map(str::trim).collect(),
                None => vec![rest],
            };
            for h in heads {
                let m: String = h
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if names.contains(&m) && m != me {
                    uses.insert(m);
                }
            }
        }
        g.insert(me, uses);
    }
    g
}

#[test]
fn modules_form_no_circle() {
    let g = graph();
    assert!(g.len() >= 12, "{g:?}");
    // Depth-first search with colours: grey = on the current path.
    fn visit<'a>(
        m: &'a str,
        g: &'a BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<&'a str, u8>,
        path: &mut Vec<&'a str>,
    ) {
        match state.get(m) {
            Some(2) => return,
            Some(1) => panic!("import circle: {} -> {m}", path.join(" -> ")),
            _ => {}
        }
        state.insert(m, 1);
        path.push(m);
        for n in &g[m] {
            visit(n, g, state, path);
        }
        path.pop();
        state.insert(m, 2);
    }
    let mut state = BTreeMap::new();
    for m in g.keys() {
        visit(m, &g, &mut state, &mut Vec::new());
    }
    // The renderer sits above the film and the covariance pass, never below.
    assert!(g["renderer"].contains("film") && g["renderer"].contains("covpass"));
    assert!(!g["film"].contains("renderer") && !g["covpass"].contains("renderer"));
}
