//! Shared by the CLI tests: running the binary from the workspace root, temporary files.
//! Each test file uses what it needs (hence `dead_code`: a file may not use every helper).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `covtrace` with `args` from the workspace root.
pub fn covtrace(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
        .args(args)
        .output()
        .expect("run covtrace")
}

/// A path `name` in a temporary folder of this test process (`what` names the test file).
pub fn tmp(what: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("covtrace-{what}-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d.join(name)
}
