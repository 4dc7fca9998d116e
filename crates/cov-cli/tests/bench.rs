//! `covtrace render-bench`: a tiny run writes every output with finite numbers, caches
//! its reference, and bad arguments give one line and exit code 2 before any work.

mod common;
use common::covtrace;
use cov_render::renderer::Method;

#[test]
fn a_tiny_bench_writes_every_output_and_caches_its_reference() {
    // A folder whose parent does not exist yet: created as `mkdir -p` would.
    let dir = common::tmp("bench", "out").join("cornell");
    let d = dir.to_str().expect("utf-8 path");
    let args = [
        "render-bench",
        "examples/scenes/cornell.ron",
        "--size",
        "32x24",
        "--ref-spp",
        "16",
        "--budgets",
        "2,4",
        "-o",
        d,
    ];
    let out = covtrace(&args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for f in [
        "results.csv",
        "results.json",
        "error_time.png",
        "error_time.svg",
        "strip.png",
        "reference.png",
        "cov.png",
        "cov.error.png",
    ] {
        let len = std::fs::metadata(dir.join(f)).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
    }
    let csv = std::fs::read_to_string(dir.join("results.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 2 * Method::ALL.len(), "{csv}");
    for r in &rows {
        let cells: Vec<&str> = r.split(',').collect();
        for c in &cells[1..10] {
            let v: f64 = c.parse().unwrap_or_else(|_| panic!("{r}: `{c}` is not a number"));
            assert!(v.is_finite() && v >= 0.0, "{r}");
        }
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("results.json")).unwrap()).unwrap();
    assert_eq!(json["runs"].as_array().map(Vec::len), Some(2 * Method::ALL.len()));
    assert!(
        !stdout.contains("NaN") && !stdout.contains("(cached)"),
        "{stdout}"
    );
    // The second run finds the reference in the cache.
    let again = covtrace(&args);
    assert!(again.status.success());
    assert!(String::from_utf8_lossy(&again.stdout).contains("(cached)"));
    // A byte flipped in the cached file's last tile: it still decodes, with other pixels,
    // and its digest tells; the reference is rendered again, and said to be.
    let exr = std::fs::read_dir(&dir)
        .expect("out")
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            p.extension().is_some_and(|x| x == "exr")
                && p.file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("reference-"))
        })
        .expect("the cached reference");
    let mut bytes = std::fs::read(&exr).expect("read");
    let k = bytes.len() - 100;
    bytes[k] ^= 0x5a;
    std::fs::write(&exr, &bytes).expect("write");
    let third = covtrace(&args);
    let out = String::from_utf8_lossy(&third.stdout);
    assert!(third.status.success());
    assert!(
        !out.contains("(cached)") && out.contains("damaged or had no digest: rendered again"),
        "{out}"
    );
    let fourth = covtrace(&args);
    assert!(String::from_utf8_lossy(&fourth.stdout).contains("(cached)"));
}

#[test]
fn bad_arguments_give_one_line() {
    let cases: [(&[&str], &str); 10] = [
        (
            &["--size", "-64x48"],
            "--size must be WIDTHxHEIGHT (or WIDTH×HEIGHT) with sides 1 to",
        ),
        (&["--budgets", ""], "'--budgets <BUDGETS>': expected a number"),
        (&["--ref-spp", "4294967296"], "'--ref-spp <REF_SPP>': too large"),
        (
            &["--budgets", "0"],
            "--budgets: each must be a whole number of samples per pixel, 1 to 65536",
        ),
        (&["--budgets", "nan"], "--budgets: each must be a whole number"),
        (
            &["--budgets", "2,1.5"],
            "--budgets: each must be a whole number of samples per pixel, 1 to 65536, got 1.5",
        ),
        (&["--methods", "cov,magic"], "unknown method `magic`"),
        (&["--cov-stride", "3"], "--cov-stride must be one of"),
        (&["--ref-spp", "0"], "--ref-spp must be 1 to 65536"),
        (
            &["--budgets", "1,2,3,4,5,6,7,8,9,10,11,12,13"],
            "give 1 to 12 values",
        ),
    ];
    for (extra, want) in cases {
        let mut args = vec![
            "render-bench",
            "examples/scenes/cornell.ron",
            "-o",
            "/nonexistent/out",
        ];
        args.extend_from_slice(extra);
        let out = covtrace(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(
            stderr.contains(want) && stderr.trim().lines().count() == 1,
            "{extra:?}: {stderr}"
        );
    }
}

/// `--parts` is checked against the scene's rows before the reference is rendered (it
/// used to fail only after the reference, minutes in at the default `--ref-spp`).
#[test]
fn parts_are_checked_before_the_reference() {
    let dir = common::tmp("bench", "parts");
    let d = dir.to_str().expect("utf-8 path");
    let out = covtrace(&[
        "render-bench",
        "examples/scenes/cornell.ron",
        "--size",
        "32x24",
        "--ref-spp",
        "64",
        "--parts",
        "100",
        "-o",
        d,
        "--cache",
        d,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("parts must be 1 to 2"), "{stderr}");
    assert!(
        !dir.join("reference.png").exists(),
        "a reference was rendered first"
    );
}

/// A scene whose light emits nothing: every error is 0, so no method "reaches" anything
/// and none is "not reached"; the report says why there is no equal-error time.
#[test]
fn a_black_scene_has_no_equal_error_time() {
    let dir = common::tmp("bench", "black");
    std::fs::create_dir_all(&dir).unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene = std::fs::read_to_string(root.join("examples/scenes/cornell.ron")).unwrap();
    let black = zero_radiance(&scene);
    let file = dir.join("black.ron");
    std::fs::write(&file, black).unwrap();
    let out = covtrace(&[
        "render-bench",
        file.to_str().unwrap(),
        "--size",
        "16x16",
        "--ref-spp",
        "4",
        "--budgets",
        "1,2",
        "--methods",
        "uniform,cov",
        "-o",
        dir.join("out").to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(!stdout.contains("not reached"), "{stdout}");
    assert!(
        stdout.contains("uniform's error at its largest budget is 0"),
        "{stdout}"
    );
}

/// `text` with every `radiance: (..)` made `(0.0, 0.0, 0.0)`.
fn zero_radiance(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("radiance: (") {
        let (head, tail) = rest.split_at(i + "radiance: (".len());
        out.push_str(head);
        out.push_str("0.0, 0.0, 0.0");
        rest = &tail[tail.find(')').expect("a closed triple")..];
    }
    out.push_str(rest);
    out
}

/// The cached reference is keyed by the files a scene reads as well as its text: a
/// texture changed under the same scene text renders a new reference.
#[test]
fn a_changed_texture_is_a_new_reference() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    let dir = common::tmp("bench", "texture");
    std::fs::create_dir_all(dir.join("textures")).expect("folder");
    std::fs::copy(root.join("snooker.ron"), dir.join("snooker.ron")).expect("scene");
    for f in std::fs::read_dir(root.join("textures"))
        .expect("textures")
        .flatten()
    {
        std::fs::copy(f.path(), dir.join("textures").join(f.file_name())).expect("texture");
    }
    let scene = dir.join("snooker.ron");
    let out = dir.join("out");
    let run = || {
        let o = covtrace(&[
            "render-bench",
            scene.to_str().expect("utf-8"),
            "--size",
            "16x12",
            "--ref-spp",
            "4",
            "--budgets",
            "2",
            "--methods",
            "uniform",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).contains("(cached)")
    };
    assert!(!run(), "the first run renders its reference");
    assert!(run(), "the second finds it");
    std::fs::copy(root.join("textures/ball12.png"), dir.join("textures/ball9.png")).expect("texture");
    assert!(!run(), "a changed texture is a new reference");
}
