//! Every bundled path evaluates; `eval --json` reads back into the library; `plot` writes
//! a PNG; `list` names every operator.

use std::path::PathBuf;
use std::process::Command;

use covtrace::path::Evaluation;

fn paths() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/paths");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("examples/paths")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .collect();
    v.sort();
    assert!(v.len() >= 10, "bundled paths: {v:?}");
    v
}

fn covtrace(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .args(args)
        .output()
        .expect("run covtrace")
}

#[test]
fn every_bundled_path_evaluates_and_round_trips_json() {
    for p in paths() {
        let ps = p.to_str().expect("utf-8 path");
        let out = covtrace(&["eval", ps]);
        assert!(
            out.status.success(),
            "{ps}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = covtrace(&["eval", "--json", ps]);
        assert!(out.status.success(), "{ps}");
        let e = Evaluation::from_json(&String::from_utf8_lossy(&out.stdout)).expect("JSON reads back");
        // The JSON result is the library's result, to the last bit.
        let direct = covtrace::path::Path::load(&p, &covtrace::registry())
            .and_then(|x| x.eval())
            .expect("eval");
        assert_eq!(e, direct, "{ps}");
        match e.layout {
            2 => drop(e.result_cov::<2>().expect("valid Σ")),
            3 => drop(e.result_cov::<3>().expect("valid Σ")),
            4 => drop(e.result_cov::<4>().expect("valid Σ")),
            _ => drop(e.result_cov::<5>().expect("valid Σ")),
        }
    }
}

#[test]
fn form_flag_selects_the_form_and_the_json_records_it() {
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/paths/demo.ron");
    let d = demo.to_str().expect("utf-8");
    let out = covtrace(&["eval", "--json", "--form", "covariance", d]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let e = Evaluation::from_json(&String::from_utf8_lossy(&out.stdout)).expect("JSON reads back");
    assert_eq!(e.form, covtrace::Form::Covariance);
    let direct = covtrace::path::Path::load(&demo, &covtrace::registry())
        .and_then(|x| x.eval_in(covtrace::Form::Covariance))
        .expect("eval");
    assert_eq!(e, direct);
    let out = covtrace(&["eval", d]);
    assert!(String::from_utf8_lossy(&out.stdout).contains("form: square root"));
    let out = covtrace(&["eval", "--form", "cholesky", d]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("square-root"));
}

#[test]
fn stiff_prints_every_case_in_both_forms() {
    let out = covtrace(&["stiff", "--length", "400"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.lines()
            .next()
            .is_some_and(|h| h.contains("ours sqrt") && h.contains("ours cov"))
    );
    assert_eq!(text.lines().count(), 1 + cov_stiff::cases(400).len());
    assert!(text.contains("400 operators (bounces) (N=4)"));
    assert!(!text.contains("NaN"));
}

#[test]
fn plot_writes_a_png() {
    let dir = std::env::temp_dir().join(format!("covtrace-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let out_png = dir.join("demo.png");
    let demo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/paths/demo.ron");
    let out = covtrace(&[
        "plot",
        demo.to_str().expect("utf-8"),
        "-o",
        out_png.to_str().expect("utf-8"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let bytes = std::fs::read(&out_png).expect("png written");
    assert_eq!(&bytes[1..4], b"PNG");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn list_names_every_registered_operator() {
    let out = covtrace(&["list"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    for e in covtrace::registry().entries() {
        assert!(text.contains(&format!("{}:", e.name)), "{}", e.name);
    }
    // Each parameter with its unit and its declared domain.
    assert!(
        text.lines()
            .any(|l| l.split_whitespace().collect::<Vec<_>>()[..].starts_with(&[
                "focus_distance",
                "m",
                ">",
                "focal_length"
            ])),
        "{text}"
    );
}
