//! The operator registry: names → parameter structs → operators.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use cov_core::{AxisSet, CovError, Operator, Spectrum, SpectrumMut};
use serde::de::DeserializeOwned;

/// An operator whose layout is chosen at run time: what a path holds. Implemented for
/// every type that implements [`Operator`] for all four layouts.
pub trait PathOperator: fmt::Debug + Send + Sync {
    /// Name for tables and messages.
    fn op_name(&self) -> &str;
    /// Axes needed.
    fn op_requires(&self) -> AxisSet;
    /// Applies in flatland.
    ///
    /// # Errors
    /// As the operator.
    fn apply2(&self, c: &mut dyn Spectrum<2>) -> Result<(), CovError>;
    /// Applies in flatland with time.
    ///
    /// # Errors
    /// As the operator.
    fn apply3(&self, c: &mut dyn Spectrum<3>) -> Result<(), CovError>;
    /// Applies in 3D.
    ///
    /// # Errors
    /// As the operator.
    fn apply4(&self, c: &mut dyn Spectrum<4>) -> Result<(), CovError>;
    /// Applies in 3D with time.
    ///
    /// # Errors
    /// As the operator.
    fn apply5(&self, c: &mut dyn Spectrum<5>) -> Result<(), CovError>;
    /// The concrete operator, for callers that look for a particular one (the CLI finds a
    /// final `Sensor` this way).
    fn as_any(&self) -> &dyn std::any::Any;
}

impl<T> PathOperator for T
where
    T: Operator<2> + Operator<3> + Operator<4> + Operator<5> + 'static,
{
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn op_name(&self) -> &str {
        Operator::<2>::name(self)
    }
    fn op_requires(&self) -> AxisSet {
        Operator::<5>::requires(self)
    }
    fn apply2(&self, c: &mut dyn Spectrum<2>) -> Result<(), CovError> {
        Operator::<2>::apply(self, c)
    }
    fn apply3(&self, c: &mut dyn Spectrum<3>) -> Result<(), CovError> {
        Operator::<3>::apply(self, c)
    }
    fn apply4(&self, c: &mut dyn Spectrum<4>) -> Result<(), CovError> {
        Operator::<4>::apply(self, c)
    }
    fn apply5(&self, c: &mut dyn Spectrum<5>) -> Result<(), CovError> {
        Operator::<5>::apply(self, c)
    }
}

/// A shared [`PathOperator`] used as an [`Operator`] of any layout.
#[derive(Clone, Debug)]
pub struct DynOperator(pub Arc<dyn PathOperator>);

impl<const N: usize> Operator<N> for DynOperator {
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        match cov.layout() {
            SpectrumMut::Two(c) => self.0.apply2(c),
            SpectrumMut::Three(c) => self.0.apply3(c),
            SpectrumMut::Four(c) => self.0.apply4(c),
            SpectrumMut::Five(c) => self.0.apply5(c),
        }
    }
    fn name(&self) -> &str {
        self.0.op_name()
    }
    fn requires(&self) -> AxisSet {
        self.0.op_requires()
    }
}

/// One documented parameter of an operator (for `covtrace list` and the docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    /// Field name in RON.
    pub name: &'static str,
    /// Unit (`m`, `1/m`, `rad`, `–` …).
    pub unit: &'static str,
    /// What it means and its domain.
    pub doc: &'static str,
}

/// The parameters of an operator as written in RON, and how to build it.
///
/// Implement it on a `#[derive(Deserialize)] #[serde(deny_unknown_fields)]` struct; then
/// one call, [`Registry::register`], makes `NAME(field: value, …)` usable in path files.
pub trait OperatorSpec: DeserializeOwned + 'static {
    /// The name used in RON (`Travel`).
    const NAME: &'static str;
    /// One line describing the operator.
    const SUMMARY: &'static str;
    /// The parameters, in the order of the struct.
    const PARAMS: &'static [Param];
    /// Whether the operator has no parameters and is written as a bare name (`Mirror`).
    const UNIT: bool = false;
    /// The operator built from the parameters.
    type Op: Operator<2> + Operator<3> + Operator<4> + Operator<5> + 'static;
    /// Validates the parameters and builds the operator.
    ///
    /// # Errors
    /// Invalid parameters (NaN, out of range): the message names the parameter.
    fn build(self) -> Result<Self::Op, CovError>;
    /// For [`OperatorSpec::UNIT`] operators: the parameters of a bare name.
    fn unit() -> Option<Self> {
        None
    }
}

/// Builds a unit (parameterless) operator, `None` if the spec has no unit form.
type BuildUnitFn = fn() -> Option<Result<Arc<dyn PathOperator>, CovError>>;

/// Builds an operator from its parameters.
type BuildFn =
    fn(&mut dyn erased_serde::Deserializer<'_>) -> Result<Arc<dyn PathOperator>, erased_serde::Error>;

/// What the registry knows of one operator.
#[derive(Clone, Copy)]
pub struct Entry {
    /// RON name.
    pub name: &'static str,
    /// One-line summary.
    pub summary: &'static str,
    /// Parameters.
    pub params: &'static [Param],
    /// Written as a bare name.
    pub unit: bool,
    pub(crate) build: BuildFn,
    pub(crate) build_unit: BuildUnitFn,
}

impl fmt::Debug for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Entry({})", self.name)
    }
}

fn build_erased<S: OperatorSpec>(
    d: &mut dyn erased_serde::Deserializer<'_>,
) -> Result<Arc<dyn PathOperator>, erased_serde::Error> {
    use serde::de::Error;
    let spec: S = erased_serde::deserialize(d)?;
    let op = spec.build().map_err(erased_serde::Error::custom)?;
    Ok(Arc::new(op))
}

fn build_unit<S: OperatorSpec>() -> Option<Result<Arc<dyn PathOperator>, CovError>> {
    S::unit().map(|s| s.build().map(|op| Arc::new(op) as Arc<dyn PathOperator>))
}

/// The explicit registry of operators a path file may name.
///
/// The facade crate's `covtrace::registry()` returns one with every built-in operator;
/// a third party adds its own with one call:
///
/// ```
/// use cov_core::{Axis, Cov, CovError, Operator, Spectrum};
/// use cov_path::{OperatorSpec, Param, Path, Registry};
///
/// #[derive(Debug)]
/// struct Blur(f64);
/// impl<const N: usize> Operator<N> for Blur {
///     fn apply(&self, c: &mut dyn Spectrum<N>) -> Result<(), CovError> { c.convolve(&[Axis::U], &[self.0]) }
///     fn name(&self) -> &str { "Blur" }
/// }
///
/// #[derive(serde::Deserialize)]
/// #[serde(deny_unknown_fields)]
/// struct BlurSpec { s: f64 }
/// impl OperatorSpec for BlurSpec {
///     const NAME: &'static str = "Blur";
///     const SUMMARY: &'static str = "an angular blur";
///     const PARAMS: &'static [Param] = &[Param { name: "s", unit: "(cycles/tan)²", doc: "lobe spectrum, ≥ 0" }];
///     type Op = Blur;
///     fn build(self) -> Result<Blur, CovError> {
///         CovError::check_non_negative("Blur", "s", self.s)?;
///         Ok(Blur(self.s))
///     }
/// }
///
/// let mut registry = Registry::new();
/// registry.register::<BlurSpec>();
/// let path = Path::parse("Path(source: Gaussian(x: 0.1, u: 0.2), operators: [Blur(s: 1.0)])", &registry)?;
/// let result = path.eval()?;
/// assert_eq!(result.layout, 2);
/// # Ok::<(), cov_path::PathError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct Registry {
    entries: BTreeMap<&'static str, Entry>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// Registers `S` under `S::NAME` (replacing an earlier entry of that name).
    pub fn register<S: OperatorSpec>(&mut self) -> &mut Self {
        self.entries.insert(
            S::NAME,
            Entry {
                name: S::NAME,
                summary: S::SUMMARY,
                params: S::PARAMS,
                unit: S::UNIT,
                build: build_erased::<S>,
                build_unit: build_unit::<S>,
            },
        );
        self
    }

    /// The entry named `name`.
    pub fn get(&self, name: &str) -> Option<&Entry> {
        self.entries.get(name)
    }

    /// All entries, by name.
    pub fn entries(&self) -> impl Iterator<Item = &Entry> {
        self.entries.values()
    }

    /// Names, comma-separated (for error messages).
    pub fn names(&self) -> String {
        self.entries.keys().copied().collect::<Vec<_>>().join(", ")
    }

    /// Number of entries.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether the registry is empty.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}
