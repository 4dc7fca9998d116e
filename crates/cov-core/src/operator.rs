//! The [`Operator`] trait and [`Chain`]s of operators (light paths).

use std::fmt;

use crate::axis::layout_set;
use crate::{AxisSet, Cov, CovError, CovFactor, Form, Spectrum};

/// An event on a light path, acting on the spectrum covariance of layout `N`.
///
/// One required method, [`Operator::apply`]; the name defaults to the type's name and the
/// required axes to flatland (`x, u`). `apply` acts through the [`Spectrum`] interface (the
/// kernels of the four rules), so the same code runs on Σ in covariance or square-root
/// form ([`Form`]); a `&mut dyn Spectrum<N>` is a `&mut dyn Spectrum<N>`. The trait is object safe: chains hold
/// `Box<dyn Operator<N>>`. An operator that can act in several layouts implements the
/// trait for each `N` (usually with one generic impl), and reports
/// [`CovError::MissingAxis`] when asked to act in a layout without the axes it needs.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, CovFactor, Operator, Spectrum};
///
/// /// Travel by a fixed distance, written as a third party would.
/// #[derive(Debug)]
/// struct MyTravel(f64);
///
/// impl<const N: usize> Operator<N> for MyTravel {
///     fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
///         cov.shear(Axis::X, Axis::U, -self.0)?;
///         if Cov::<N>::has(Axis::Y) {
///             cov.shear(Axis::Y, Axis::V, -self.0)?;
///         }
///         Ok(())
///     }
/// }
///
/// let mut c = Cov::<2>::gaussian([0.1, f64::INFINITY])?;
/// Operator::<2>::apply(&MyTravel(2.0), &mut c)?;
/// assert!(c.get(1, 1) > 0.0); // travel moved spatial content into angle
/// assert_eq!(Operator::<2>::name(&MyTravel(2.0)), "MyTravel");
///
/// // The same code acts on the square-root form.
/// let mut f = CovFactor::from_cov(&Cov::<2>::gaussian([0.1, f64::INFINITY])?);
/// Operator::<2>::apply(&MyTravel(2.0), &mut f)?;
/// approx::assert_relative_eq!(f.to_cov()?, c, max_relative = 1e-14);
/// # Ok::<(), CovError>(())
/// ```
pub trait Operator<const N: usize>: fmt::Debug + Send + Sync {
    /// Applies the operator to Σ in place.
    ///
    /// # Errors
    /// Whatever the operator finds wrong (missing axis, no transport, overflow). On error
    /// Σ may be partly updated; [`Chain`] restores it.
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError>;

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
}

fn short_type_name(full: &'static str) -> &'static str {
    let base = full.split('<').next().unwrap_or(full);
    base.rsplit("::").next().unwrap_or(base)
}

/// A light path: operators applied in order.
///
/// ```
/// use cov_core::{Axis, Chain, Cov, CovError, Form, Operator, Spectrum};
/// # #[derive(Debug)] struct Travel(f64);
/// # impl<const N: usize> Operator<N> for Travel {
/// #     fn apply(&self, c: &mut dyn Spectrum<N>) -> Result<(), CovError> { c.shear(Axis::X, Axis::U, -self.0) }
/// # }
/// let chain = Chain::<2>::new().with(Travel(1.0)).with(Travel(2.0));
/// let start = Cov::<2>::gaussian([0.1, 1.0])?;
/// let trace = chain.trace(start)?;
/// assert_eq!(trace.steps.len(), 2);
/// assert_eq!(trace.last(), chain.eval(start)?);
/// // The covariance form gives the same Σ to rounding.
/// let c = chain.eval_in(Form::Covariance, start)?;
/// approx::assert_relative_eq!(c, chain.eval(start)?, max_relative = 1e-12);
/// # Ok::<(), CovError>(())
/// ```
#[derive(Debug, Default)]
pub struct Chain<const N: usize> {
    steps: Vec<Box<dyn Operator<N>>>,
}

/// One recorded step of a [`Chain::trace`].
#[derive(Clone, Debug, PartialEq)]
pub struct Step<const N: usize> {
    /// Name of the operator.
    pub name: String,
    /// Σ after the operator.
    pub cov: Cov<N>,
}

/// Σ before and after every step of a chain.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace<const N: usize> {
    /// Σ before the first step.
    pub start: Cov<N>,
    /// One entry per step.
    pub steps: Vec<Step<N>>,
}

impl<const N: usize> Trace<N> {
    /// Σ after the last step (the start if the chain is empty).
    pub fn last(&self) -> Cov<N> {
        self.steps.last().map(|s| s.cov).unwrap_or(self.start)
    }
}

impl<const N: usize> Chain<N> {
    /// An empty chain (the identity).
    pub fn new() -> Self {
        Chain { steps: Vec::new() }
    }

    /// Appends an operator.
    pub fn push(&mut self, op: impl Operator<N> + 'static) {
        self.steps.push(Box::new(op));
    }

    /// Appends a boxed operator.
    pub fn push_boxed(&mut self, op: Box<dyn Operator<N>>) {
        self.steps.push(op);
    }

    /// Builder form of [`Chain::push`].
    pub fn with(mut self, op: impl Operator<N> + 'static) -> Self {
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
    pub fn operators(&self) -> impl Iterator<Item = &dyn Operator<N>> {
        self.steps.iter().map(|b| b.as_ref())
    }

    /// Applies every step to `start` in the default form ([`Form::SquareRoot`]) and
    /// returns the result.
    ///
    /// # Errors
    /// The first failing step, as [`CovError::Step`] with its index and name; also a
    /// step that returns a non-finite Σ (caught here even if the operator did not check).
    pub fn eval(&self, start: Cov<N>) -> Result<Cov<N>, CovError> {
        self.eval_in(Form::default(), start)
    }

    /// Applies every step to `start`, holding Σ in `form` along the way.
    ///
    /// # Errors
    /// As [`Chain::eval`]; in square-root form also an overflow of the final Σ (the
    /// factor can carry √Σ beyond the range where Σ itself fits in f64).
    pub fn eval_in(&self, form: Form, start: Cov<N>) -> Result<Cov<N>, CovError> {
        match form {
            Form::Covariance => {
                let mut c = start;
                self.apply(&mut c)?;
                Ok(c)
            }
            Form::SquareRoot => {
                let mut f = CovFactor::from_cov(&start);
                self.apply(&mut f)?;
                f.to_cov()
            }
        }
    }

    /// Like [`Chain::eval`], recording Σ after every step.
    ///
    /// # Errors
    /// As [`Chain::eval`].
    pub fn trace(&self, start: Cov<N>) -> Result<Trace<N>, CovError> {
        self.trace_in(Form::default(), start)
    }

    /// Like [`Chain::eval_in`], recording Σ after every step.
    ///
    /// # Errors
    /// As [`Chain::eval_in`].
    pub fn trace_in(&self, form: Form, start: Cov<N>) -> Result<Trace<N>, CovError> {
        let mut cov = start;
        let mut factor: CovFactor<N>;
        let s: &mut dyn Spectrum<N> = match form {
            Form::Covariance => &mut cov,
            Form::SquareRoot => {
                factor = CovFactor::from_cov(&start);
                &mut factor
            }
        };
        let mut steps = Vec::with_capacity(self.steps.len());
        for (index, op) in self.steps.iter().enumerate() {
            apply_step(index, op.as_ref(), s)?;
            let cov = s.cov().map_err(|e| step_error(index, op.as_ref(), e))?;
            steps.push(Step {
                name: op.name().to_string(),
                cov,
            });
        }
        Ok(Trace { start, steps })
    }
}

fn step_error<const N: usize>(index: usize, op: &dyn Operator<N>, e: CovError) -> CovError {
    CovError::Step {
        index,
        operator: op.name().to_string(),
        source: Box::new(e),
    }
}

fn apply_step<const N: usize>(
    index: usize,
    op: &dyn Operator<N>,
    c: &mut dyn Spectrum<N>,
) -> Result<(), CovError> {
    let before = c.snapshot();
    let result = op.apply(c).and_then(|()| c.check_finite(op.name()));
    if let Err(e) = result {
        c.restore(&before);
        return Err(step_error(index, op, e));
    }
    Ok(())
}

impl<const N: usize> Operator<N> for Chain<N> {
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        let start = cov.snapshot();
        for (index, op) in self.steps.iter().enumerate() {
            if let Err(e) = apply_step(index, op.as_ref(), cov) {
                cov.restore(&start);
                return Err(e);
            }
        }
        Ok(())
    }

    fn name(&self) -> &str {
        "Chain"
    }

    fn requires(&self) -> AxisSet {
        self.steps
            .iter()
            .fold(AxisSet::FLAT, |s, op| s.union(op.requires()))
    }
}

/// Checks that the layout `N` has every axis `op` requires.
///
/// # Errors
/// [`CovError::MissingAxis`] naming the first missing axis.
pub fn check_layout<const N: usize>(op: &dyn Operator<N>) -> Result<(), CovError> {
    let have = layout_set(N);
    for axis in op.requires().iter() {
        if !have.contains(axis) {
            return Err(CovError::MissingAxis { axis, layout: N });
        }
    }
    Ok(())
}
