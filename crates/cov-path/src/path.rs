//! The RON format of a light path, its parsing, layout inference and evaluation.

use std::fmt;

use cov_core::{Axis, AxisSet, Chain, Cov, CovError, Form, Operator, layout_axes, layout_set};
use ron::extensions::Extensions;
use serde::de::{
    self, DeserializeSeed, Deserializer, EnumAccess, MapAccess, SeqAccess, VariantAccess, Visitor,
};
use serde::{Deserialize, Serialize};

use crate::registry::{DynOperator, Entry, Registry};

/// Everything that can go wrong with a path file: a position in the file when there is one.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PathError {
    /// Malformed RON, an unknown operator or parameter, a bad value: with its position.
    #[error("{file}:{line}:{col}: {message}")]
    Parse {
        /// File name (or `<string>`).
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        col: usize,
        /// What is wrong.
        message: String,
    },
    /// A path that parsed but cannot be traced (overflow, a layout the operators do not
    /// fit …), with the position of the step when it is known.
    #[error("{file}:{}{message}", at.map(|(l, c)| format!("{l}:{c}: ")).unwrap_or_else(|| " ".into()))]
    Eval {
        /// File name (or `<string>`).
        file: String,
        /// Line and column of the failing step.
        at: Option<(usize, usize)>,
        /// What is wrong.
        message: String,
    },
    /// The file could not be read.
    #[error("{file}: {message}")]
    Io {
        /// File name.
        file: String,
        /// The I/O error.
        message: String,
    },
}

impl PathError {
    fn eval(message: impl Into<String>) -> Self {
        PathError::Eval {
            file: "<string>".into(),
            at: None,
            message: message.into(),
        }
    }

    fn eval_at(at: Option<(usize, usize)>, message: impl Into<String>) -> Self {
        PathError::Eval {
            file: "<string>".into(),
            at,
            message: message.into(),
        }
    }

    /// The same error attributed to `file`.
    pub fn in_file(self, name: &str) -> Self {
        match self {
            PathError::Parse {
                line, col, message, ..
            } => PathError::Parse {
                file: name.into(),
                line,
                col,
                message,
            },
            PathError::Eval { message, at, .. } => PathError::Eval {
                file: name.into(),
                at,
                message,
            },
            PathError::Io { message, .. } => PathError::Io {
                file: name.into(),
                message,
            },
        }
    }
}

/// The initial covariance of a path, from physical quantities.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub enum Source {
    /// A Gaussian light field with a primal std per named axis (m, tangent, s); an axis
    /// left out (or `inf`) is constant. `Gaussian(x: 0.1, y: 0.1)` is a 10 cm area light
    /// emitting uniformly in angle.
    Gaussian {
        /// Std along x (m).
        #[serde(default)]
        x: Option<f64>,
        /// Std along y (m).
        #[serde(default)]
        y: Option<f64>,
        /// Std along u (tangent).
        #[serde(default)]
        u: Option<f64>,
        /// Std along v (tangent).
        #[serde(default)]
        v: Option<f64>,
        /// Std along t (s).
        #[serde(default)]
        t: Option<f64>,
    },
    /// A point (Dirac-like) source: see `Cov::dirac` (default `relative_size` 1e-6).
    Dirac {
        /// Size of the scene (m).
        scene_scale: f64,
        /// Std of the point relative to the scene.
        #[serde(default)]
        relative_size: Option<f64>,
    },
    /// Σ given directly, `N` rows of `N` numbers (fixes the layout).
    Matrix {
        /// The rows.
        rows: Vec<Vec<f64>>,
    },
}

impl Source {
    fn gaussian_stds(&self) -> Option<[(Axis, Option<f64>); 5]> {
        match self {
            Source::Gaussian { x, y, u, v, t } => Some([
                (Axis::X, *x),
                (Axis::Y, *y),
                (Axis::U, *u),
                (Axis::V, *v),
                (Axis::T, *t),
            ]),
            _ => None,
        }
    }

    /// The axes the source names (or the layout a matrix fixes).
    pub fn requires(&self) -> AxisSet {
        match self {
            Source::Gaussian { .. } => {
                let mut s = AxisSet::FLAT;
                for (axis, std) in self.gaussian_stds().into_iter().flatten() {
                    if std.is_some() {
                        s = s.with(axis);
                    }
                }
                s
            }
            Source::Dirac { .. } => AxisSet::FLAT,
            Source::Matrix { rows } => layout_set(rows.len()),
        }
    }

    /// Checks the values (and, when the layout is known, the axes) of the source.
    ///
    /// # Errors
    /// A message naming the bad value.
    pub fn check(&self, layout: Option<usize>) -> Result<(), String> {
        match self {
            Source::Gaussian { .. } => {
                for (axis, std) in self.gaussian_stds().into_iter().flatten() {
                    if let Some(s) = std
                        && (s.is_nan() || s <= 0.0)
                    {
                        return Err(format!(
                            "Gaussian source: std `{axis}` = {s} must be > 0 (inf: constant)"
                        ));
                    }
                }
            }
            Source::Dirac {
                scene_scale,
                relative_size,
            } => {
                Cov::<2>::dirac(
                    *scene_scale,
                    relative_size.unwrap_or(cov_core::DIRAC_RELATIVE_SIZE),
                )
                .map_err(|e| format!("Dirac source: {e}"))?;
            }
            Source::Matrix { rows } => {
                let n = rows.len();
                if !(2..=5).contains(&n) || rows.iter().any(|r| r.len() != n) {
                    return Err(format!(
                        "Matrix source: expected N rows of N numbers with N in 2..=5, got {n} rows of lengths {:?}",
                        rows.iter().map(Vec::len).collect::<Vec<_>>()
                    ));
                }
                let checked = match n {
                    2 => self.covariance::<2>().map(|_| ()),
                    3 => self.covariance::<3>().map(|_| ()),
                    4 => self.covariance::<4>().map(|_| ()),
                    _ => self.covariance::<5>().map(|_| ()),
                };
                checked.map_err(|e| format!("Matrix source: {e}"))?;
                if let Some(l) = layout
                    && l != n
                {
                    return Err(format!("the source matrix is {n}×{n} but the layout is {l}"));
                }
            }
        }
        if let Some(n) = layout {
            let have = layout_set(n);
            if let Some(axis) = self.requires().iter().find(|a| !have.contains(*a)) {
                return Err(format!(
                    "the source needs axis `{axis}`, which layout {n} ({}) does not have",
                    axes_string(n)
                ));
            }
        }
        Ok(())
    }

    /// Σ of the source in layout `N`.
    ///
    /// # Errors
    /// Invalid values, an axis not in the layout, a matrix of the wrong size.
    pub fn covariance<const N: usize>(&self) -> Result<Cov<N>, CovError> {
        match self {
            Source::Gaussian { .. } => {
                let mut stds = [f64::INFINITY; N];
                for (axis, std) in self.gaussian_stds().into_iter().flatten() {
                    if let Some(s) = std {
                        stds[Cov::<N>::index(axis)?] = s;
                    }
                }
                Cov::gaussian(stds)
            }
            Source::Dirac {
                scene_scale,
                relative_size,
            } => Cov::dirac(
                *scene_scale,
                relative_size.unwrap_or(cov_core::DIRAC_RELATIVE_SIZE),
            ),
            Source::Matrix { rows } => {
                if rows.len() != N || rows.iter().any(|r| r.len() != N) {
                    return Err(CovError::Shape {
                        what: "Matrix source".into(),
                        expected: format!("{N} rows of {N} numbers"),
                        got: format!("{} rows", rows.len()),
                    });
                }
                Cov::from_matrix(&matrix_of_rows::<N>(rows))
            }
        }
    }
}

/// The `N × N` matrix `Cov::from_matrix` takes.
type Matrix<const N: usize> = nalgebra::SMatrix<f64, N, N>;

fn matrix_of_rows<const N: usize>(rows: &[Vec<f64>]) -> Matrix<N> {
    Matrix::<N>::from_fn(|i, j| rows[i][j])
}

/// A parsed light path.
#[derive(Clone, Debug)]
pub struct Path {
    /// The layout the file fixes, if any.
    pub layout: Option<usize>,
    /// The initial covariance.
    pub source: Source,
    /// The operators, in order.
    pub operators: Vec<DynOperator>,
    /// Line and column of each operator in the text (empty when not known).
    pub positions: Vec<(usize, usize)>,
}

/// The options every path file is read with: `Some` may be left out, and a newtype
/// variant's struct may be written inline (`Travel(distance: 1)`).
pub fn ron_options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
}

impl Path {
    /// Parses a path from RON text with the operators of `registry`.
    ///
    /// # Errors
    /// [`PathError::Parse`] with the line and column of the problem.
    pub fn parse(text: &str, registry: &Registry) -> Result<Path, PathError> {
        // Nested operator lists (`Moving(..., operators: [...])`) read the registry from
        // this scope.
        let _scope = crate::nested::RegistryScope::enter(registry);
        // First pass: the declared layout, wherever it stands in the file, so that the
        // second pass can check every operator against it where it is written.
        let declared = ron_options().from_str_seed(text, LayoutProbe).ok().flatten();
        let mut path = ron_options()
            .from_str_seed(text, PathSeed { registry, declared })
            .map_err(|e| PathError::Parse {
                file: "<string>".into(),
                line: e.span.start.line,
                col: e.span.start.col,
                message: e.code.to_string(),
            })?;
        let positions = crate::scan::operator_positions(text);
        if positions.len() == path.operators.len() {
            path.positions = positions;
        }
        Ok(path)
    }

    /// Reads and parses a file.
    ///
    /// # Errors
    /// [`PathError::Io`] or [`PathError::Parse`] naming the file.
    pub fn load(file: &std::path::Path, registry: &Registry) -> Result<Path, PathError> {
        let name = file.display().to_string();
        let text = std::fs::read_to_string(file).map_err(|e| PathError::Io {
            file: name.clone(),
            message: e.to_string(),
        })?;
        Self::parse(&text, registry).map_err(|e| e.in_file(&name))
    }

    /// Union of what the source and every operator need.
    pub fn requires(&self) -> AxisSet {
        self.operators.iter().fold(self.source.requires(), |s, op| {
            s.union(Operator::<5>::requires(op))
        })
    }

    /// The layout the path is traced in: the declared one, or the smallest that holds what
    /// every operator needs. The flag says whether it was inferred.
    ///
    /// # Errors
    /// A declared layout that lacks an axis some operator needs (naming both).
    pub fn resolve_layout(&self) -> Result<(usize, bool), PathError> {
        let needed = self.requires();
        match self.layout {
            None => Ok((needed.smallest_layout(), true)),
            Some(n) => {
                let have = layout_set(n);
                if let Source::Matrix { rows } = &self.source
                    && rows.len() != n
                {
                    return Err(PathError::eval(format!(
                        "the source matrix is {}×{} but the layout is {n}",
                        rows.len(),
                        rows.len()
                    )));
                }
                for (i, op) in self.operators.iter().enumerate() {
                    let req = Operator::<5>::requires(op);
                    if let Some(axis) = req.iter().find(|a| !have.contains(*a)) {
                        return Err(PathError::eval_at(
                            self.positions.get(i).copied(),
                            format!(
                                "step {i} ({}) needs axis `{axis}`, which layout {n} ({}) does not have",
                                Operator::<5>::name(op),
                                axes_string(n)
                            ),
                        ));
                    }
                }
                if let Some(axis) = self.source.requires().iter().find(|a| !have.contains(*a)) {
                    return Err(PathError::eval(format!(
                        "the source needs axis `{axis}`, which layout {n} ({}) does not have",
                        axes_string(n)
                    )));
                }
                Ok((n, false))
            }
        }
    }

    /// Traces the path: Σ after every step, in the resolved layout, holding Σ in the
    /// default (square-root) form.
    ///
    /// # Errors
    /// Layout mismatch, invalid source, or a failing step (named with its index).
    pub fn eval(&self) -> Result<Evaluation, PathError> {
        self.eval_in(Form::default())
    }

    /// [`Path::eval`] holding Σ in `form` along the way.
    ///
    /// # Errors
    /// As [`Path::eval`].
    pub fn eval_in(&self, form: Form) -> Result<Evaluation, PathError> {
        let (n, inferred) = self.resolve_layout()?;
        match n {
            2 => self.eval_n::<2>(inferred, form),
            3 => self.eval_n::<3>(inferred, form),
            4 => self.eval_n::<4>(inferred, form),
            _ => self.eval_n::<5>(inferred, form),
        }
    }

    /// The operators as a chain of layout `N`.
    pub fn chain<const N: usize>(&self) -> Chain<N> {
        let mut c = Chain::new();
        for op in &self.operators {
            c.push(op.clone());
        }
        c
    }

    fn eval_n<const N: usize>(&self, inferred: bool, form: Form) -> Result<Evaluation, PathError> {
        let start = self
            .source
            .covariance::<N>()
            .map_err(|e| PathError::eval(format!("source: {e}")))?;
        let trace = self.chain::<N>().trace_in(form, start).map_err(|e| {
            let at = match &e {
                CovError::Step { index, .. } => self.positions.get(*index).copied(),
                _ => None,
            };
            PathError::eval_at(at, e.to_string())
        })?;
        let to_rows =
            |c: &Cov<N>| -> Vec<Vec<f64>> { (0..N).map(|i| (0..N).map(|j| c.get(i, j)).collect()).collect() };
        Ok(Evaluation {
            layout: N,
            inferred,
            form,
            axes: Cov::<N>::axes().iter().map(|a| a.name().to_string()).collect(),
            start: to_rows(&trace.start),
            steps: trace
                .steps
                .iter()
                .map(|s| EvalStep {
                    operator: s.name.clone(),
                    matrix: to_rows(&s.cov),
                    bandwidths: s.cov.bandwidths().to_vec(),
                })
                .collect(),
            result: to_rows(&trace.last()),
        })
    }
}

fn axes_string(n: usize) -> String {
    layout_axes(n)
        .unwrap_or(&[])
        .iter()
        .map(|a| a.name())
        .collect::<Vec<_>>()
        .join(",")
}

/// The result of [`Path::eval`]: serialisable (`covtrace eval --json`) and readable back.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Layout size N.
    pub layout: usize,
    /// Whether N was inferred (not declared in the file).
    pub inferred: bool,
    /// The form Σ was held in while tracing.
    #[serde(default)]
    pub form: Form,
    /// Axis names in order.
    pub axes: Vec<String>,
    /// Σ of the source.
    pub start: Vec<Vec<f64>>,
    /// Σ after each step.
    pub steps: Vec<EvalStep>,
    /// Σ after the last step.
    pub result: Vec<Vec<f64>>,
}

/// One step of an [`Evaluation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvalStep {
    /// Operator name.
    pub operator: String,
    /// Σ after the step (N rows of N numbers).
    pub matrix: Vec<Vec<f64>>,
    /// √Σ_ii per axis (cycles per unit).
    pub bandwidths: Vec<f64>,
}

impl Evaluation {
    /// The final Σ as a typed covariance (validated).
    ///
    /// # Errors
    /// `N` differs from the evaluation's layout, or the matrix is invalid.
    pub fn result_cov<const N: usize>(&self) -> Result<Cov<N>, CovError> {
        if N != self.layout || self.result.len() != N {
            return Err(CovError::Shape {
                what: "Evaluation::result_cov".into(),
                expected: format!("layout {}", self.layout),
                got: format!("N = {N}"),
            });
        }
        Cov::from_matrix(&matrix_of_rows::<N>(&self.result))
    }

    /// Reads an evaluation back from `covtrace eval --json` output.
    ///
    /// # Errors
    /// Malformed JSON.
    pub fn from_json(text: &str) -> Result<Evaluation, serde_json::Error> {
        serde_json::from_str(text)
    }

    /// The JSON form.
    pub fn to_json(&self) -> String {
        // Invariant: plain numbers, strings and vectors always serialise.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

// ---- the seeds -------------------------------------------------------------------

/// Reads a bare identifier (a variant or field name) as a string.
struct Ident;

impl<'de> DeserializeSeed<'de> for Ident {
    type Value = String;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<String, D::Error> {
        d.deserialize_identifier(self)
    }
}

impl Visitor<'_> for Ident {
    type Value = String;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a name")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<String, E> {
        Ok(v.to_string())
    }
}

struct PathSeed<'r> {
    registry: &'r Registry,
    declared: Option<usize>,
}

/// First pass: reads `layout` only.
struct LayoutProbe;

impl<'de> DeserializeSeed<'de> for LayoutProbe {
    type Value = Option<usize>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Option<usize>, D::Error> {
        d.deserialize_struct("Path", FIELDS, self)
    }
}

impl<'de> Visitor<'de> for LayoutProbe {
    type Value = Option<usize>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a path")
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Option<usize>, A::Error> {
        let mut layout = None;
        while let Some(key) = map.next_key_seed(Ident)? {
            if key == "layout" {
                layout = Some(map.next_value::<usize>()?);
            } else {
                map.next_value::<de::IgnoredAny>()?;
            }
        }
        Ok(layout.filter(|n| (2..=5).contains(n)))
    }
}

const FIELDS: &[&str] = &["layout", "source", "operators"];

impl<'de> DeserializeSeed<'de> for PathSeed<'_> {
    type Value = Path;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Path, D::Error> {
        d.deserialize_struct("Path", FIELDS, self)
    }
}

impl<'de> Visitor<'de> for PathSeed<'_> {
    type Value = Path;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a path: Path(layout: N (optional), source: ..., operators: [...])")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Path, A::Error> {
        let mut layout: Option<usize> = None;
        let mut source: Option<Source> = None;
        let mut operators: Option<Vec<DynOperator>> = None;
        while let Some(key) = map.next_key_seed(Ident)? {
            match key.as_str() {
                "layout" => {
                    if layout.is_some() {
                        return Err(de::Error::duplicate_field("layout"));
                    }
                    let n: usize = map.next_value()?;
                    if !(2..=5).contains(&n) {
                        return Err(de::Error::custom(format!(
                            "layout must be 2 (x,u), 3 (x,u,t), 4 (x,y,u,v) or 5 (x,y,u,v,t), got {n}"
                        )));
                    }
                    layout = Some(n);
                }
                "source" => {
                    if source.is_some() {
                        return Err(de::Error::duplicate_field("source"));
                    }
                    let s: Source = map.next_value()?;
                    s.check(layout.or(self.declared)).map_err(de::Error::custom)?;
                    source = Some(s);
                }
                "operators" => {
                    if operators.is_some() {
                        return Err(de::Error::duplicate_field("operators"));
                    }
                    operators = Some(map.next_value_seed(OpsSeed {
                        registry: self.registry,
                        layout: layout.or(self.declared),
                    })?);
                }
                other => return Err(de::Error::unknown_field(other, FIELDS)),
            }
        }
        let source = source.ok_or_else(|| de::Error::missing_field("source"))?;
        let operators = operators.ok_or_else(|| de::Error::missing_field("operators"))?;
        if operators.is_empty() {
            return Err(de::Error::custom("the path has no operators (`operators: []`)"));
        }
        Ok(Path {
            layout,
            source,
            operators,
            positions: Vec::new(),
        })
    }
}

pub(crate) struct OpsSeed<'r> {
    pub(crate) registry: &'r Registry,
    pub(crate) layout: Option<usize>,
}

impl<'de> DeserializeSeed<'de> for OpsSeed<'_> {
    type Value = Vec<DynOperator>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for OpsSeed<'_> {
    type Value = Vec<DynOperator>;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a list of operators, e.g. [Travel(distance: 1.0)]")
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(op) = seq.next_element_seed(OpSeed {
            registry: self.registry,
            layout: self.layout,
        })? {
            out.push(op);
        }
        Ok(out)
    }
}

struct OpSeed<'r> {
    registry: &'r Registry,
    layout: Option<usize>,
}

impl<'de> DeserializeSeed<'de> for OpSeed<'_> {
    type Value = DynOperator;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<DynOperator, D::Error> {
        d.deserialize_enum("Operator", &[], self)
    }
}

impl<'de> Visitor<'de> for OpSeed<'_> {
    type Value = DynOperator;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("an operator, e.g. Travel(distance: 1.0)")
    }
    fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<DynOperator, A::Error> {
        let (name, variant) = data.variant_seed(Ident)?;
        let Some(entry) = self.registry.get(&name) else {
            return Err(de::Error::custom(format!(
                "unknown operator `{name}`; known operators: {}",
                self.registry.names()
            )));
        };
        let op = if entry.unit {
            variant.unit_variant()?;
            match (entry.build_unit)() {
                Some(Ok(op)) => op,
                Some(Err(e)) => return Err(de::Error::custom(e)),
                None => {
                    return Err(de::Error::custom(format!(
                        "`{name}` cannot be written without parameters"
                    )));
                }
            }
        } else {
            variant.newtype_variant_seed(EntrySeed { entry })?
        };
        let op = DynOperator(op);
        if let Some(n) = self.layout {
            let have = layout_set(n);
            if let Some(axis) = Operator::<5>::requires(&op).iter().find(|a| !have.contains(*a)) {
                return Err(de::Error::custom(format!(
                    "operator `{name}` needs axis `{axis}`, which layout {n} ({}) does not have",
                    axes_string(n)
                )));
            }
        }
        Ok(op)
    }
}

struct EntrySeed<'e> {
    entry: &'e Entry,
}

impl<'de> DeserializeSeed<'de> for EntrySeed<'_> {
    type Value = std::sync::Arc<dyn crate::PathOperator>;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        let mut erased = <dyn erased_serde::Deserializer>::erase(d);
        let name = self.entry.name;
        (self.entry.build)(&mut erased).map_err(|e| {
            let msg = e.to_string();
            if msg.starts_with(&format!("{name}: ")) {
                de::Error::custom(msg)
            } else {
                de::Error::custom(format!("{name}: {msg}"))
            }
        })
    }
}
