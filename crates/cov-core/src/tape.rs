//! Compiled chains: a [`Tape`] is the list of kernel calls a sequence of operators makes
//! in one layout and form, with axes resolved to indices and parameters checked once,
//! when it is recorded. Running it is the fast path of [`crate::Chain`]: no parameter
//! validation, no axis lookup, no `Result` and no finiteness check per kernel, no dynamic
//! dispatch, and no copy of Σ per step. Finiteness is checked where a later kernel could
//! hide an ∞ (before a window or a multi-axis lobe, and in square-root form before every
//! lobe; the covariance form's one-axis lobe snaps a row to `v − v`, which keeps an ∞
//! visible) and once at the end; a run that fails
//! is repeated in checked mode by the caller, which finds and reports the failing step
//! exactly as before.
//!
//! A chain runs its tape as a program lowered once for the concrete form and run by one
//! interpreter: each simple kernel, and the two kernels an operator makes on the
//! transverse planes (x, u) and (y, v) (travel, curvature, a frame rotation, a mirror,
//! a window) as one instruction, is dispatched to its update with constant indices,
//! inlined, with the same operations in the same order; in square-root form the
//! variances a window adds on several axes are one fold instead of one per axis (the
//! same Σ to rounding, within the stiff suite's and the random-chain test's bounds). The
//! batch lanes ([`crate::Chain::eval_batch`]) run the same program. A tape run through
//! [`Tape::run_cov`] or [`Tape::run_factor`] goes kernel by kernel and gives the checked
//! kernels' bits.
//!
//! A chain's first evaluation in a layout and form is not recorded (a renderer's
//! per-path chain runs once): its operators run on the unchecked kernels directly
//! (`Direct`), with the same finiteness checks and the same checked re-run on failure.
//!
//! Recording needs no special support from operators: a tape records by applying each
//! operator to a [`Recorder`], a [`Spectrum`] whose raw kernels append to the tape. An
//! operator whose kernel calls depend on Σ itself (it reads [`Spectrum::cov`] or takes
//! a snapshot) cannot be replayed from a recording; [`Tape::push_shared`] then keeps the
//! operator as an opaque step that runs through its checked `apply`, and
//! [`Tape::record`] reports it.
//!
//! ```
//! use cov_core::{Axis, CovError, Cov, Form, Operator, Spectrum, Tape};
//!
//! #[derive(Debug)]
//! struct Travel(f64);
//! impl Operator for Travel {
//!     fn apply(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
//!         s.shear(Axis::X, Axis::U, -self.0)
//!     }
//! }
//!
//! // One tape, reused ray after ray with each ray's own parameters.
//! let mut tape = Tape::new(2, Form::Covariance)?;
//! for d in [0.5, 2.0] {
//!     tape.clear();
//!     tape.record(&Travel(d))?;
//!     let start = Cov::<2>::gaussian([0.1, 1.0])?;
//!     let fast = tape.run_cov(start).expect("finite");
//!     let mut checked = start;
//!     Travel(d).apply(&mut checked)?;
//!     assert_eq!(fast, checked); // the same bits as the checked kernels
//! }
//! # Ok::<(), CovError>(())
//! ```

use std::cell::Cell;
use std::sync::{Arc, OnceLock};

use crate::form::Kernels;
use crate::linalg::{MAX, Small};
use crate::{AnyCov, AnySpectrum, Cov, CovError, CovFactor, Form, Operator, Spectrum};

/// One kernel call, as recorded: indices into the layout, parameters already checked.
#[derive(Clone, Debug)]
pub enum Kernel {
    /// [`Spectrum::raw_shear`].
    Shear {
        /// Target index.
        i: u8,
        /// Source index.
        j: u8,
        /// Shear factor.
        s: f64,
    },
    /// [`Spectrum::raw_scale`].
    Scale {
        /// Index.
        i: u8,
        /// Factor.
        c: f64,
    },
    /// One plane of [`Spectrum::raw_rotate`].
    Rotate {
        /// First index of the plane.
        i: u8,
        /// Second index of the plane.
        j: u8,
        /// Cosine of the angle.
        c: f64,
        /// Sine of the angle.
        s: f64,
    },
    /// [`Spectrum::raw_add_variance`].
    AddVariance {
        /// Index.
        i: u8,
        /// Variance added (≥ 0).
        w: f64,
    },
    /// [`Spectrum::raw_lobe_1`].
    Lobe1 {
        /// Index.
        p: u8,
        /// Lobe spectrum (≥ 0; 0 integrates).
        s: f64,
    },
    /// [`Spectrum::raw_add_window`] on several indices.
    AddWindow(Box<Block>),
    /// [`Spectrum::raw_lobe`] on several indices.
    Lobe(Box<Block>),
    /// [`Spectrum::raw_congruence`].
    Congruence(Box<Small>),
    /// An operator that reads Σ: run through its checked [`Operator::apply`].
    Opaque(Arc<dyn Operator>),
}

/// The indices and matrix of a multi-axis window or lobe.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    /// The indices (first `k` used).
    pub p: [usize; MAX],
    /// How many indices.
    pub k: usize,
    /// The `k × k` matrix (`W` or `S`).
    pub m: Small,
}

impl Block {
    fn new(p: &[usize], m: &Small) -> Box<Block> {
        let mut idx = [0; MAX];
        idx[..p.len()].copy_from_slice(p);
        Box::new(Block {
            p: idx,
            k: p.len(),
            m: *m,
        })
    }
}

/// A compiled sequence of kernel calls in one layout and form (see the module docs).
#[derive(Debug)]
pub struct Tape {
    dim: usize,
    form: Form,
    kernels: Vec<Kernel>,
    /// The kernels lowered for the tape's form and layout, built by [`Tape::prepare`]
    /// for tapes that run many times (a [`crate::Chain`]'s).
    program: OnceLock<Vec<Instr>>,
}

impl Clone for Tape {
    fn clone(&self) -> Self {
        Tape {
            dim: self.dim,
            form: self.form,
            kernels: self.kernels.clone(),
            program: OnceLock::new(),
        }
    }
}

/// What a lowered kernel does: one kernel with indices (turned into constants when it
/// runs), or a pair of kernels that one operator makes on the transverse planes (x, u)
/// and (y, v) of layouts 4 and 5 ([`pair`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Code {
    Shear,
    Rotate,
    Scale,
    AddVariance,
    /// After a finiteness check (a lobe may zero a row that held ∞).
    Lobe1,
    /// Shears (0, 2) and (1, 3): travel.
    ShearXU,
    /// Shears (2, 0) and (3, 1): curvature.
    ShearUX,
    /// Rotations of (0, 1) and (2, 3) by the same angle: a frame rotation.
    RotateFrame,
    /// Scales of 2 and 3: a mirror.
    ScaleUV,
    /// Variances on 0 and 1 (covariance form): a window.
    VarianceXY,
}

/// One lowered kernel: a [`Code`] with its indices and two parameters, a window of
/// several variances (square-root form), or the general kernel `q` of the tape.
#[derive(Debug)]
pub(crate) enum Instr {
    /// A simple kernel or a transverse pair (indices below the layout size), as the
    /// flat code of [`flat_dispatch!`], with its two parameters.
    Op {
        /// The code ([`flat`]).
        f: u8,
        /// First parameter.
        a: f64,
        /// Second parameter.
        b: f64,
    },
    /// A window on several axes (square-root form), held as its factor `F` (`W = F Fᵀ`),
    /// computed once when the tape is lowered: `√w` on the diagonal for a run of
    /// variances, [`crate::form::psd_factor`] of the matrix for a multi-axis window.
    Window(Box<Block>),
    General(usize),
}

/// The tape's kernels lowered for the concrete form `K` as its compiled program: pairs of kernels that one
/// operator makes on the two transverse planes ([`pair`]) become one instruction; in
/// square-root form, a run of variances added on distinct axes becomes one window (each
/// `AddVariance` folds the factor back with Householder reflections, the form's most
/// expensive kernel; one fold of `k` new columns does the work of `k`, to rounding), and
/// a multi-axis window keeps the factor of its matrix, computed here once (the same bits
/// as factoring it at every run).
///
/// Runs of rule-1 kernels are not composed into one dense map: tried, it cut the
/// covariance bounce chain by a quarter, but the stiff suite's 10⁴-operator chain lost a
/// factor 3 in accuracy in covariance form (4.1e-9 → 1.3e-8, past its 1e-8 limit): a
/// composed `G` rounds entries the kernels keep exact.
fn plan<K: Kernels>(kernels: &[Kernel]) -> Vec<Instr> {
    let n = K::DIM;
    let mut out = Vec::with_capacity(kernels.len());
    let mut q = 0;
    while q < kernels.len() {
        if let Some(both) = kernels.get(q + 1).and_then(|next| pair::<K>(&kernels[q], next)) {
            out.push(both);
            q += 2;
            continue;
        }
        if K::FORM == Form::SquareRoot {
            let mut idx = Vec::new();
            let mut w: Small = [[0.0; MAX]; MAX];
            for k in &kernels[q..] {
                match *k {
                    Kernel::AddVariance { i, w: v } if (i as usize) < n && !idx.contains(&(i as usize)) => {
                        // The window's factor, as `k_add_window` would take it (`v ≥ 0`).
                        w[idx.len()][idx.len()] = v.max(0.0).sqrt();
                        idx.push(i as usize);
                    }
                    _ => break,
                }
            }
            if idx.len() >= 2 {
                q += idx.len();
                out.push(Instr::Window(Block::new(&idx, &w)));
                continue;
            }
            // A multi-axis window: its factor once, here, instead of at every run.
            if let Kernel::AddWindow(b) = &kernels[q]
                && b.p[..b.k].iter().all(|&i| i < n)
            {
                let f = crate::form::psd_factor(b.k, &b.m);
                out.push(Instr::Window(Block::new(&b.p[..b.k], &f)));
                q += 1;
                continue;
            }
        }
        out.push(lower::<K>(&kernels[q], q));
        q += 1;
    }
    out
}

/// Two consecutive kernels that one operator makes on the transverse planes (x, u) and
/// (y, v) of layouts 4 and 5, as one instruction: travel's and curvature's two shears, a
/// frame rotation's two planes, two scales of u and v (a mirror), two variances on x and
/// y (a window, covariance form). `None` for anything else.
fn pair<K: Kernels>(a: &Kernel, b: &Kernel) -> Option<Instr> {
    if K::DIM < 4 {
        return None;
    }
    let op = |code, a, b| {
        Some(Instr::Op {
            f: flat(code, 0, 0),
            a,
            b,
        })
    };
    match (a, b) {
        (&Kernel::Shear { i: 0, j: 2, s }, &Kernel::Shear { i: 1, j: 3, s: t }) => op(Code::ShearXU, s, t),
        (&Kernel::Shear { i: 2, j: 0, s }, &Kernel::Shear { i: 3, j: 1, s: t }) => op(Code::ShearUX, s, t),
        (
            &Kernel::Rotate { i: 0, j: 1, c, s },
            &Kernel::Rotate {
                i: 2,
                j: 3,
                c: c2,
                s: s2,
            },
        ) if c.to_bits() == c2.to_bits() && s.to_bits() == s2.to_bits() => op(Code::RotateFrame, c, s),
        (&Kernel::Scale { i: 2, c }, &Kernel::Scale { i: 3, c: d }) => op(Code::ScaleUV, c, d),
        (&Kernel::AddVariance { i: 0, w }, &Kernel::AddVariance { i: 1, w: v })
            if K::FORM == Form::Covariance =>
        {
            op(Code::VarianceXY, w, v)
        }
        _ => None,
    }
}

/// `match` on a flat instruction code ([`flat`]) with one literal arm per kernel and
/// index pair, each binding its indices as constants: a single jump table per
/// instruction, where matching the kind and then the indices took two or three. The
/// compiled program ([`Tape::run`]) and the batch lanes dispatch through it.
#[rustfmt::skip]
macro_rules! flat_dispatch {
    (
        $code:expr;
        shear |$si:ident, $sj:ident| $shear:expr;
        rotate |$ri:ident, $rj:ident| $rotate:expr;
        scale |$ci:ident| $scale:expr;
        variance |$vi:ident| $variance:expr;
        lobe |$li:ident| $lobe:expr;
        pairs $pxu:expr, $pux:expr, $prf:expr, $puv:expr, $pxy:expr $(,)?
    ) => {
        match $code {
            1 => { let ($si, $sj): (usize, usize) = (0, 1); $shear }
            2 => { let ($si, $sj): (usize, usize) = (0, 2); $shear }
            3 => { let ($si, $sj): (usize, usize) = (0, 3); $shear }
            4 => { let ($si, $sj): (usize, usize) = (0, 4); $shear }
            5 => { let ($si, $sj): (usize, usize) = (1, 0); $shear }
            7 => { let ($si, $sj): (usize, usize) = (1, 2); $shear }
            8 => { let ($si, $sj): (usize, usize) = (1, 3); $shear }
            9 => { let ($si, $sj): (usize, usize) = (1, 4); $shear }
            10 => { let ($si, $sj): (usize, usize) = (2, 0); $shear }
            11 => { let ($si, $sj): (usize, usize) = (2, 1); $shear }
            13 => { let ($si, $sj): (usize, usize) = (2, 3); $shear }
            14 => { let ($si, $sj): (usize, usize) = (2, 4); $shear }
            15 => { let ($si, $sj): (usize, usize) = (3, 0); $shear }
            16 => { let ($si, $sj): (usize, usize) = (3, 1); $shear }
            17 => { let ($si, $sj): (usize, usize) = (3, 2); $shear }
            19 => { let ($si, $sj): (usize, usize) = (3, 4); $shear }
            20 => { let ($si, $sj): (usize, usize) = (4, 0); $shear }
            21 => { let ($si, $sj): (usize, usize) = (4, 1); $shear }
            22 => { let ($si, $sj): (usize, usize) = (4, 2); $shear }
            23 => { let ($si, $sj): (usize, usize) = (4, 3); $shear }
            26 => { let ($ri, $rj): (usize, usize) = (0, 1); $rotate }
            27 => { let ($ri, $rj): (usize, usize) = (0, 2); $rotate }
            28 => { let ($ri, $rj): (usize, usize) = (0, 3); $rotate }
            29 => { let ($ri, $rj): (usize, usize) = (0, 4); $rotate }
            30 => { let ($ri, $rj): (usize, usize) = (1, 0); $rotate }
            32 => { let ($ri, $rj): (usize, usize) = (1, 2); $rotate }
            33 => { let ($ri, $rj): (usize, usize) = (1, 3); $rotate }
            34 => { let ($ri, $rj): (usize, usize) = (1, 4); $rotate }
            35 => { let ($ri, $rj): (usize, usize) = (2, 0); $rotate }
            36 => { let ($ri, $rj): (usize, usize) = (2, 1); $rotate }
            38 => { let ($ri, $rj): (usize, usize) = (2, 3); $rotate }
            39 => { let ($ri, $rj): (usize, usize) = (2, 4); $rotate }
            40 => { let ($ri, $rj): (usize, usize) = (3, 0); $rotate }
            41 => { let ($ri, $rj): (usize, usize) = (3, 1); $rotate }
            42 => { let ($ri, $rj): (usize, usize) = (3, 2); $rotate }
            44 => { let ($ri, $rj): (usize, usize) = (3, 4); $rotate }
            45 => { let ($ri, $rj): (usize, usize) = (4, 0); $rotate }
            46 => { let ($ri, $rj): (usize, usize) = (4, 1); $rotate }
            47 => { let ($ri, $rj): (usize, usize) = (4, 2); $rotate }
            48 => { let ($ri, $rj): (usize, usize) = (4, 3); $rotate }
            50 => { let $ci: usize = 0; $scale }
            51 => { let $ci: usize = 1; $scale }
            52 => { let $ci: usize = 2; $scale }
            53 => { let $ci: usize = 3; $scale }
            54 => { let $ci: usize = 4; $scale }
            55 => { let $vi: usize = 0; $variance }
            56 => { let $vi: usize = 1; $variance }
            57 => { let $vi: usize = 2; $variance }
            58 => { let $vi: usize = 3; $variance }
            59 => { let $vi: usize = 4; $variance }
            60 => { let $li: usize = 0; $lobe }
            61 => { let $li: usize = 1; $lobe }
            62 => { let $li: usize = 2; $lobe }
            63 => { let $li: usize = 3; $lobe }
            64 => { let $li: usize = 4; $lobe }
            65 => $pxu,
            66 => $pux,
            67 => $prf,
            68 => $puv,
            69 => $pxy,
            _ => {}
        }
    };
}

/// The flat code of an instruction for [`flat_dispatch!`]: shears 0–24 and rotations
/// 25–49 (`5i + j`), scales 50–54, variances 55–59 and lobes 60–64 (`i`), the pairs
/// 65–69.
fn flat(code: Code, i: u8, j: u8) -> u8 {
    let (i, j) = (i.min(4), j.min(4));
    match code {
        Code::Shear => 5 * i + j,
        Code::Rotate => 25 + 5 * i + j,
        Code::Scale => 50 + i,
        Code::AddVariance => 55 + i,
        Code::Lobe1 => 60 + i,
        Code::ShearXU => 65,
        Code::ShearUX => 66,
        Code::RotateFrame => 67,
        Code::ScaleUV => 68,
        Code::VarianceXY => 69,
    }
}

pub(crate) use flat_dispatch;

/// Lowers kernel `q` for the concrete form `K`: a simple kernel with indices in range
/// becomes an [`Instr::Op`] (its indices constants when it runs); anything else runs
/// as the tape's general kernel.
fn lower<K: Kernels>(kernel: &Kernel, q: usize) -> Instr {
    let fits = |i: u8| (i as usize) < K::DIM;
    let op = |code, i, j, a, b| Instr::Op {
        f: flat(code, i, j),
        a,
        b,
    };
    match *kernel {
        Kernel::Shear { i, j, s } if fits(i) && fits(j) && i != j => op(Code::Shear, i, j, s, 0.0),
        Kernel::Rotate { i, j, c, s } if fits(i) && fits(j) && i != j => op(Code::Rotate, i, j, c, s),
        Kernel::Scale { i, c } if fits(i) => op(Code::Scale, i, 0, c, 0.0),
        Kernel::AddVariance { i, w } if fits(i) => op(Code::AddVariance, i, 0, w, 0.0),
        Kernel::Lobe1 { p, s } if fits(p) => op(Code::Lobe1, p, 0, s, 0.0),
        _ => Instr::General(q),
    }
}

impl Tape {
    /// An empty tape for layout `dim` (2 to 5) in `form`.
    ///
    /// # Errors
    /// [`CovError::Shape`] for a layout size outside 2..=5.
    pub fn new(dim: usize, form: Form) -> Result<Tape, CovError> {
        if !(2..=MAX).contains(&dim) {
            return Err(CovError::Shape {
                what: "Tape::new".into(),
                expected: "a layout size of 2 to 5".into(),
                got: dim.to_string(),
            });
        }
        Ok(Tape::empty(dim, form))
    }

    /// An empty tape; `dim` is a valid layout size (from a `Kernels` type).
    pub(crate) fn empty(dim: usize, form: Form) -> Tape {
        Tape {
            dim,
            form,
            kernels: Vec::new(),
            program: OnceLock::new(),
        }
    }

    /// The layout size.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The form the tape was recorded for.
    pub fn form(&self) -> Form {
        self.form
    }

    /// The recorded kernel calls.
    pub fn kernels(&self) -> &[Kernel] {
        &self.kernels
    }

    /// Empties the tape, keeping its storage (one tape serves ray after ray).
    pub fn clear(&mut self) {
        self.kernels.clear();
        self.program.take();
    }

    /// Appends what `op` does.
    ///
    /// # Errors
    /// What `op` reports for this layout (a missing axis, say), or
    /// [`CovError::NoTransport`] if `op` reads Σ, so that its kernel calls cannot be
    /// recorded (use [`Tape::push_shared`]). The tape is unchanged on error.
    pub fn record(&mut self, op: &dyn Operator) -> Result<(), CovError> {
        self.program.take();
        let mark = self.kernels.len();
        let mut rec = Recorder {
            tape: self,
            read: Cell::new(false),
        };
        let result = op.apply(&mut rec);
        let read = rec.read.get();
        if result.is_err() || read {
            self.kernels.truncate(mark);
        }
        if read {
            return Err(CovError::NoTransport {
                operator: op.name().to_string(),
                reason: "reads Σ while it acts, so it cannot be recorded on a tape".into(),
            });
        }
        result
    }

    /// Appends what `op` does, or `op` itself as an opaque step (run through its checked
    /// `apply`) if it cannot be recorded: it reads Σ, or it fails in this layout (the
    /// opaque step then reports the failure when the tape runs).
    pub fn push_shared(&mut self, op: &Arc<dyn Operator>) {
        if self.record(op.as_ref()).is_err() {
            self.kernels.push(Kernel::Opaque(op.clone()));
        }
    }

    /// Runs the tape on a covariance-form Σ (layout `N` must be the tape's, and the tape
    /// recorded in covariance form): the fast path without per-kernel checks.
    ///
    /// Returns `None` if the tape is not for this layout and form, if Σ became non-finite
    /// (an overflow), or if an opaque step failed: re-run the operators in checked mode
    /// to learn which step and why.
    pub fn run_cov<const N: usize>(&self, start: Cov<N>) -> Option<Cov<N>> {
        let mut c = start;
        self.run(&mut c).then_some(c)
    }

    /// [`Tape::run_cov`] for the square-root form (the tape recorded in that form).
    pub fn run_factor<const N: usize>(&self, start: CovFactor<N>) -> Option<CovFactor<N>> {
        let mut f = start;
        self.run(&mut f).then_some(f)
    }

    /// Lowers the tape for the concrete form `K` once, for a tape that will run many
    /// times ([`plan`]): constant-index kernels, pairs of them as one call, and in
    /// square-root form a run of variances as one window.
    pub(crate) fn prepare<K: Kernels>(&self) {
        if K::DIM == self.dim && K::FORM == self.form {
            self.program.get_or_init(|| plan::<K>(&self.kernels));
        }
    }

    /// The compiled program, once [`Tape::prepare`] has built it.
    pub(crate) fn program(&self) -> Option<&[Instr]> {
        self.program.get().map(|p| p.as_slice())
    }

    /// Runs every kernel on `k` in place; false if the layout or form does not match,
    /// an opaque step failed or the result is not finite (`k` is then garbage, except
    /// for a prepared tape in covariance form, which leaves `k` as it was).
    ///
    /// A prepared tape runs its program on a local copy of Σ, every simple kernel
    /// dispatched to its constant-index form inlined here, so that the compiler may keep
    /// Σ's entries in registers from one kernel to the next; the few kernels that are
    /// not inlined (windows in square-root form, general and opaque steps) take a copy.
    #[inline]
    pub(crate) fn run<K: Kernels>(&self, k: &mut K) -> bool {
        if K::DIM != self.dim || K::FORM != self.form {
            return false;
        }
        let Some(prog) = self.program() else {
            for kernel in &self.kernels {
                if !self.run_kernel(k, kernel) {
                    return false;
                }
            }
            return k.all_finite();
        };
        if K::FORM == Form::Covariance {
            // Σ's entries may live in registers: a local copy, written back on success.
            let mut w = *k;
            if !self.exec(prog, &mut w) {
                return false;
            }
            *k = w;
            true
        } else {
            // The factor's lobe and fold are calls: it stays in place.
            self.exec(prog, k)
        }
    }

    /// The program's loop, for [`Tape::run`].
    #[inline(always)]
    fn exec<K: Kernels>(&self, prog: &[Instr], w: &mut K) -> bool {
        // Non-inlined kernels take a copy in covariance form, so that `w` itself is
        // only ever touched at constant offsets (and may stay in registers).
        let local = K::FORM == Form::Covariance;
        for ins in prog {
            match *ins {
                Instr::Op { f, a, b } => flat_dispatch!(f;
                    shear |ci, cj| w.k_shear(ci, cj, a);
                    rotate |ci, cj| w.k_rotate(ci, cj, a, b);
                    scale |ci| w.k_scale(ci, a);
                    variance |ci| w.k_add_variance(ci, a);
                    lobe |ci| {
                        if !K::LOBE_1_KEEPS_NON_FINITE && !w.all_finite() {
                            return false;
                        }
                        w.k_lobe_1(ci, a)
                    };
                    pairs {
                        w.k_shear(0, 2, a);
                        w.k_shear(1, 3, b);
                    }, {
                        w.k_shear(2, 0, a);
                        w.k_shear(3, 1, b);
                    }, {
                        w.k_rotate(0, 1, a, b);
                        w.k_rotate(2, 3, a, b);
                    }, {
                        w.k_scale(2, a);
                        w.k_scale(3, b);
                    }, {
                        w.k_add_variance(0, a);
                        w.k_add_variance(1, b);
                    }
                ),
                Instr::Window(ref b) => {
                    if !w.all_finite() {
                        return false;
                    }
                    if local {
                        let mut t = *w;
                        t.k_add_window_factor(&b.p[..b.k], &b.m);
                        *w = t;
                    } else {
                        w.k_add_window_factor(&b.p[..b.k], &b.m);
                    }
                }
                Instr::General(q) => {
                    let ok = if local {
                        let mut t = *w;
                        let ok = self.run_kernel(&mut t, &self.kernels[q]);
                        *w = t;
                        ok
                    } else {
                        self.run_kernel(w, &self.kernels[q])
                    };
                    if !ok {
                        return false;
                    }
                }
            }
        }
        w.all_finite()
    }

    /// One kernel with run-time indices; false if a check before it or an opaque step
    /// failed.
    #[inline]
    fn run_kernel<K: Kernels>(&self, k: &mut K, kernel: &Kernel) -> bool {
        match kernel {
            Kernel::Shear { i, j, s } => k.k_shear(*i as usize, *j as usize, *s),
            Kernel::Scale { i, c } => k.k_scale(*i as usize, *c),
            Kernel::Rotate { i, j, c, s } => k.k_rotate(*i as usize, *j as usize, *c, *s),
            Kernel::AddVariance { i, w } => k.k_add_variance(*i as usize, *w),
            // A lobe may zero a row that held ∞: check before it.
            Kernel::Lobe1 { p, s } => {
                if !K::LOBE_1_KEEPS_NON_FINITE && !k.all_finite() {
                    return false;
                }
                k.k_lobe_1(*p as usize, *s)
            }
            Kernel::AddWindow(b) => {
                if !k.all_finite() {
                    return false;
                }
                k.k_add_window(&b.p[..b.k], &b.m)
            }
            Kernel::Lobe(b) => {
                if !k.all_finite() {
                    return false;
                }
                k.k_lobe(&b.p[..b.k], &b.m)
            }
            Kernel::Congruence(a) => k.k_congruence(a),
            Kernel::Opaque(op) => {
                if !k.all_finite() || op.apply(k).is_err() {
                    return false;
                }
            }
        }
        true
    }
}

/// The [`Spectrum`] a [`Tape`] records through: its raw kernels append to the tape, and
/// reading Σ marks the operator as not recordable. Operators see its layout and form.
#[derive(Debug)]
pub struct Recorder<'a> {
    tape: &'a mut Tape,
    read: Cell<bool>,
}

impl Recorder<'_> {
    fn push(&mut self, k: Kernel) -> Result<(), CovError> {
        self.tape.kernels.push(k);
        Ok(())
    }

    fn mark_read(&self) {
        self.read.set(true);
    }
}

impl Spectrum for Recorder<'_> {
    fn dim(&self) -> usize {
        self.tape.dim
    }
    fn form(&self) -> Form {
        self.tape.form
    }
    fn cov(&self) -> Result<AnyCov, CovError> {
        self.mark_read();
        Err(CovError::NoTransport {
            operator: "Tape".into(),
            reason: "Σ is not known while a tape records".into(),
        })
    }
    fn assign(&mut self, _c: &AnyCov) -> Result<(), CovError> {
        self.mark_read();
        Ok(())
    }
    fn snapshot(&self) -> AnySpectrum {
        self.mark_read();
        let zero = AnyCov::zeros(self.tape.dim).unwrap_or(AnyCov::from(Cov::<2>::zeros()));
        AnySpectrum::new(self.tape.form, &zero)
    }
    fn restore(&mut self, _s: &AnySpectrum) {
        self.mark_read();
    }
    fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        None
    }
    fn concrete(&mut self) -> crate::Concrete<'_> {
        crate::Concrete::Tape(self.tape)
    }

    fn raw_congruence(&mut self, _op: &str, a: &Small) -> Result<(), CovError> {
        self.push(Kernel::Congruence(Box::new(*a)))
    }
    fn raw_shear(&mut self, _op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError> {
        self.push(Kernel::Shear {
            i: i as u8,
            j: j as u8,
            s,
        })
    }
    fn raw_scale(&mut self, _op: &str, i: usize, c: f64) -> Result<(), CovError> {
        self.push(Kernel::Scale { i: i as u8, c })
    }
    fn raw_rotate(&mut self, _op: &str, planes: &[(usize, usize)], c: f64, s: f64) -> Result<(), CovError> {
        for &(i, j) in planes {
            self.push(Kernel::Rotate {
                i: i as u8,
                j: j as u8,
                c,
                s,
            })?;
        }
        Ok(())
    }
    fn raw_add_window(&mut self, _op: &str, p: &[usize], w: &Small) -> Result<(), CovError> {
        self.push(Kernel::AddWindow(Block::new(p, w)))
    }
    fn raw_add_variance(&mut self, _op: &str, i: usize, w: f64) -> Result<(), CovError> {
        self.push(Kernel::AddVariance { i: i as u8, w })
    }
    fn raw_lobe_1(&mut self, _op: &str, p: usize, s: f64) -> Result<(), CovError> {
        self.push(Kernel::Lobe1 { p: p as u8, s })
    }
    fn raw_lobe(&mut self, _op: &str, p: &[usize], s: &Small) -> Result<(), CovError> {
        self.push(Kernel::Lobe(Block::new(p, s)))
    }
}

/// [`Spectrum::concrete`] of a `Cov<N>` (a type check the compiler folds).
pub(crate) fn concrete_cov<const N: usize>(c: &mut Cov<N>) -> crate::Concrete<'_> {
    use crate::Concrete as C;
    let any = c as &mut dyn std::any::Any;
    let found = match N {
        2 => any.downcast_mut::<Cov<2>>().map(C::Cov2),
        3 => any.downcast_mut::<Cov<3>>().map(C::Cov3),
        4 => any.downcast_mut::<Cov<4>>().map(C::Cov4),
        _ => any.downcast_mut::<Cov<5>>().map(C::Cov5),
    };
    found.unwrap_or(C::Other)
}

/// [`Spectrum::concrete`] of a `CovFactor<N>`.
pub(crate) fn concrete_factor<const N: usize>(f: &mut CovFactor<N>) -> crate::Concrete<'_> {
    use crate::Concrete as C;
    let any = f as &mut dyn std::any::Any;
    let found = match N {
        2 => any.downcast_mut::<CovFactor<2>>().map(C::Factor2),
        3 => any.downcast_mut::<CovFactor<3>>().map(C::Factor3),
        4 => any.downcast_mut::<CovFactor<4>>().map(C::Factor4),
        _ => any.downcast_mut::<CovFactor<5>>().map(C::Factor5),
    };
    found.unwrap_or(C::Other)
}

/// A [`Spectrum`] that runs the unchecked kernels of a concrete form directly: the
/// one-shot fast path of [`crate::Chain`] (a chain's first evaluation in a layout and
/// form, and each state of [`crate::eval_batch_with`]). Operators validate their
/// parameters and resolve their axes as usual; the kernels then run without a check or
/// a commit per call, and finiteness is checked where a kernel could hide an ∞ (before
/// a window or a multi-axis lobe, and before a one-axis lobe unless the form's snap
/// keeps an ∞ visible, `Kernels::LOBE_1_KEEPS_NON_FINITE`) and, by the caller, at the
/// end. Any error here only means "not
/// clean": the caller re-runs the operators in checked mode from the start, which
/// reports the failing step exactly.
#[derive(Debug)]
pub(crate) struct Direct<'a, K>(pub(crate) &'a mut K);

impl<K: Kernels> Direct<'_, K> {
    /// `Err` (never shown: the checked re-run reports) if Σ holds a non-finite entry.
    #[inline(always)]
    fn finite(&self, op: &str) -> Result<(), CovError> {
        if self.0.all_finite() {
            Ok(())
        } else {
            Err(CovError::Overflow {
                operator: op.into(),
                row: 0,
                col: 0,
                value: f64::NAN,
            })
        }
    }
}

impl<K: Kernels> Spectrum for Direct<'_, K> {
    fn dim(&self) -> usize {
        K::DIM
    }
    fn form(&self) -> Form {
        K::FORM
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
    fn concrete(&mut self) -> crate::Concrete<'_> {
        self.0.concrete()
    }

    fn raw_congruence(&mut self, _op: &str, a: &Small) -> Result<(), CovError> {
        self.0.k_congruence(a);
        Ok(())
    }
    #[inline(always)]
    fn raw_shear(&mut self, _op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError> {
        self.0.k_shear(i, j, s);
        Ok(())
    }
    #[inline(always)]
    fn raw_scale(&mut self, _op: &str, i: usize, c: f64) -> Result<(), CovError> {
        self.0.k_scale(i, c);
        Ok(())
    }
    #[inline(always)]
    fn raw_rotate(&mut self, _op: &str, planes: &[(usize, usize)], c: f64, s: f64) -> Result<(), CovError> {
        for &(i, j) in planes {
            self.0.k_rotate(i, j, c, s);
        }
        Ok(())
    }
    fn raw_add_window(&mut self, op: &str, p: &[usize], w: &Small) -> Result<(), CovError> {
        self.finite(op)?;
        self.0.k_add_window(p, w);
        Ok(())
    }
    #[inline(always)]
    fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError> {
        // The square-root form folds with reflections, which would spread an ∞ as NaN:
        // the end check still sees it, but check first to keep the fold finite.
        if K::FORM == Form::SquareRoot {
            self.finite(op)?;
        }
        self.0.k_add_variance(i, w);
        Ok(())
    }
    #[inline(always)]
    fn raw_lobe_1(&mut self, op: &str, p: usize, s: f64) -> Result<(), CovError> {
        if !K::LOBE_1_KEEPS_NON_FINITE {
            self.finite(op)?;
        }
        self.0.k_lobe_1(p, s);
        Ok(())
    }
    fn raw_lobe(&mut self, op: &str, p: &[usize], s: &Small) -> Result<(), CovError> {
        self.finite(op)?;
        self.0.k_lobe(p, s);
        Ok(())
    }
}
