//! Every file in `tests/broken/` must fail with exit code 2 and one line on stderr,
//! `covtrace: FILE:LINE:COL: message`, at the position and with the message fragment
//! listed in `tests/broken/EXPECTED`. And no file may make the binary panic.

use std::path::PathBuf;
use std::process::Command;

fn broken_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/broken")
}

#[test]
fn broken_files_give_positioned_one_line_errors() {
    let expected = std::fs::read_to_string(broken_dir().join("EXPECTED")).expect("EXPECTED manifest");
    let mut checked = 0;
    for line in expected
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
    {
        let parts: Vec<&str> = line.split('\t').collect();
        assert_eq!(parts.len(), 3, "manifest line: {line}");
        let (file, pos, fragment) = (parts[0], parts[1], parts[2]);
        let path = broken_dir().join(file);
        let out = Command::new(env!("CARGO_BIN_EXE_covtrace"))
            .arg("eval")
            .arg(&path)
            .output()
            .expect("run covtrace");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{file}: exit code; stderr {stderr}");
        assert!(out.stdout.is_empty(), "{file}: nothing on stdout");
        assert_eq!(
            stderr.trim_end().lines().count(),
            1,
            "{file}: one line, got {stderr}"
        );
        let prefix = format!("covtrace: {}:{pos}: ", path.display());
        assert!(
            stderr.starts_with(&prefix),
            "{file}: expected prefix {prefix}, got {stderr}"
        );
        assert!(
            stderr.contains(fragment),
            "{file}: expected `{fragment}` in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{file}: panic");
        checked += 1;
    }
    assert!(checked >= 50, "only {checked} broken files");
    // Every .ron file in the folder is listed.
    let listed = std::fs::read_dir(broken_dir())
        .expect("broken dir")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "ron"))
        })
        .count();
    assert_eq!(listed, checked, "every broken file has an expectation");
}

#[test]
fn usage_errors_exit_2() {
    let out = Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .arg("frobnicate")
        .output()
        .expect("run");
    assert_eq!(out.status.code(), Some(2));
    let out = Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .args(["eval", "/nonexistent/path.ron"])
        .output()
        .expect("run");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/path.ron"));
}
