//! RON parameters of the sensor operators.

use cov_core::{Axis, CovError};
use cov_core::{OperatorSpec, Registrar};

use crate::{Integrate, Sensor, SensorParams};

impl TryFrom<SensorParams> for Sensor {
    type Error = CovError;
    fn try_from(p: SensorParams) -> Result<Sensor, CovError> {
        Sensor::new(p)
    }
}

/// `Integrate(axes: [t])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "integration over axes (rule 4): lens, shutter, angle")]
pub struct IntegrateSpec {
    /// Axes to integrate over: a list of `x`, `y`, `u`, `v`, `t`.
    pub axes: Vec<Axis>,
}

impl TryFrom<IntegrateSpec> for Integrate {
    type Error = CovError;
    fn try_from(spec: IntegrateSpec) -> Result<Integrate, CovError> {
        Integrate::new(spec.axes)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<SensorParams>().add::<IntegrateSpec>();
}
