//! Tracing a path: [`Path::eval`] and its serialisable result, [`Evaluation`].

use cov_core::{AnyCov, Cov, CovError, Form, Report};
use serde::{Deserialize, Serialize};

use crate::error::PathError;
use crate::path::Path;

impl Path {
    /// Traces the path: Σ after every step, in the resolved layout, holding Σ in the
    /// default (square-root) form.
    ///
    /// # Errors
    /// Layout mismatch, invalid source, or a failing step (named with its index and
    /// positioned in the file).
    pub fn eval(&self) -> Result<Evaluation, PathError> {
        self.eval_in(Form::default())
    }

    /// [`Path::eval`] holding Σ in `form` along the way.
    ///
    /// # Errors
    /// As [`Path::eval`].
    pub fn eval_in(&self, form: Form) -> Result<Evaluation, PathError> {
        let (n, inferred) = self.resolve_layout()?;
        let start = self.source.covariance(n).map_err(|e| PathError::Invalid {
            file: self.file.clone(),
            at: None,
            message: format!("source: {e}"),
        })?;
        let trace = self
            .operators
            .trace_in(form, start)
            .map_err(|e| PathError::Eval {
                file: self.file.clone(),
                at: match &e {
                    CovError::Step { index, .. } => self.positions.get(*index).copied(),
                    _ => None,
                },
                source: Box::new(e),
            })?;
        let reports = trace
            .reports()
            .map(|(step, r)| StepReport {
                step,
                operator: trace.steps[step].name.clone(),
                report: r.clone(),
            })
            .collect();
        Ok(Evaluation {
            layout: n,
            inferred,
            form,
            axes: start.axes().iter().map(|a| a.name().to_string()).collect(),
            start,
            steps: trace
                .steps
                .iter()
                .map(|s| EvalStep {
                    operator: s.name.clone(),
                    matrix: s.cov,
                    bandwidths: s.cov.bandwidths(),
                })
                .collect(),
            result: trace.last(),
            reports,
        })
    }
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
    /// Σ of the source (serialised as rows).
    pub start: AnyCov,
    /// Σ after each step.
    pub steps: Vec<EvalStep>,
    /// Σ after the last step.
    pub result: AnyCov,
    /// What operators reported (a sensor's per-pixel decisions), by step.
    #[serde(default)]
    pub reports: Vec<StepReport>,
}

/// One step of an [`Evaluation`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvalStep {
    /// Operator name.
    pub operator: String,
    /// Σ after the step (N rows of N numbers).
    pub matrix: AnyCov,
    /// √Σ_ii per axis (cycles per unit).
    pub bandwidths: Vec<f64>,
}

/// A report of one step ([`cov_core::Operator::report`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// Index of the step.
    pub step: usize,
    /// Its operator.
    pub operator: String,
    /// What it reported; the typed value is there after [`Path::eval`]
    /// ([`Report::get`]), not after reading JSON back.
    pub report: Report,
}

impl Evaluation {
    /// The final Σ as a typed covariance.
    ///
    /// # Errors
    /// `N` differs from the evaluation's layout.
    pub fn result_cov<const N: usize>(&self) -> Result<Cov<N>, CovError> {
        self.result.to::<N>().ok_or_else(|| CovError::Shape {
            what: "Evaluation::result_cov".into(),
            expected: format!("layout {}", self.layout),
            got: format!("N = {N}"),
        })
    }

    /// The first report whose typed value is a `T` (the sensor's decisions, say).
    pub fn report<T: std::any::Any>(&self) -> Option<&T> {
        self.reports.iter().find_map(|r| r.report.get::<T>())
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
