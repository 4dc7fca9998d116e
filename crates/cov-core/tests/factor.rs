//! The square-root form: factorisation round trips, the cases where it must be exact,
//! and error handling (overflow, restore after a failing step). Random chains in both
//! forms against a double-double reference are in the workspace's `tests/forms.rs`.

use cov_core::{Axis, Chain, Cov, CovError, CovFactor, Form, Operator, Spectrum};
use nalgebra::{DMatrix, SMatrix};
use proptest::prelude::*;

/// Σ = D L Lᵀ D with D = diag(scales) and L of the given rank (columns beyond it zero).
fn make_cov<const N: usize>(l: &[f64], scales: &[f64], rank: usize) -> Cov<N> {
    let mut lm = DMatrix::from_row_slice(N, N, &l[..N * N]);
    for c in rank..N {
        lm.set_column(c, &nalgebra::DVector::zeros(N));
    }
    let m = &lm * lm.transpose();
    let s = SMatrix::<f64, N, N>::from_fn(|i, j| 0.5 * (m[(i, j)] + m[(j, i)]) * scales[i] * scales[j]);
    Cov::from_matrix(&s).expect("random PSD matrix is valid")
}

/// Largest entry error after scaling each axis by 1/√Σ_ii of the reference (a correlation
/// error, blind to units); axes with zero variance compare absolutely against the norm.
fn scaled_err<const N: usize>(a: &Cov<N>, r: &Cov<N>) -> f64 {
    let norm = r.max_abs().max(f64::MIN_POSITIVE);
    let mut worst: f64 = 0.0;
    for i in 0..N {
        for j in 0..N {
            let (di, dj) = (r.get(i, i), r.get(j, j));
            let diff = a.get(i, j) - r.get(i, j);
            let e = if di > 0.0 && dj > 0.0 {
                (diff / di.sqrt() / dj.sqrt()).abs()
            } else {
                (diff / norm).abs()
            };
            worst = worst.max(e);
        }
    }
    worst
}

fn assert_sym_psd<const N: usize>(c: &Cov<N>, what: &str) {
    let m = c.to_matrix();
    assert_eq!(m, m.transpose(), "{what}: not exactly symmetric");
    let v = c.validity();
    assert!(v.finite && v.psd, "{what}: {v}");
}

fn check_round_trip<const N: usize>(l: &[f64], scales: &[f64], rank: usize) {
    let c = make_cov::<N>(l, scales, rank);
    let back = CovFactor::from_cov(&c).to_cov().unwrap();
    assert_sym_psd(&back, "round trip");
    let e = scaled_err(&back, &c);
    assert!(e <= 1e-13, "N={N} rank {rank}: {e}\n{c}\n{back}");
}

fn entries(n: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, n)
}

fn scales() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec((-3.0f64..3.0).prop_map(|e| 10f64.powf(e)), 5)
}

/// `add_variance` on a factor (the Givens update when the factor is triangular in some row
/// order, the general fold otherwise: a factor from `from_cov`, then the same after a
/// shear, which breaks the order) agrees with the covariance form.
fn check_add_variance<const N: usize>(l: &[f64], scales: &[f64], rank: usize, axis: Axis, w: f64) {
    let c = make_cov::<N>(l, scales, rank);
    for shear in [false, true] {
        let (mut a, mut f) = (c, CovFactor::from_cov(&c));
        if shear {
            // The covariance form's shear of a rank-deficient Σ cancels (Σ_uu of 4e-5 from
            // terms of 0.7 loses 1e4 ε): start both forms from the factor's Σ, so that
            // what is compared is `add_variance` alone.
            f.shear(Axis::X, Axis::U, 0.7).unwrap();
            a = f.to_cov().unwrap();
        }
        a.add_variance(axis, w).unwrap();
        f.add_variance(axis, w).unwrap();
        let back = f.to_cov().unwrap();
        assert_sym_psd(&back, "add_variance");
        let e = scaled_err(&back, &a);
        assert!(
            e <= 1e-12,
            "N={N} rank {rank} shear {shear} {axis:?} w {w}: {e}\n{a}\n{back}"
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn factor_add_variance_matches_the_covariance_form(
        l in entries(25), sc in scales(), rank in 0usize..6, k in 0usize..4, lw in -3.0f64..3.0,
    ) {
        let w = 10f64.powf(lw);
        let axes = [Axis::X, Axis::U, Axis::Y, Axis::V];
        check_add_variance::<2>(&l, &sc, rank.min(2), axes[k % 2], w);
        check_add_variance::<4>(&l, &sc, rank.min(4), axes[k], w);
        check_add_variance::<5>(&l, &sc, rank, axes[k], w);
    }

    #[test]
    fn factor_round_trip(l in entries(25), sc in scales(), rank in 0usize..6) {
        check_round_trip::<2>(&l, &sc, rank.min(2));
        check_round_trip::<3>(&l, &sc, rank.min(3));
        check_round_trip::<4>(&l, &sc, rank.min(4));
        check_round_trip::<5>(&l, &sc, rank);
    }
}

#[test]
fn extreme_scales_round_trip() {
    for s in [1e-300, 1e-150, 1.0, 1e150, 1e300] {
        let c =
            Cov::<2>::from_matrix(&SMatrix::<f64, 2, 2>::new(2.0 * s, 0.5 * s, 0.5 * s, 1.0 * s)).unwrap();
        let back = CovFactor::from_cov(&c).to_cov().unwrap();
        assert!(scaled_err(&back, &c) <= 1e-15, "{s:e}: {back}");
    }
    // Mixed: 1e-300 on one axis, 1e300 on the other, correlated.
    let c = Cov::<2>::from_matrix(&SMatrix::<f64, 2, 2>::new(1e-300, 0.5, 0.5, 1e300)).unwrap();
    let back = CovFactor::from_cov(&c).to_cov().unwrap();
    assert!(scaled_err(&back, &c) <= 1e-15, "{back}");
}

/// A lobe of spectrum `s` on an angular spectrum far wider than `s` leaves `≈ s`: the lobe
/// is information, not cancellation, and must survive in both forms (a snap of "cancelled"
/// diagonals once zeroed it).
#[test]
fn lobe_limits_a_huge_bandwidth_in_both_forms() {
    for big in [1e10, 1e20, 1e100, 1e300] {
        let c =
            Cov::<2>::from_matrix(&SMatrix::<f64, 2, 2>::new(2.0 * big, 0.3 * big, 0.3 * big, big)).unwrap();
        let s = 0.25;
        let expect_uu = big * s / (s + big);
        let expect_xu = 0.3 * big * s / (s + big);
        for form in [Form::Covariance, Form::SquareRoot] {
            let r = Chain::new().with(Lobe(s)).eval_in(form, c).unwrap();
            let uu = r.get(1, 1);
            assert!(
                (uu / expect_uu - 1.0).abs() < 1e-14,
                "{form:?} {big:e}: Σ_uu {uu}"
            );
            // The cross term is resolved to a correlation of ε (square root) or better.
            let rho = (r.get(0, 1) - expect_xu) / (r.get(0, 0) * uu).sqrt();
            assert!(rho.abs() < 1e-15, "{form:?} {big:e}: ρ error {rho:e}");
        }
    }
}

#[derive(Debug)]
struct Lobe(f64);
impl Operator for Lobe {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        c.convolve(&[Axis::U], &[self.0])
    }
}

#[derive(Debug)]
struct Travel(f64);
impl Operator for Travel {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        c.shear(Axis::X, Axis::U, -self.0)
    }
}

#[derive(Debug)]
struct Diffuse;
impl Operator for Diffuse {
    fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
        c.convolve(&[Axis::U], &[0.0])
    }
}

/// A point source seen through a diffuse bounce is exactly smooth (Σ = 0 after it) in the
/// square-root form too, so a long travel afterwards cannot amplify rounding noise.
#[test]
fn dirac_through_diffuse_is_exactly_zero() {
    let dirac = Cov::<2>::dirac(1.0, 1e-6).unwrap();
    let chain = Chain::new().with(Travel(2.0)).with(Diffuse).with(Travel(1e3));
    for form in [Form::Covariance, Form::SquareRoot] {
        let r = chain.eval_in(form, dirac).unwrap();
        assert_eq!(r, Cov::<2>::zeros(), "{form:?}: {r}");
    }
}

/// The factor carries √Σ, so an intermediate Σ beyond f64 is fine as long as the result
/// fits; a result that does not is a typed error, in either form.
#[test]
fn overflow_is_a_typed_error_and_leaves_the_start() {
    let c = Cov::<2>::from_matrix(&SMatrix::<f64, 2, 2>::new(1e300, 0.0, 0.0, 1e300)).unwrap();
    for form in [Form::Covariance, Form::SquareRoot] {
        let err = Chain::new().with(Travel(1e10)).eval_in(form, c).unwrap_err();
        assert!(
            err.to_string().contains("overflow") || err.to_string().contains("finite"),
            "{form:?}: {err}"
        );
    }
    // A failing step restores the factor exactly (snapshot, not a refactorisation).
    let mut f = CovFactor::from_cov(&Cov::<2>::gaussian([0.1, 0.2]).unwrap());
    f.shear(Axis::X, Axis::U, 0.7).unwrap();
    let before = f;
    let chain = Chain::new().with(Travel(1.0)).with(Travel(f64::MAX));
    let s: &mut dyn Spectrum = &mut f;
    assert!(Operator::apply(&chain, s).is_err());
    assert_eq!(f, before);
}

/// Square-root form against nalgebra: `L Lᵀ` of the factor is the dense product.
#[test]
fn factor_product_matches_nalgebra() {
    let f = CovFactor::<3>::from_rows([[1.0, 2.0, 0.0], [-0.5, 0.25, 3.0], [0.0, 1e-3, -2.0]]).unwrap();
    let l = DMatrix::from_fn(3, 3, |i, j| f.rows()[i][j]);
    let dense = &l * l.transpose();
    let c = f.to_cov().unwrap();
    for i in 0..3 {
        for j in 0..3 {
            assert!((c.get(i, j) - dense[(i, j)]).abs() <= 1e-15 * dense.norm());
        }
    }
    assert!(CovFactor::<2>::from_rows([[f64::NAN, 0.0], [0.0, 1.0]]).is_err());
}

#[test]
fn row_snap_is_the_square_root_of_the_schur_snap() {
    assert_eq!(cov_core::ROW_SNAP * cov_core::ROW_SNAP, cov_core::SCHUR_SNAP);
}
