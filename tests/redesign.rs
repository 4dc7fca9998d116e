//! The interfaces of the one-step redesign: operators without a layout parameter, specs
//! declared once, the registry passed to nested lists, typed evaluation results.

use covtrace::path::{Path, PathError};
use covtrace::sensor::PixelDecisions;
use covtrace::{
    AnyCov, Axis, Build, Chain, Checked, Cov, CovError, Form, Operator, OperatorSpec, Registrar, Spectrum,
};

fn parse(text: &str) -> Result<Path, PathError> {
    Path::parse(text, &covtrace::registry())
}

#[test]
fn an_operator_with_all_defaults_is_written_bare_or_with_parentheses() {
    for ops in [
        "[Mirror]",
        "[Mirror()]",
        "[Mirror, Mirror()]",
        "[Mirror /* c */ ()]",
    ] {
        let p = parse(&format!("Path(source: Gaussian(x: 0.1), operators: {ops})"))
            .unwrap_or_else(|e| panic!("{ops}: {e}"));
        assert_eq!(p.operators.names().split('+').next(), Some("Mirror"));
    }
    // A required parameter cannot be left out, and the message says how to write it.
    let err = parse("Path(source: Gaussian(x: 0.1), operators: [Travel])").unwrap_err();
    assert!(
        err.to_string()
            .contains("`Travel` needs parameters: write `Travel(distance: …)`"),
        "{err}"
    );
    // Nested lists follow the same rule.
    parse("Path(source: Gaussian(x: 0.1, t: 0.1), operators: [Moving(velocity: [1.0], operators: [Mirror, Mirror()])])")
        .unwrap();
}

#[derive(Debug)]
struct Blur(f64);

impl Operator for Blur {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        for &u in c.direction_axes() {
            c.convolve(&[u], &[self.0])?;
        }
        Ok(())
    }
}

/// `Blur(s: 1.0)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "a third-party blur")]
struct BlurSpec {
    /// Lobe spectrum.
    #[param(unit = "(cycles/tan)²", default = 4.0, non_negative)]
    s: f64,
}

impl Build for BlurSpec {
    type Op = Blur;
    fn make(p: Checked<Self>) -> Result<Blur, CovError> {
        Ok(Blur(p.s))
    }
}

#[test]
fn nested_lists_read_with_the_registry_they_are_given() {
    let mut registry = covtrace::registry();
    registry.add::<BlurSpec>();
    let text = "Path(source: Gaussian(x: 0.1, t: 0.01), operators: [Moving(velocity: [1.0], operators: [Blur(s: 2.0), Blur])])";
    let e = Path::parse(text, &registry).unwrap().eval().unwrap();
    assert_eq!(e.steps[0].operator, "Moving");
    // The same text with a registry that lacks Blur: an unknown operator, positioned in
    // the nested list.
    let err = Path::parse(text, &covtrace::registry()).unwrap_err();
    assert!(
        err.to_string()
            .starts_with("<string>:1:89: Moving: unknown operator `Blur`"),
        "{err}"
    );
}

#[test]
fn one_operator_value_serves_every_layout_and_form() {
    let blur = Blur(3.0);
    let chain = Chain::new()
        .with(covtrace::travel::Travel::new(1.0).unwrap())
        .with(Blur(3.0));
    let c2 = chain.eval(Cov::<2>::gaussian([0.1, 0.2]).unwrap()).unwrap();
    let c5 = chain
        .eval_in(
            Form::Covariance,
            Cov::<5>::gaussian([0.1, 0.1, 0.2, 0.2, 1.0]).unwrap(),
        )
        .unwrap();
    assert!((c2.get(1, 1) - c5.get(2, 2)).abs() <= 1e-12 * c2.get(1, 1));
    let mut any = AnyCov::from(Cov::<3>::gaussian([0.1, 0.2, 0.3]).unwrap());
    blur.apply(any.as_spectrum_mut()).unwrap();
    assert!(any.get(1, 1) < 1.0 / (4.0 * std::f64::consts::PI.powi(2) * 0.04));
}

#[test]
fn errors_keep_the_file_and_the_typed_cause() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = dir.join("crates/cov-cli/tests/broken/58_overflow_at_eval.ron");
    let p = Path::load(&file, &covtrace::registry()).unwrap();
    assert_eq!(p.file, file.display().to_string());
    match p.eval().unwrap_err() {
        PathError::Eval { file: f, at, source } => {
            assert_eq!(f, file.display().to_string());
            assert_eq!(at, Some((3, 17)));
            assert!(matches!(*source, CovError::Step { index: 0, .. }), "{source:?}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_sensor_reports_typed_decisions_in_the_evaluation() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let e = Path::load(&dir.join("examples/paths/motion_blur.ron"), &covtrace::registry())
        .unwrap()
        .eval()
        .unwrap();
    let d: &PixelDecisions = e.report::<PixelDecisions>().expect("a sensor ends the path");
    assert_eq!(d.sampled_axes, ["x_px", "y_px", "t"]);
    assert!(d.samples_per_pixel.is_finite() && d.samples_per_pixel > 0.0);
    // The report's fields say the same without the type, and survive JSON.
    let r = &e.reports[0];
    assert_eq!(r.step, e.steps.len() - 1);
    assert_eq!(
        r.report.field("samples per pixel"),
        Some(&covtrace::Field::Number(d.samples_per_pixel))
    );
    let back = covtrace::path::Evaluation::from_json(&e.to_json()).unwrap();
    assert_eq!(back, e);
    assert!(
        back.report::<PixelDecisions>().is_none(),
        "the typed value lives in memory only"
    );
    let _ = Axis::X;
}

#[derive(Debug)]
struct Repeat(u32, f64);

impl Operator for Repeat {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        for _ in 0..self.0 {
            c.scale(Axis::X, self.1)?;
        }
        Ok(())
    }
}

/// `Repeat(times: 2, by: 1.5)`: an integer parameter and a float one, both with a default
/// written as a whole number.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "a scaling repeated")]
struct RepeatSpec {
    /// How many times.
    #[param(default = 2, ge = 1, le = 8)]
    times: u32,
    /// The scale each time.
    #[param(default = 1, gt = 0)]
    by: f64,
}

impl Build for RepeatSpec {
    type Op = Repeat;
    fn make(p: Checked<Self>) -> Result<Repeat, CovError> {
        Ok(Repeat(p.times, p.by))
    }
}

#[test]
fn whole_number_parameters_take_plain_defaults_and_say_what_is_wrong() {
    let mut registry = covtrace::registry();
    registry.add::<RepeatSpec>();
    let parse = |ops: &str| {
        Path::parse(
            &format!("Path(source: Gaussian(x: 0.5, u: 0.5),\n operators: [{ops}])"),
            &registry,
        )
    };
    // `default = 2` on a `u32` and `default = 1` on an `f64` are plain literals.
    let e = parse("Repeat").unwrap().eval().unwrap();
    let bare = e.result.get(0, 0);
    let e = parse("Repeat(times: 2, by: 1.0)").unwrap().eval().unwrap();
    assert_eq!(e.result.get(0, 0), bare);
    // A value of the wrong type names its parameter, points at it and gives its domain,
    // at the top level and inside a nested list.
    for (ops, want) in [
        (
            "Repeat(times: -1)",
            ":2:21: Repeat: parameter `times` = -1 is out of range: must be in [1, 8]",
        ),
        (
            "Repeat(times: 9)",
            ":2:21: Repeat: parameter `times` = 9 is out of range: must be in [1, 8]",
        ),
        (
            "Repeat(by: \"two\")",
            ":2:21: Repeat: parameter `by` = \"two\": expected a number, > 0",
        ),
        (
            "Repeat(times: true)",
            ":2:21: Repeat: parameter `times` = true: expected a whole number, in [1, 8]",
        ),
        (
            "Moving(velocity: [0.1], operators: [Repeat(by: \"two\")])",
            ":2:57: Moving: Repeat: parameter `by` = \"two\": expected a number, > 0",
        ),
        (
            "Moving(velocity: [0.1], operators: [Repeat(tims: 2)])",
            ":2:57: Moving: Repeat: unknown parameter `tims`; the parameter is either `times` or `by`",
        ),
    ] {
        let err = parse(ops).unwrap_err().to_string();
        assert!(err.contains(want), "{ops}: {err}");
    }
}

/// A build that leaves out operator features (`default-features = false`) says so when a
/// file names an operator it does not know: the name may be one of those left out, and a
/// near name it does know is no longer the only hint. The registry below is what such a
/// build's `covtrace::registry()` gives: the travel operators alone, the others noted as
/// left out.
#[test]
fn an_unknown_operator_names_the_features_left_out() {
    let mut registry = covtrace::path::Registry::new();
    covtrace::travel::spec::register(&mut registry);
    registry.add::<BlurSpec>();
    for f in ["brdf", "occlusion"] {
        registry.leave_out(f);
    }
    let text = "Path(source: Gaussian(x: 0.1), operators: [Reflect(cos_in: 1.0, cos_out: 1.0)])";
    let err = Path::parse(text, &registry).unwrap_err().to_string();
    assert!(
        err.contains("unknown operator `Reflect` (this build leaves out covtrace's features `brdf`, `occlusion`; an operator of your own needs a binary that registers it"),
        "{err}"
    );
    // A near name is still offered, beside the features left out.
    let err = Path::parse(&text.replace("Reflect", "Bur"), &registry)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("(did you mean `Blur`? this build leaves out covtrace's features `brdf`, `occlusion`)"),
        "{err}"
    );
    // The whole build leaves nothing out.
    assert!(covtrace::registry().left_out().is_empty());
}
