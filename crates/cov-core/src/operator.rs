//! The [`Operator`] trait and [`Chain`]s of operators (light paths).

use std::fmt;
use std::sync::Arc;

use crate::direct::Direct;
use crate::form::Kernels;
use crate::{AnyCov, AnySpectrum, AxisSet, Concrete, Cov, CovError, Form, Report, Spectrum};

/// An event on a light path, acting on the spectrum covariance.
///
/// One required method, [`Operator::apply`]. It acts through `&mut dyn Spectrum`, which
/// knows its layout at run time ([`Spectrum::dim`], [`Spectrum::has`],
/// [`Spectrum::transverse_pairs`]) and its form, so the same body serves every layout and
/// both forms ([`Form`]); an operator asked to act in a layout without the axes it needs
/// reports [`CovError::MissingAxis`] (the kernels do). The name defaults to the type's
/// name and the required axes to flatland (`x, u`). The trait is object safe: chains hold
/// `Arc<dyn Operator>`.
///
/// **Typed bodies.** Through `dyn Spectrum` every kernel call is a dynamic call that
/// resolves its axes at run time. An operator can write its body inside
/// [`typed!`](crate::typed): `fn apply(&self, cov) { cov_core::typed!(cov, |cov| { … }) }`.
/// The body, written once, is then compiled for each form and layout, and on a `Cov<N>`
/// or `CovFactor<N>` its kernels inline with constant indices, with the same checks and
/// the same bits as on `&mut dyn Spectrum`. The bundled operators of the bounce chain
/// (travel, curvature, projection, mirror, frame rotation, BRDF lobe, window) do this.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, CovFactor, Operator, Spectrum};
///
/// /// Travel by a fixed distance, written as a third party would.
/// #[derive(Debug)]
/// struct MyTravel(f64);
///
/// impl Operator for MyTravel {
///     fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
///         for &(p, d) in cov.transverse_pairs() {
///             cov.shear(p, d, -self.0)?;
///         }
///         Ok(())
///     }
/// }
///
/// let mut c = Cov::<2>::gaussian([0.1, f64::INFINITY])?;
/// MyTravel(2.0).apply(&mut c)?;
/// assert!(c.get(1, 1) > 0.0); // travel moved spatial content into angle
/// assert_eq!(MyTravel(2.0).name(), "MyTravel");
///
/// // The same code acts on the square-root form, and in 3D.
/// let mut f = CovFactor::from_cov(&Cov::<2>::gaussian([0.1, f64::INFINITY])?);
/// MyTravel(2.0).apply(&mut f)?;
/// approx::assert_relative_eq!(f.to_cov()?, c, max_relative = 1e-14);
/// let mut c4 = Cov::<4>::gaussian([0.1, 0.1, f64::INFINITY, f64::INFINITY])?;
/// MyTravel(2.0).apply(&mut c4)?;
/// assert!(c4.get(3, 3) > 0.0);
/// # Ok::<(), CovError>(())
/// ```
pub trait Operator: fmt::Debug + Send + Sync {
    /// Applies the operator to Σ in place.
    ///
    /// # Errors
    /// Whatever the operator finds wrong (missing axis, no transport, overflow). On error
    /// Σ may be partly updated; [`Chain`] restores it.
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError>;

    /// A short name for tables and error messages (default: the type's name without its
    /// module path).
    fn name(&self) -> &str {
        short_type_name(std::any::type_name::<Self>())
    }

    /// The axes this operator needs (default: `x, u`). A path is traced in the smallest
    /// layout containing what all its operators need.
    fn requires(&self) -> AxisSet {
        AxisSet::FLAT
    }

    /// What this operator reports when a chain is traced, given Σ just before it (a
    /// sensor's per-pixel decisions). Default: nothing. Reports land in
    /// [`Step::report`], typed ([`Report::get`]).
    ///
    /// # Errors
    /// A report that cannot be computed (an overflowing decision, say).
    fn report(&self, before: &AnyCov) -> Result<Option<Report>, CovError> {
        let _ = before;
        Ok(None)
    }

    /// Whether this operator ends a path: nothing may follow it, and it may stand only
    /// once, at the top level (a sensor). Default: no.
    fn is_terminal(&self) -> bool {
        false
    }
}

/// Runs an operator's body with the spectrum's concrete type known: `typed!(cov, |s|
/// body)` evaluates `body` with `s` bound to the `Cov<N>` or `CovFactor<N>` behind `cov`
/// (a `&mut dyn Spectrum`), or to `cov` itself for any other spectrum. The body is
/// written once and compiled for each form and layout, so its kernel calls inline with
/// constant axis indices instead of going through the trait object; the results, bits
/// and errors are those of the same body on `&mut dyn Spectrum`. `?` and `return` in the
/// body leave the enclosing function, as in any block.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, Operator, Spectrum};
///
/// #[derive(Debug)]
/// struct MyTravel(f64);
///
/// impl Operator for MyTravel {
///     fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
///         cov_core::typed!(cov, |s| {
///             for &(p, d) in s.transverse_pairs() {
///                 s.shear(p, d, -self.0)?;
///             }
///             Ok(())
///         })
///     }
/// }
///
/// let mut c = Cov::<4>::gaussian([0.1, 0.1, f64::INFINITY, f64::INFINITY])?;
/// MyTravel(2.0).apply(&mut c)?;
/// assert!(c.get(3, 3) > 0.0);
/// # Ok::<(), CovError>(())
/// ```
#[macro_export]
macro_rules! typed {
    ($cov:expr, |$s:ident| $body:expr) => {{
        let cov: &mut dyn $crate::Spectrum = $cov;
        match cov.concrete() {
            $crate::Concrete::Cov2($s) => $body,
            $crate::Concrete::Cov3($s) => $body,
            $crate::Concrete::Cov4($s) => $body,
            $crate::Concrete::Cov5($s) => $body,
            $crate::Concrete::Factor2($s) => $body,
            $crate::Concrete::Factor3($s) => $body,
            $crate::Concrete::Factor4($s) => $body,
            $crate::Concrete::Factor5($s) => $body,
            $crate::Concrete::Other => {
                let $s = cov;
                $body
            }
        }
    }};
}

fn short_type_name(full: &'static str) -> &'static str {
    let base = full.split('<').next().unwrap_or(full);
    base.rsplit("::").next().unwrap_or(base)
}

/// A light path: operators applied in order. It has no layout of its own: it evaluates Σ
/// of any layout its operators fit.
///
/// ```
/// use cov_core::{Axis, Chain, Cov, CovError, Form, Operator, Spectrum};
/// # #[derive(Debug)] struct Travel(f64);
/// # impl Operator for Travel {
/// #     fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> { c.shear(Axis::X, Axis::U, -self.0) }
/// # }
/// let chain = Chain::new().with(Travel(1.0)).with(Travel(2.0));
/// let start = Cov::<2>::gaussian([0.1, 1.0])?;
/// let trace = chain.trace(start)?;
/// assert_eq!(trace.steps.len(), 2);
/// assert_eq!(trace.last().to::<2>(), Some(chain.eval(start)?));
/// // The covariance form gives the same Σ to rounding.
/// let c = chain.eval_in(Form::Covariance, start)?;
/// approx::assert_relative_eq!(c, chain.eval(start)?, max_relative = 1e-12);
/// # Ok::<(), CovError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct Chain {
    steps: Vec<Arc<dyn Operator>>,
}

/// One recorded step of a [`Chain::trace`].
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// Name of the operator.
    pub name: String,
    /// Σ after the operator.
    pub cov: AnyCov,
    /// What the operator reported ([`Operator::report`]), if anything.
    pub report: Option<Report>,
}

/// Σ before and after every step of a chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// Σ before the first step.
    pub start: AnyCov,
    /// One entry per step.
    pub steps: Vec<Step>,
}

impl Trace {
    /// Σ after the last step (the start if the chain is empty).
    pub fn last(&self) -> AnyCov {
        self.steps.last().map(|s| s.cov).unwrap_or(self.start)
    }

    /// The reports of the trace, with the index of their step.
    pub fn reports(&self) -> impl Iterator<Item = (usize, &Report)> {
        self.steps
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.report.as_ref().map(|r| (i, r)))
    }
}

impl Chain {
    /// An empty chain (the identity).
    pub fn new() -> Self {
        Chain::default()
    }

    /// Appends an operator.
    pub fn push(&mut self, op: impl Operator + 'static) {
        self.push_shared(Arc::new(op));
    }

    /// Appends a shared operator.
    pub fn push_shared(&mut self, op: Arc<dyn Operator>) {
        self.steps.push(op);
    }

    /// The fast path on a concrete form, on a copy of Σ committed if it ran clean: the
    /// operators through [`Direct`] (typed bodies on the checked kernels, others on the
    /// unchecked ones), with one finiteness check at the end and no per-step check. Otherwise the checked path, which finds and reports the failing step and
    /// leaves Σ as it was.
    fn apply_fast<K: Kernels>(&self, k: &mut K) -> Result<(), CovError> {
        let mut work = *k;
        if self.apply_direct(&mut work) {
            *k = work;
            return Ok(());
        }
        self.apply_checked(k)
    }

    /// Every step on the unchecked kernels; whether all ran and Σ is finite (`k` is
    /// garbage otherwise).
    pub(crate) fn apply_direct<K: Kernels>(&self, k: &mut K) -> bool {
        let mut d = Direct(k);
        self.steps.iter().all(|op| op.apply(&mut d).is_ok()) && d.0.all_finite()
    }

    /// Every step with its checks: parameters, axes, the kernels' overflow checks and a
    /// finiteness check after each step; Σ is restored to its start on error.
    pub(crate) fn apply_checked(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        let start = cov.snapshot();
        for (index, op) in self.steps.iter().enumerate() {
            if let Err(e) = apply_step(index, op.as_ref(), cov) {
                cov.restore(&start);
                return Err(e);
            }
        }
        Ok(())
    }

    /// Builder form of [`Chain::push`].
    pub fn with(mut self, op: impl Operator + 'static) -> Self {
        self.push(op);
        self
    }

    /// Number of steps.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Whether the chain has no step.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// The operators, in order.
    pub fn operators(&self) -> impl Iterator<Item = &dyn Operator> {
        self.steps.iter().map(|b| b.as_ref())
    }

    /// Names joined with `+` (for an enclosing operator's name).
    pub fn names(&self) -> String {
        self.steps
            .iter()
            .map(|op| op.name())
            .collect::<Vec<_>>()
            .join("+")
    }

    /// Applies every step to `start` in the default form ([`Form::SquareRoot`]) and
    /// returns the result.
    ///
    /// # Errors
    /// The first failing step, as [`CovError::Step`] with its index and name; also a
    /// step that returns a non-finite Σ (caught here even if the operator did not check).
    pub fn eval<const N: usize>(&self, start: Cov<N>) -> Result<Cov<N>, CovError> {
        self.eval_in(Form::default(), start)
    }

    /// Applies every step to `start`, holding Σ in `form` along the way.
    ///
    /// # Errors
    /// As [`Chain::eval`]; in square-root form also an overflow of the final Σ (the
    /// factor can carry √Σ beyond the range where Σ itself fits in f64).
    pub fn eval_in<const N: usize>(&self, form: Form, start: Cov<N>) -> Result<Cov<N>, CovError> {
        match form {
            Form::Covariance => {
                let mut c = start;
                self.apply(&mut c)?;
                Ok(c)
            }
            Form::SquareRoot => {
                let mut f = crate::CovFactor::from_cov(&start);
                self.apply(&mut f)?;
                f.to_cov()
            }
        }
    }

    /// [`Chain::eval_in`] for a Σ whose layout is known at run time.
    ///
    /// # Errors
    /// As [`Chain::eval_in`].
    pub fn eval_any(&self, form: Form, start: &AnyCov) -> Result<AnyCov, CovError> {
        let mut held = AnySpectrum::new(form, start);
        self.apply(held.as_spectrum_mut())?;
        held.cov()
    }

    /// Like [`Chain::eval`], recording Σ (and any report) after every step.
    ///
    /// # Errors
    /// As [`Chain::eval`].
    pub fn trace(&self, start: impl Into<AnyCov>) -> Result<Trace, CovError> {
        self.trace_in(Form::default(), start)
    }

    /// Like [`Chain::eval_in`], recording Σ (and any report) after every step.
    ///
    /// # Errors
    /// As [`Chain::eval_in`], and a failing report (as [`CovError::Step`]).
    pub fn trace_in(&self, form: Form, start: impl Into<AnyCov>) -> Result<Trace, CovError> {
        let start = start.into();
        let mut held = AnySpectrum::new(form, &start);
        let s = held.as_spectrum_mut();
        let mut steps = Vec::with_capacity(self.steps.len());
        let mut before = start;
        for (index, op) in self.steps.iter().enumerate() {
            let report = op
                .report(&before)
                .map_err(|e| step_error(index, op.as_ref(), e))?;
            apply_step(index, op.as_ref(), s)?;
            let cov = s.cov().map_err(|e| step_error(index, op.as_ref(), e))?;
            steps.push(Step {
                name: op.name().to_string(),
                cov,
                report,
            });
            before = cov;
        }
        Ok(Trace { start, steps })
    }
}

fn step_error(index: usize, op: &dyn Operator, e: CovError) -> CovError {
    CovError::Step {
        index,
        operator: op.name().to_string(),
        source: Box::new(e),
    }
}

/// Applies one step and checks its result. It does not restore Σ on error: a failing
/// chain restores its start once ([`Chain`]'s `apply`), and `eval`/`trace` discard Σ.
fn apply_step(index: usize, op: &dyn Operator, c: &mut dyn Spectrum) -> Result<(), CovError> {
    let result = op.apply(c).and_then(|()| match c.first_non_finite() {
        None => Ok(()),
        Some(at) => Err(CovError::overflow(op.name(), at)),
    });
    result.map_err(|e| step_error(index, op, e))
}

impl Operator for Chain {
    /// On `Cov<N>` and `CovFactor<N>` this runs the operators on a copy of Σ (see
    /// `direct.rs`) and checks finiteness once, at the end; it falls back to the checked steps only if
    /// that result is not clean, so errors name the same step, operator and value as the
    /// checked path, and Σ is left as it was on error. Other spectra take the checked
    /// path.
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        match cov.concrete() {
            Concrete::Cov2(c) => self.apply_fast(c),
            Concrete::Cov3(c) => self.apply_fast(c),
            Concrete::Cov4(c) => self.apply_fast(c),
            Concrete::Cov5(c) => self.apply_fast(c),
            Concrete::Factor2(f) => self.apply_fast(f),
            Concrete::Factor3(f) => self.apply_fast(f),
            Concrete::Factor4(f) => self.apply_fast(f),
            Concrete::Factor5(f) => self.apply_fast(f),
            Concrete::Other => self.apply_checked(cov),
        }
    }

    fn name(&self) -> &str {
        "Chain"
    }

    /// The union of what the steps need.
    fn requires(&self) -> AxisSet {
        self.steps
            .iter()
            .fold(AxisSet::FLAT, |s, op| s.union(op.requires()))
    }
}
