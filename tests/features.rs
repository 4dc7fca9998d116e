//! The feature promise: a build with only the operators it uses compiles only those, and
//! the RON format (ron, erased-serde, serde_json) only with the `path` feature.

use std::process::Command;

/// `cargo tree` of what a dependent compiles (normal edges) with the given features.
fn tree(features: &[&str]) -> String {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let mut cmd = Command::new(cargo);
    cmd.current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "tree",
            "--offline",
            "-p",
            "covtrace",
            "-e",
            "normal",
            "--prefix",
            "none",
        ])
        .args(["--no-default-features"]);
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    let out = cmd.output().expect("cargo tree runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn has(tree: &str, krate: &str) -> bool {
    tree.lines().any(|l| l.split_whitespace().next() == Some(krate))
}

#[test]
fn travel_alone_compiles_no_file_format_and_no_other_operator() {
    let t = tree(&["travel"]);
    for absent in [
        "ron",
        "erased-serde",
        "serde_json",
        "cov-path",
        "cov-brdf",
        "cov-sensor",
        "cov-motion",
    ] {
        assert!(
            !has(&t, absent),
            "`{absent}` in the tree of --features travel:\n{t}"
        );
    }
    for present in ["cov-core", "cov-travel"] {
        assert!(has(&t, present), "`{present}` missing:\n{t}");
    }
}

#[test]
fn the_path_feature_brings_the_ron_format() {
    let t = tree(&["travel", "path"]);
    assert!(has(&t, "ron") && has(&t, "cov-path"), "{t}");
}
