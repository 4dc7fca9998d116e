//! The two forms of Σ (covariance and square root) on random chains of every kernel,
//! against the double-double reference of `cov-stiff`; and every bundled path evaluated in
//! both forms.
//!
//! Property: after every step Σ is exactly symmetric and PSD to the chain's rounding; the
//! final Σ of the square-root form is within the error that a step-by-step backward-stable evaluation
//! can have on that chain (`Σ_k κ_k · 1024 ε`, with `κ_k` the reference's own amplification
//! of a change after step k), measured with the stiff suite's error measure. Random
//! chains include rank-deficient starts, integrations and diffuse lobes, where the exact
//! answer can be arbitrarily sensitive: the bound says how sensitive.

use cov_stiff::reference::Dense;
use cov_stiff::rel_error;
use covtrace::path::Path;
use covtrace::{Chain, Cov, CovError, CovFactor, Form, Operator, Spectrum};
use nalgebra::{DMatrix, SMatrix};
use proptest::prelude::*;
use twofloat::TwoFloat;

#[derive(Clone, Copy, Debug)]
enum Op {
    Shear(usize, usize, f64),
    Scale(usize, f64),
    Rotate(usize, usize, f64),
    Window(usize, f64),
    Lobe(usize, f64),
    Lobe2(usize, usize, f64),
    Integrate(usize),
}

fn op_of(n: usize, kind: u8, p: f64, q: f64) -> Op {
    let a = (kind as usize / 7) % n;
    let b = (a + 1) % n;
    match kind % 7 {
        0 => Op::Shear(a, b, p),
        1 => Op::Scale(a, 0.1 + q),
        2 => Op::Rotate(a, b, p),
        3 => Op::Window(a, q),
        4 => Op::Lobe(a, q),
        5 => Op::Lobe2(a, b, 0.01 + q),
        _ => Op::Integrate(a),
    }
}

fn apply(s: &mut dyn Spectrum, op: Op) -> Result<(), CovError> {
    let ax = s.axes();
    match op {
        Op::Shear(a, b, v) => s.shear(ax[a], ax[b], v),
        Op::Scale(a, c) => s.scale(ax[a], c),
        Op::Rotate(a, b, t) => s.rotate(ax[a], ax[b], t),
        Op::Window(a, w) => s.add_variance(ax[a], w),
        Op::Lobe(a, v) => s.convolve(&[ax[a]], &[v]),
        Op::Lobe2(a, b, q) => s.convolve(&[ax[a], ax[b]], &[q, 0.3 * q, 0.3 * q, 2.0 * q]),
        Op::Integrate(a) => s.integrate(&[ax[a]]),
    }
}

/// One op as an operator, for the chain's fast path.
#[derive(Debug)]
struct Step(Op);

impl Operator for Step {
    fn apply(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        apply(s, self.0)
    }
}

/// The chain's result in `form` through its unchecked fast path (`Chain::eval_in`),
/// checked against `check`.
fn through_chain<const N: usize>(ops: &[Op], c0: Cov<N>, form: Form, check: impl Fn(&Cov<N>, &str)) {
    let mut chain = Chain::new();
    for &op in ops {
        chain.push(Step(op));
    }
    check(&chain.eval_in(form, c0).unwrap(), "chain");
}

fn reference(d: &mut Dense<TwoFloat>, op: Op) {
    let n = d.n;
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        a[i * n + i] = 1.0;
    }
    match op {
        Op::Shear(i, j, v) => {
            a[i * n + j] = v;
            d.congruence(&a);
        }
        Op::Scale(i, c) => {
            a[i * n + i] = c;
            d.congruence(&a);
        }
        Op::Rotate(i, j, t) => {
            let (s, c) = t.sin_cos();
            a[i * n + i] = c;
            a[i * n + j] = -s;
            a[j * n + i] = s;
            a[j * n + j] = c;
            d.congruence(&a);
        }
        Op::Window(i, w) => d.window(i, w),
        Op::Lobe(i, v) => d.lobe(i, v),
        Op::Lobe2(i, j, q) => d.lobe2(i, j, [q, 0.3 * q, 0.3 * q, 2.0 * q]),
        Op::Integrate(i) => d.lobe(i, 0.0),
    }
}

fn make_cov<const N: usize>(l: &[f64], scales: &[f64], rank: usize) -> Cov<N> {
    let mut lm = DMatrix::from_row_slice(N, N, &l[..N * N]);
    for c in rank.min(N)..N {
        lm.set_column(c, &nalgebra::DVector::zeros(N));
    }
    let m = &lm * lm.transpose();
    let s = SMatrix::<f64, N, N>::from_fn(|i, j| 0.5 * (m[(i, j)] + m[(j, i)]) * scales[i] * scales[j]);
    Cov::from_matrix(&s).expect("random PSD matrix is valid")
}

fn dense<const N: usize>(c: &Cov<N>) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, j| c.get(i, j))
}

/// Relative perturbation used to measure how the chain amplifies a change of Σ.
const PERTURB: f64 = 1e-13;

/// The covariance form is held to this multiple of the bound: it is not backward stable
/// step by step where a Schur complement cancels (its rounding is ε × the state before,
/// not after), which is why the square-root form is the default. Measured worst on the
/// calibration set below: see its output.
const COV_SLACK: f64 = 1000.0;

/// Chains whose bound exceeds this are ill-posed: only symmetry, PSD and finiteness are
/// asserted on them.
const WELL_POSED: f64 = 1e-4;

/// Local rounding allowance per step, in units of ε: a kernel of size ≤ 5 is backward
/// stable with a constant well below this.
const LOCAL: f64 = 1024.0;

/// The chain's own conditioning: for each step k, how much a relative change of `PERTURB`
/// in the exact Σ after step k changes the exact final Σ (relative, the stiff measure).
/// `Σ_k κ_k · LOCAL · ε` bounds the final error of any evaluation that is backward stable
/// step by step, whichever form it holds Σ in.
/// `states` are the reference's Σ before the first step and after each of `ops`.
fn conditioning(states: &[Dense<TwoFloat>], ops: &[Op]) -> f64 {
    let n = states[0].n;
    let exact = DMatrix::from_row_slice(n, n, &states[ops.len()].to_f64());
    let peak = peaks(states);
    let mut total = 0.0;
    for (k, state) in states.iter().enumerate() {
        let rows = state.to_f64();
        // Two relative patterns (alternating signs, graded) and one additive: PERTURB × the
        // axis' peak on each diagonal, which is what rounding leaves on an axis whose
        // content cancelled (an exactly empty axis is the most sensitive place of all).
        let mut kappa: f64 = 0.0;
        for pattern in 0..3 {
            let bumped: Vec<f64> = rows
                .iter()
                .enumerate()
                .map(|(e, v)| {
                    let (i, j) = (e / n, e % n);
                    match pattern {
                        0 => v * (1.0 + PERTURB * if (i + j) % 2 == 0 { 1.0 } else { -0.7 }),
                        1 => v * (1.0 + PERTURB * (0.5 - ((i * j) % 3) as f64 * 0.6)),
                        _ => v + if i == j { PERTURB * peak[i] } else { 0.0 },
                    }
                })
                .collect();
            let mut d = Dense::<TwoFloat>::from_f64(n, &bumped);
            for &op in &ops[k..] {
                reference(&mut d, op);
            }
            let moved = DMatrix::from_row_slice(n, n, &d.to_f64());
            let e = rel_error(&moved, &exact, &peak) / PERTURB;
            kappa = if e.is_finite() {
                kappa.max(e)
            } else {
                f64::INFINITY
            };
        }
        total += kappa;
    }
    total
}

fn peaks(states: &[Dense<TwoFloat>]) -> Vec<f64> {
    let n = states[0].n;
    (0..n)
        .map(|i| states.iter().fold(0.0f64, |m, s| m.max(f64::from(s.at(i, i)))))
        .collect()
}

/// Final errors of (square root, covariance) against the reference and the chain's bound;
/// asserts exact symmetry and PSD (to the chain's rounding) after every step, and both
/// final errors within the bound.
fn run_chain<const N: usize>(
    l: &[f64],
    scales: &[f64],
    rank: usize,
    raw: &[(u8, f64, f64)],
) -> (f64, f64, f64) {
    let ops: Vec<Op> = raw.iter().map(|&(k, p, q)| op_of(N, k, p, q)).collect();
    let c0 = make_cov::<N>(l, scales, rank);
    let mut cov = c0;
    let mut fac = CovFactor::from_cov(&c0);
    let start = Dense::<TwoFloat>::from_f64(N, dense(&c0).transpose().as_slice());
    let mut r = start.clone();
    let mut states = vec![start.clone()];
    for &op in &ops {
        apply(&mut cov, op).unwrap();
        apply(&mut fac, op).unwrap();
        reference(&mut r, op);
        states.push(r.clone());
        let top = peaks(&states).iter().fold(0.0f64, |a, v| a.max(*v));
        let fc = fac.to_cov().unwrap();
        for c in [&fc, &cov] {
            let m = dense(c);
            assert_eq!(m, m.transpose(), "not exactly symmetric");
        }
        // The square-root form is PSD by construction, to the rounding of L Lᵀ, which is
        // ε × the largest Σ met along the chain.
        let min = dense(&fc).symmetric_eigen().eigenvalues.min();
        assert!(
            min >= -1e-12 * top,
            "square root after {op:?}: λmin {min:e}, peak {top:e}"
        );
    }
    let peak = peaks(&states);
    let top = peak.iter().fold(0.0f64, |a, v| a.max(*v));
    let exact = DMatrix::from_row_slice(N, N, &r.to_f64());
    let ef = rel_error(&dense(&fac.to_cov().unwrap()), &exact, &peak);
    let ec = rel_error(&dense(&cov), &exact, &peak);
    let bound = (conditioning(&states, &ops) * LOCAL * f64::EPSILON).max(1e-13);
    // The covariance form is PSD to its own error: an error of `bound` (relative to the
    // chain's peak) can move an eigenvalue by that much.
    let min = dense(&cov).symmetric_eigen().eigenvalues.min();
    assert!(
        min >= -bound.max(1e-12) * top,
        "covariance: λmin {min:e}, peak {top:e}, bound {bound:e}"
    );
    // Well-posed chains only: beyond 1e-4 the exact answer itself is not worth a digit.
    if bound <= WELL_POSED {
        assert!(
            ef <= bound,
            "N={N} square root: {ef:e} > bound {bound:e}, ops {ops:?}"
        );
        assert!(
            ec <= COV_SLACK * bound,
            "N={N} covariance: {ec:e} > {COV_SLACK} × bound {bound:e}, ops {ops:?}"
        );
        // The chain's unchecked fast path is held to its form's bound.
        for (form, slack) in [(Form::SquareRoot, 1.0), (Form::Covariance, COV_SLACK)] {
            through_chain(&ops, c0, form, |c, how| {
                let e = rel_error(&dense(c), &exact, &peak);
                assert!(
                    e <= slack * bound,
                    "N={N} {how} {form:?}: {e:e} > {slack} × bound {bound:e}, ops {ops:?}"
                );
            });
        }
    }
    (ef, ec, bound)
}

fn entries() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, 25)
}

fn scales() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec((-3.0f64..3.0).prop_map(|e| 10f64.powf(e)), 5)
}

fn ops() -> impl Strategy<Value = Vec<(u8, f64, f64)>> {
    prop::collection::vec((0u8..70, -3.0f64..3.0, 0.0f64..5.0), 1..25)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn random_chains_match_the_reference_in_both_forms(l in entries(), sc in scales(), rank in 0usize..6, o in ops()) {
        run_chain::<2>(&l, &sc, rank, &o);
        run_chain::<3>(&l, &sc, rank, &o);
        run_chain::<4>(&l, &sc, rank, &o);
        run_chain::<5>(&l, &sc, rank, &o);
    }
}

/// Every bundled path gives the same Σ in both forms.
#[test]
fn bundled_paths_agree_in_both_forms() {
    let registry = covtrace::registry();
    let mut n = 0;
    for entry in std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/paths")).unwrap() {
        let file = entry.unwrap().path();
        if file.extension().and_then(|e| e.to_str()) != Some("ron") {
            continue;
        }
        let p = Path::load(&file, &registry).unwrap();
        let a = p.eval_in(Form::SquareRoot).unwrap();
        let b = p.eval_in(Form::Covariance).unwrap();
        assert_eq!(a.steps.len(), b.steps.len());
        for (sa, sb) in a.steps.iter().zip(&b.steps) {
            let k = sa.matrix.dim();
            let ma = DMatrix::from_fn(k, k, |i, j| sa.matrix.get(i, j));
            let mb = DMatrix::from_fn(k, k, |i, j| sb.matrix.get(i, j));
            let peak: Vec<f64> = (0..k).map(|i| ma[(i, i)].max(mb[(i, i)])).collect();
            let e = rel_error(&ma, &mb, &peak);
            assert!(e <= 1e-10, "{}: {} differs by {e:e}", file.display(), sa.operator);
        }
        n += 1;
    }
    assert!(n >= 17, "{n} paths");
}

/// Calibration, printed with `--nocapture`: over a fixed set of random chains, how far
/// each form is from the reference in units of the chain's bound.
#[test]
fn forms_against_the_bound_on_random_chains() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strat = (entries(), scales(), 0usize..6, ops());
    let (mut ws, mut wc, mut sum_s, mut sum_c, mut count) = (0.0f64, 0.0f64, 0.0, 0.0, 0.0);
    let mut ill = 0;
    for _ in 0..200 {
        let (l, sc, rank, o) = strat.new_tree(&mut runner).unwrap().current();
        for (s, c, b) in [
            run_chain::<2>(&l, &sc, rank, &o),
            run_chain::<3>(&l, &sc, rank, &o),
            run_chain::<4>(&l, &sc, rank, &o),
            run_chain::<5>(&l, &sc, rank, &o),
        ] {
            if b > WELL_POSED {
                ill += 1;
                continue;
            }
            ws = ws.max(s / b);
            wc = wc.max(c / b);
            sum_s += (s / b).max(1e-6).log10();
            sum_c += (c / b).max(1e-6).log10();
            count += 1.0;
        }
    }
    println!(
        "800 random chains ({ill} ill-posed, skipped), error / bound: square root worst {ws:.2e} (geometric mean {:.2e}), covariance worst {wc:.2e} (geometric mean {:.2e})",
        10f64.powf(sum_s / count),
        10f64.powf(sum_c / count)
    );
    assert!(ws <= 1.0 && wc <= COV_SLACK);
}

/// Regression: integrating an axis whose factor row holds only accumulated rounding (67 ε
/// of its former norm, left by integrating a proportional axis) must not project other
/// rows onto that noise. The square-root form once lost 99.9995% of Σ_xx here.
#[test]
fn integration_along_rounding_noise_removes_nothing() {
    let l = [
        0.022497088417035366,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.9245497914825194,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        -0.28247319426258394,
        0.0,
        0.0,
        0.0,
        0.0,
        0.865361433599254,
        0.0,
        0.0,
        0.0,
        0.0,
    ];
    let sc = [
        0.09251546204630104,
        0.0017263194144690737,
        1.0,
        148.09610848660245,
        5.1663961516243155,
    ];
    let raw: [(u8, f64, f64); 5] = [
        (38, 0.0, 0.7959599431167542),
        (25, 0.0, 0.489398873210664),
        (13, 0.0, 0.0),
        (59, 0.0, 2.484470584570756),
        (34, 0.0, 0.0),
    ];
    let c0 = make_cov::<5>(&l, &sc, 1);
    let mut cov = c0;
    let mut fac = CovFactor::from_cov(&c0);
    let mut r = Dense::<TwoFloat>::from_f64(5, dense(&c0).transpose().as_slice());
    for (k, p, q) in raw {
        let op = op_of(5, k, p, q);
        apply(&mut cov, op).unwrap();
        apply(&mut fac, op).unwrap();
        reference(&mut r, op);
    }
    let exact = DMatrix::from_row_slice(5, 5, &r.to_f64());
    let peak = vec![1.0; 5];
    for (what, c) in [("square root", fac.to_cov().unwrap()), ("covariance", cov)] {
        let e = rel_error(&dense(&c), &exact, &peak);
        assert!(e <= 1e-10, "{what}: {e:e}\n{c}");
    }
}
