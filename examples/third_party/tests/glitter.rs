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
    assert!(err.to_string().starts_with("<string>:1:"), "{err}");
    assert!(err.to_string().contains("flake"), "{err}");
}
