//! # covtrace
//!
//! Covariance tracing: frequency analysis of light transport. Along a light path a small
//! symmetric matrix Σ describes the local Fourier spectrum of radiance around the ray;
//! each event on the path is an operator on Σ, and at the sensor Σ tells a renderer how
//! many samples a pixel needs and how wide its reconstruction filter may be.
//!
//! This facade re-exports [`cov_core`] at its root and each operator crate as a module,
//! behind a Cargo feature of the same name (all on by default), so a renderer for a scene
//! without, say, refraction builds with `default-features = false, features = [...]`
//! and never compiles what it does not use.
//!
//! ```
//! use covtrace::{Axis, Cov, CovError};
//!
//! let mut c = Cov::<4>::gaussian([1e-3, 1e-3, f64::INFINITY, f64::INFINITY])?;
//! c.shear(Axis::X, Axis::U, -1.0)?;
//! c.shear(Axis::Y, Axis::V, -1.0)?;
//! println!("{c}");
//! # Ok::<(), CovError>(())
//! ```

pub use cov_core::*;

/// Free-space travel (crate `cov-travel`, feature `travel`).
#[cfg(feature = "travel")]
pub use cov_travel as travel;

/// Occluders, blocker edges, textures (crate `cov-occlusion`, feature `occlusion`).
#[cfg(feature = "occlusion")]
pub use cov_occlusion as occlusion;

/// Projection, mirror symmetry, frame rotation (crate `cov-projection`, feature `projection`).
#[cfg(feature = "projection")]
pub use cov_projection as projection;

/// Curvature (crate `cov-curvature`, feature `curvature`).
#[cfg(feature = "curvature")]
pub use cov_curvature as curvature;

/// BRDF lobes and reflection (crate `cov-brdf`, feature `brdf`).
#[cfg(feature = "brdf")]
pub use cov_brdf as brdf;

/// Refraction (crate `cov-refraction`, feature `refraction`).
#[cfg(feature = "refraction")]
pub use cov_refraction as refraction;
