//! Operators that turn the frame by a parameter compute the turn's cosine and sine once,
//! when they are built (`Turn`). Here each is checked against the same operator written
//! with `Spectrum::rotate_frame(angle)`, which does the trigonometry at every call: the
//! same bits in both forms and all layouts, for random angles and the special ones
//! (±0, large, tiny), and the same errors.

use covtrace::curvature::Curvature;
use covtrace::projection::{Project, RotateFrame, Unproject};
use covtrace::{Axis, Cov, CovError, CovFactor, Operator, Spectrum, Turn};
use proptest::prelude::*;

/// A correlated Σ of layout `N` from its stds (every entry of the rotated block nonzero).
fn start<const N: usize>(d: &[f64]) -> Cov<N> {
    let mut diag = [0.0; N];
    for (k, v) in diag.iter_mut().enumerate() {
        *v = d[k];
    }
    let mut c = Cov::from_diagonal(diag).expect("non-negative diagonal");
    let _ = c.shear(Axis::X, Axis::U, 0.3);
    if N >= 4 {
        let _ = c.shear(Axis::Y, Axis::U, -0.7);
        let _ = c.shear(Axis::X, Axis::V, 0.2);
    }
    c
}

/// The operators built with `angle` (and `k`, `c` for curvature and projection), each
/// beside the same operator spelled out with `rotate_frame(angle)`.
type Reference = fn(&mut dyn Spectrum, f64, f64, f64) -> Result<(), CovError>;

fn cases(angle: f64, k: f64, c: f64) -> Vec<(Box<dyn Operator>, Reference)> {
    let mut out: Vec<(Box<dyn Operator>, Reference)> = Vec::new();
    out.push((
        Box::new(RotateFrame::new(angle).expect("finite")),
        |s, a, _, _| s.rotate_frame(a),
    ));
    out.push((
        Box::new(Project::with_angle(c, angle).expect("valid")),
        |s, a, _, c| {
            if a != 0.0 {
                s.rotate_frame(a)?;
            }
            s.scale(Axis::X, c)
        },
    ));
    out.push((
        Box::new(Unproject::with_angle(c, angle).expect("valid")),
        |s, a, _, c| {
            s.scale(Axis::X, 1.0 / c)?;
            if a != 0.0 {
                s.rotate_frame(a)?;
            }
            Ok(())
        },
    ));
    out.push((
        Box::new(Curvature::anisotropic(k, 0.5 * k + 0.1, angle).expect("finite")),
        |s, a, k, _| {
            s.rotate_frame(a)?;
            s.shear(Axis::U, Axis::X, k)?;
            s.shear(Axis::V, Axis::Y, 0.5 * k + 0.1)?;
            s.rotate_frame(-a)
        },
    ));
    out
}

/// Every case on `start`, both ways, compared bit for bit (results and errors).
fn same<S: Spectrum + Copy + PartialEq + std::fmt::Debug>(start: S, angle: f64, k: f64, c: f64) {
    for (op, reference) in cases(angle, k, c) {
        let (mut a, mut b) = (start, start);
        let ra = op.apply(&mut a).map_err(|e| e.to_string());
        let rb = reference(&mut b, angle, k, c).map_err(|e| e.to_string());
        assert_eq!(
            ra.is_ok(),
            rb.is_ok(),
            "{op:?} at angle {angle:e}: {ra:?} against {rb:?}"
        );
        if ra.is_ok() {
            assert_eq!(a, b, "{op:?} at angle {angle:e}");
        }
    }
}

fn both_forms<const N: usize>(d: &[f64], angle: f64, k: f64, c: f64) {
    let s = start::<N>(d);
    same(s, angle, k, c);
    same(CovFactor::from_cov(&s), angle, k, c);
}

fn angles() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-0.0),
        Just(1e-300),
        Just(-1e-300),
        Just(1e6),
        Just(-1e300),
        -7.0f64..7.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn precomputed_turns_match_rotate_frame(
        d in prop::collection::vec(prop_oneof![Just(0.0), 1e-3f64..10.0], 5),
        angle in angles(),
        k in -5.0f64..5.0,
        c in 0.05f64..1.0,
    ) {
        both_forms::<4>(&d, angle, k, c);
        both_forms::<5>(&d, angle, k, c);
    }
}

#[test]
fn turn_is_rotate_frame_and_names_its_parameter() {
    for angle in [0.0f64, -0.0, 0.3, -2.5, 1e-300, 1e12, 1e300, 3.0e-8, 710.5] {
        let t = Turn::new(covtrace::arg!("Op", angle)).expect("finite");
        let (s, c) = angle.sin_cos();
        assert_eq!((t.sin().to_bits(), t.cos().to_bits()), (s.to_bits(), c.to_bits()));
        assert_eq!(t.angle().to_bits(), angle.to_bits());
        // The way back without trigonometry: `sin` odd to the bit.
        let minus = -angle;
        let back = Turn::new(covtrace::arg!("Op", minus)).expect("finite");
        let inv = t.inverse();
        assert_eq!(
            (inv.sin().to_bits(), inv.cos().to_bits()),
            (back.sin().to_bits(), back.cos().to_bits())
        );
    }
    let zero = 0.0;
    assert_eq!(Turn::ZERO, Turn::new(covtrace::arg!("Op", zero)).expect("finite"));
    for azimuth in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let bad = azimuth;
        let e = Turn::new(covtrace::arg!("Scatter", azimuth))
            .expect_err("non-finite")
            .to_string();
        assert!(e.contains("Scatter") && e.contains("azimuth"), "{e}");
        // The operators still name themselves and their own parameter.
        let e = RotateFrame::new(bad).expect_err("non-finite").to_string();
        assert!(e.contains("RotateFrame") && e.contains("angle"), "{e}");
        let e = Curvature::anisotropic(1.0, 2.0, bad)
            .expect_err("non-finite")
            .to_string();
        assert!(e.contains("Curvature") && e.contains("angle"), "{e}");
    }
    // Flatland has no frame to turn: the same error as `rotate_frame`.
    let mut flat = Cov::<2>::from_diagonal([1.0, 2.0]).expect("valid");
    let angle = 0.3;
    let t = Turn::new(covtrace::arg!("Op", angle)).expect("finite");
    assert_eq!(
        flat.rotate_frame_by(t).map_err(|e| e.to_string()),
        flat.rotate_frame(0.3).map_err(|e| e.to_string())
    );
    assert!(flat.rotate_frame_by(t).is_err());
}
