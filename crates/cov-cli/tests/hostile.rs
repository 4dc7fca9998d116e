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

/// Every matrix `covtrace eval --json` prints (start, each step, result).
fn matrices(json: &serde_json::Value) -> Vec<Vec<Vec<f64>>> {
    let m = |v: &serde_json::Value| -> Vec<Vec<f64>> {
        v.as_array()
            .expect("rows")
            .iter()
            .map(|r| {
                r.as_array()
                    .expect("row")
                    .iter()
                    .map(|x| x.as_f64().expect("number"))
                    .collect()
            })
            .collect()
    };
    let mut out = vec![m(&json["start"])];
    for s in json["steps"].as_array().expect("steps") {
        out.push(m(&s["matrix"]));
    }
    out.push(m(&json["result"]));
    out
}

/// A ray refocused by a curved surface (travel 1/3, then curvature 3: Σ_xx is exactly 0)
/// and a long chain of such refocusings keep a symmetric Σ with no negative diagonal in
/// covariance form (it used to print −4.4e-16), and in square-root form.
#[test]
fn refocusing_chains_stay_psd_in_both_forms() {
    let one = "Travel(distance: 0.3333333333333333), Curvature(k: 3.0)";
    let long = vec![one; 200].join(", ");
    for ops in [one.to_string(), long] {
        let ron = common::tmp("hostile", "refocus.ron");
        std::fs::write(
            &ron,
            format!("Path(source: Gaussian(x: 0.1, y: 0.1), operators: [{ops}])"),
        )
        .expect("write");
        for form in ["covariance", "square-root"] {
            let o = covtrace(&["eval", "--json", "--form", form, ron.to_str().expect("utf-8")]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let json: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
            for (k, m) in matrices(&json).iter().enumerate() {
                for i in 0..m.len() {
                    assert!(
                        m[i][i] >= 0.0 && m[i][i].is_finite(),
                        "{form}, matrix {k}: Σ_{i}{i} = {}",
                        m[i][i]
                    );
                    for j in 0..m.len() {
                        assert_eq!(m[i][j], m[j][i], "{form}, matrix {k}: not symmetric");
                    }
                }
            }
        }
    }
}

/// The worst inputs within the documented bounds run in bounded memory: a path of the most
/// operators a path may hold (100,000), evaluated (as text and as JSON) and plotted, under
/// a 2 GiB address-space limit (`ulimit -v`), and within a minute each; a path file just
/// under the 16 MiB cap (400,000 steps) is refused for its length, in the same bounds.
#[test]
fn the_largest_inputs_run_in_bounded_memory() {
    let path = |n: usize| {
        let ops = vec!["Travel(distance: 1.0)"; n].join(",");
        format!("Path(source: Gaussian(x: 0.1), operators: [{ops}])")
    };
    let ron = common::tmp("hostile", "huge.ron");
    std::fs::write(&ron, path(100_000)).expect("write");
    let over = common::tmp("hostile", "over.ron");
    let text = path(400_000);
    assert!(text.len() < 16 << 20);
    std::fs::write(&over, text).expect("write");
    let png = common::tmp("hostile", "huge.png");
    let bin = env!("CARGO_BIN_EXE_covtrace");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    for cmd in [
        format!("'{bin}' eval '{}' > /dev/null", ron.display()),
        format!("'{bin}' eval --json '{}' > /dev/null", ron.display()),
        format!(
            "'{bin}' plot '{}' -o '{}' > /dev/null",
            ron.display(),
            png.display()
        ),
        format!(
            "'{bin}' eval '{}' 2>&1 | grep -q 'the path holds 400000 operators; at most 100000'",
            over.display()
        ),
    ] {
        let t = std::time::Instant::now();
        let o = Command::new("bash")
            .current_dir(&root)
            .args(["-c", &format!("ulimit -v 2097152; {cmd}")])
            .output()
            .expect("bash");
        assert!(
            o.status.success(),
            "{cmd}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        // Not a timing test: a bound far above the measured seconds, to catch a hang.
        assert!(t.elapsed().as_secs() < 60, "{cmd}");
    }
}

/// `stiff --length` is bounded: past it (or past the integers) one line and exit 2, no
/// allocation attempted (it used to abort on a 32 GB request or panic on a capacity
/// overflow).
#[test]
fn the_stiff_length_is_bounded() {
    for length in ["1000001", "18446744073709551615", "0"] {
        let o = covtrace(&["stiff", "--length", length]);
        assert_eq!(o.status.code(), Some(2), "{length}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("--length"), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
}

/// `render-check` on an image smaller than one of its tiles: one line and exit code 2,
/// not a report of zeros; with a single tile, the rank correlations it cannot define read
/// `n/a`.
#[test]
fn render_check_needs_tiles() {
    let o = covtrace(&["render-check", "examples/scenes/cornell.ron", "--size", "1x1"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("must be at least that") && err.trim_end().lines().count() == 1,
        "{err}"
    );
    let o = covtrace(&[
        "render-check",
        "examples/scenes/cornell.ron",
        "--size",
        "16x16",
        "--ref-spp",
        "4",
    ]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        out.contains("rank correlation (Spearman) over tiles with detail: n/a"),
        "{out}"
    );
}

/// No command writes over what it reads: a scene's texture under `render -o`, the scene
/// itself through a file written beside the image, through a hard link or through a later
/// frame's outputs (checked before the first frame), a path file
/// under `plot -o`, a scene under `render-check --json`, and a scene in render-bench's
/// output folder. One line, exit code 2, and the input unchanged.
#[test]
fn outputs_never_overwrite_inputs() {
    let dir = std::env::temp_dir().join(format!("covtrace-hostile-test-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("textures")).expect("dir");
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    for f in ["snooker.ron", "cornell.ron"] {
        std::fs::copy(scenes.join(f), dir.join(f)).expect("copy");
    }
    for e in std::fs::read_dir(scenes.join("textures"))
        .expect("textures")
        .flatten()
    {
        std::fs::copy(e.path(), dir.join("textures").join(e.file_name())).expect("copy");
    }
    let d = |f: &str| dir.join(f).to_str().expect("utf-8").to_string();
    std::fs::copy(dir.join("cornell.ron"), dir.join("scene.cov.json")).expect("copy");
    std::fs::copy(dir.join("cornell.ron"), dir.join("f.0001.cov.json")).expect("copy");
    std::fs::hard_link(dir.join("cornell.ron"), dir.join("linked.exr")).expect("link");
    std::fs::copy(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/paths/brdf.ron"),
        dir.join("demo.png"),
    )
    .expect("copy");
    std::fs::create_dir_all(dir.join("rb")).expect("dir");
    std::fs::copy(dir.join("cornell.ron"), dir.join("rb/results.csv")).expect("copy");
    let texture = std::fs::read_dir(dir.join("textures"))
        .expect("textures")
        .flatten()
        .map(|e| e.path())
        .find(|p| p.extension().is_some_and(|x| x == "png"))
        .expect("a PNG texture");
    let tex_exr = texture.with_extension("exr");
    let inputs = [
        texture,
        dir.join("scene.cov.json"),
        dir.join("cornell.ron"),
        dir.join("demo.png"),
        dir.join("rb/results.csv"),
        dir.join("f.0001.cov.json"),
    ];
    let read = || -> Vec<Vec<u8>> { inputs.iter().map(|p| std::fs::read(p).expect("input")).collect() };
    let before = read();
    let small = ["--size", "32x24", "--spp", "1"];
    let runs: Vec<Vec<String>> = vec![
        vec![
            "render".into(),
            d("snooker.ron"),
            "-o".into(),
            tex_exr.to_str().expect("utf-8").into(),
        ],
        vec!["render".into(), d("scene.cov.json"), "-o".into(), d("scene.exr")],
        vec!["render".into(), d("cornell.ron"), "-o".into(), d("linked.exr")],
        // Frame 1's outputs include the scene: refused before frame 0 is rendered.
        vec![
            "render".into(),
            d("f.0001.cov.json"),
            "--frames".into(),
            "0..1".into(),
            "-o".into(),
            d("f.exr"),
        ],
        vec!["plot".into(), d("demo.png"), "-o".into(), d("demo.png")],
        vec![
            "render-bench".into(),
            d("rb/results.csv"),
            "--size".into(),
            "16x16".into(),
            "--ref-spp".into(),
            "4".into(),
            "--budgets".into(),
            "2".into(),
            "-o".into(),
            d("rb"),
        ],
    ];
    for (k, run) in runs.iter().enumerate() {
        let mut args: Vec<&str> = run.iter().map(String::as_str).collect();
        if k < 4 {
            args.extend(small);
        }
        let o = covtrace(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains("an input of this run, which") && err.trim_end().lines().count() == 1,
            "{args:?}: {err}"
        );
    }
    assert!(before == read(), "an input changed");
    assert!(!dir.join("f.0000.exr").exists(), "frame 0 was rendered");
}

/// A file name with a line break in it is shown escaped: the error stays one line.
#[test]
fn a_line_break_in_a_path_stays_escaped() {
    for args in [
        vec!["eval", "no\nsuch.ron"],
        vec!["render", "examples/scenes/cornell.ron", "-o", "no\nsuch/x.exr"],
    ] {
        let o = covtrace(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("no\\nsuch"), "{err}");
    }
}

/// An output name that is not UTF-8 names every file the render writes, byte for byte:
/// the feature images, the maps and the JSON came out under a name with U+FFFD instead.
#[cfg(unix)]
#[test]
fn an_output_name_that_is_not_utf8_names_every_output() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = common::tmp("hostile-utf8", "");
    std::fs::create_dir_all(&dir).expect("dir");
    let stem = OsStr::from_bytes(b"bad\xffout");
    let mut exr = stem.to_os_string();
    exr.push(".exr");
    let o = Command::new(env!("CARGO_BIN_EXE_covtrace"))
        .current_dir(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
        .args([
            "render",
            "examples/scenes/cornell.ron",
            "--size",
            "32x24",
            "--spp",
            "2",
            "-o",
        ])
        .arg(dir.join(&exr))
        .output()
        .expect("run covtrace");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<Vec<u8>> = std::fs::read_dir(&dir)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().as_bytes().to_vec())
        .collect();
    names.sort();
    let want: Vec<Vec<u8>> = [
        ".aov.exr",
        ".cov.json",
        ".density.png",
        ".exr",
        ".filter.png",
        ".png",
    ]
    .iter()
    .map(|s| [b"bad\xffout".as_slice(), s.as_bytes()].concat())
    .collect();
    assert_eq!(names, want);
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A default `filter` that overflows because the pixel pitch is tiny names the pitch and
/// where it comes from, not the filter alone.
#[test]
fn a_tiny_pixel_pitch_is_named_where_the_filter_overflows() {
    let path = common::tmp("hostile-pitch", "sensor.ron");
    std::fs::write(
        &path,
        "Path(source: Gaussian(x: 0.1, y: 0.1), operators: [Travel(distance: 1.0), Sensor(width: 100, fov_x: 1e-300)])\n",
    )
    .expect("write");
    let o = covtrace(&["eval", path.to_str().expect("utf-8")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains(":1:107: Sensor: parameter `filter` = 0.5")
            && err.contains("pixel pitch of 1e-302 m (from distance, fov_x and width)")
            && err.trim_end().lines().count() == 1,
        "{err}"
    );
}

/// A scene of more mesh triangles than the process may hold (here `ulimit -v`, as a job's
/// limit would be) is refused at the placement that passes it, in one line, instead of
/// aborting when an allocation fails.
#[cfg(target_os = "linux")]
#[test]
fn meshes_past_the_process_memory_are_refused_where_they_pass_it() {
    let dir = common::tmp("hostile-meshes", "");
    let scenes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
    std::fs::copy(scenes.join("torus.obj"), dir.join("torus.obj")).expect("copy");
    // 300 placements of 2,304 triangles: 0.69 GB at 1000 bytes a triangle.
    let shapes: Vec<String> = (0..300)
        .map(|i| {
            format!(
                r#"Mesh(obj: "torus.obj", material: "w", translate: ({}.0, 0.0, {}.0))"#,
                (i % 50) * 2,
                -(i / 50) * 2 - 3
            )
        })
        .collect();
    let scene = format!(
        "Scene(camera: (position: (0.0, 1.0, 3.9), look_at: (0.0, 0.9, 0.0), fov: 40.0, width: 32, height: 24), \
         materials: {{\"w\": Diffuse(albedo: (0.7, 0.7, 0.7))}}, \
         lights: [Rect(corner: (-0.25, 5.0, -0.25), edge_u: (0.5, 0.0, 0.0), edge_v: (0.0, 0.0, 0.5), radiance: (1.0, 1.0, 1.0))], \
         shapes: [\n{}\n])\n",
        shapes.join(",\n")
    );
    std::fs::write(dir.join("meshes.ron"), scene).expect("write");
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v 500000 && exec '{}' render meshes.ron --spp 1 --method uniform -o out.exr",
            env!("CARGO_BIN_EXE_covtrace")
        ))
        .current_dir(&dir)
        .output()
        .expect("run covtrace under ulimit");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.starts_with("covtrace: meshes.ron:")
            && err.contains("triangles, which need about")
            && err.contains("GB are available to this process")
            && err.trim_end().lines().count() == 1,
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A negative number given to an option is that option's bad value, named, in one line:
/// clap took it for an unknown flag and advised `-- -1`, which does not work either.
#[test]
fn a_negative_number_is_the_options_bad_value() {
    for (args, want) in [
        (
            vec!["render", "examples/scenes/cornell.ron", "--spp", "-1"],
            "invalid value '-1' for '--spp <SPP>'",
        ),
        (
            vec!["render", "examples/scenes/cornell.ron", "--time", "-1"],
            "--time must be more than 0",
        ),
        (
            vec!["render-bench", "examples/scenes/cornell.ron", "--repeat", "-1"],
            "invalid value '-1' for '--repeat <REPEAT>'",
        ),
        (
            vec!["stiff", "--length", "-5"],
            "invalid value '-5' for '--length <LENGTH>'",
        ),
    ] {
        let o = covtrace(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(want) && !err.contains("-- -") && err.trim_end().lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

/// A covariance path deeper than the scene's path tracer (`max_depth`, 2 when the scene
/// does not say) is refused in one line by every command that traces one, before any
/// rendering and before render-bench makes its folders.
#[test]
fn a_covariance_depth_past_the_scenes_is_refused() {
    let dir = std::env::temp_dir().join(format!("covtrace-deep-{}", std::process::id()));
    let out = dir.join("out").display().to_string();
    for cmd in ["render", "render-check", "render-bench"] {
        let mut args = vec![cmd, "examples/scenes/cornell.ron", "--cov-depth", "3"];
        if cmd == "render-bench" {
            args.extend(["-o", out.as_str()]);
        }
        let o = covtrace(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(
                "--cov-depth must be 1 to the scene's max_depth, 2 (2 where the scene file gives none"
            ) && err.trim_end().lines().count() == 1,
            "{args:?}: {err}"
        );
    }
    assert!(!dir.exists(), "render-bench made its folders before refusing");
}
