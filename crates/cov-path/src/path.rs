//! A parsed light path: parsing, layout inference.

use cov_core::{AxisSet, Chain, Operator, layout_axes, layout_set};
use ron::extensions::Extensions;

use crate::de::{LayoutProbe, PathSeed, Reader};
use crate::error::PathError;
use crate::registry::Registry;
use crate::source::Source;

/// A parsed light path.
#[derive(Clone, Debug)]
pub struct Path {
    /// The file it was read from (`<string>` for text).
    pub file: String,
    /// The layout the file fixes, if any.
    pub layout: Option<usize>,
    /// The initial covariance.
    pub source: Source,
    /// The operators, in order.
    pub operators: Chain,
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
        // First pass: the declared layout, wherever it stands in the file, so that the
        // second pass can check every operator against it where it is written.
        let declared = ron_options().from_str_seed(text, LayoutProbe).ok().flatten();
        let reader = Reader::new(registry, crate::scan::operator_elements(text));
        let mut path = ron_options()
            .from_str_seed(
                text,
                PathSeed {
                    reader: &reader,
                    declared,
                },
            )
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

    /// Parses text and names it `file` in every error and in [`Path::file`].
    ///
    /// # Errors
    /// As [`Path::parse`], naming `file`.
    pub fn parse_named(text: &str, file: &str, registry: &Registry) -> Result<Path, PathError> {
        let mut path = Self::parse(text, registry).map_err(|e| e.in_file(file))?;
        path.file = file.to_string();
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
        Self::parse_named(&text, &name, registry)
    }

    /// Union of what the source and every operator need.
    pub fn requires(&self) -> AxisSet {
        self.source.requires().union(self.operators.requires())
    }

    /// The layout the path is traced in: the declared one, or the smallest that holds what
    /// every operator needs. The flag says whether it was inferred.
    ///
    /// # Errors
    /// A declared layout that lacks an axis some operator needs (naming both).
    pub fn resolve_layout(&self) -> Result<(usize, bool), PathError> {
        let needed = self.requires();
        let Some(n) = self.layout else {
            return Ok((needed.smallest_layout(), true));
        };
        let have = layout_set(n);
        let invalid = |at: Option<(usize, usize)>, message: String| PathError::Invalid {
            file: self.file.clone(),
            at,
            message,
        };
        if let Source::Matrix { rows } = &self.source
            && rows.len() != n
        {
            return Err(invalid(
                None,
                format!("the source matrix is {0}×{0} but the layout is {n}", rows.len()),
            ));
        }
        for (i, op) in self.operators.operators().enumerate() {
            if let Some(axis) = op.requires().iter().find(|a| !have.contains(*a)) {
                return Err(invalid(
                    self.positions.get(i).copied(),
                    format!(
                        "step {i} ({}) needs axis `{axis}`, which layout {n} ({}) does not have",
                        op.name(),
                        axes_string(n)
                    ),
                ));
            }
        }
        if let Some(axis) = self.source.requires().iter().find(|a| !have.contains(*a)) {
            return Err(invalid(
                None,
                format!(
                    "the source needs axis `{axis}`, which layout {n} ({}) does not have",
                    axes_string(n)
                ),
            ));
        }
        Ok((n, false))
    }
}

/// The axis names of layout `n`, comma-separated.
pub(crate) fn axes_string(n: usize) -> String {
    layout_axes(n)
        .unwrap_or(&[])
        .iter()
        .map(|a| a.name())
        .collect::<Vec<_>>()
        .join(",")
}
