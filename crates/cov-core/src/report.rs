//! [`Report`]: what an operator tells about Σ when a chain is traced (a sensor's
//! per-pixel decisions), as a typed value plus named fields for tables and JSON.

use std::any::Any;
use std::fmt;
use std::sync::Arc;

/// A value an operator reports at evaluation ([`crate::Operator::report`]).
///
/// It carries the operator's own typed value, read back with [`Report::get`] (the sensor's
/// `PixelDecisions`, say), and the same content as named [`ReportField`]s, which any
/// caller can print or serialise without knowing the type. Serialisation keeps the title
/// and fields; the typed value lives only in memory.
///
/// ```
/// use cov_core::{Field, Report, ReportField};
///
/// #[derive(Debug, PartialEq)]
/// struct Spp(f64);
/// let r = Report::new("decisions", vec![ReportField::new("samples per pixel", "", Field::Number(2.5))], Spp(2.5));
/// assert_eq!(r.get::<Spp>(), Some(&Spp(2.5)));
/// assert_eq!(r.fields[0].value, Field::Number(2.5));
/// ```
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct Report {
    /// What is reported (a heading).
    pub title: String,
    /// The content, field by field.
    pub fields: Vec<ReportField>,
    #[serde(skip)]
    value: Option<Arc<dyn Any + Send + Sync>>,
}

impl Report {
    /// A report with its typed value.
    pub fn new<T: Any + Send + Sync>(title: impl Into<String>, fields: Vec<ReportField>, value: T) -> Report {
        Report {
            title: title.into(),
            fields,
            value: Some(Arc::new(value)),
        }
    }

    /// The typed value, if it is a `T` (and the report was not read back from text).
    pub fn get<T: Any>(&self) -> Option<&T> {
        self.value.as_ref()?.downcast_ref::<T>()
    }

    /// The field named `name`.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name).map(|f| &f.value)
    }
}

impl PartialEq for Report {
    /// Title and fields (the typed value is what the fields say).
    fn eq(&self, other: &Self) -> bool {
        self.title == other.title && self.fields == other.fields
    }
}

impl fmt::Debug for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Report")
            .field("title", &self.title)
            .field("fields", &self.fields)
            .finish()
    }
}

/// One named, unit-carrying entry of a [`Report`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ReportField {
    /// Name, as printed.
    pub name: String,
    /// Unit (empty when dimensionless).
    pub unit: String,
    /// The value.
    pub value: Field,
}

impl ReportField {
    /// A field.
    pub fn new(name: impl Into<String>, unit: impl Into<String>, value: Field) -> ReportField {
        ReportField {
            name: name.into(),
            unit: unit.into(),
            value,
        }
    }
}

/// The value of a [`ReportField`].
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Field {
    /// One number.
    Number(f64),
    /// A vector.
    Numbers(Vec<f64>),
    /// A matrix, row by row.
    Matrix(Vec<Vec<f64>>),
    /// Names or words.
    Text(Vec<String>),
    /// Yes or no.
    Flag(bool),
}
