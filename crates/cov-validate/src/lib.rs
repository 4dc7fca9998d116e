//! # cov-validate: the brute-force ground truth
//!
//! Builds the primal local light field of a chain directly from the definitions of
//! `docs/physics.md` section 3, as a composed function of `z` ([`Field`]): coordinate
//! maps, products with windows (smooth or hard), convolutions with lobes and integrations
//! by quadrature. [`measure`] samples it on a grid under a Gaussian window, FFTs it
//! (rustfft) and returns the normalised second moments of `|l̂|` minus the window's own
//! covariance (section 5). Nothing here uses the covariance kernels: the two sides of a
//! validation share no code beyond the `Cov` type that holds the prediction.
//!
//! Any layout `N = 2..5` works, with one FFT over all axes (`grid^N` samples: 64–128 per
//! axis in 2D/3D, 24–32 in 4D, 16 in 5D keep a case under a second in release builds).
//!
//! ```
//! use cov_core::{Axis, Cov, Spectrum};
//! use cov_validate::{Field, Grid, Primal, compare};
//!
//! // A Gaussian spot (std 0.1 m, constant in angle) after a travel of 0.5 m.
//! let field = Field::gaussian(&[0.1, f64::INFINITY]).then(Primal::travel(2, 0.5));
//! let mut predicted = Cov::<2>::gaussian([0.1, f64::INFINITY]).unwrap();
//! predicted.shear(Axis::X, Axis::U, -0.5).unwrap();
//! let report = compare(&field, &predicted, &Grid::auto(&predicted, 64, &[1.0, 1.0])).unwrap();
//! assert!(report.rel_error < 1e-3, "{report:?}");
//! ```

#![warn(missing_docs)]

mod field;
mod measure;

pub use field::{Field, Primal, PrimalFn};
pub use measure::{Comparison, Grid, ValidateError, WINDOW_FRACTION, compare, measure};
