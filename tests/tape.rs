//! The compiled fast path ([`Tape`], used by `Chain` from its second evaluation on) against
//! the checked path, on random chains of every kernel in both forms and all four layouts:
//! a tape run kernel by kernel gives the same bits, and so does a chain's compiled
//! program in covariance form (kernels paired into one call do the same operations); in
//! square-root form the program folds a run of variances at once, which agrees to
//! rounding (its accuracy against double-double is `tests/forms.rs`'s and the stiff
//! suite's); the same errors (step, operator, value) and an unchanged Σ on overflow;
//! opaque operators and nested chains; and the batch evaluation against the compiled
//! scalar one, bit for bit.

use std::sync::Arc;

use covtrace::brdf::{Lobe, Reflect};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{AnyCov, Chain, Cov, CovError, CovFactor, CovLanes, Form, Kernel, Operator, Spectrum, Tape};
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

/// An operator that reads Σ (so it cannot be recorded): it scales x by 1/(1 + Σ_xx).
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
    // `trace_in` runs every step checked, never the tape.
    chain
        .trace_in(form, c)
        .map(|t| t.last().to::<N>().expect("layout"))
}

/// Whether `a` and `b` agree to `1e-6` of the largest entry of either or of the start
/// `c0` (a window folded at once rounds differently from one fold per axis; a snap
/// decided on the other side of its threshold, then amplified by the rest of a random
/// chain, stays far below this; an exact 0 against rounding noise is measured against
/// the start).
fn close<const N: usize>(a: &Cov<N>, b: &Cov<N>, c0: &Cov<N>) -> bool {
    let top = a.max_abs().max(b.max_abs()).max(c0.max_abs());
    a.packed()
        .iter()
        .zip(b.packed())
        .all(|(x, y)| (x - y).abs() <= 1e-6 * top)
}

fn same_in_both_paths<const N: usize>(chain: &Chain, seed: &[f64]) {
    let c0 = start::<N>(seed);
    for form in [Form::Covariance, Form::SquareRoot] {
        let want = checked(chain, form, c0);
        // The tape run kernel by kernel (no fusion): the same bits.
        let tape = chain.compile(N, form).unwrap();
        let by_kernel = match form {
            Form::Covariance => tape.run_cov(c0),
            Form::SquareRoot => tape
                .run_factor(CovFactor::from_cov(&c0))
                .and_then(|f| f.to_cov().ok()),
        };
        if let (Ok(a), Some(b)) = (&want, &by_kernel) {
            assert_eq!(a, b, "N={N} {form:?}: kernel-by-kernel tape");
        }
        // First evaluation: checked; second and third: the compiled program.
        for _ in 0..3 {
            let got = chain.eval_in(form, c0);
            match (&want, &got) {
                (Ok(a), Ok(b)) if form == Form::Covariance => assert_eq!(a, b, "N={N}"),
                (Ok(a), Ok(b)) => assert!(close(a, b, &c0), "N={N} {form:?}: {a:?} vs {b:?}"),
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
                _ => panic!("N={N} {form:?}: checked {want:?}, compiled {got:?}"),
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn compiled_chains_agree_with_the_checked_path(
        seed in prop::collection::vec(-1.0f64..1.0, 25),
        ops in prop::collection::vec((0u8..80, -3.0f64..3.0, 0.0f64..5.0), 1..20),
        opaque in 0usize..30,
    ) {
        let mut chain = Chain::new();
        for (i, &(k, p, q)) in ops.iter().enumerate() {
            if i == opaque {
                chain.push(Reads);
            }
            chain.push(K(k, p, q));
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
fn a_missing_axis_is_reported_by_the_compiled_chain() {
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
fn operators_record_without_opaque_steps() {
    let chain = bounce(2.0, 0.7, 0.9, 0.3);
    for n in [4, 5] {
        let tape = chain.compile(n, Form::Covariance).unwrap();
        assert!(tape.kernels().iter().all(|k| !matches!(k, Kernel::Opaque(_))));
        assert!(tape.kernels().len() >= 14, "{}", tape.kernels().len());
    }
    // A chain nested in a chain records its steps one by one.
    let outer = Chain::new().with(chain.clone()).with(Reads);
    let tape = outer.compile(4, Form::SquareRoot).unwrap();
    let opaque = tape
        .kernels()
        .iter()
        .filter(|k| matches!(k, Kernel::Opaque(_)))
        .count();
    assert_eq!(opaque, 1);
    // Reflect (a compound operator) records too.
    let reflect = Reflect::new(
        0.8,
        0.6,
        Curvature::isotropic(1.0).unwrap(),
        Lobe::Phong { exponent: 20.0 },
    );
    let mut t = Tape::new(4, Form::Covariance).unwrap();
    t.record(&reflect.unwrap()).unwrap();
    assert!(!t.kernels().is_empty());
    // An operator that reads Σ cannot be recorded, and the tape is unchanged.
    let before = t.kernels().len();
    let e = t.record(&Reads).unwrap_err().to_string();
    assert!(e.contains("cannot be recorded"), "{e}");
    assert_eq!(t.kernels().len(), before);
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
fn a_tape_refuses_another_layout_or_form() {
    let chain = Chain::new().with(Travel::new(1.0).unwrap());
    let tape = chain.compile(2, Form::Covariance).unwrap();
    let c = Cov::<2>::gaussian([0.1, 1.0]).unwrap();
    assert!(tape.run_cov(c).is_some());
    assert!(tape.run_cov(Cov::<4>::zeros()).is_none());
    assert!(tape.run_factor(CovFactor::from_cov(&c)).is_none());
    assert!(Tape::new(6, Form::Covariance).is_err());
    let shared: Arc<dyn Operator> = Arc::new(Reads);
    let mut t = Tape::new(2, Form::Covariance).unwrap();
    t.push_shared(&shared);
    assert!(matches!(t.kernels(), [Kernel::Opaque(_)]));
}

fn batch_matches_scalar<const N: usize>(chain: &Chain, seeds: &[Vec<f64>]) {
    let starts: Vec<Cov<N>> = seeds.iter().map(|s| start::<N>(s)).collect();
    for form in [Form::Covariance, Form::SquareRoot] {
        let mut batch = starts.clone();
        // The batch compiles the chain; `eval_in` then takes the compiled path too.
        let failed = chain.eval_batch(form, &mut batch);
        let mut f = failed.iter();
        let mut next = f.next();
        for (i, c0) in starts.iter().enumerate() {
            match (chain.eval_in(form, *c0), next) {
                (Ok(want), _) => assert_eq!(batch[i], want, "N={N} {form:?} state {i}"),
                (Err(want), Some((j, got))) if *j == i => {
                    assert_eq!(got.to_string(), want.to_string());
                    assert_eq!(batch[i], *c0, "a failed state is left as it was");
                    next = f.next();
                }
                (Err(want), other) => panic!("state {i}: {want} not reported ({other:?})"),
            }
        }
        assert!(next.is_none(), "a state reported that did not fail");
        if form == Form::Covariance {
            // The same states stored structure-of-arrays: the same bits and failures.
            let mut lanes: CovLanes<N> = starts.iter().copied().collect();
            let failed_lanes = chain.eval_lanes(&mut lanes);
            assert_eq!(lanes.to_vec(), batch, "N={N}: eval_lanes against eval_batch");
            let render =
                |f: &[(usize, CovError)]| f.iter().map(|(i, e)| format!("{i}: {e}")).collect::<Vec<_>>();
            assert_eq!(render(&failed_lanes), render(&failed));
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn batches_give_the_compiled_scalar_bits(
        seeds in prop::collection::vec(prop::collection::vec(-1.0f64..1.0, 25), 1..40),
        ops in prop::collection::vec((0u8..80, -3.0f64..3.0, 0.0f64..5.0), 1..12),
        simple in any::<bool>(),
    ) {
        // Simple kernels only (the lane path) or any kernel (the per-state path).
        let mut chain = Chain::new();
        for &(k, p, q) in &ops {
            let k = if simple { [0u8, 1, 2, 3, 4][k as usize % 5] + 8 * (k / 8) } else { k };
            chain.push(K(k, p, q));
        }
        batch_matches_scalar::<2>(&chain, &seeds);
        batch_matches_scalar::<3>(&chain, &seeds);
        batch_matches_scalar::<4>(&chain, &seeds);
        batch_matches_scalar::<5>(&chain, &seeds);
    }
}

#[test]
fn batch_reports_failing_states_by_index() {
    // States 3 and 20 overflow (a huge start); the rest pass; 1,100 states span chunks
    // and a ragged lane tail.
    let chain = Chain::new()
        .with(K(1, 0.0, 1e100))
        .with(bounce(2.0, 0.6, 0.9, 0.4));
    let seed: Vec<f64> = (0..25).map(|i| (i as f64 * 0.37).sin()).collect();
    let mut states = vec![start::<4>(&seed); 1100];
    for i in [3, 20] {
        states[i] = Cov::<4>::gaussian([1e-150, 1e-150, 1.0, 1.0]).unwrap();
    }
    let before = states.clone();
    let failed = chain.eval_batch(Form::Covariance, &mut states);
    let idx: Vec<usize> = failed.iter().map(|(i, _)| *i).collect();
    assert_eq!(idx, vec![3, 20]);
    assert!(
        failed[0].1.to_string().starts_with("step 0 (K)"),
        "{}",
        failed[0].1
    );
    assert_eq!(states[3], before[3]);
    let want = chain.eval_in(Form::Covariance, before[1099]).unwrap();
    assert_eq!(states[1099], want);
}

#[test]
fn an_overflow_is_not_hidden_by_a_later_lobe() {
    // Σ_xx overflows (x scaled by ~1e200), then a lobe on another axis: the row of x
    // cancels "to nothing" relative to ∞ and its snap would zero it, leaving a finite Σ.
    // The compiled program, the lanes and the per-state batch check only at the end, so
    // the snap must keep the ∞ visible: every path reports the checked path's error.
    let chain = Chain::new().with(K(1, 0.0, 1e200)).with(K(12, 0.0, 5.0));
    // Σ_xu = 0 keeps the lobe's own update of row x finite (∞ − 0·0), so only the snap
    // decides whether the ∞ survives.
    let c0 = Cov::<2>::from_diagonal([1.0, 1.0]).unwrap();
    for form in [Form::Covariance, Form::SquareRoot] {
        // The first evaluation runs checked (in square-root form the factor stays finite
        // and Σ overflows when it is formed, which that path reports without a step).
        let want = chain.eval_in(form, c0).unwrap_err().to_string();
        if form == Form::Covariance {
            assert!(want.starts_with("step 0 (K)"), "{want}");
        }
        for _ in 0..3 {
            assert_eq!(chain.eval_in(form, c0).unwrap_err().to_string(), want);
        }
        let mut states = vec![c0; 100];
        let failed = chain.eval_batch(form, &mut states);
        assert_eq!(failed.len(), 100, "{form:?}");
        assert_eq!(failed[99].1.to_string(), want);
        assert!(states.iter().all(|s| *s == c0));
        let mut states = vec![c0; 10];
        let failed = covtrace::eval_batch_with(form, &mut states, |_, s| chain.apply(s));
        assert_eq!(failed.len(), 10, "{form:?}");
    }
    let mut lanes: CovLanes<2> = std::iter::repeat_n(c0, 70).collect();
    let failed = chain.eval_lanes(&mut lanes);
    assert_eq!(
        failed.iter().map(|(i, _)| *i).collect::<Vec<_>>(),
        (0..70).collect::<Vec<_>>()
    );
    assert!(
        lanes.iter().all(|s| s == c0),
        "failed states are left as they were"
    );
}

#[test]
fn lanes_store_states_across_groups_and_report_by_index() {
    // 1,100 states: chunks, groups and a ragged last group; states 3 and 700 overflow.
    let seed: Vec<f64> = (0..25).map(|i| (i as f64 * 0.37).sin()).collect();
    let chain = Chain::new()
        .with(K(1, 0.0, 1e100))
        .with(bounce(2.0, 0.6, 0.9, 0.4));
    let mut states: Vec<Cov<4>> = (0..1100)
        .map(|i| {
            let mut c = start::<4>(&seed);
            c.set(0, 0, c.get(0, 0) + i as f64);
            c
        })
        .collect();
    for i in [3, 700] {
        states[i] = Cov::<4>::gaussian([1e-150, 1e-150, 1.0, 1.0]).unwrap();
    }
    let mut lanes = CovLanes::from(&states[..]);
    assert_eq!(lanes.len(), 1100);
    assert_eq!(lanes.to_vec(), states);
    assert_eq!(lanes.get(1100), None);
    let failed = chain.eval_lanes(&mut lanes);
    assert_eq!(failed.iter().map(|(i, _)| *i).collect::<Vec<_>>(), vec![3, 700]);
    assert!(
        failed[1].1.to_string().starts_with("step 0 (K)"),
        "{}",
        failed[1].1
    );
    for i in [0, 3, 63, 64, 511, 512, 700, 1099] {
        let want = chain.eval_in(Form::Covariance, states[i]).unwrap_or(states[i]);
        assert_eq!(lanes.get(i), Some(want), "state {i}");
    }
    // Editing: set, push into a new group, extend, clear.
    lanes.set(64, states[1]);
    assert_eq!(lanes.get(64), Some(states[1]));
    lanes.push(states[2]);
    lanes.extend(states[..30].iter().copied());
    assert_eq!(lanes.len(), 1131);
    assert_eq!(lanes.get(1100), Some(states[2]));
    assert_eq!(lanes.get(1130), Some(states[29]));
    assert_eq!(
        format!("{:?}", CovLanes::from(&states[..1])),
        format!("[{:?}]", states[0])
    );
    lanes.clear();
    assert!(lanes.is_empty() && chain.eval_lanes(&mut lanes).is_empty());
}

#[test]
fn per_state_batches_match_each_chain() {
    // 1,100 states (chunks and a tail), each through its own bounce; state 5 overflows.
    let seed: Vec<f64> = (0..25).map(|i| (i as f64 * 0.61).cos()).collect();
    let chains: Vec<Chain> = (0..1100)
        .map(|i| {
            let t = i as f64 / 1100.0;
            let c = bounce(3.0 * t - 1.5, 0.3 + 0.6 * t, 0.9 - 0.5 * t, 6.0 * t);
            if i == 5 {
                Chain::new().with(K(1, 0.0, 1e300)).with(c)
            } else {
                c
            }
        })
        .collect();
    for form in [Form::Covariance, Form::SquareRoot] {
        let mut states = vec![start::<4>(&seed); 1100];
        states[5] = Cov::<4>::gaussian([1e-150, 1.0, 1.0, 1.0]).unwrap();
        let before = states.clone();
        let failed = covtrace::eval_batch_with(form, &mut states, |i, s| chains[i].apply(s));
        assert_eq!(failed.len(), 1, "{form:?}");
        assert_eq!(failed[0].0, 5);
        let want = chains[5].eval_in(form, before[5]).unwrap_err();
        assert_eq!(failed[0].1.to_string(), want.to_string());
        assert_eq!(states[5], before[5], "a failed state is left as it was");
        for i in [0, 511, 512, 1099] {
            // Each chain ran once inside the batch: its checked path.
            assert_eq!(
                states[i],
                checked(&chains[i], form, before[i]).unwrap(),
                "{form:?} {i}"
            );
        }
    }
}
