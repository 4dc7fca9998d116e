//! RON parameters of the sensor operators.

use cov_core::{Axis, Build, Checked, CovError, FOUR_PI_SQ, OperatorSpec, Registrar};

use crate::{Integrate, Sensor, SensorParams};

impl Build for SensorParams {
    type Op = Sensor;
    fn make(p: Checked<Self>) -> Result<Sensor, CovError> {
        let p = p.into_inner();
        let pitch = 2.0 * p.distance * (0.5 * p.fov_x).tan() / f64::from(p.width);
        if !(pitch > 0.0 && pitch.is_finite()) {
            return Err(SensorParams::DISTANCE.error(
                p.distance,
                format!(
                    "gives a pixel pitch of {pitch} m (with this fov_x and width): it must be finite and > 0"
                ),
            ));
        }
        // The pixel filter's window, `filter` pixels of the pitch: reported on the user's
        // `filter` when it overflows, with the pitch that `distance`, `fov_x` and `width`
        // give (a default `filter` with a tiny `fov_x` overflows too).
        let s = p.filter * pitch;
        if !(1.0 / (FOUR_PI_SQ * s * s)).is_finite() {
            return Err(SensorParams::FILTER.error(
                p.filter,
                format!(
                    "too small for a pixel pitch of {pitch:e} m (from distance, fov_x and width): the pixel filter's spectrum variance overflows f64"
                ),
            ));
        }
        Ok(Sensor { p, pitch })
    }
}

/// `Integrate(axes: [t])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "integration over axes (rule 4): lens, shutter, angle")]
pub struct IntegrateSpec {
    /// Axes to integrate over: a list of `x`, `y`, `u`, `v`, `t`.
    pub axes: Vec<Axis>,
}

impl Build for IntegrateSpec {
    type Op = Integrate;
    fn make(spec: Checked<Self>) -> Result<Integrate, CovError> {
        Integrate::new(spec.into_inner().axes)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<SensorParams>().add::<IntegrateSpec>();
}
