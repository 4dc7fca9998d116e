//! Compiled chains: a [`Tape`] is the list of kernel calls a sequence of operators makes
//! in one layout and form, with axes resolved to indices and parameters checked once,
//! when it is recorded. Running it is the fast path of [`crate::Chain`]: no parameter
//! validation, no axis lookup, no `Result` and no finiteness check per kernel, no dynamic
//! dispatch, and no copy of Σ per step. Finiteness is checked where a later kernel could
//! hide an ∞ (before a lobe, which may zero a row) and once at the end; a run that fails
//! is repeated in checked mode by the caller, which finds and reports the failing step
//! exactly as before.
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
use std::sync::Arc;

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
#[derive(Clone, Debug)]
pub struct Tape {
    dim: usize,
    form: Form,
    kernels: Vec<Kernel>,
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
        Ok(Tape {
            dim,
            form,
            kernels: Vec::new(),
        })
    }

    /// An empty tape; `dim` is a valid layout size (from a `Kernels` type).
    pub(crate) fn empty(dim: usize, form: Form) -> Tape {
        Tape {
            dim,
            form,
            kernels: Vec::new(),
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
    }

    /// Appends what `op` does.
    ///
    /// # Errors
    /// What `op` reports for this layout (a missing axis, say), or
    /// [`CovError::NoTransport`] if `op` reads Σ, so that its kernel calls cannot be
    /// recorded (use [`Tape::push_shared`]). The tape is unchanged on error.
    pub fn record(&mut self, op: &dyn Operator) -> Result<(), CovError> {
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

    /// Runs every kernel on `k` in place; false if the layout or form does not match,
    /// an opaque step failed or the result is not finite (`k` is then garbage).
    #[inline]
    pub(crate) fn run<K: Kernels>(&self, k: &mut K) -> bool {
        if K::DIM != self.dim || K::FORM != self.form {
            return false;
        }
        for kernel in &self.kernels {
            match kernel {
                Kernel::Shear { i, j, s } => k.k_shear(*i as usize, *j as usize, *s),
                Kernel::Scale { i, c } => k.k_scale(*i as usize, *c),
                Kernel::Rotate { i, j, c, s } => k.k_rotate(*i as usize, *j as usize, *c, *s),
                Kernel::AddVariance { i, w } => k.k_add_variance(*i as usize, *w),
                Kernel::Lobe1 { p, s } => {
                    // A lobe may zero a row that held ∞: check before it.
                    if !k.all_finite() {
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
        }
        k.all_finite()
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
