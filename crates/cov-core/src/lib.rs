//! # cov-core
//!
//! The shared machinery of covtrace: the spectrum covariance [`Cov<N>`] of the local light
//! field around a ray, generic over the four layouts of `docs/physics.md`
//! (`N = 2`: x,u; `3`: x,u,t; `4`: x,y,u,v; `5`: x,y,u,v,t), the [`Operator`] trait that
//! every event on a light path implements, [`Chain`]s of operators, the kernels that
//! implement the four algebraic rules, and the queries a renderer needs.
//!
//! ## Conventions
//!
//! - Axes are in the order `x, y, u, v, t` (see [`Axis`]): position in metres, direction as
//!   the tangent of the angular offset, time in seconds. Frequencies in cycles per unit.
//! - Σ is the normalised second moment of the **amplitude** spectrum `|l̂|`. A Gaussian
//!   light field of primal covariance `C` has `Σ = C⁻¹ / 4π²` ([`Cov::gaussian`]).
//! - Rule 1 (change of coordinates `l'(z) = l(A z)`): `Σ' = Aᵀ Σ A`
//!   ([`Cov::congruence`], [`Cov::shear`], [`Cov::scale`], [`Cov::rotate`]).
//! - Rule 2 (product with a window): `Σ' = Σ + W` ([`Cov::add_window`],
//!   [`Cov::add_variance`]).
//! - Rule 3 (convolution with a lobe of spectrum covariance `S`):
//!   `Σ' = Σ − Σ Pᵀ (S + PΣPᵀ)⁻¹ P Σ` ([`Cov::convolve`]), never inverting Σ.
//! - Rule 4 (integration over axes): the Schur complement on the kept axes, and 0 on the
//!   integrated ones ([`Cov::integrate`], [`Cov::integrated`]).
//!
//! ### Surface conventions (used by the operator crates)
//!
//! - A positive distance travels along the ray: `l'(x,u) = l(x − d·u, u)`.
//! - Curvature `k` (1/m) is positive for a **convex** surface seen from the side the light
//!   arrives on (a sphere of radius `R` seen from outside has `k = 1/R`); it acts in the
//!   surface frame as `l'(x,u) = l(x, u + k·x)`.
//! - The tangent frame is rotated by a positive angle counter-clockwise from `x` to `y`
//!   (as seen looking back along the ray), turning `(x,y)` and `(u,v)` together.
//!
//! ## Numerics
//!
//! All arithmetic is f64. Singular Σ is normal (a point source, a diffuse bounce, an
//! integrated axis) and every kernel handles it without inverting Σ; pseudo-inverses use
//! a unit-invariant rank decision ([`linalg::PINV_RCOND`]). Kernels reject non-finite
//! parameters and restore Σ when a result would overflow, returning
//! [`CovError::Overflow`] instead of propagating infinities or NaN.
//!
//! Operators act through the [`Spectrum`] interface, so a [`Chain`] holds Σ in either
//! [`Form`]: the square-root [`CovFactor`] (`Σ = L Lᵀ`, the default; PSD by construction,
//! and a cancelling Schur complement loses `ε·√(Σ_big/Σ_small)` instead of
//! `ε·Σ_big/Σ_small`: 2.4e-12 against 4.1e-9 on the stiff suite's 10⁴-operator bounce
//! chains) or the covariance [`Cov`] itself (cheaper kernels). Both make the same rank
//! decisions ([`SCHUR_SNAP`] on Σ, [`ROW_SNAP`] `= √SCHUR_SNAP` on the factor's rows): an
//! entry or row that cancelled below it is set to 0, which errs towards a smaller
//! bandwidth and is exact only when the true value is 0. A small variance well determined
//! by the parameters but not by Σ's entries (a window far below a beam's size, refocused
//! by a lobe) is kept by the square-root form (≤ 1.9e-15 on the stiff suite: a cancelled
//! row is rebuilt from its component along the lobe's row and its orthogonal part, both
//! computed without cancellation) and lost by the covariance form (up to 100%).
//!
//! ```
//! use cov_core::{Axis, Cov, CovError, Spectrum};
//!
//! // A Gaussian spot of 1 mm std emitting into a cone of std 0.05 (tangent).
//! let mut c = Cov::<2>::gaussian([1e-3, 0.05])?;
//! c.shear(Axis::X, Axis::U, -0.5)?; // travel 0.5 m
//! c.convolve(&[Axis::U], &[100.0])?; // a glossy lobe
//! let image = c.integrated(&[Axis::X])?; // what a sensor integrating over angle sees
//! assert!(image.bandwidths()[0] > 0.0);
//! # Ok::<(), CovError>(())
//! ```

#![warn(missing_docs)]

mod any;
mod axis;
mod cov;
mod direct;
mod error;
mod form;
pub mod linalg;
mod operator;
mod query;
mod report;
pub mod spec;
mod spectrum;

pub use any::{AnyCov, AnyFactor, AnySpectrum};
pub use axis::{Axis, AxisSet, axis_index, layout_axes, layout_set};
pub use cov::{Cov, DIRAC_RELATIVE_SIZE, FOUR_PI_SQ, PSD_RTOL, Validity};
pub use cov_derive::OperatorSpec;
pub use error::{CovError, ECHO_MAX, approx, echo, line_col, num, one_line, utf8_error_at};
pub use form::{CovFactor, ROW_SNAP, SCHUR_SNAP};
pub use operator::{Chain, Operator, Step, Trace};
pub use query::{CovBlock, Filter, NYQUIST_K};
pub use report::{Field, Report, ReportField};
pub use spec::{Build, Checked, OperatorReader, OperatorSpec, Param, ParamValue, Registrar};
pub use spectrum::{Concrete, Form, Spectrum, Turn};

/// serde, for the code `#[derive(OperatorSpec)]` generates.
#[doc(hidden)]
pub use serde as __serde;
