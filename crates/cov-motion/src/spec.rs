//! RON parameters of the motion operators.

use cov_core::CovError;
use cov_core::{Chain, OperatorSpec, Registrar};

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
#[derive(Debug, OperatorSpec)]
#[operator(summary = "an object in motion: its operators applied in its moving frame")]
pub struct MovingSpec {
    /// Velocity in the tangent plane, `[vx]` or `[vx, vy]`, finite.
    #[param(unit = "m/s")]
    pub velocity: Vec<f64>,
    /// Angular velocity, `[wu]` or `[wu, wv]`.
    #[param(unit = "rad/s", default)]
    pub angular: Vec<f64>,
    /// The object's static operators, applied in its moving frame.
    #[param(nested)]
    pub operators: Chain,
}

impl TryFrom<MovingSpec> for Moving {
    type Error = CovError;
    fn try_from(spec: MovingSpec) -> Result<Moving, CovError> {
        let v = pad(Moving::NAME, "velocity", &spec.velocity)?;
        let w = pad(Moving::NAME, "angular", &spec.angular)?;
        Moving::new(v, w, spec.operators)
    }
}

/// `CameraMotion(velocity: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "the camera moves: the rest of the path in its frame")]
pub struct CameraMotionSpec {
    /// Velocity of the camera, `[vx]` or `[vx, vy]`, finite.
    #[param(unit = "m/s")]
    pub velocity: Vec<f64>,
    /// Angular velocity of the camera, `[wu]` or `[wu, wv]`.
    #[param(unit = "rad/s", default)]
    pub angular: Vec<f64>,
}

impl TryFrom<CameraMotionSpec> for CameraMotion {
    type Error = CovError;
    fn try_from(spec: CameraMotionSpec) -> Result<CameraMotion, CovError> {
        CameraMotion::new(
            pad(CameraMotion::NAME, "velocity", &spec.velocity)?,
            pad(CameraMotion::NAME, "angular", &spec.angular)?,
        )
    }
}

/// `Shutter(duration: 0.02, shape: Box)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "the shutter as a time window")]
pub struct ShutterSpec {
    /// Exposure, > 0.
    #[param(unit = "s")]
    pub duration: f64,
    /// `Box` (default) or `Gaussian` (std = duration).
    #[param(default)]
    pub shape: Option<ShutterShape>,
}

impl TryFrom<ShutterSpec> for Shutter {
    type Error = CovError;
    fn try_from(spec: ShutterSpec) -> Result<Shutter, CovError> {
        Shutter::new(spec.duration, spec.shape.unwrap_or(ShutterShape::Box))
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<MovingSpec>()
        .add::<CameraMotionSpec>()
        .add::<ShutterSpec>();
}
