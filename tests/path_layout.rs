//! Layout inference and layout errors through the facade's registry.

use covtrace::path::Path;

fn eval(text: &str) -> Result<covtrace::path::Evaluation, covtrace::path::PathError> {
    Path::parse(text, &covtrace::registry())?.eval()
}

#[test]
fn smallest_layout_is_inferred() {
    let e = eval("Path(source: Gaussian(x: 0.1), operators: [Travel(distance: 1.0)])").unwrap();
    assert_eq!((e.layout, e.inferred), (2, true));
    let e = eval("Path(source: Gaussian(x: 0.1, y: 0.1), operators: [Travel(distance: 1.0)])").unwrap();
    assert_eq!(e.layout, 4, "the source names y");
    let e = eval("Path(source: Gaussian(x: 0.1), operators: [Curvature(kx: 1, ky: 2, angle: 0)])").unwrap();
    assert_eq!(e.layout, 4, "anisotropic curvature needs y, v");
    let e = eval("Path(source: Gaussian(x: 0.1, t: 0.01), operators: [Travel(distance: 1.0)])").unwrap();
    assert_eq!(e.layout, 3, "time without y");
    let e =
        eval("Path(source: Gaussian(x: 0.1, v: 0.1, t: 0.01), operators: [Travel(distance: 1.0)])").unwrap();
    assert_eq!(e.layout, 5);
}

#[test]
fn declared_layout_is_kept_and_checked() {
    let e = eval("Path(layout: 5, source: Gaussian(x: 0.1), operators: [Travel(distance: 1.0)])").unwrap();
    assert_eq!((e.layout, e.inferred), (5, false));
    assert_eq!(e.axes, ["x", "y", "u", "v", "t"]);
    let err =
        eval("Path(layout: 2, source: Gaussian(x: 0.1), operators: [RotateFrame(angle: 1.0)])").unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("RotateFrame") && msg.contains("layout 2"), "{msg}");
}

#[test]
fn flatland_and_3d_agree_on_separable_paths() {
    // A static path traced in 2D and in 4D gives the same (x, u) block.
    let ops = "[Travel(distance: 1.0), BlockerEdge(distance: 0.05), Reflect(cos_in: 0.7, cos_out: 0.7, curvature: (k: 1.5), lobe: Phong(exponent: 80)), Travel(distance: 2.0)]";
    let e2 = eval(&format!(
        "Path(layout: 2, source: Gaussian(x: 0.1), operators: {ops})"
    ))
    .unwrap();
    let e4 = eval(&format!(
        "Path(layout: 4, source: Gaussian(x: 0.1, y: 0.1), operators: {ops})"
    ))
    .unwrap();
    let (a, b) = (&e2.result, &e4.result);
    for (i, j, k, l) in [(0, 0, 0, 0), (0, 1, 0, 2), (1, 1, 2, 2)] {
        assert!(
            (a.get(i, j) - b.get(k, l)).abs() <= 1e-12 * a.get(i, j).abs().max(1.0),
            "({i},{j})"
        );
    }
}
