//! RON parameters of the motion operators.

use cov_core::{Build, Chain, Checked, CovError, FOUR_PI_SQ, OperatorSpec, Param, Registrar};

use crate::{CameraMotion, MotionFrame, Moving, Shutter, ShutterShape};

/// `[]`, `[a]` or `[a, b]` as `[a, b]`; `p` is the parameter.
fn pad(p: &Param, v: &[f64]) -> Result<[f64; 2], CovError> {
    match v {
        [] => Ok([0.0, 0.0]),
        [a] => Ok([*a, 0.0]),
        [a, b] => Ok([*a, *b]),
        _ => Err(p.wrong_length(v.len(), "1 or 2 components")),
    }
}

/// `Moving(velocity: [2.0, 0.0], angular: [0.0], operators: [Window(std_x: 0.001)])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "an object in motion: its operators applied in its moving frame")]
pub struct MovingSpec {
    /// Velocity in the tangent plane, `[vx]` or `[vx, vy]`.
    #[param(unit = "m/s")]
    pub velocity: Vec<f64>,
    /// Angular velocity, `[wu]` or `[wu, wv]`.
    #[param(unit = "rad/s", default)]
    pub angular: Vec<f64>,
    /// The object's static operators, applied in its moving frame.
    #[param(nested)]
    pub operators: Chain,
}

impl Build for MovingSpec {
    type Op = Moving;
    fn make(spec: Checked<Self>) -> Result<Moving, CovError> {
        let spec = spec.into_inner();
        Ok(Moving {
            frame: MotionFrame {
                v: pad(&Self::VELOCITY, &spec.velocity)?,
                w: pad(&Self::ANGULAR, &spec.angular)?,
            },
            operators: spec.operators,
        })
    }
}

/// `CameraMotion(velocity: [0.5])`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "the camera moves: the rest of the path in its frame")]
pub struct CameraMotionSpec {
    /// Velocity of the camera, `[vx]` or `[vx, vy]`.
    #[param(unit = "m/s")]
    pub velocity: Vec<f64>,
    /// Angular velocity of the camera, `[wu]` or `[wu, wv]`.
    #[param(unit = "rad/s", default)]
    pub angular: Vec<f64>,
}

impl Build for CameraMotionSpec {
    type Op = CameraMotion;
    fn make(spec: Checked<Self>) -> Result<CameraMotion, CovError> {
        Ok(CameraMotion {
            frame: MotionFrame {
                v: pad(&Self::VELOCITY, &spec.velocity)?,
                w: pad(&Self::ANGULAR, &spec.angular)?,
            },
        })
    }
}

/// `Shutter(duration: 0.02, shape: Box)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "the shutter as a time window")]
pub struct ShutterSpec {
    /// Exposure.
    #[param(unit = "s", positive)]
    pub duration: f64,
    /// `Box` (default) or `Gaussian` (std = duration).
    #[param(default)]
    pub shape: Option<ShutterShape>,
}

impl Build for ShutterSpec {
    type Op = Shutter;
    fn make(spec: Checked<Self>) -> Result<Shutter, CovError> {
        let std = match spec.shape.unwrap_or(ShutterShape::Box) {
            ShutterShape::Box => spec.duration / 12f64.sqrt(),
            ShutterShape::Gaussian => spec.duration,
        };
        let w = 1.0 / (FOUR_PI_SQ * std * std);
        if !w.is_finite() {
            return Err(Self::DURATION.error(spec.duration, "too short: 1/(4π² s²) overflows"));
        }
        Ok(Shutter { std, w })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<MovingSpec>()
        .add::<CameraMotionSpec>()
        .add::<ShutterSpec>();
}
