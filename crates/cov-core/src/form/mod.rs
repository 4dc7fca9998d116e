//! The two forms Σ is held in, each implementing the raw kernels of [`crate::Spectrum`]:
//! the covariance itself ([`crate::Cov`], `cov.rs`) and its square-root factor
//! ([`CovFactor`], `factor.rs`).

pub(crate) mod cov;
mod factor;

pub use cov::SCHUR_SNAP;
pub use factor::{CovFactor, ROW_SNAP};

/// Where a form's finiteness check failed, as (row, column, value).
pub(crate) fn overflow_at(check: Result<(), crate::CovError>) -> Option<(usize, usize, f64)> {
    check.err().map(|e| match e {
        crate::CovError::Overflow { row, col, value, .. } => (row, col, value),
        _ => (0, 0, f64::NAN),
    })
}
