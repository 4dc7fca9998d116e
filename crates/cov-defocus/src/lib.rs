//! # cov-defocus: thin lens, aperture, pinhole
//!
//! **Primal definitions** (docs/physics.md section 3): a thin lens of focal length `f` is a
//! curvature of `1/f`, `l'(x,u) = l(x, u + x/f)`, followed by travel to the sensor; the
//! aperture is a window on the lens position (rule 2); the sensor integrates over the
//! lens (rule 4, done by cov-sensor). The sensor sits where the focus plane is imaged:
//! `d_s = f·d_f / (d_f − f)` (thin-lens equation), so a point at distance `d_f` in front
//! of the lens lands on one sensor point whatever the aperture (tested: no defocus term).
//!
//! The **pinhole** is the limit of a vanishing aperture, computed in closed form instead of
//! with an infinite window: the sensor at `d_s` sees `L(x_s) = l(0, x_s/d_s)`, rule 1 with
//! the singular map `(x, u) ↦ (0, x/d_s)`, i.e. `Σ'_xx = Σ_uu / d_s²` and nothing left in
//! angle. No NaN, no infinity.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `ThinLens` | `focal_length` | m | required | > 0 | Focal length. |
//! |  | `aperture` | m | required | > 0 | Std of the aperture (a disk of radius R: R/2). |
//! |  | `focus_distance` | m | required | > focal_length | Focus distance (beyond the focal length: a real image). |
//! | `Pinhole` | `sensor_distance` | m | required | > 0 | Pinhole to sensor. |
//! <!-- end of parameters -->
//!
//! **Worked example**: `f = 50 mm`, focus at `2 m` → `d_s = 0.05·2/1.95 = 51.28 mm`. A point
//! at 1 m (out of focus) is imaged at `d_i = 52.63 mm`; on the sensor its rays spread over
//! `aperture × |1 − d_s/d_i| = 5 mm × 0.0256 = 0.128 mm` (std), the defocus blur that the
//! validator measures (`tests/validate.rs`).
//!
//! ```
//! use cov_core::{Axis, Cov, Operator};
//! use cov_defocus::ThinLens;
//!
//! let lens = ThinLens::new(0.05, 0.005, 2.0)?;
//! assert!((lens.sensor_distance() - 0.05 * 2.0 / 1.95).abs() < 1e-15);
//! let mut c = Cov::<2>::zeros();
//! Operator::apply(&lens, &mut c)?;
//! assert!(c.validity().is_valid());
//! # Ok::<(), cov_core::CovError>(())
//! ```
//!
//! In RON:
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_defocus::spec::register(&mut registry);
//! let text = "Path(source: Gaussian(x: 0.01), operators: [ThinLens(focal_length: 0.05, aperture: 0.005, focus_distance: 2.0)])";
//! let result = cov_path::Path::parse(text, &registry)?.eval()?;
//! assert_eq!(result.layout, 2);
//! # Ok::<(), cov_path::PathError>(())
//! ```

#![warn(missing_docs)]

pub mod spec;

use cov_core::{CovError, FOUR_PI_SQ, Operator, OperatorSpec, Spectrum};

/// A thin lens with a Gaussian aperture, focused at `focus_distance`; ends at the sensor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    f: f64,
    aperture: f64,
    d_s: f64,
}

impl ThinLens {
    /// Operator name.
    pub const NAME: &'static str = "ThinLens";

    /// # Errors
    /// Non-positive or non-finite parameters, or `focus_distance ≤ focal_length` (no real
    /// image).
    pub fn new(focal_length: f64, aperture: f64, focus_distance: f64) -> Result<Self, CovError> {
        spec::ThinLensSpec {
            focal_length,
            aperture,
            focus_distance,
        }
        .build()
    }

    /// Lens-to-sensor distance `d_s` (m).
    pub fn sensor_distance(&self) -> f64 {
        self.d_s
    }

    /// Aperture std (m).
    pub fn aperture(&self) -> f64 {
        self.aperture
    }
}

impl Operator for ThinLens {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        let w = 1.0 / (FOUR_PI_SQ * self.aperture * self.aperture);
        for &(x, u) in cov.transverse_pairs() {
            cov.add_variance(x, w)?;
            cov.shear(u, x, 1.0 / self.f)?;
            cov.shear(x, u, -self.d_s)?;
        }
        Ok(())
    }
}

/// A pinhole camera: the sensor at `sensor_distance` behind an infinitely small hole.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    d_s: f64,
}

impl Pinhole {
    /// Operator name.
    pub const NAME: &'static str = "Pinhole";

    /// # Errors
    /// Non-positive or non-finite distance.
    pub fn new(sensor_distance: f64) -> Result<Self, CovError> {
        spec::PinholeSpec { sensor_distance }.build()
    }
}

impl Operator for Pinhole {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        // (x, u) ↦ (0, x/d_s) on each pair; time untouched.
        // A (row-major), the identity but on the pairs.
        let n = cov.dim();
        let mut a = [0.0; 25];
        for i in 0..n {
            a[i * n + i] = 1.0;
        }
        for &(x, u) in cov.transverse_pairs() {
            let (ix, iu) = (cov.index(x)?, cov.index(u)?);
            a[ix * n + ix] = 0.0;
            a[iu * n + iu] = 0.0;
            a[iu * n + ix] = 1.0 / self.d_s;
        }
        cov.congruence(&a[..n * n])
    }
}
