//! # cov-motion: moving objects, moving cameras, shutters
//!
//! **Primal definition** (docs/physics.md section 3): an object moving with velocity `v` (m/s,
//! in the tangent plane) acts through its static operator applied in its own frame,
//! `x_o = x − v·t`; e.g. a moving window gives `l'(x,u,t) = l(x,u,t)·w(x − v·t)`. An
//! object turning at angular velocity `ω` (rad/s) sees directions `u_o = u − ω·t`.
//!
//! **Spectrum**: entering the object's frame is rule 1 with the shears
//! `x ← x + v·t`, `u ← u + ω·t` (the field seen from the object is
//! `l_o(x_o, u_o, t) = l(x_o + v·t, u_o + ω·t, t)`); the static operators act there; leaving
//! is the opposite shears. The x–t correlation this creates is linear in `v`: doubling a
//! velocity doubles the shear (tested).
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Moving` | `velocity` | m/s | required | finite | Velocity in the tangent plane, `[vx]` or `[vx, vy]`. |
//! |  | `angular` | rad/s | optional | finite | Angular velocity, `[wu]` or `[wu, wv]`. |
//! |  | `operators` | – | required | – | The object's static operators, applied in its moving frame. |
//! | `CameraMotion` | `velocity` | m/s | required | finite | Velocity of the camera, `[vx]` or `[vx, vy]`. |
//! |  | `angular` | rad/s | optional | finite | Angular velocity of the camera, `[wu]` or `[wu, wv]`. |
//! | `Shutter` | `duration` | s | required | > 0 | Exposure. |
//! |  | `shape` | – | optional | – | `Box` (default) or `Gaussian` (std = duration). |
//! <!-- end of parameters -->
//!
//! All need the time axis (layouts 3 and 5). A zero-length shutter is rejected
//! (`duration > 0`): its limit is a static image, traced without `t`.
//!
//! **Worked example**: a 1 mm Gaussian occluder crossing the ray at 2 m/s, then a 20 ms box
//! shutter: the window adds `1/(4π²·1e-6) ≈ 2.53e4 (cycles/m)²` to `Σ_xx` in the occluder's
//! frame; back in the ray's frame it also gives `Σ_xt = −2 × 2.53e4` and `Σ_tt = 4 × 2.53e4`:
//! the occluder's edge sweeps past at 2 m/s, so its 1 mm of spatial detail becomes 0.5 ms of
//! temporal detail. The shutter adds `1/(4π² (0.02/√12)²) ≈ 760 (cycles/s)²` to `Σ_tt`.
//!
//! ```
//! use cov_core::{Axis, Chain, Cov, Operator};
//! use cov_motion::{Moving, Shutter, ShutterShape};
//!
//! let window = cov_occlusion::Window::isotropic(0.001)?; // a 1 mm Gaussian occluder
//! let moving = Moving::new([2.0, 0.0], [0.0, 0.0], Chain::new().with(window))?;
//! let mut c = Cov::<3>::zeros();
//! Operator::apply(&moving, &mut c)?;
//! Operator::apply(&Shutter::new(0.02, ShutterShape::Box)?, &mut c)?;
//! let w = 1.0 / (4.0 * std::f64::consts::PI.powi(2) * 1e-6);
//! assert!((c.at(Axis::X, Axis::T)? + 2.0 * w).abs() < 1e-9 * w);
//! # Ok::<(), cov_core::CovError>(())
//! ```
//!
//! In RON:
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_motion::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.2, t: 1.0),
//!     operators: [
//!         CameraMotion(velocity: [0.5]),
//!         Moving(velocity: [2.0], operators: [Shutter(duration: 0.5, shape: Gaussian)]),
//!         Shutter(duration: 0.02, shape: Box),
//!     ],
//! )
//! "#;
//! let result = cov_path::Path::parse(text, &registry)?.eval()?;
//! assert_eq!(result.layout, 3);
//! # Ok::<(), cov_path::PathError>(())
//! ```

#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, AxisSet, Chain, CovError, Operator, OperatorSpec, Spectrum, arg};

/// The frame of an object in motion: linear and angular velocity in the tangent plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionFrame {
    v: [f64; 2],
    w: [f64; 2],
}

impl MotionFrame {
    /// # Errors
    /// Non-finite components.
    pub fn new(velocity: [f64; 2], angular: [f64; 2]) -> Result<Self, CovError> {
        Self::for_operator("MotionFrame", velocity, angular)
    }

    /// As [`MotionFrame::new`], errors naming `operator`.
    ///
    /// # Errors
    /// Non-finite components.
    pub fn for_operator(
        operator: &'static str,
        velocity: [f64; 2],
        angular: [f64; 2],
    ) -> Result<Self, CovError> {
        for k in 0..2 {
            arg!(operator, velocity[k]).finite()?;
            arg!(operator, angular[k]).finite()?;
        }
        Ok(MotionFrame {
            v: velocity,
            w: angular,
        })
    }

    /// Axes needed: `t`, plus `y`/`v` when a second component is non-zero.
    pub fn requires(&self) -> AxisSet {
        let base = AxisSet::FLAT_TIME;
        if self.v[1] != 0.0 || self.w[1] != 0.0 {
            base.union(AxisSet::SPACE)
        } else {
            base
        }
    }

    /// Shears by `sign` × the motion: `+1` enters the moving frame, `−1` leaves it.
    ///
    /// # Errors
    /// Missing time axis, overflow.
    pub fn shear(&self, cov: &mut dyn Spectrum, sign: f64) -> Result<(), CovError> {
        let pairs = [
            (Axis::X, self.v[0]),
            (Axis::Y, self.v[1]),
            (Axis::U, self.w[0]),
            (Axis::V, self.w[1]),
        ];
        cov.index(Axis::T)?;
        for (axis, rate) in pairs {
            if rate != 0.0 {
                cov.shear(axis, Axis::T, sign * rate)?;
            }
        }
        Ok(())
    }
}

/// An object in motion: its static operators applied in its moving frame.
#[derive(Clone, Debug)]
pub struct Moving {
    frame: MotionFrame,
    operators: Chain,
}

impl Moving {
    /// Operator name.
    pub const NAME: &'static str = "Moving";

    /// # Errors
    /// Non-finite velocities.
    pub fn new(velocity: [f64; 2], angular: [f64; 2], operators: Chain) -> Result<Self, CovError> {
        spec::MovingSpec {
            velocity: velocity.to_vec(),
            angular: angular.to_vec(),
            operators,
        }
        .build()
    }
}

impl Operator for Moving {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        self.frame.shear(cov, 1.0)?;
        self.operators.apply(cov)?;
        self.frame.shear(cov, -1.0)
    }
    fn requires(&self) -> AxisSet {
        self.frame.requires().union(self.operators.requires())
    }
}

/// The camera moves: the rest of the path is seen in its frame.
#[derive(Clone, Copy, Debug)]
pub struct CameraMotion {
    frame: MotionFrame,
}

impl CameraMotion {
    /// Operator name.
    pub const NAME: &'static str = "CameraMotion";

    /// # Errors
    /// Non-finite velocities.
    pub fn new(velocity: [f64; 2], angular: [f64; 2]) -> Result<Self, CovError> {
        spec::CameraMotionSpec {
            velocity: velocity.to_vec(),
            angular: angular.to_vec(),
        }
        .build()
    }
}

impl Operator for CameraMotion {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        self.frame.shear(cov, 1.0)
    }
    fn requires(&self) -> AxisSet {
        self.frame.requires()
    }
}

/// Shape of the shutter's time window.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
pub enum ShutterShape {
    /// Open for `duration` seconds; approximated by the Gaussian of equal variance
    /// (`std = duration/√12`), whose spectrum has a finite second moment (a box's does not).
    Box,
    /// A Gaussian of std `duration`.
    Gaussian,
}

/// The shutter as a window on time (rule 2). Integration over the exposure is the
/// sensor's job (cov-sensor), or `Integrate(axes: [t])`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shutter {
    std: f64,
    w: f64,
}

impl Shutter {
    /// Operator name.
    pub const NAME: &'static str = "Shutter";

    /// # Errors
    /// Non-positive or non-finite duration (a zero-length shutter is a static image: trace
    /// without time instead).
    pub fn new(duration: f64, shape: ShutterShape) -> Result<Self, CovError> {
        spec::ShutterSpec {
            duration,
            shape: Some(shape),
        }
        .build()
    }

    /// Std of the (equivalent) Gaussian time window (s).
    pub fn std(&self) -> f64 {
        self.std
    }
}

impl Operator for Shutter {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov.add_variance(Axis::T, self.w)
    }
    fn requires(&self) -> AxisSet {
        AxisSet::FLAT_TIME
    }
}
