//! Degenerate input gives a documented result, never NaN or a panic.

use cov_core::{Axis, Chain, Cov, CovError, Operator, Spectrum};
use nalgebra::SMatrix;

fn all_kernels<const N: usize>(c: Cov<N>) -> Vec<Result<Cov<N>, CovError>> {
    let mut out = Vec::new();
    let run = |f: &dyn Fn(&mut Cov<N>) -> Result<(), CovError>| {
        let mut x = c;
        f(&mut x).map(|()| x)
    };
    out.push(run(&|x| x.shear(Axis::X, Axis::U, -1.0)));
    out.push(run(&|x| x.shear(Axis::U, Axis::X, 3.0)));
    out.push(run(&|x| x.scale(Axis::X, 0.5)));
    out.push(run(&|x| x.rotate(Axis::X, Axis::U, 0.3)));
    out.push(run(&|x| x.add_variance(Axis::U, 1.0)));
    out.push(run(&|x| x.convolve(&[Axis::U], &[2.0])));
    out.push(run(&|x| x.convolve(&[Axis::U], &[0.0])));
    out.push(run(&|x| x.integrate(&[Axis::U])));
    out.push(run(&|x| {
        x.congruence(SMatrix::<f64, N, N>::identity().as_slice())
    }));
    if N >= 4 {
        out.push(run(&|x| x.rotate_frame(1.0)));
        out.push(run(&|x| x.convolve(&[Axis::U, Axis::V], &[1.0, 0.0, 0.0, 0.0])));
    }
    out
}

fn check_clean<const N: usize>(c: Cov<N>, what: &str) {
    for (k, r) in all_kernels(c).into_iter().enumerate() {
        let r = r.unwrap_or_else(|e| panic!("{what}, kernel {k}: {e}"));
        let v = r.validity();
        assert!(v.is_valid(), "{what}, kernel {k}: {v}");
    }
}

#[test]
fn zero_sigma_stays_zero() {
    fn go<const N: usize>() {
        for r in all_kernels(Cov::<N>::zeros()) {
            let r = r.unwrap();
            // add_variance is the one kernel that adds content.
            let nonzero: usize = r.packed().iter().filter(|v| **v != 0.0).count();
            assert!(nonzero <= 1, "{r:?}");
        }
    }
    go::<2>();
    go::<3>();
    go::<4>();
    go::<5>();
}

#[test]
fn rank_deficient_sigma() {
    // Rank one: content only along (1, 1, 0, 0) in (x, y, u, v).
    let m = SMatrix::<f64, 4, 4>::from_fn(|i, j| if i < 2 && j < 2 { 1.0 } else { 0.0 });
    let c = Cov::<4>::from_matrix(&m).unwrap();
    check_clean(c, "rank one");
    // Rank one with x-u correlation (a point after travel).
    let m = SMatrix::<f64, 2, 2>::new(1.0, -2.0, -2.0, 4.0);
    check_clean(Cov::<2>::from_matrix(&m).unwrap(), "x-u rank one");
}

#[test]
fn diffuse_lobe_removes_all_angular_content() {
    let m = SMatrix::<f64, 2, 2>::new(4.0, 1.0, 1.0, 2.0);
    let mut c = Cov::<2>::from_matrix(&m).unwrap();
    c.convolve(&[Axis::U], &[0.0]).unwrap();
    assert_eq!(c.get(1, 1), 0.0);
    assert_eq!(c.get(0, 1), 0.0);
    // Kept block: Schur complement 4 − 1·1/2.
    assert!((c.get(0, 0) - 3.5).abs() < 1e-15);
    // Identical to integration over u.
    let mut d = Cov::<2>::from_matrix(&m).unwrap();
    d.integrate(&[Axis::U]).unwrap();
    assert_eq!(c, d);
}

#[test]
fn integrate_over_zero_variance_axis_keeps_the_rest() {
    let m = SMatrix::<f64, 3, 3>::new(4.0, 1.0, 0.0, 1.0, 2.0, 0.0, 0.0, 0.0, 0.0);
    let mut c = Cov::<3>::from_matrix(&m).unwrap();
    c.integrate(&[Axis::T]).unwrap();
    assert_eq!(c.to_matrix(), m);
}

#[test]
fn extreme_magnitudes() {
    for s in [1e-300, 1e-150, 1e150, 1e300] {
        let m = SMatrix::<f64, 2, 2>::new(2.0 * s, 0.5 * s, 0.5 * s, 1.0 * s);
        let c = Cov::<2>::from_matrix(&m).unwrap();
        check_clean(c, &format!("scale {s:e}"));
        let m4 = SMatrix::<f64, 4, 4>::from_fn(|i, j| if i == j { s } else { 0.1 * s });
        check_clean(Cov::<4>::from_matrix(&m4).unwrap(), &format!("4D scale {s:e}"));
    }
    // Mixed: 1e300 on x, 1e-300 on u.
    let m = SMatrix::<f64, 2, 2>::new(1e300, 0.0, 0.0, 1e-300);
    check_clean(Cov::<2>::from_matrix(&m).unwrap(), "mixed");
}

#[test]
fn overflow_is_an_error_and_restores_sigma() {
    let m = SMatrix::<f64, 2, 2>::new(1e300, 0.0, 0.0, 1e300);
    let c = Cov::<2>::from_matrix(&m).unwrap();
    let mut x = c;
    let err = x.shear(Axis::U, Axis::X, 1e10).unwrap_err();
    assert!(matches!(err, CovError::Overflow { .. }), "{err}");
    assert_eq!(x, c, "Σ restored");
}

#[test]
fn non_finite_parameters_are_rejected() {
    let mut c = Cov::<2>::gaussian([1.0, 1.0]).unwrap();
    let before = c;
    assert!(matches!(
        c.shear(Axis::X, Axis::U, f64::NAN),
        Err(CovError::NonFinite { .. })
    ));
    assert!(matches!(
        c.scale(Axis::X, f64::INFINITY),
        Err(CovError::NonFinite { .. })
    ));
    assert!(c.rotate(Axis::X, Axis::U, f64::NAN).is_err());
    assert!(c.add_variance(Axis::U, -1.0).is_err());
    assert!(c.convolve(&[Axis::U], &[f64::NAN]).is_err());
    assert!(c.convolve(&[Axis::U], &[-1.0]).is_err());
    assert!(c.convolve(&[Axis::U, Axis::X], &[1.0]).is_err());
    assert!(c.convolve(&[Axis::U, Axis::U], &[1.0, 0.0, 0.0, 1.0]).is_err());
    assert!(c.integrate(&[Axis::T]).is_err());
    assert!(c.shear(Axis::X, Axis::X, 1.0).is_err());
    assert_eq!(c, before);
}

#[derive(Debug)]
struct Boom;
impl Operator for Boom {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        // Writes Σ directly, as an operator outside the kernels would.
        let mut x = c.cov()?;
        x.set(0, 0, f64::NAN);
        c.assign(&x)
    }
}

#[derive(Debug)]
struct Travel(f64);
impl Operator for Travel {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        c.shear(Axis::X, Axis::U, -self.0)
    }
}

#[test]
fn chain_catches_a_misbehaving_operator() {
    let chain = Chain::new().with(Travel(1.0)).with(Boom);
    let start = Cov::<2>::gaussian([1.0, 1.0]).unwrap();
    let err = chain.eval(start).unwrap_err();
    match err {
        CovError::Step { index, operator, .. } => {
            assert_eq!(index, 1);
            assert_eq!(operator, "Boom");
        }
        other => panic!("{other}"),
    }
    let mut c = start;
    assert!(Operator::apply(&chain, &mut c).is_err());
    assert_eq!(c, start, "chain restores Σ on error");
}

/// A denormal `Σ_uu` beside a huge `Σ_xx` (rank 1: `Σ_xu² = Σ_xx Σ_uu`): `Σ_xu / Σ_uu`
/// overflows, and integrating `u` used to leave `Σ_xx` NaN with `Ok`. The update is well
/// posed, `Σ_xx' = Σ_xx s / (s + Σ_uu)` (0 for integration): every path gives it.
#[test]
fn integration_over_a_denormal_axis_beside_a_huge_one() {
    let m = SMatrix::<f64, 2, 2>::new(1e300, 1e-10, 1e-10, 1e-320);
    let c = Cov::<2>::from_matrix(&m).expect("PSD");
    for (what, s) in [
        ("integrate", None),
        ("convolve 1e-320", Some(1e-320)),
        ("convolve 1", Some(1.0)),
    ] {
        let mut x = c;
        match s {
            None => x.integrate(&[Axis::U]),
            Some(s) => x.convolve(&[Axis::U], &[s]),
        }
        .expect("well posed");
        assert!(x.is_finite(), "{what}: {x:?}");
        let s = s.unwrap_or(0.0);
        let want = 1e300 * (s / (s + 1e-320));
        // Σ_uu = 1e-320 is denormal: about 11 bits of precision.
        assert!(
            (x.get(0, 0) - want).abs() <= 1e-3 * want + 1e288,
            "{what}: Σ_xx = {}, want {want}",
            x.get(0, 0)
        );
        check_clean(x, what);
    }
    // A chain's unchecked fast path falls back to the checked kernel: the same.
    let mut chain = Chain::new();
    chain.push(IntegrateU);
    for _ in 0..3 {
        let mut x = c;
        chain.apply(&mut x).expect("well posed");
        assert!(x.is_finite() && x.get(0, 0).abs() <= 1e288, "{x:?}");
    }
}

#[derive(Debug)]
struct IntegrateU;

impl Operator for IntegrateU {
    fn apply(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        s.integrate(&[Axis::U])
    }
}
