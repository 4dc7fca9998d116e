//! RON parameters of the travel operator.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};

use crate::Travel;

/// `Travel(distance: 1.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "free-space travel along the ray")]
pub struct TravelSpec {
    /// Distance; negative travels back.
    #[param(unit = "m")]
    pub distance: f64,
}

impl Build for TravelSpec {
    type Op = Travel;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Travel, CovError> {
        Ok(Travel {
            distance: spec.distance,
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<TravelSpec>();
}
