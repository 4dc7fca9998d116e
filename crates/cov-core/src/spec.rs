//! Operator specs: the parameters of an operator as a file names them, declared once.
//!
//! A spec is a plain struct with `#[derive(OperatorSpec)]`: each field is a parameter,
//! its doc comment the parameter's documentation, `#[param(unit = "m")]` its unit,
//! `#[param(default)]` (or `#[param(default = expr)]`) makes it optional, and
//! `#[param(nested)]` marks a [`Chain`] field written as an operator list. The derive
//! generates [`OperatorSpec`]: the name, the parameter table ([`OperatorSpec::PARAMS`],
//! shown by `covtrace list`), a reader that denies unknown fields, and the all-defaults
//! value that lets an operator whose parameters are all optional be written bare
//! (`Mirror`) or with parentheses (`Mirror()`). The operator is built from the spec by
//! `TryFrom<Spec> for Op`.
//!
//! Nothing here knows a file format: the format crate (`cov-path`, RON) drives
//! [`OperatorSpec::deserialize_in`] with its own deserializer and an [`OperatorReader`]
//! for nested lists, and collects specs through [`Registrar`].
//!
//! ```
//! use cov_core::{Axis, CovError, Operator, OperatorSpec, Spectrum};
//!
//! /// An angular blur.
//! #[derive(Debug)]
//! pub struct Blur(f64);
//! impl Operator for Blur {
//!     fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> {
//!         c.convolve(&[Axis::U], &[self.0])
//!     }
//! }
//!
//! /// `Blur(s: 4.0)`: an angular blur.
//! #[derive(Debug, OperatorSpec)]
//! #[operator(summary = "an angular blur")]
//! pub struct BlurSpec {
//!     /// Lobe spectrum variance, ≥ 0.
//!     #[param(unit = "(cycles/tan)²", default = 1.0)]
//!     pub s: f64,
//! }
//! impl TryFrom<BlurSpec> for Blur {
//!     type Error = CovError;
//!     fn try_from(spec: BlurSpec) -> Result<Blur, CovError> {
//!         Ok(Blur(CovError::require_non_negative("Blur", "s", spec.s)?))
//!     }
//! }
//!
//! assert_eq!(BlurSpec::NAME, "Blur");
//! assert_eq!(BlurSpec::PARAMS[0].name, "s");
//! assert_eq!(BlurSpec::PARAMS[0].unit, "(cycles/tan)²");
//! assert_eq!(BlurSpec::PARAMS[0].doc, "Lobe spectrum variance, ≥ 0.");
//! assert_eq!(BlurSpec::PARAMS[0].default, Some("1.0"));
//! assert!(BlurSpec::defaults().is_some());
//! ```

use std::fmt;

use serde::de::{DeserializeSeed, Deserializer, Visitor};

use crate::{Chain, CovError, Operator};

/// One documented parameter of an operator (for `covtrace list` and the docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    /// Field name as written in a file.
    pub name: &'static str,
    /// Unit (`m`, `1/m`, `rad`, …; empty when dimensionless).
    pub unit: &'static str,
    /// What it means and its domain (the field's doc comment).
    pub doc: &'static str,
    /// The default, as written in the source, when the parameter may be left out.
    pub default: Option<&'static str>,
}

/// The parameters of an operator as written in a file, and how to build it. Derive it
/// (`#[derive(OperatorSpec)]`, see the module docs) rather than implementing it by hand.
pub trait OperatorSpec: Sized + 'static {
    /// The name used in files (`Travel`).
    const NAME: &'static str;
    /// One line describing the operator.
    const SUMMARY: &'static str;
    /// The parameters, in the order of the struct.
    const PARAMS: &'static [Param];
    /// The operator built from the parameters.
    type Op: Operator + 'static;

    /// Validates the parameters and builds the operator.
    ///
    /// # Errors
    /// Invalid parameters (NaN, out of range): the message names the parameter.
    fn build(self) -> Result<Self::Op, CovError>;

    /// Reads the parameters from `d` (a struct of named fields; unknown and repeated
    /// fields are errors, optional ones take their defaults), with nested operator lists
    /// read by `reader`.
    ///
    /// # Errors
    /// The deserializer's, positioned by it.
    fn deserialize_in<'de, D: Deserializer<'de>, R: OperatorReader>(
        d: D,
        reader: &R,
    ) -> Result<Self, D::Error>;

    /// The parameters when every one takes its default (`None` if one is required).
    fn defaults() -> Option<Self>;
}

/// Reads an operator list nested in a spec (`Moving(…, operators: [ … ])`), in whatever
/// format and with whatever registry the caller parses with.
pub trait OperatorReader {
    /// Reads a list of operators.
    ///
    /// # Errors
    /// The deserializer's (unknown operator, bad parameters), positioned by it.
    fn read_operators<'de, D: Deserializer<'de>>(&self, d: D) -> Result<Chain, D::Error>;
}

/// Something operator crates register their specs with (the RON registry of `cov-path`).
/// An operator crate offers `pub fn register<R: Registrar>(r: &mut R)` that adds each of
/// its specs.
pub trait Registrar {
    /// Adds `S` under `S::NAME`.
    fn add<S: OperatorSpec>(&mut self) -> &mut Self;
}

/// A [`Registrar`] that only records what it is given: each spec's name, summary and
/// parameters. Operator crates' docs tables and `covtrace list` are made from it, so a
/// parameter is declared once, on its field.
///
/// ```
/// use cov_core::spec::Catalogue;
/// # use cov_core::{CovError, Operator, OperatorSpec, Registrar, Spectrum};
/// # #[derive(Debug)] pub struct Nudge;
/// # impl Operator for Nudge { fn apply(&self, _: &mut dyn Spectrum) -> Result<(), CovError> { Ok(()) } }
/// # impl TryFrom<NudgeSpec> for Nudge { type Error = CovError; fn try_from(_: NudgeSpec) -> Result<Nudge, CovError> { Ok(Nudge) } }
/// /// `Nudge(by: 0.1)`.
/// #[derive(OperatorSpec)]
/// #[operator(summary = "does nothing, gently")]
/// pub struct NudgeSpec {
///     /// How much.
///     #[param(unit = "m", default = 0.1)]
///     pub by: f64,
/// }
/// let mut c = Catalogue::default();
/// c.add::<NudgeSpec>();
/// assert!(c.markdown().contains("| `Nudge` | `by` | m | `0.1` | How much. |"));
/// ```
#[derive(Clone, Debug, Default)]
pub struct Catalogue {
    /// The specs, in the order they were added.
    pub entries: Vec<CatalogueEntry>,
}

/// One spec of a [`Catalogue`].
#[derive(Clone, Copy, Debug)]
pub struct CatalogueEntry {
    /// Name in files.
    pub name: &'static str,
    /// One line.
    pub summary: &'static str,
    /// The parameters.
    pub params: &'static [Param],
}

impl Registrar for Catalogue {
    fn add<S: OperatorSpec>(&mut self) -> &mut Self {
        self.entries.push(CatalogueEntry {
            name: S::NAME,
            summary: S::SUMMARY,
            params: S::PARAMS,
        });
        self
    }
}

impl Catalogue {
    /// The parameter table in Markdown: one row per parameter (one for an operator
    /// without any), columns operator, parameter, unit, default, meaning.
    pub fn markdown(&self) -> String {
        let mut out =
            String::from("| operator | parameter | unit | default | meaning |\n|---|---|---|---|---|\n");
        for e in &self.entries {
            if e.params.is_empty() {
                out.push_str(&format!(
                    "| `{}` | – | | | {} (no parameters) |\n",
                    e.name, e.summary
                ));
            }
            for (i, p) in e.params.iter().enumerate() {
                let op = if i == 0 {
                    format!("`{}`", e.name)
                } else {
                    String::new()
                };
                let unit = if p.unit.is_empty() { "–" } else { p.unit };
                let default = match p.default {
                    None => "required".to_string(),
                    Some(OPTIONAL) => "optional".to_string(),
                    Some(d) => format!("`{d}`"),
                };
                let doc = p.doc.replace('|', "\\|");
                out.push_str(&format!("| {op} | `{}` | {unit} | {default} | {doc} |\n", p.name));
            }
        }
        out
    }
}

/// [`Param::default`] of a parameter that may be left out and has no written default
/// (`#[param(default)]`: `Option`s, empty lists, zero).
pub const OPTIONAL: &str = "optional";

/// The seed the derive uses for a `#[param(nested)]` field.
#[doc(hidden)]
pub struct NestedSeed<'r, R>(pub &'r R);

impl<'de, R: OperatorReader> DeserializeSeed<'de> for NestedSeed<'_, R> {
    type Value = Chain;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Chain, D::Error> {
        self.0.read_operators(d)
    }
}

/// A serde seed that reads an identifier (a field or variant name) as a string: used by
/// the derive for parameter names and by format crates for operator and field names.
pub struct FieldName;

impl<'de> DeserializeSeed<'de> for FieldName {
    type Value = String;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<String, D::Error> {
        d.deserialize_identifier(self)
    }
}

impl Visitor<'_> for FieldName {
    type Value = String;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a parameter name")
    }
    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<String, E> {
        Ok(v.to_string())
    }
}
