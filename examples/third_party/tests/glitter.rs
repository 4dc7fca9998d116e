//! The third-party operator works from RON without changes to covtrace's crates, and its
//! errors carry positions like the built-in ones.

#[test]
fn glitter_path_evaluates() {
    let mut registry = covtrace::registry();
    covtrace_sparkle::register(&mut registry);
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glitter.ron");
    let e = covtrace::path::Path::load(&file, &registry)
        .and_then(|p| p.eval())
        .expect("evaluates");
    assert_eq!(e.layout, 4);
    assert_eq!(e.steps[2].operator, "Sparkle");
    // The flakes add spatial frequency: 1/(4π² · 0.0005²) ≈ 1.0e5 (cycles/m)².
    assert!(e.steps[2].matrix.get(0, 0) > 1.0e5);
}

#[test]
fn unregistered_sparkle_is_an_unknown_operator() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glitter.ron");
    let err = covtrace::path::Path::load(&file, &covtrace::registry()).expect_err("not registered");
    assert!(
        err.to_string().contains(":8:9: unknown operator `Sparkle`"),
        "{err}"
    );
}

#[test]
fn bad_sparkle_parameter_is_positioned() {
    let mut registry = covtrace::registry();
    covtrace_sparkle::register(&mut registry);
    let err = covtrace::path::Path::parse(
        "Path(source: Gaussian(x: 0.1), operators: [Sparkle(flake: 0.0, spread: 1.0)])",
        &registry,
    )
    .expect_err("flake must be > 0");
    // At the parameter as written, with the domain declared on the field.
    assert_eq!(
        err.to_string(),
        "<string>:1:52: Sparkle: parameter `flake` = 0 is out of range: must be > 0"
    );
    // Rust callers get the same check.
    let err = covtrace_sparkle::Sparkle::new(0.0, 1.0).expect_err("flake must be > 0");
    assert_eq!(err.to_string(), "Sparkle: parameter `flake` = 0 is out of range: must be > 0");
    assert!(covtrace_sparkle::Sparkle::new(1e-3, f64::NAN).is_err());
    // A spread inside its domain whose lobe overflows is named as written, not as the
    // kernel's argument.
    let err = covtrace::path::Path::parse(
        "Path(source: Gaussian(x: 0.1), operators: [Sparkle(flake: 0.001, spread: 1e-320)])",
        &registry,
    )
    .expect_err("the lobe overflows");
    assert!(
        err.to_string()
            .contains("Sparkle: parameter `spread` = 1e-320 is out of range: too small"),
        "{err}"
    );
}

/// The operator in every layout (2 to 5) and both forms of Σ, against its closed form:
/// the flakes add `1/(4π² flake²)` to every spatial variance.
#[test]
fn sparkle_in_every_layout_and_form() {
    let mut registry = covtrace::registry();
    covtrace_sparkle::register(&mut registry);
    let want = 1.0 / (covtrace::FOUR_PI_SQ * 0.002 * 0.002);
    for layout in 2..=5usize {
        let text = format!(
            "Path(layout: {layout}, source: Gaussian(x: 1.0), operators: [Sparkle(flake: 0.002, spread: 0.01)])"
        );
        let path = covtrace::path::Path::parse(&text, &registry).expect("parses");
        for form in [covtrace::Form::SquareRoot, covtrace::Form::Covariance] {
            let e = path.eval_in(form).expect("evaluates");
            assert_eq!(e.layout, layout);
            let before = e.start.get(0, 0);
            let after = e.steps[0].matrix.get(0, 0);
            assert!(
                ((after - before) - want).abs() <= 1e-9 * want,
                "layout {layout} {form:?}: {after} - {before} vs {want}"
            );
        }
    }
}

/// The package's binary is covtrace's command line with `Sparkle` registered.
#[test]
fn the_binary_runs_eval_list_and_plot_with_sparkle() {
    let run = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_covtrace-sparkle"))
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .args(args)
            .output()
            .expect("runs")
    };
    let out = run(&["eval", "glitter.ron"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(String::from_utf8_lossy(&out.stdout).contains("Sparkle"));
    let out = run(&["list"]);
    let list = String::from_utf8_lossy(&out.stdout);
    assert!(list.contains("Sparkle: glitter") && list.contains("Travel"), "{list}");
    let png = std::env::temp_dir().join(format!("sparkle-{}.png", std::process::id()));
    let out = run(&["plot", "glitter.ron", "-o", png.to_str().expect("utf-8")]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(std::fs::metadata(&png).map(|m| m.len() > 0).unwrap_or(false));
    let _ = std::fs::remove_file(png);
    let out = run(&["eval", "missing.ron"]);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stderr).trim_end().lines().count(), 1);
}
