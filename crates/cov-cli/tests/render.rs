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
            ":4:54: must be finite and > 0, got NaN",
        ),
        (
            "zero resolution",
            "0",
            "0.5",
            ok_shape,
            ":2:85: must be 1 to 8192 px, got 0",
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
    let out = covtrace(&["render", "examples/scenes/pool.ron", "--spp", "0"]);
    assert_eq!(out.status.code(), Some(2));
}
