//! RON parameters of the sensor operators.

use cov_core::{Axis, CovError};
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Integrate, Sensor, SensorParams};

impl OperatorSpec for SensorParams {
    const NAME: &'static str = Sensor::NAME;
    const SUMMARY: &'static str =
        "the sensor: pixel filter, integration over lens and shutter, per-pixel decisions";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "width",
            unit: "px",
            doc: "≥ 1",
        },
        Param {
            name: "fov_x",
            unit: "rad",
            doc: "(0, π)",
        },
        Param {
            name: "distance",
            unit: "m",
            doc: "lens to sensor, default 1",
        },
        Param {
            name: "filter",
            unit: "px",
            doc: "pixel filter std, default 0.5",
        },
        Param {
            name: "aperture",
            unit: "m",
            doc: "aperture std if the lens is sampled",
        },
        Param {
            name: "shutter",
            unit: "s",
            doc: "shutter std if time is sampled",
        },
        Param {
            name: "nyquist",
            unit: "–",
            doc: "Nyquist factor k, default 2",
        },
        Param {
            name: "max_filter",
            unit: "px",
            doc: "largest filter std, default 8",
        },
    ];
    type Op = Sensor;
    fn build(self) -> Result<Sensor, CovError> {
        Sensor::new(self)
    }
}

/// `Integrate(axes: [t])`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegrateSpec {
    /// Axes to integrate over.
    pub axes: Vec<Axis>,
}

impl OperatorSpec for IntegrateSpec {
    const NAME: &'static str = Integrate::NAME;
    const SUMMARY: &'static str = "integration over axes (rule 4): lens, shutter, angle";
    const PARAMS: &'static [Param] = &[Param {
        name: "axes",
        unit: "",
        doc: "list of x, y, u, v, t",
    }];
    type Op = Integrate;
    fn build(self) -> Result<Integrate, CovError> {
        Integrate::new(self.axes)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<SensorParams>().register::<IntegrateSpec>();
}
