//! RON parameters of the travel operator.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::Travel;

/// `Travel(distance: 1.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "free-space travel along the ray")]
pub struct TravelSpec {
    /// Distance (m); finite; negative travels back
    #[param(unit = "m")]
    pub distance: f64,
}

impl TryFrom<TravelSpec> for Travel {
    type Error = CovError;
    fn try_from(spec: TravelSpec) -> Result<Travel, CovError> {
        Travel::new(spec.distance)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<TravelSpec>();
}
