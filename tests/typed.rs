//! The operators' typed bodies (`apply_to`, the spectrum's type known at the call, so
//! the kernels inline with constant indices) against `Operator::apply` (`&mut dyn
//! Spectrum`): on random sequences of the bounce chain's operators with random
//! parameters, in both forms and all four layouts, the same bits after every step, the
//! same errors (missing axis, overflow) and the same Σ after an error.

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::{Curvature, CurvatureTensor};
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{Cov, CovError, CovFactor, Operator, Spectrum};
use proptest::prelude::*;

/// One operator with parameters from `(kind, p, q)`; `None` where the constructor
/// rejects them (then there is nothing to apply).
#[derive(Clone, Copy, Debug)]
enum Op {
    Travel(Travel),
    Curvature(Curvature),
    Tensor(CurvatureTensor),
    Project(Project),
    Unproject(Unproject),
    Mirror,
    Rotate(RotateFrame),
    Brdf(Brdf),
    Window(Window),
}

fn op_of(kind: u8, p: f64, q: f64) -> Option<Op> {
    let cos = 0.05 + 0.95 * q.abs().fract();
    let op = match kind % 13 {
        0 => Op::Travel(Travel::new(p).ok()?),
        1 => Op::Curvature(Curvature::isotropic(p).ok()?),
        2 => Op::Curvature(Curvature::anisotropic(p, q, p * q).ok()?),
        3 => Op::Tensor(CurvatureTensor::new(p, 0.3 * q, q).ok()?),
        4 => Op::Project(Project::with_angle(cos, if kind.is_multiple_of(2) { 0.0 } else { p }).ok()?),
        5 => Op::Unproject(Unproject::with_angle(cos, if kind.is_multiple_of(2) { 0.0 } else { q }).ok()?),
        6 => Op::Mirror,
        7 => Op::Rotate(RotateFrame::new(p).ok()?),
        8 => Op::Brdf(
            Brdf::new(Lobe::Phong {
                exponent: q.abs() * 100.0,
            })
            .ok()?,
        ),
        9 => Op::Brdf(
            Brdf::new(Lobe::Gaussian {
                var_u: q.abs(),
                var_v: 0.0,
            })
            .ok()?,
        ),
        10 => Op::Brdf(Brdf::new(Lobe::Diffuse).ok()?),
        11 => Op::Window(Window::new(q.abs() + 1e-3, p.abs() + 1e-3).ok()?),
        // Large enough to overflow after a few steps: the error paths.
        _ => Op::Travel(Travel::new(p * 1e150).ok()?),
    };
    Some(op)
}

fn dyn_op(op: &Op) -> &dyn Operator {
    match op {
        Op::Travel(o) => o,
        Op::Curvature(o) => o,
        Op::Tensor(o) => o,
        Op::Project(o) => o,
        Op::Unproject(o) => o,
        Op::Mirror => &Mirror,
        Op::Rotate(o) => o,
        Op::Brdf(o) => o,
        Op::Window(o) => o,
    }
}

fn typed<S: Spectrum>(op: &Op, s: &mut S) -> Result<(), CovError> {
    match op {
        Op::Travel(o) => o.apply_to(s),
        Op::Curvature(o) => o.apply_to(s),
        Op::Tensor(o) => o.apply_to(s),
        Op::Project(o) => o.apply_to(s),
        Op::Unproject(o) => o.apply_to(s),
        Op::Mirror => Mirror.apply_to(s),
        Op::Rotate(o) => o.apply_to(s),
        Op::Brdf(o) => o.apply_to(s),
        Op::Window(o) => o.apply_to(s),
    }
}

/// Runs `ops` both ways on `start` and compares after every step; returns how many
/// steps failed (so that the caller can see that error paths were reached).
fn both<S: Spectrum + Copy + PartialEq + std::fmt::Debug>(start: S, ops: &[Op]) -> usize {
    let (mut a, mut b) = (start, start);
    // After an error both go on from the Σ the failed operator left (the same, checked).
    let mut failed = 0;
    for (k, op) in ops.iter().enumerate() {
        let ra = typed(op, &mut a);
        let rb = dyn_op(op).apply(&mut b);
        assert_eq!(
            ra.as_ref().map_err(ToString::to_string),
            rb.as_ref().map_err(ToString::to_string),
            "step {k} {op:?}"
        );
        assert_eq!(a, b, "step {k} {op:?}: typed and dynamic Σ differ");
        if ra.is_err() {
            failed += 1;
        }
    }
    failed
}

fn start<const N: usize>(d: &[f64]) -> Cov<N> {
    let mut diag = [0.0; N];
    for (k, v) in diag.iter_mut().enumerate() {
        *v = d[k];
    }
    let mut c = Cov::from_diagonal(diag).expect("non-negative diagonal");
    // Correlate x and u so that every kernel sees off-diagonal entries.
    let _ = c.shear(covtrace::Axis::X, covtrace::Axis::U, 0.3);
    c
}

fn run<const N: usize>(d: &[f64], ops: &[Op]) -> usize {
    let c = start::<N>(d);
    both(c, ops) + both(CovFactor::from_cov(&c), ops)
}

fn ops() -> impl Strategy<Value = Vec<(u8, f64, f64)>> {
    prop::collection::vec((any::<u8>(), -3.0f64..3.0, -2.0f64..2.0), 1..24)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn typed_bodies_match_dynamic_apply(
        d in prop::collection::vec(prop_oneof![Just(0.0), 1e-3f64..10.0], 5),
        o in ops(),
    ) {
        let ops: Vec<Op> = o.iter().filter_map(|&(k, p, q)| op_of(k, p, q)).collect();
        run::<2>(&d, &ops);
        run::<3>(&d, &ops);
        run::<4>(&d, &ops);
        run::<5>(&d, &ops);
    }
}

/// The error paths are reached: a missing axis (a frame rotation in flatland) and an
/// overflow, reported the same both ways.
#[test]
fn typed_bodies_report_the_same_errors() {
    let rotate = op_of(7, 0.4, 0.0).expect("valid");
    let far = Op::Travel(Travel::new(1e200).expect("finite"));
    assert_eq!(run::<2>(&[1.0; 5], &[rotate]), 2, "RotateFrame needs y and v");
    let c = start::<4>(&[1.0; 5]);
    assert_eq!(both(c, &[far, far]), 2, "Σ_uu = 1e400 overflows");
    // The factor holds √Σ: its rows reach 1e200 and stay finite.
    assert_eq!(both(CovFactor::from_cov(&c), &[far, far]), 0);
}

/// Per-state operators for the typed batch: state `i` runs `chains[i]`.
struct Chains(Vec<Vec<Op>>);

impl covtrace::StateOps for Chains {
    fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
        self.0[i].iter().try_for_each(|op| typed(op, s))
    }
}

/// `eval_batch_typed` (typed bodies on the unchecked kernels, checked re-run on failure)
/// gives `eval_batch_with`'s results (operators through `dyn Spectrum`): the same bits,
/// the same failing states with the same messages, and failed states left as they were.
fn batches_agree<const N: usize>(d: &[f64], chains: &Chains) -> usize {
    use covtrace::Form;
    let mut failed = 0;
    for form in [Form::Covariance, Form::SquareRoot] {
        let start: Vec<Cov<N>> = (0..chains.0.len()).map(|i| start::<N>(&d[i % 3..])).collect();
        let (mut a, mut b) = (start.clone(), start.clone());
        let fa = covtrace::eval_batch_typed(form, &mut a, chains);
        let fb = covtrace::eval_batch_with(form, &mut b, |i, s| {
            chains.0[i].iter().try_for_each(|op| dyn_op(op).apply(s))
        });
        // A state left non-finite with no operator error is reported under the batch's
        // own name, which differs between the two; everything else must be identical.
        let text = |f: &[(usize, CovError)]| {
            f.iter()
                .map(|(i, e)| (*i, e.to_string().replace("eval_batch_typed", "eval_batch_with")))
                .collect::<Vec<_>>()
        };
        assert_eq!(text(&fa), text(&fb), "{form:?}: failures differ");
        assert_eq!(a, b, "{form:?}: typed and dynamic batches differ");
        for (i, _) in &fa {
            assert_eq!(a[*i], start[*i], "{form:?}: failed state {i} was changed");
        }
        failed += fa.len();
    }
    failed
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    #[test]
    fn typed_batch_matches_closure_batch(
        d in prop::collection::vec(prop_oneof![Just(0.0), 1e-3f64..10.0], 8),
        o in prop::collection::vec(ops(), 1..40),
    ) {
        let chains = Chains(
            o.iter()
                .map(|c| c.iter().filter_map(|&(k, p, q)| op_of(k, p, q)).collect())
                .collect(),
        );
        batches_agree::<2>(&d, &chains);
        batches_agree::<4>(&d, &chains);
        batches_agree::<5>(&d, &chains);
    }
}

/// The typed batch reaches its error paths: states that overflow and states whose layout
/// lacks an axis fail, with the checked kernels' messages, among states that succeed.
#[test]
fn typed_batch_reports_failing_states() {
    let rotate = op_of(7, 0.4, 0.0).expect("valid");
    let far = Op::Travel(Travel::new(1e200).expect("finite"));
    let near = Op::Travel(Travel::new(0.5).expect("finite"));
    let chains = Chains(vec![vec![near], vec![far, far], vec![near, rotate], vec![near]]);
    // Flatland: the rotation needs y and v (state 2); Σ_uu = 1e400 overflows in
    // covariance form (state 1), while the factor's rows stay finite but Σ = L Lᵀ
    // does not (reported when the factor is turned back into Σ).
    assert_eq!(batches_agree::<2>(&[1.0; 8], &chains), 4);
    // 4D has the rotation's axes: only the overflow fails, in both forms.
    assert_eq!(batches_agree::<4>(&[1.0; 8], &chains), 2);
}
