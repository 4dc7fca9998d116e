//! The operator registry: names → specs → operators, for RON files.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use cov_core::{CovError, Operator, OperatorSpec, Param, Registrar};

use crate::de::Reader;

/// Builds an operator from its parameters, read by `reader` (nested lists included).
type BuildFn = for<'a, 'de> fn(
    &'a mut dyn erased_serde::Deserializer<'de>,
    &Reader<'_>,
) -> Result<Arc<dyn Operator>, erased_serde::Error>;

/// Builds an operator from the defaults of every parameter, `None` if one is required.
type DefaultsFn = fn() -> Option<Result<Arc<dyn Operator>, CovError>>;

/// What the registry knows of one operator.
#[derive(Clone, Copy)]
pub struct Entry {
    /// RON name.
    pub name: &'static str,
    /// One-line summary.
    pub summary: &'static str,
    /// Parameters.
    pub params: &'static [Param],
    pub(crate) build: BuildFn,
    pub(crate) defaults: DefaultsFn,
}

impl fmt::Debug for Entry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Entry({})", self.name)
    }
}

fn build_erased<S: OperatorSpec>(
    d: &mut dyn erased_serde::Deserializer<'_>,
    reader: &Reader<'_>,
) -> Result<Arc<dyn Operator>, erased_serde::Error> {
    use serde::de::Error;
    let spec = S::deserialize_in(d, reader)?;
    let op = spec.build().map_err(erased_serde::Error::custom)?;
    Ok(Arc::new(op))
}

fn build_defaults<S: OperatorSpec>() -> Option<Result<Arc<dyn Operator>, CovError>> {
    S::defaults().map(|s| s.build().map(|op| Arc::new(op) as Arc<dyn Operator>))
}

/// The explicit registry of operators a path file may name.
///
/// The facade crate's `covtrace::registry()` returns one with every built-in operator;
/// a third party adds its own with one call:
///
/// ```
/// use cov_core::{Axis, Build, Checked, CovError, Operator, OperatorSpec, Registrar, Spectrum};
/// use cov_path::{Path, Registry};
///
/// #[derive(Debug)]
/// struct Blur(f64);
/// impl Operator for Blur {
///     fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> { c.convolve(&[Axis::U], &[self.0]) }
/// }
///
/// /// `Blur(s: 1.0)`.
/// #[derive(OperatorSpec)]
/// #[operator(summary = "an angular blur")]
/// struct BlurSpec {
///     /// Lobe spectrum.
///     #[param(unit = "(cycles/tan)²", non_negative)]
///     s: f64,
/// }
/// impl Build for BlurSpec {
///     type Op = Blur;
///     fn make(p: Checked<Self>) -> Result<Blur, CovError> {
///         Ok(Blur(p.s))
///     }
/// }
///
/// let mut registry = Registry::new();
/// registry.add::<BlurSpec>();
/// let path = Path::parse("Path(source: Gaussian(x: 0.1, u: 0.2), operators: [Blur(s: 1.0)])", &registry)?;
/// let result = path.eval()?;
/// assert_eq!(result.layout, 2);
/// // The declared domain, checked and positioned at the parameter as written.
/// let text = "Path(source: Gaussian(x: 0.1, u: 0.2),\n  operators: [Blur(s: -1.0)])";
/// let err = Path::parse(text, &registry).unwrap_err().to_string();
/// assert!(err.contains(":2:20: Blur: parameter `s` = -1 is out of range: must be ≥ 0"), "{err}");
/// # Ok::<(), cov_path::PathError>(())
/// ```
#[derive(Clone, Debug, Default)]
pub struct Registry {
    entries: BTreeMap<&'static str, Entry>,
    left_out: Vec<&'static str>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Self::default()
    }

    /// Notes that this build leaves out the operators of a cargo feature (`covtrace`'s
    /// `brdf`, say): a file that names an operator the registry does not know is then told
    /// that it may be one of them.
    pub fn leave_out(&mut self, feature: &'static str) {
        if !self.left_out.contains(&feature) {
            self.left_out.push(feature);
        }
    }

    /// The features [`Registry::leave_out`] noted, in the order noted.
    pub fn left_out(&self) -> &[&'static str] {
        &self.left_out
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

    /// The registered name closest to `name`, when one is close enough to be what was meant:
    /// the same letters in another case, or at most two edits away (Damerau–Levenshtein;
    /// one for names of four letters or fewer).
    pub fn closest(&self, name: &str) -> Option<&'static str> {
        let lower = name.to_lowercase();
        let near = if name.chars().count() <= 4 { 1 } else { 2 };
        self.entries
            .keys()
            .map(|k| {
                let d = if k.to_lowercase() == lower {
                    0
                } else {
                    strsim::damerau_levenshtein(k, name)
                };
                (d, *k)
            })
            .filter(|(d, _)| *d <= near)
            .min()
            .map(|(_, k)| k)
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

/// The one way to register: `registry.add::<MySpec>()` (with [`Registrar`] in scope).
impl Registrar for Registry {
    /// Adds `S` under `S::NAME` (replacing an earlier entry of that name).
    fn add<S: OperatorSpec>(&mut self) -> &mut Self {
        self.entries.insert(
            S::NAME,
            Entry {
                name: S::NAME,
                summary: S::SUMMARY,
                params: S::PARAMS,
                build: build_erased::<S>,
                defaults: build_defaults::<S>,
            },
        );
        self
    }
}
