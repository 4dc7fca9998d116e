//! `covtrace render`: the bundled scenes render at a small size and write every output;
//! bad scene files give one positioned line and exit code 2, before any work.

use std::path::PathBuf;

mod common;
use common::covtrace;

fn tmp(name: &str) -> PathBuf {
    common::tmp("render", name)
}

#[test]
fn each_bundled_scene_renders_and_writes_its_outputs() {
    for name in ["cornell", "pool", "glossy"] {
        let exr = tmp(&format!("{name}.exr"));
        let out = covtrace(&[
            "render",
            &format!("examples/scenes/{name}.ron"),
            "--spp",
            "2",
            "--cov-paths",
            "1",
            "--size",
            "32x24",
            "-o",
            exr.to_str().expect("utf-8 path"),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{name}: {stderr}");
        for f in cov_cli::render::outputs(&exr).iter().chain([&exr]) {
            let len = std::fs::metadata(f).map(|m| m.len()).unwrap_or(0);
            assert!(len > 0, "{name}: {} missing or empty", f.display());
        }
        let png = image::open(exr.with_extension("png"))
            .expect("png reads")
            .to_rgb8();
        assert_eq!(png.dimensions(), (32, 24));
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            stdout.contains("covariance:") && !stdout.contains("NaN") && !stdout.contains("inf"),
            "{stdout}"
        );
    }
}

#[test]
fn bad_scene_files_give_one_positioned_line() {
    let base = r#"Scene(
    camera: (position: (0.0, 1.0, 3.0), look_at: (0.0, 1.0, 0.0), fov: 40.0, width: WIDTH, height: 8),
    materials: { "w": Diffuse(albedo: (0.5, 0.5, 0.5)) },
    lights: [Sphere(center: (0.0, 2.0, 0.0), radius: RADIUS, radiance: (1.0, 1.0, 1.0))],
    shapes: [SHAPE],
)"#;
    let ok_shape = r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "w")"#;
    let cases: [(&str, &str, &str, &str, &str); 5] = [
        (
            "unknown shape",
            "8",
            "0.5",
            r#"Cone(apex: (0.0, 0.0, 0.0), material: "w")"#,
            ":5:14: Unexpected variant named `Cone`",
        ),
        (
            "missing obj",
            "8",
            "0.5",
            r#"Mesh(obj: "nowhere.obj", material: "w")"#,
            ":5:24: OBJ `nowhere.obj`: no such file",
        ),
        (
            "NaN radius",
            "8",
            "NaN",
            ok_shape,
            ":4:54: `radius` must be finite and > 0, got NaN",
        ),
        (
            "zero resolution",
            "0",
            "0.5",
            ok_shape,
            ":2:85: `width` must be 1 to 8192 px, got 0",
        ),
        (
            "unknown material",
            "8",
            "0.5",
            r#"Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "gold")"#,
            ":5:69: unknown material `gold`; the scene defines: w",
        ),
    ];
    for (what, width, radius, shape, expected) in cases {
        let text = base
            .replace("WIDTH", width)
            .replace("RADIUS", radius)
            .replace("SHAPE", shape);
        let file = tmp(&format!("{}.ron", what.replace(' ', "_")));
        std::fs::write(&file, text).expect("write scene");
        let exr = tmp("bad.exr");
        let out = covtrace(&[
            "render",
            file.to_str().expect("utf-8"),
            "-o",
            exr.to_str().expect("utf-8"),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{what}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{what}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{what}: expected `{expected}` in {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{what}");
    }
    // Arguments are checked before the scene is rendered.
    let out = covtrace(&[
        "render",
        "examples/scenes/pool.ron",
        "-o",
        "/nonexistent-dir/x.exr",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no such folder"));
    // A count out of range or not a whole number says what --spp takes; a huge --time is
    // printed compactly.
    for spp in ["0", "1e12", "70000", "2.5"] {
        let out = covtrace(&["render", "examples/scenes/pool.ron", "--spp", spp]);
        assert_eq!(out.status.code(), Some(2));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("must be a whole number of samples per pixel, 1 to 65536"),
            "{err}"
        );
    }
    let out = covtrace(&["render", "examples/scenes/pool.ron", "--time", "1e300"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("at most 604800 s, got 1e300") && err.len() < 120,
        "{err}"
    );
}

/// Renders `scene` at 32×24 with `extra` arguments into `name.exr`; returns the EXR's
/// path and stdout.
fn render(scene: &str, name: &str, extra: &[&str]) -> (PathBuf, String) {
    let exr = tmp(&format!("{name}.exr"));
    let mut args = vec![
        "render",
        scene,
        "--size",
        "32x24",
        "-o",
        exr.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    let out = covtrace(&args);
    assert!(
        out.status.success(),
        "{name}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    (exr, String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The EXR's pixels (f32, as written).
fn pixels(exr: &std::path::Path) -> Vec<f32> {
    image::open(exr).expect("exr reads").into_rgb32f().into_raw()
}

/// `--method` picks the method: covariance tracing by default (with the maps), plain
/// Monte Carlo without a covariance pass, and each method its own image.
#[test]
fn method_picks_the_method_and_covariance_is_the_default() {
    let scene = "examples/scenes/cornell.ron";
    let (def, out) = render(scene, "default", &["--spp", "4"]);
    assert!(
        out.contains("render: cov,") && out.contains("covariance: 1 path(s) per 4×4 block"),
        "{out}"
    );
    let (cov, _) = render(scene, "cov", &["--spp", "4", "--method", "cov"]);
    assert_eq!(pixels(&def), pixels(&cov));
    let (uni, out) = render(scene, "uniform", &["--spp", "4", "--method", "uniform"]);
    assert!(
        out.contains("render: uniform,") && !out.contains("covariance:"),
        "{out}"
    );
    assert!(!out.contains("density.png"), "{out}");
    assert_ne!(pixels(&uni), pixels(&cov));
    for m in ["gauss", "variance", "cov-density", "cov-filter"] {
        let (_, out) = render(scene, m, &["--spp", "4", "--method", m]);
        assert!(out.contains(&format!("render: {m},")), "{out}");
    }
    let bad = covtrace(&["render", scene, "--method", "fast\nest"]);
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{err}");
    assert!(err.contains(r"unknown method `fast\nest`"), "{err}");
}

/// `--spp` is the average budget: the samples taken are the budget times the pixels
/// (within rounding), for uniform and for the adaptive allocation.
#[test]
fn spp_is_the_average_budget() {
    for (m, spp) in [("uniform", "3"), ("cov", "8")] {
        let (_, out) = render(
            "examples/scenes/pool.ron",
            &format!("spp-{m}"),
            &["--spp", spp, "--method", m],
        );
        let want = spp.parse::<u64>().unwrap() * 32 * 24;
        let samples: u64 = out
            .split("render: ")
            .nth(1)
            .and_then(|r| r.split(", ").nth(1))
            .and_then(|r| r.split(' ').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no sample count in {out}"));
        assert!(
            samples.abs_diff(want) <= 32 * 24,
            "{m}: {samples} samples for {want}"
        );
    }
    for bad in ["0", "65537", "-1", "x"] {
        let out = covtrace(&["render", "examples/scenes/pool.ron", &format!("--spp={bad}")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "--spp {bad}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
}

/// `--time` renders passes until the time is spent and says what it reached.
#[test]
fn time_renders_progressively_and_says_what_it_reached() {
    let (exr, out) = render(
        "examples/scenes/pool.ron",
        "timed",
        &["--spp", "1", "--time", "1"],
    );
    let passes: u32 = out
        .split(" passes of 1 spp in the 1 s asked")
        .next()
        .and_then(|p| p.rsplit(' ').next())
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("no pass count in {out}"));
    assert!(passes >= 2, "{out}");
    assert!(out.contains("spp on average reached"), "{out}");
    assert!(pixels(&exr).iter().all(|v| v.is_finite()));
    for bad in ["0", "-2", "nan", "inf", "1e9", "soon"] {
        let o = covtrace(&["render", "examples/scenes/pool.ron", &format!("--time={bad}")]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "--time {bad}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    // A render that fills every pixel to the most a pixel takes stops early and says so;
    // the time limit's passes go on until then (16 passes of 4096 make 65536).
    let exr = tmp("capped.exr");
    let o = covtrace(&[
        "render",
        "examples/scenes/pool.ron",
        "--size",
        "2x2",
        "--method",
        "uniform",
        "--spp",
        "4096",
        "--time",
        "600",
        "-o",
        exr.to_str().expect("utf-8 path"),
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("16 passes of 4096 spp in the 600 s asked, 65536.0 spp on average reached (stopped before the time: every pixel holds 65536 samples"),
        "{out}"
    );
}

/// `render --method cov --spp 16 --seed 1` writes the image that `render-bench` measures
/// for the same method, budget and seed: one renderer, the same bits.
#[test]
fn render_and_render_bench_give_the_same_bits() {
    let scene = "examples/scenes/glossy.ron";
    let (exr, _) = render(scene, "same", &["--method", "cov", "--spp", "16", "--seed", "1"]);
    let dir = tmp("bench-same");
    let out = covtrace(&[
        "render-bench",
        scene,
        "--size",
        "32x24",
        "--ref-spp",
        "4",
        "--budgets",
        "16",
        "--methods",
        "cov",
        "--seed",
        "1",
        "-o",
        dir.to_str().expect("utf-8 path"),
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(pixels(&exr), pixels(&dir.join("cov.exr")));
    // And another seed gives another image (the comparison can fail).
    let (other, _) = render(scene, "other", &["--method", "cov", "--spp", "16", "--seed", "2"]);
    assert_ne!(pixels(&other), pixels(&dir.join("cov.exr")));
}

/// Without Open Image Denoise in the build, `--denoise` and the `+oidn` methods say how
/// to get it, in one line, before any work.
#[cfg(not(feature = "oidn"))]
#[test]
fn denoise_without_oidn_says_how_to_get_it() {
    for args in [
        vec!["render", "examples/scenes/pool.ron", "--denoise", "oidn"],
        vec![
            "render-bench",
            "examples/scenes/pool.ron",
            "--methods",
            "cov+oidn",
        ],
    ] {
        let out = covtrace(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("--features oidn"), "{err}");
    }
    let out = covtrace(&["render", "examples/scenes/pool.ron", "--denoise", "magic"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown denoiser `magic`"));
}

/// With Open Image Denoise: `--denoise oidn` writes a denoised image and says how long
/// the denoiser took.
#[cfg(feature = "oidn")]
#[test]
fn denoise_with_oidn_writes_a_denoised_image() {
    let (exr, out) = render(
        "examples/scenes/cornell.ron",
        "denoised",
        &["--spp", "2", "--denoise", "oidn"],
    );
    assert!(
        out.contains("render: cov+oidn,") && out.contains("denoising"),
        "{out}"
    );
    let (noisy, _) = render("examples/scenes/cornell.ron", "noisy", &["--spp", "2"]);
    assert_ne!(pixels(&exr), pixels(&noisy));
    assert!(pixels(&exr).iter().all(|v| v.is_finite() && *v >= 0.0));
}

/// A scene whose only light faces away from everything renders black, and says why.
#[test]
fn a_black_image_says_so() {
    let text = r#"Scene(
    camera: (position: (0.0, 1.0, 3.0), look_at: (0.0, 1.0, 0.0), fov: 40.0, width: 8, height: 8),
    materials: { "w": Diffuse(albedo: (0.5, 0.5, 0.5)) },
    lights: [Rect(corner: (-0.5, 2.0, -0.5), edge_u: (0.0, 0.0, 1.0), edge_v: (1.0, 0.0, 0.0), radiance: (5.0, 5.0, 5.0))],
    shapes: [Quad(corner: (-5.0, 0.0, -5.0), edge_u: (10.0, 0.0, 0.0), edge_v: (0.0, 0.0, 10.0), material: "w")],
)"#;
    let file = tmp("upward_light.ron");
    std::fs::write(&file, text).expect("write scene");
    // On the standard error, where warnings and errors go, not among the results.
    let stderr = |scene: &str, name: &str| {
        let exr = tmp(&format!("{name}.exr"));
        let args = [
            "render",
            scene,
            "--size",
            "32x24",
            "--spp",
            "2",
            "-o",
            exr.to_str().expect("utf-8"),
        ];
        let out = covtrace(&args);
        assert!(out.status.success(), "{name}");
        assert!(
            !String::from_utf8_lossy(&out.stdout).contains("warning"),
            "{name}"
        );
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let e = stderr(file.to_str().expect("utf-8"), "upward_light");
    assert!(e.contains("warning: the image is black"), "{e}");
    let e = stderr("examples/scenes/cornell.ron", "not_black");
    assert!(!e.contains("warning"), "{e}");
}
