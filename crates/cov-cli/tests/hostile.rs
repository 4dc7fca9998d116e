//! Hostile input and output: bounded reads, standard input, a byte-order mark, and a
//! failed write reported instead of a silent success.

use std::io::Write;
use std::process::{Command, Stdio};

mod common;
use common::covtrace;

#[test]
fn an_endless_input_is_cut_at_the_cap_with_a_message() {
    let o = covtrace(&["eval", "/dev/zero"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("path files are read up to 16 MiB"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1);
}

#[test]
fn standard_input_and_a_byte_order_mark_are_read() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .args(["eval", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    child
        .stdin
        .take()
        .expect("stdin")
        .write_all("\u{feff}Path(source: Gaussian(x: 0.1), operators: [Travel(distance: 1.0)])".as_bytes())
        .expect("write");
    let o = child.wait_with_output().expect("wait");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("layout: 2"));
}

#[test]
fn a_failed_write_is_an_error() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .expect("/dev/full");
    let o = Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .args(["list"])
        .stdout(full)
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot write the output"));
}

#[test]
fn the_largest_count_a_user_may_give_is_bounded_work() {
    // The largest slice count allowed evaluates at once; a larger one is refused before
    // any work (it used to run for minutes).
    let ron = common::tmp("hostile", "slices.ron");
    std::fs::write(
        &ron,
        "Path(source: Gaussian(x: 0.1), operators: [ThickOccluder(depth: 0.3, slices: 10000, std: 0.05)])",
    )
    .expect("write");
    let t = std::time::Instant::now();
    let o = covtrace(&["eval", ron.to_str().expect("utf-8")]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Not a timing test: a bound far above the measured few milliseconds, to catch a hang.
    assert!(t.elapsed().as_secs() < 60);
}
