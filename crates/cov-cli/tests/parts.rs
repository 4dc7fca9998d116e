//! `covtrace render --part I/N` and `covtrace merge`: the merged image is the single
//! render's (the digests both print), and bad parts get one line and exit code 2;
//! `--frames A..B` writes one file per frame.

use std::path::PathBuf;

mod common;
use common::covtrace;

fn tmp(name: &str) -> PathBuf {
    common::tmp("parts", name)
}

fn s(p: &std::path::Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The `image digest:` line of a run's output.
fn digest(out: &std::process::Output) -> String {
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    text.lines()
        .find_map(|l| l.strip_prefix("image digest: "))
        .unwrap_or_else(|| panic!("no digest in {text}"))
        .to_string()
}

const SCENE: &str = "examples/scenes/chess.ron";
const OPTS: [&str; 6] = ["--size", "40x96", "--spp", "4", "--seed", "2"];

#[test]
fn merged_parts_are_the_single_render() {
    let single = tmp("single.exr");
    let mut args = vec!["render", SCENE, "--parts", "3", "-o", s(&single)];
    args.extend(OPTS);
    let want = digest(&covtrace(&args));
    // Without --parts the budget is spread over the whole image: another image.
    let whole = tmp("whole.exr");
    let mut args = vec!["render", SCENE, "-o", s(&whole)];
    args.extend(OPTS);
    assert_ne!(digest(&covtrace(&args)), want);
    let parts: Vec<PathBuf> = (1..=3).map(|i| tmp(&format!("part{i}.exr"))).collect();
    // In reverse order: the parts do not depend on one another.
    for (i, p) in parts.iter().enumerate().rev() {
        let part = format!("{}/3", i + 1);
        let mut args = vec!["render", SCENE, "--part", &part, "-o", s(p)];
        args.extend(OPTS);
        let out = covtrace(&args);
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success() && text.contains(&format!("part {part}: rows")),
            "{text}"
        );
    }
    let merged = tmp("merged.exr");
    let mut args = vec!["merge", "-o", s(&merged)];
    args.extend(parts.iter().map(|p| s(p)));
    let out = covtrace(&args);
    assert_eq!(digest(&out), want);
    for f in cov_cli::render::outputs(&merged).iter().chain([&merged]) {
        assert!(f.exists(), "{} missing", f.display());
    }
    // A part missing, given twice, or from another render: one line, exit code 2.
    let other = tmp("other2.exr");
    let mut args = vec![
        "render",
        SCENE,
        "--part",
        "2/3",
        "-o",
        s(&other),
        "--size",
        "40x96",
        "--spp",
        "8",
    ];
    args.extend(["--seed", "2"]);
    assert!(covtrace(&args).status.success());
    for (files, want) in [
        (vec![&parts[0], &parts[2]], "part 2/3 (rows 32..64) is missing"),
        (
            vec![&parts[0], &parts[1], &parts[1], &parts[2]],
            "part 2/3 is given twice",
        ),
        (vec![&parts[0], &other, &parts[2]], "`spp` is 8.0 against 4.0"),
        (vec![&single], "not a covtrace part file"),
    ] {
        let mut args = vec!["merge", "-o", s(&merged)];
        args.extend(files.iter().map(|p| s(p)));
        let out = covtrace(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(want) && err.trim_end().lines().count() == 1, "{err}");
    }
    // An output that is one of the parts (the EXR, or a file written beside it) is
    // refused before anything is written: the part survives, byte for byte.
    let before = std::fs::read(&parts[0]).expect("part 1");
    let aov_named = tmp("part1");
    std::fs::copy(&parts[0], aov_named.with_extension("aov.exr")).expect("copy");
    for (out_name, part) in [
        (parts[0].clone(), parts[0].clone()),
        (
            aov_named.with_extension("exr"),
            aov_named.with_extension("aov.exr"),
        ),
    ] {
        let mut args = vec!["merge", "-o", s(&out_name), s(&part)];
        args.extend([s(&parts[1]), s(&parts[2])]);
        let out = covtrace(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("an input of this run, which the outputs of -o")
                && err.contains("would overwrite")
                && err.trim_end().lines().count() == 1,
            "{err}"
        );
    }
    assert_eq!(std::fs::read(&parts[0]).expect("part 1"), before);
}

#[test]
fn bad_part_options_get_one_line() {
    let out_file = tmp("bad.exr");
    for (args, want) in [
        (vec!["--part", "0/2"], "--part must be I/N"),
        (
            vec!["--part", "3/5", "--size", "40x64"],
            "--part 3/5: this image's 64 rows make 4 tile rows of 16, so it splits into 1 to 4 parts, not 5",
        ),
        (
            vec!["--part", "-1/4"],
            "--part must be I/N with 1 ≤ I ≤ N, got `-1/4`",
        ),
        (
            vec!["--part", "1/2", "--parts", "3"],
            "--part 1/2 renders a part of 2 parts, but --parts is 3",
        ),
        (vec!["--parts", "0"], "'--parts <PARTS>': 0 is not in 1..=512"),
        (
            vec!["--parts", "9", "--size", "40x64"],
            "--parts must be 1 to 4 for this image (its 64 rows make 4 tile rows of 16), got 9",
        ),
        (
            vec!["--part", "1/2", "--time", "1"],
            "--part and --time exclude each other",
        ),
        (vec!["--frames", "3..1"], "--frames must be A..B"),
        (vec!["--frame", "2000000"], "2000000 is not in 0..=1000000"),
    ] {
        let mut a = vec!["render", SCENE, "-o", s(&out_file)];
        a.extend(args);
        let out = covtrace(&a);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(want) && err.trim_end().lines().count() == 1, "{err}");
    }
}

/// `covtrace render SCENE --frames RANGE` at 24×16 px and 2 spp, to `out`.
fn render_frames(scene: &str, range: &str, out: &std::path::Path) -> std::process::Output {
    covtrace(&[
        "render",
        scene,
        "--frames",
        range,
        "--size",
        "24x16",
        "--spp",
        "2",
        "-o",
        s(out),
    ])
}

#[test]
fn frames_write_one_file_each_and_differ() {
    let out_file = tmp("anim.exr");
    let out = render_frames(SCENE, "0..1", &out_file);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    let digests: Vec<&str> = text
        .lines()
        .filter_map(|l| l.strip_prefix("image digest: "))
        .collect();
    assert_eq!(digests.len(), 2, "{text}");
    assert_ne!(digests[0], digests[1], "the moving piece moved between frames");
    for k in 0..2 {
        let f = cov_cli::render::frame_path(&out_file, k);
        assert!(f.exists(), "{} missing", f.display());
    }
}

/// `--frames` checks every frame before it renders the first: a range whose last frame
/// carries a ball beyond the coordinate limit renders nothing and says which frames, from
/// the first out of range.
#[test]
fn frames_are_checked_before_any_is_rendered() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("examples/scenes/pool.ron")).expect("pool");
    let fast = text.replacen("camera: (", "camera: (\n        frame_rate: 6e-12,", 1);
    assert_ne!(fast, text, "the camera gets a frame rate");
    let scene = tmp("fast.ron");
    std::fs::write(&scene, fast).expect("scene");
    let out_file = tmp("fast.exr");
    let out = render_frames(s(&scene), "0..2", &out_file);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--frames 0..2: frame 2 is out of range: must be a frame at which every shape and the camera stay within"),
        "{err}"
    );
    assert!(out.stdout.is_empty());
    assert!(
        !cov_cli::render::frame_path(&out_file, 0).exists(),
        "no frame was rendered"
    );
    // A longer range names the first frame out of range, not the last.
    let out = render_frames(s(&scene), "0..9", &out_file);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--frames 0..9: frames 2 to 9 are out of range: must be a frame at which every shape and the camera stay within")
            && err.contains("(at frame 2, one of them reaches"),
        "{err}"
    );
}
