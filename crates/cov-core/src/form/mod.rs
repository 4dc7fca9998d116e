//! The two forms Σ is held in, each implementing the raw kernels of [`crate::Spectrum`]:
//! the covariance itself ([`crate::Cov`], `cov.rs`) and its square-root factor
//! ([`CovFactor`], `factor.rs`).

pub(crate) mod cov;
mod factor;

pub use cov::SCHUR_SNAP;
pub use factor::{CovFactor, ROW_SNAP};
