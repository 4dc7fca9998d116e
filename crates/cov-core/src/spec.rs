//! Operator specs: the parameters of an operator as a file names them, declared once.
//!
//! # Writing an operator outside covtrace
//!
//! **Depend on one crate**, `covtrace` (it re-exports this crate and the derive), and
//! import `use covtrace::{Build, Checked, CovError, Operator, OperatorSpec, Registrar,
//! Spectrum};`. Inside the workspace the same names come from `cov_core`.
//!
//! **Declare each parameter once**, as a field of a spec struct with
//! `#[derive(OperatorSpec)]`:
//!
//! | on | attribute | meaning |
//! |---|---|---|
//! | struct | `#[operator(summary = "…")]` | one line for `covtrace list` (required) |
//! | struct | `#[operator(name = "…")]` | the name in files; default: the struct's name without `Spec` (`BlurSpec` → `Blur`) |
//! | field | `/// text` | the parameter's documentation |
//! | field | `#[param(unit = "m")]` | its unit |
//! | field | `#[param(default)]`, `#[param(default = expr)]` | optional, with `Default::default()` or `expr` (taken as the field's type for a number: `default = 2` on a `u32`, `default = 1` on an `f64`; a number outside the bounds written as numbers is a compile error) |
//! | field | `#[param(positive)]`, `#[param(non_negative)]` | domain `> 0`, `≥ 0` |
//! | field | `#[param(gt = a)]`, `ge`, `lt`, `le` (one lower, one upper) | bounds: numbers, constants or other fields (`gt = self.focal_length`) |
//! | field | `#[param(finite)]` | finite; implied for `f64`, `Option<f64>`, `Vec<f64>`, `[f64; N]` |
//! | field | `#[param(nested)]` | a [`Chain`] written as an operator list |
//!
//! **Say which operator the spec builds, and how**, with [`Build`]: `type Op` names the
//! operator type (whatever its name) and [`Build::make`] receives the spec [`Checked`]
//! against every declared domain. Checks that relate parameters, or that the derive
//! cannot express, go there and report through the spec's parameter constants
//! (`MySpec::FIELD`, one per field, a [`Param`]): no parameter name is typed twice.
//! Values that are not fields (an enum variant's field, a function's argument) are named
//! by their identifier with [`arg!`](crate::arg).
//!
//! **Register** with one call, `registry.add::<MySpec>()` on any [`Registrar`] (the RON
//! registry of `covtrace::registry()`, a [`Catalogue`]); a crate of operators offers
//! `pub fn register<R: Registrar>(r: &mut R)`.
//!
//! **What comes for free**: the RON syntax (`Blur(s: 4.0)`, defaults, `Blur` bare when
//! every parameter is optional), errors positioned at the parameter as written
//! (`file:line:column`, for unknown, repeated, missing and out-of-domain parameters), the
//! parameter table of `covtrace list` and of the docs (name, unit, default, domain,
//! meaning), `eval`, `plot` and `list` from a `main` of one line,
//! `cov_cli::run_with(my_ops::register)` (crate `cov-cli`), and the checked constructor
//! for Rust callers ([`OperatorSpec::build`]: an operator's `new` is `MySpec { … }.build()`,
//! the same checks as a file's).
//!
//! **Good to know**: an operator is `Debug + Send + Sync` (it is shared across threads);
//! tables and runtime errors name a step by [`Operator::name`], the Rust type's name
//! unless you override it (return the spec's name when the two differ); a parameter
//! without `unit` is dimensionless (`–` in tables); a derived quantity that can overflow
//! (a window's `1/(4π² s²)`, with [`FOUR_PI_SQ`](crate::FOUR_PI_SQ)) is checked in
//! `make` and reported on the parameter the user wrote, `MySpec::RADIUS.error(value,
//! "too small: …")`, rather than left to the kernel, which would name its own argument.
//!
//! Nothing here knows a file format: the format crate (`cov-path`, RON) drives
//! [`OperatorSpec::deserialize_in`] with its own deserializer and an [`OperatorReader`]
//! for nested lists, and collects specs through [`Registrar`].
//!
//! ```
//! use cov_core::{Axis, Build, Checked, CovError, Operator, OperatorSpec, Spectrum};
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
//!     /// Lobe spectrum variance.
//!     #[param(unit = "(cycles/tan)²", default = 1.0, non_negative)]
//!     pub s: f64,
//! }
//! impl Build for BlurSpec {
//!     type Op = Blur;
//!     fn make(spec: Checked<Self>) -> Result<Blur, CovError> {
//!         Ok(Blur(spec.s)) // `s` is finite and ≥ 0 here
//!     }
//! }
//!
//! assert_eq!(BlurSpec::NAME, "Blur");
//! assert_eq!(BlurSpec::PARAMS[0], BlurSpec::S);
//! assert_eq!(BlurSpec::S.name, "s");
//! assert_eq!(BlurSpec::S.unit, "(cycles/tan)²");
//! assert_eq!(BlurSpec::S.doc, "Lobe spectrum variance.");
//! assert_eq!(BlurSpec::S.default, Some("1.0"));
//! assert_eq!(BlurSpec::S.domain, "≥ 0");
//! assert!(BlurSpec::defaults().is_some());
//! // Rust callers get the same checks as files.
//! let err = BlurSpec { s: -1.0 }.build().unwrap_err().to_string();
//! assert_eq!(err, "Blur: parameter `s` = -1 is out of range: must be ≥ 0");
//! assert!(BlurSpec { s: f64::NAN }.build().is_err());
//! ```

use std::fmt;

use serde::de::{DeserializeSeed, Deserializer, Visitor};

use crate::{Chain, CovError, Operator};

/// One documented parameter of an operator: what `covtrace list` and the docs show, and
/// what its errors name. The derive makes one per field, as an associated constant of the
/// spec named after the field (`ThinLensSpec::FOCAL_LENGTH`), so code that reports a
/// parameter (a constraint relating two of them) names it through the constant and never
/// types the name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Param {
    /// The operator's name in files.
    pub operator: &'static str,
    /// Field name as written in a file.
    pub name: &'static str,
    /// Unit (`m`, `1/m`, `rad`, …; empty when dimensionless).
    pub unit: &'static str,
    /// What it means (the field's doc comment).
    pub doc: &'static str,
    /// The default, as written in the source, when the parameter may be left out.
    pub default: Option<&'static str>,
    /// Its domain as declared by `#[param(…)]` (`> 0`, `in (0, 1]`, `finite`; empty when
    /// the field's type has no declared domain).
    pub domain: &'static str,
}

impl Param {
    /// This parameter with a value, for functions that take an [`Arg`] (`Turn::new`).
    pub fn of(&self, value: f64) -> Arg {
        Arg {
            operator: self.operator,
            name: self.name,
            value,
            index: None,
        }
    }

    /// The error for `value`, out of this parameter's domain: `expected` says the domain
    /// in words (`must be > focal_length = 0.05`).
    #[cold]
    pub fn error(&self, value: f64, expected: impl Into<String>) -> CovError {
        self.of(value).error(expected)
    }

    /// The error for this parameter given with one it excludes, or for a choice of forms
    /// of which none was given (`expected`: the forms, in words): `Curvature: parameter
    /// `kx`: not with `k`; give either `k` alone or …`.
    #[cold]
    pub fn choice(&self, expected: impl Into<String>) -> CovError {
        CovError::Choice {
            operator: self.operator.to_string(),
            parameter: self.name.to_string(),
            expected: expected.into(),
        }
    }

    /// The error for a list parameter of `len` values where `expected` (in words,
    /// `"1 or 2 components"`) belongs: `Moving: parameter `velocity`: expected 1 or 2
    /// components, got 3`.
    #[cold]
    pub fn wrong_length(&self, len: usize, expected: impl Into<String>) -> CovError {
        CovError::Shape {
            what: format!("{}: parameter `{}`", self.operator, self.name),
            expected: expected.into(),
            got: format!("{len}"),
        }
    }

    /// `value` if it is finite and `ok(value)`, else the error naming this parameter, with
    /// `expected()` (built only on failure) saying the domain.
    ///
    /// # Errors
    /// [`CovError::NonFinite`] or [`CovError::OutOfRange`].
    #[inline(always)]
    pub fn require(
        &self,
        value: f64,
        ok: impl FnOnce(f64) -> bool,
        expected: impl FnOnce() -> String,
    ) -> Result<f64, CovError> {
        self.of(value).require(ok, expected)
    }
}

/// A value given to a Rust constructor that is not a spec's field (an enum variant's
/// field, an argument computed by a renderer), checked like a parameter and named after
/// its identifier: `arg!(Texture::NAME, mean_sq).non_negative()?`, or an element of a
/// list, `arg!("Tabulated", values[k])` (named `values[k]` with `k`'s value). The name is
/// never typed as a string, so it cannot drift from the code.
#[macro_export]
macro_rules! arg {
    ($operator:expr, $value:ident) => {
        $crate::spec::Arg {
            operator: $operator,
            name: ::core::stringify!($value),
            value: $value,
            index: ::core::option::Option::None,
        }
    };
    ($operator:expr, $list:ident[$k:expr]) => {
        $crate::spec::Arg {
            operator: $operator,
            name: ::core::stringify!($list),
            value: $list[$k],
            index: ::core::option::Option::Some($k),
        }
    };
}

/// See [`arg!`](crate::arg).
#[derive(Clone, Copy, Debug)]
pub struct Arg {
    /// The operator or function taking it.
    pub operator: &'static str,
    /// Its name (the identifier).
    pub name: &'static str,
    /// Its value.
    pub value: f64,
    /// The element, for an element of a list.
    pub index: Option<usize>,
}

impl Arg {
    /// A value named `name`, given to `operator` (for names that are not an identifier in
    /// scope; otherwise [`arg!`](crate::arg)).
    pub const fn new(operator: &'static str, name: &'static str, value: f64) -> Arg {
        Arg {
            operator,
            name,
            value,
            index: None,
        }
    }

    /// The value if it is finite and `ok(value)`.
    ///
    /// # Errors
    /// [`CovError::NonFinite`] or [`CovError::OutOfRange`] with `expected`.
    #[inline(always)]
    pub fn require(
        self,
        ok: impl FnOnce(f64) -> bool,
        expected: impl FnOnce() -> String,
    ) -> Result<f64, CovError> {
        let Arg {
            operator,
            name,
            value,
            index,
        } = self;
        if value.is_finite() && ok(value) {
            return Ok(value);
        }
        Err(Arg::fail(
            operator,
            name,
            index,
            value,
            value.is_finite().then(expected),
        ))
    }

    /// The value if it is finite.
    ///
    /// # Errors
    /// [`CovError::NonFinite`].
    #[inline(always)]
    pub fn finite(self) -> Result<f64, CovError> {
        self.require(|_| true, String::new)
    }

    /// The value if it is finite and > 0.
    ///
    /// # Errors
    /// [`CovError::NonFinite`] or [`CovError::OutOfRange`].
    #[inline(always)]
    pub fn positive(self) -> Result<f64, CovError> {
        self.require(|v| v > 0.0, || "must be > 0".into())
    }

    /// The value if it is finite and ≥ 0.
    ///
    /// # Errors
    /// [`CovError::NonFinite`] or [`CovError::OutOfRange`].
    #[inline(always)]
    pub fn non_negative(self) -> Result<f64, CovError> {
        self.require(|v| v >= 0.0, || "must be ≥ 0".into())
    }

    /// The error for this value, out of its domain.
    #[cold]
    pub fn error(self, expected: impl Into<String>) -> CovError {
        Arg::fail(
            self.operator,
            self.name,
            self.index,
            self.value,
            Some(expected.into()),
        )
    }

    /// [`CovError::NonFinite`] without `expected`, else [`CovError::OutOfRange`]. It takes
    /// the parts, not the `Arg`: passed by value, the `Arg` was built on the path that
    /// succeeds too, and a per-ray bounce chain ran 6% more instructions (3,247 against
    /// 3,053 at N = 4, `tools/chain-probe`).
    #[cold]
    #[inline(never)]
    fn fail(
        operator: &'static str,
        name: &'static str,
        index: Option<usize>,
        value: f64,
        expected: Option<String>,
    ) -> CovError {
        let operator = operator.into();
        let parameter = match index {
            Some(k) => format!("{name}[{k}]"),
            None => name.to_string(),
        };
        match expected {
            None => CovError::NonFinite {
                operator,
                parameter,
                value,
            },
            Some(expected) => CovError::OutOfRange {
                operator,
                parameter,
                value,
                expected,
            },
        }
    }
}

/// A value of a parameter with a declared domain: what the code `#[derive(OperatorSpec)]`
/// generates calls to check a field. Implemented for `f64` and the integers (the value
/// itself), `Option` (when given) and lists of numbers (each element, named `name[k]`).
#[diagnostic::on_unimplemented(
    message = "a `#[param(…)]` domain cannot be checked on a `{Self}`",
    note = "domains (`finite`, `positive`, `non_negative`, `gt`, `ge`, `lt`, `le`) apply to numbers, their `Option`s and lists; check other types in `Build::make`"
)]
pub trait ParamValue {
    /// Checks every number in `self` against `ok` (and finiteness).
    ///
    /// # Errors
    /// The first number out of its domain, named after `p`.
    fn check_param(
        &self,
        p: &Param,
        ok: impl Fn(f64) -> bool,
        expected: impl Fn() -> String,
    ) -> Result<(), CovError>;
}

macro_rules! number_param {
    ($($t:ty),*) => {$(
        impl ParamValue for $t {
            #[inline(always)]
            fn check_param(
                &self,
                p: &Param,
                ok: impl Fn(f64) -> bool,
                expected: impl Fn() -> String,
            ) -> Result<(), CovError> {
                // Exact for every count a user may give (≤ 2⁵³); the identity for `f64`.
                #[allow(clippy::cast_precision_loss, clippy::unnecessary_cast)]
                let v = *self as f64;
                p.require(v, ok, expected).map(|_| ())
            }
        }
    )*};
}
number_param!(f64, u32, u64, usize, i32, i64);

impl<T: ParamValue> ParamValue for Option<T> {
    #[inline(always)]
    fn check_param(
        &self,
        p: &Param,
        ok: impl Fn(f64) -> bool,
        expected: impl Fn() -> String,
    ) -> Result<(), CovError> {
        match self {
            Some(v) => v.check_param(p, ok, expected),
            None => Ok(()),
        }
    }
}

impl ParamValue for [f64] {
    fn check_param(
        &self,
        p: &Param,
        ok: impl Fn(f64) -> bool,
        expected: impl Fn() -> String,
    ) -> Result<(), CovError> {
        for (k, &v) in self.iter().enumerate() {
            let arg = Arg {
                index: Some(k),
                ..p.of(v)
            };
            arg.require(&ok, &expected)?;
        }
        Ok(())
    }
}

impl ParamValue for Vec<f64> {
    #[inline]
    fn check_param(
        &self,
        p: &Param,
        ok: impl Fn(f64) -> bool,
        expected: impl Fn() -> String,
    ) -> Result<(), CovError> {
        self.as_slice().check_param(p, ok, expected)
    }
}

impl<const N: usize> ParamValue for [f64; N] {
    #[inline]
    fn check_param(
        &self,
        p: &Param,
        ok: impl Fn(f64) -> bool,
        expected: impl Fn() -> String,
    ) -> Result<(), CovError> {
        self.as_slice().check_param(p, ok, expected)
    }
}

/// A spec whose declared domains have been checked ([`OperatorSpec::check`]): what
/// [`Build::make`] receives, so an operator is never built from unchecked parameters.
/// Only [`OperatorSpec::build`] makes one.
#[derive(Debug)]
pub struct Checked<S>(S);

impl<S> Checked<S> {
    /// The spec itself (to move its fields out).
    pub fn into_inner(self) -> S {
        self.0
    }
}

impl<S> std::ops::Deref for Checked<S> {
    type Target = S;
    fn deref(&self) -> &S {
        &self.0
    }
}

/// How an operator is made from its spec, once the spec's declared domains hold. The one
/// thing a spec implements by hand, next to `#[derive(OperatorSpec)]`.
#[diagnostic::on_unimplemented(
    message = "`{Self}` derives `OperatorSpec` but does not say which operator it builds, or how",
    label = "no `impl Build for {Self}`",
    note = "add `impl Build for {Self} {{ type Op = YourOperator; fn make(spec: Checked<Self>) -> Result<YourOperator, CovError> {{ … }} }}` (`use covtrace::{{Build, Checked}}`, or `cov_core::…`)",
    note = "the operator's type is named there, by `type Op`, whatever its name; the parameters' `#[param(…)]` domains are checked before `make` runs"
)]
pub trait Build: Sized {
    /// The operator built from the parameters.
    type Op: Operator + 'static;

    /// Makes the operator from checked parameters, with any check that relates several
    /// of them (reported through the spec's parameter constants).
    ///
    /// # Errors
    /// Parameters that are valid one by one but not together.
    fn make(spec: Checked<Self>) -> Result<Self::Op, CovError>;
}

/// The parameters of an operator as written in a file, and how to build it. Derive it
/// (`#[derive(OperatorSpec)]`, see the module docs) rather than implementing it by hand;
/// implement [`Build`] next to it.
pub trait OperatorSpec: Build + 'static {
    /// The name used in files (`Travel`).
    const NAME: &'static str;
    /// One line describing the operator.
    const SUMMARY: &'static str;
    /// The parameters, in the order of the struct.
    const PARAMS: &'static [Param];

    /// Checks every parameter against its declared domain (`#[param(positive)]`, …;
    /// finiteness for numbers).
    ///
    /// # Errors
    /// The first parameter out of its domain, named as in files.
    fn check(&self) -> Result<(), CovError>;

    /// Checks the parameters and builds the operator: the one way from a spec to an
    /// operator, for files and for Rust callers alike.
    ///
    /// # Errors
    /// Invalid parameters (NaN, out of range): the message names the parameter.
    #[inline(always)]
    fn build(self) -> Result<Self::Op, CovError> {
        self.check()?;
        <Self as Build>::make(Checked(self))
    }

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
/// # impl cov_core::Build for NudgeSpec { type Op = Nudge; fn make(_: cov_core::Checked<Self>) -> Result<Nudge, CovError> { Ok(Nudge) } }
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
/// assert!(c.markdown().contains("| `Nudge` | `by` | m | `0.1` | finite | How much. |"));
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
    /// without any), columns operator, parameter, unit, default, domain, meaning.
    pub fn markdown(&self) -> String {
        let mut out = String::from(
            "| operator | parameter | unit | default | domain | meaning |\n|---|---|---|---|---|---|\n",
        );
        for e in &self.entries {
            if e.params.is_empty() {
                out.push_str(&format!(
                    "| `{}` | – | | | | {} (no parameters) |\n",
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
                let domain = if p.domain.is_empty() { "–" } else { p.domain };
                out.push_str(&format!(
                    "| {op} | `{}` | {unit} | {default} | {domain} | {doc} |\n",
                    p.name
                ));
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
