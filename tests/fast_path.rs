//! A chain's unchecked fast path (`Chain::apply` on a `Cov<N>` or `CovFactor<N>`: the
//! operators on the forms' unchecked kernels, one finiteness check at the end) against
//! the checked path (`Chain::trace_in`, every step checked), on random chains of every
//! kernel in both forms and all four layouts: the same bits, the same errors (step,
//! operator, value), and an unchanged Σ on overflow; operators that read Σ and nested
//! chains included.

use covtrace::brdf::Lobe;
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{AnyCov, Chain, Cov, CovError, CovFactor, Form, Operator, Spectrum};
use proptest::prelude::*;

/// One kernel call as an operator, on the axis indices of the layout.
#[derive(Clone, Copy, Debug)]
struct K(u8, f64, f64);

impl Operator for K {
    fn apply(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        let ax = s.axes();
        let n = ax.len();
        let a = (self.0 as usize / 8) % n;
        let b = (a + 1) % n;
        let (p, q) = (self.1, self.2);
        match self.0 % 8 {
            0 => s.shear(ax[a], ax[b], p),
            1 => s.scale(ax[a], 0.1 + q),
            2 => s.rotate(ax[a], ax[b], p),
            3 => s.add_variance(ax[a], q),
            4 => s.convolve(&[ax[a]], &[q]),
            5 => s.convolve(&[ax[a], ax[b]], &[q, 0.3 * q, 0.3 * q, 2.0 * q]),
            6 => s.add_window(&[ax[a], ax[b]], &[q, 0.5 * q, 0.5 * q, q]),
            _ => s.integrate(&[ax[a]]),
        }
    }
}

/// An operator that reads Σ: it scales x by 1/(1 + Σ_xx).
#[derive(Debug)]
struct Reads;

impl Operator for Reads {
    fn apply(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        let c = s.cov()?;
        s.scale(covtrace::Axis::X, 1.0 / (1.0 + c.get(0, 0)))
    }
}

fn start<const N: usize>(seed: &[f64]) -> Cov<N> {
    let m = nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| seed[(i * 5 + j) % seed.len()]);
    Cov::from_matrix(&(m * m.transpose() + nalgebra::SMatrix::<f64, N, N>::identity() * 1e-3)).expect("PSD")
}

fn checked<const N: usize>(chain: &Chain, form: Form, c: Cov<N>) -> Result<Cov<N>, CovError> {
    // `trace_in` runs every step checked, never the fast path.
    chain
        .trace_in(form, c)
        .map(|t| t.last().to::<N>().expect("layout"))
}

fn same_in_both_paths<const N: usize>(chain: &Chain, seed: &[f64]) {
    let c0 = start::<N>(seed);
    for form in [Form::Covariance, Form::SquareRoot] {
        let want = checked(chain, form, c0);
        for _ in 0..2 {
            let got = chain.eval_in(form, c0);
            match (&want, &got) {
                (Ok(a), Ok(b)) => assert_eq!(a, b, "N={N} {form:?}"),
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                _ => panic!("N={N} {form:?}: checked {want:?}, fast {got:?}"),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_fast_path_agrees_with_the_checked_path(
        seed in prop::collection::vec(-1.0f64..1.0, 25),
        ops in prop::collection::vec((0u8..80, -3.0f64..3.0, 0.0f64..5.0), 1..20),
        reads in 0usize..30,
        nested in 0usize..30,
    ) {
        let mut chain = Chain::new();
        for (i, &(k, p, q)) in ops.iter().enumerate() {
            if i == reads {
                chain.push(Reads);
            }
            if i == nested {
                chain.push(Chain::new().with(K(k ^ 1, q, p.abs())).with(K(k, p, q)));
            } else {
                chain.push(K(k, p, q));
            }
        }
        same_in_both_paths::<2>(&chain, &seed);
        same_in_both_paths::<3>(&chain, &seed);
        same_in_both_paths::<4>(&chain, &seed);
        same_in_both_paths::<5>(&chain, &seed);
    }
}

#[test]
fn overflow_is_reported_by_step_and_leaves_sigma() {
    let chain = Chain::new()
        .with(K(1, 0.0, 1e150))
        .with(Travel::new(1.0).unwrap())
        .with(K(1, 0.0, 1e200));
    let c0 = Cov::<4>::gaussian([0.1, 0.1, 1.0, 1.0]).unwrap();
    for form in [Form::Covariance, Form::SquareRoot] {
        let want = checked(&chain, form, c0).unwrap_err().to_string();
        for _ in 0..3 {
            let got = chain.eval_in(form, c0).unwrap_err().to_string();
            assert_eq!(got, want);
            assert!(got.starts_with("step 2 (K)"), "{got}");
        }
    }
    // Through `apply` on a concrete Σ: unchanged on error, in either form.
    let mut c = c0;
    for _ in 0..3 {
        assert!(chain.apply(&mut c).is_err());
        assert_eq!(c, c0);
    }
    let f0 = CovFactor::from_cov(&c0);
    let mut f = f0;
    for _ in 0..3 {
        assert!(chain.apply(&mut f).is_err());
        assert_eq!(f, f0);
    }
}

#[test]
fn a_missing_axis_is_reported_by_the_fast_path() {
    let chain = Chain::new()
        .with(Travel::new(1.0).unwrap())
        .with(RotateFrame::new(0.3).unwrap());
    let c0 = Cov::<2>::gaussian([0.1, 1.0]).unwrap();
    let want = checked(&chain, Form::Covariance, c0).unwrap_err().to_string();
    for _ in 0..3 {
        assert_eq!(chain.eval_in(Form::Covariance, c0).unwrap_err().to_string(), want);
    }
    assert!(want.contains("RotateFrame"), "{want}");
}

fn bounce(k: f64, cos_in: f64, cos_out: f64, turn: f64) -> Chain {
    let lobe = Lobe::Phong { exponent: 50.0 };
    Chain::new()
        .with(Travel::new(1.5).unwrap())
        .with(Project::with_angle(cos_in, 0.4).unwrap())
        .with(Mirror)
        .with(Curvature::isotropic(k).unwrap())
        .with(Mirror)
        .with(covtrace::brdf::Brdf::new(lobe).unwrap())
        .with(Curvature::isotropic(-k).unwrap())
        .with(Unproject::with_angle(cos_out, -0.2).unwrap())
        .with(RotateFrame::new(turn).unwrap())
        .with(Travel::new(2.5).unwrap())
        .with(Window::isotropic(0.05).unwrap())
}

#[test]
fn bounce_chain_is_the_same_in_both_paths() {
    let chain = bounce(3.0, 0.5, 0.8, 0.7);
    let seed: Vec<f64> = (0..25).map(|i| ((i * 37 % 11) as f64 - 5.0) / 5.0).collect();
    same_in_both_paths::<4>(&chain, &seed);
    same_in_both_paths::<5>(&chain, &seed);
    // The run-time layout entry point takes the same path.
    let c0 = AnyCov::from(start::<5>(&seed));
    let a = chain.eval_any(Form::Covariance, &c0).unwrap();
    let b = chain.eval_any(Form::Covariance, &c0).unwrap();
    assert_eq!(a, b);
}

#[test]
fn an_overflow_is_not_hidden_by_a_later_lobe() {
    // Σ_xx overflows (x scaled by ~1e200), then a lobe on another axis: the row of x
    // cancels "to nothing" relative to ∞ and its snap would zero it, leaving a finite Σ.
    // The fast path checks only at the end, so the snap must keep the ∞ visible: it
    // reports the checked path's error (this fails if the snap writes 0 instead of
    // `v − v`).
    let chain = Chain::new().with(K(1, 0.0, 1e200)).with(K(12, 0.0, 5.0));
    // Σ_xu = 0 keeps the lobe's own update of row x finite (∞ − 0·0), so only the snap
    // decides whether the ∞ survives.
    let c0 = Cov::<2>::from_diagonal([1.0, 1.0]).unwrap();
    let want = checked(&chain, Form::Covariance, c0).unwrap_err().to_string();
    assert!(want.starts_with("step 0 (K)"), "{want}");
    assert_eq!(chain.eval_in(Form::Covariance, c0).unwrap_err().to_string(), want);
    // In square-root form the factor stays finite (its rows reach 1e200) and Σ overflows
    // when it is formed at the end, which is reported without a step.
    let got = chain.eval_in(Form::SquareRoot, c0).unwrap_err().to_string();
    assert!(got.contains("result is not finite"), "{got}");
    let mut c = c0;
    assert!(chain.apply(&mut c).is_err());
    assert_eq!(c, c0, "a failed chain leaves Σ as it was");
}
