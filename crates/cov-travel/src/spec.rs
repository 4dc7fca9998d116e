//! RON parameters of the travel operator.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::Travel;

/// `Travel(distance: 1.5)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TravelSpec {
    /// Distance (m).
    pub distance: f64,
}

impl OperatorSpec for TravelSpec {
    const NAME: &'static str = Travel::NAME;
    const SUMMARY: &'static str = "free-space travel along the ray";
    const PARAMS: &'static [Param] = &[Param {
        name: "distance",
        unit: "m",
        doc: "finite; negative travels back",
    }];
    type Op = Travel;
    fn build(self) -> Result<Travel, CovError> {
        Travel::new(self.distance)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<TravelSpec>();
}
