//! RON parameters of the lens operators.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::{Pinhole, ThinLens};

/// `ThinLens(focal_length: 0.05, aperture: 0.005, focus_distance: 2.0)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "thin lens with a Gaussian aperture, travel to the sensor")]
pub struct ThinLensSpec {
    /// Focal length, > 0.
    #[param(unit = "m")]
    pub focal_length: f64,
    /// Std of the aperture, > 0 (a disk of radius R: R/2).
    #[param(unit = "m")]
    pub aperture: f64,
    /// Focus distance, > `focal_length`.
    #[param(unit = "m")]
    pub focus_distance: f64,
}

impl TryFrom<ThinLensSpec> for ThinLens {
    type Error = CovError;
    fn try_from(spec: ThinLensSpec) -> Result<ThinLens, CovError> {
        ThinLens::new(spec.focal_length, spec.aperture, spec.focus_distance)
    }
}

/// `Pinhole(sensor_distance: 0.05)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "pinhole camera (the zero-aperture limit, in closed form)")]
pub struct PinholeSpec {
    /// Pinhole to sensor, > 0.
    #[param(unit = "m")]
    pub sensor_distance: f64,
}

impl TryFrom<PinholeSpec> for Pinhole {
    type Error = CovError;
    fn try_from(spec: PinholeSpec) -> Result<Pinhole, CovError> {
        Pinhole::new(spec.sensor_distance)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<ThinLensSpec>().add::<PinholeSpec>();
}
