//! RON parameters of the motion operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Operators, Param, Registry};
use serde::Deserialize;

use crate::{CameraMotion, Moving, Shutter, ShutterShape};

fn pad(op: &str, name: &str, v: &[f64]) -> Result<[f64; 2], CovError> {
    match v {
        [] => Ok([0.0, 0.0]),
        [a] => Ok([*a, 0.0]),
        [a, b] => Ok([*a, *b]),
        _ => Err(CovError::Shape {
            what: format!("{op}: {name}"),
            expected: "1 or 2 components".into(),
            got: format!("{}", v.len()),
        }),
    }
}

/// `Moving(velocity: [2.0, 0.0], angular: [0.0], operators: [Window(std_x: 0.001)])`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MovingSpec {
    /// m/s, 1 or 2 components.
    pub velocity: Vec<f64>,
    /// rad/s, 0 to 2 components.
    #[serde(default)]
    pub angular: Vec<f64>,
    /// The object's static operators.
    pub operators: Operators,
}

impl OperatorSpec for MovingSpec {
    const NAME: &'static str = Moving::NAME;
    const SUMMARY: &'static str = "an object in motion: its operators applied in its moving frame";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "velocity",
            unit: "m/s",
            doc: "[vx] or [vx, vy], finite",
        },
        Param {
            name: "angular",
            unit: "rad/s",
            doc: "[wu] or [wu, wv], optional",
        },
        Param {
            name: "operators",
            unit: "",
            doc: "the object's static operators",
        },
    ];
    type Op = Moving;
    fn build(self) -> Result<Moving, CovError> {
        let v = pad(Moving::NAME, "velocity", &self.velocity)?;
        let w = pad(Moving::NAME, "angular", &self.angular)?;
        Moving::new(v, w, self.operators.0)
    }
}

/// `CameraMotion(velocity: [0.5])`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraMotionSpec {
    /// m/s.
    pub velocity: Vec<f64>,
    /// rad/s.
    #[serde(default)]
    pub angular: Vec<f64>,
}

impl OperatorSpec for CameraMotionSpec {
    const NAME: &'static str = CameraMotion::NAME;
    const SUMMARY: &'static str = "the camera moves: the rest of the path in its frame";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "velocity",
            unit: "m/s",
            doc: "[vx] or [vx, vy]",
        },
        Param {
            name: "angular",
            unit: "rad/s",
            doc: "[wu] or [wu, wv], optional",
        },
    ];
    type Op = CameraMotion;
    fn build(self) -> Result<CameraMotion, CovError> {
        CameraMotion::new(
            pad(CameraMotion::NAME, "velocity", &self.velocity)?,
            pad(CameraMotion::NAME, "angular", &self.angular)?,
        )
    }
}

/// `Shutter(duration: 0.02, shape: Box)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShutterSpec {
    /// Seconds.
    pub duration: f64,
    /// `Box` (default) or `Gaussian`.
    #[serde(default)]
    pub shape: Option<ShutterShape>,
}

impl OperatorSpec for ShutterSpec {
    const NAME: &'static str = Shutter::NAME;
    const SUMMARY: &'static str = "the shutter as a time window";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "duration",
            unit: "s",
            doc: "> 0",
        },
        Param {
            name: "shape",
            unit: "",
            doc: "Box (default) or Gaussian (std = duration)",
        },
    ];
    type Op = Shutter;
    fn build(self) -> Result<Shutter, CovError> {
        Shutter::new(self.duration, self.shape.unwrap_or(ShutterShape::Box))
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<MovingSpec>()
        .register::<CameraMotionSpec>()
        .register::<ShutterSpec>();
}
