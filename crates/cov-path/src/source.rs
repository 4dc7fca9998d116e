//! The source of a path: its initial Σ, from physical quantities.

use cov_core::{AnyCov, Axis, AxisSet, CovError, axis_index, layout_set};
use serde::{Deserialize, Serialize};

use crate::path::axes_string;

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
                    if let Some(s) = std
                        && !(1.0 / (cov_core::FOUR_PI_SQ * s * s)).is_finite()
                    {
                        return Err(format!(
                            "Gaussian source: std `{axis}` = {} is too small: its spectrum variance 1/(4π² s²) overflows f64",
                            cov_core::num(s)
                        ));
                    }
                }
            }
            Source::Dirac {
                scene_scale,
                relative_size,
            } => {
                AnyCov::dirac(
                    2,
                    *scene_scale,
                    relative_size.unwrap_or(cov_core::DIRAC_RELATIVE_SIZE),
                )
                .map_err(|e| format!("Dirac source: {}", user_words(&e)))?;
            }
            Source::Matrix { rows } => {
                let n = rows.len();
                if !(2..=5).contains(&n) || rows.iter().any(|r| r.len() != n) {
                    return Err(format!(
                        "Matrix source: expected N rows of N numbers with N in 2..=5, got {n} rows of lengths {:?}",
                        rows.iter().map(Vec::len).collect::<Vec<_>>()
                    ));
                }
                AnyCov::from_rows(rows).map_err(|e| format!("Matrix source: {}", user_words(&e)))?;
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

    /// Σ of the source in layout `n`.
    ///
    /// # Errors
    /// Invalid values, an axis not in the layout, a matrix of the wrong size.
    pub fn covariance(&self, n: usize) -> Result<AnyCov, CovError> {
        match self {
            Source::Gaussian { .. } => {
                let mut stds = [f64::INFINITY; 5];
                for (axis, std) in self.gaussian_stds().into_iter().flatten() {
                    if let Some(s) = std {
                        stds[axis_index(n, axis)?] = s;
                    }
                }
                AnyCov::gaussian(stds.get(..n).unwrap_or(&[]))
            }
            Source::Dirac {
                scene_scale,
                relative_size,
            } => AnyCov::dirac(
                n,
                *scene_scale,
                relative_size.unwrap_or(cov_core::DIRAC_RELATIVE_SIZE),
            ),
            Source::Matrix { rows } => {
                if rows.len() != n {
                    return Err(CovError::Shape {
                        what: "Matrix source".into(),
                        expected: format!("{n} rows of {n} numbers"),
                        got: format!("{} rows", rows.len()),
                    });
                }
                AnyCov::from_rows(rows)
            }
        }
    }
}

/// A core error in the path author's words: without the name of the library function that
/// raised it (`Cov::dirac: …`), which means nothing in a path file.
fn user_words(e: &cov_core::CovError) -> String {
    let s = e.to_string();
    match s.split_once(": ") {
        Some((op, rest)) if op.contains("::") => rest.to_string(),
        _ => s,
    }
}
