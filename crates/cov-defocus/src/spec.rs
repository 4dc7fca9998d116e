//! RON parameters of the lens operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Pinhole, ThinLens};

/// `ThinLens(focal_length: 0.05, aperture: 0.005, focus_distance: 2.0)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThinLensSpec {
    /// m.
    pub focal_length: f64,
    /// Aperture std (m).
    pub aperture: f64,
    /// m.
    pub focus_distance: f64,
}

impl OperatorSpec for ThinLensSpec {
    const NAME: &'static str = ThinLens::NAME;
    const SUMMARY: &'static str = "thin lens with a Gaussian aperture, travel to the sensor";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "focal_length",
            unit: "m",
            doc: "> 0",
        },
        Param {
            name: "aperture",
            unit: "m",
            doc: "std of the aperture, > 0 (disk of radius R: R/2)",
        },
        Param {
            name: "focus_distance",
            unit: "m",
            doc: "> focal_length",
        },
    ];
    type Op = ThinLens;
    fn build(self) -> Result<ThinLens, CovError> {
        ThinLens::new(self.focal_length, self.aperture, self.focus_distance)
    }
}

/// `Pinhole(sensor_distance: 0.05)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PinholeSpec {
    /// m.
    pub sensor_distance: f64,
}

impl OperatorSpec for PinholeSpec {
    const NAME: &'static str = Pinhole::NAME;
    const SUMMARY: &'static str = "pinhole camera (the zero-aperture limit, in closed form)";
    const PARAMS: &'static [Param] = &[Param {
        name: "sensor_distance",
        unit: "m",
        doc: "> 0",
    }];
    type Op = Pinhole;
    fn build(self) -> Result<Pinhole, CovError> {
        Pinhole::new(self.sensor_distance)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<ThinLensSpec>().register::<PinholeSpec>();
}
