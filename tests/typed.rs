//! `Operator::apply` on a `Cov<N>` or `CovFactor<N>`, where the bundled operators run
//! their body with the spectrum's type known (`cov_core::typed!`: kernels inlined with
//! constant indices), against the same operators on a spectrum that hides its type (a
//! third party's `Spectrum`, where the body runs through `&mut dyn Spectrum`): on random
//! sequences of the bounce chain's operators with random parameters, in both forms and
//! all four layouts, the same bits after every step, the same errors (missing axis,
//! overflow) and the same Σ after an error.

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::{Curvature, CurvatureTensor};
use covtrace::linalg::Small;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{AnyCov, AnySpectrum, Cov, CovError, CovFactor, Form, Operator, Spectrum};
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

/// A spectrum that hides its concrete type ([`Spectrum::concrete`] is `Other`), as a
/// third party's would: operators run their body through `&mut dyn Spectrum`.
#[derive(Debug)]
struct Opaque<'a>(&'a mut dyn Spectrum);

impl Spectrum for Opaque<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn form(&self) -> Form {
        self.0.form()
    }
    fn cov(&self) -> Result<AnyCov, CovError> {
        self.0.cov()
    }
    fn assign(&mut self, c: &AnyCov) -> Result<(), CovError> {
        self.0.assign(c)
    }
    fn snapshot(&self) -> AnySpectrum {
        self.0.snapshot()
    }
    fn restore(&mut self, s: &AnySpectrum) {
        self.0.restore(s)
    }
    fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        self.0.first_non_finite()
    }
    fn raw_congruence(&mut self, op: &str, a: &Small) -> Result<(), CovError> {
        self.0.raw_congruence(op, a)
    }
    fn raw_shear(&mut self, op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError> {
        self.0.raw_shear(op, i, j, s)
    }
    fn raw_scale(&mut self, op: &str, i: usize, c: f64) -> Result<(), CovError> {
        self.0.raw_scale(op, i, c)
    }
    fn raw_rotate(&mut self, op: &str, planes: &[(usize, usize)], c: f64, s: f64) -> Result<(), CovError> {
        self.0.raw_rotate(op, planes, c, s)
    }
    fn raw_add_window(&mut self, op: &str, p: &[usize], w: &Small) -> Result<(), CovError> {
        self.0.raw_add_window(op, p, w)
    }
    fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError> {
        self.0.raw_add_variance(op, i, w)
    }
    fn raw_lobe_1(&mut self, op: &str, p: usize, s: f64) -> Result<(), CovError> {
        self.0.raw_lobe_1(op, p, s)
    }
    fn raw_lobe(&mut self, op: &str, p: &[usize], s: &Small) -> Result<(), CovError> {
        self.0.raw_lobe(op, p, s)
    }
}

/// Runs `ops` both ways on `start` and compares after every step; returns how many
/// steps failed (so that the caller can see that error paths were reached).
fn both<S: Spectrum + Copy + 'static + PartialEq + std::fmt::Debug>(start: S, ops: &[Op]) -> usize {
    let (mut a, mut b) = (start, start);
    // After an error both go on from the Σ the failed operator left (the same, checked).
    let mut failed = 0;
    for (k, op) in ops.iter().enumerate() {
        let ra = dyn_op(op).apply(&mut a);
        let rb = dyn_op(op).apply(&mut Opaque(&mut b));
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
