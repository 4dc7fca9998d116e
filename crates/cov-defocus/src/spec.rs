//! RON parameters of the lens operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};

use crate::{Pinhole, ThinLens};

/// `ThinLens(focal_length: 0.05, aperture: 0.005, focus_distance: 2.0)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "thin lens with a Gaussian aperture, travel to the sensor")]
pub struct ThinLensSpec {
    /// Focal length.
    #[param(unit = "m", positive)]
    pub focal_length: f64,
    /// Std of the aperture (a disk of radius R: R/2).
    #[param(unit = "m", positive)]
    pub aperture: f64,
    /// Focus distance (beyond the focal length: a real image).
    #[param(unit = "m", gt = self.focal_length)]
    pub focus_distance: f64,
}

impl Build for ThinLensSpec {
    type Op = ThinLens;
    fn make(spec: Checked<Self>) -> Result<ThinLens, CovError> {
        let (f, d) = (spec.focal_length, spec.focus_distance);
        // Thin-lens equation; overflows only for a focus distance a rounding above f.
        let d_s = f * d / (d - f);
        if !d_s.is_finite() {
            return Err(ThinLensSpec::FOCUS_DISTANCE
                .error(d, "too close to focal_length: the sensor distance overflows"));
        }
        Ok(ThinLens {
            f,
            aperture: spec.aperture,
            d_s,
        })
    }
}

/// `Pinhole(sensor_distance: 0.05)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "pinhole camera (the zero-aperture limit, in closed form)")]
pub struct PinholeSpec {
    /// Pinhole to sensor.
    #[param(unit = "m", positive)]
    pub sensor_distance: f64,
}

impl Build for PinholeSpec {
    type Op = Pinhole;
    fn make(spec: Checked<Self>) -> Result<Pinhole, CovError> {
        Ok(Pinhole {
            d_s: spec.sensor_distance,
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<ThinLensSpec>().add::<PinholeSpec>();
}
