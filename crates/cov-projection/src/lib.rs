//! # cov-projection: from the ray to the surface and back
//!
//! **Primal definitions** (docs/physics.md section 3), with `c = |cos θ|` and the frame's `x`
//! axis in the plane of incidence:
//!
//! - projection, ray → surface: `l'(x,u) = l(c·x, u)` ([`Project`]);
//! - inverse projection, surface → outgoing ray: `l'(x,u) = l(x / c_out, u)` ([`Unproject`]);
//! - mirror symmetry (reflection): `l'(x,u) = l(x, −u)` on every direction axis ([`Mirror`]);
//! - rotation of the tangent frame by `α` (3D): `(x,y)` and `(u,v)` turn together
//!   ([`RotateFrame`]; positive is counter-clockwise from `x` to `y`).
//!
//! Foreshortening lowers spatial frequencies on the surface by `c`: `Σ_xx' = c² Σ_xx`.
//! Grazing incidence (`c → 0`) is a limit, not an error, as long as `c > 0`: the result
//! stays finite and PSD (`c = 1e-12` is part of the tests).
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Project` | `cos` | – | required | in (0, 1] | `\|cos θ\|`. |
//! |  | `angle` | rad | optional | finite | Frame rotation applied first (3D). |
//! | `Unproject` | `cos` | – | required | in (0, 1] | `\|cos θ_out\|`. |
//! |  | `angle` | rad | optional | finite | Frame rotation applied last (3D). |
//! | `Mirror` | – | | | | mirror symmetry of directions, l(x, −u) (no parameters) |
//! | `RotateFrame` | `angle` | rad | required | finite | Angle, counter-clockwise x → y. |
//! <!-- end of parameters -->
//!
//! [`Project::from_vectors`] computes `cos` and the frame turn (its cosine and sine; the
//! angle only if [`Project::angle`] asks) from the ray direction, the ray frame's `x`
//! axis and the surface normal (glam `DVec3`).
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_projection::{Project, Unproject};
//!
//! let mut c = Cov::<2>::gaussian([0.01, 0.1])?;
//! let before = c.get(0, 0);
//! Operator::apply(&Project::new(0.5)?, &mut c)?;
//! assert!((c.get(0, 0) - 0.25 * before).abs() < 1e-12 * before);
//! Operator::apply(&Unproject::new(0.5)?, &mut c)?; // back to the same angle
//! assert!((c.get(0, 0) - before).abs() < 1e-12 * before);
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Project, Unproject, Mirror, RotateFrame; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_projection::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.05, y: 0.02, u: 0.1),
//!     operators: [RotateFrame(angle: 0.4), Project(cos: 0.3), Mirror, Unproject(cos: 0.5, angle: -0.4)],
//! )
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 4); // inferred from what the operators need
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, AxisSet, CovError, Operator, OperatorSpec, Spectrum, Turn};
use glam::DVec3;

/// The frame turn of a projection: none at 0, so a flatland layout accepts it.
#[inline(always)]
fn rotate<S: Spectrum + ?Sized>(cov: &mut S, turn: Turn) -> Result<(), CovError> {
    if !turn.is_zero() {
        cov.rotate_frame_by(turn)
    } else {
        Ok(())
    }
}

fn needs(turn: Turn) -> AxisSet {
    if !turn.is_zero() {
        AxisSet::SPACE
    } else {
        AxisSet::FLAT
    }
}

/// Projection from the ray's transverse plane onto the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Project {
    cos: f64,
    turn: Turn,
}

impl Project {
    /// Operator name.
    pub const NAME: &'static str = "Project";

    /// Projection with `|cos θ| = cos`, frame already aligned.
    ///
    /// # Errors
    /// `cos` not in (0, 1].
    #[inline]
    pub fn new(cos: f64) -> Result<Self, CovError> {
        Self::with_angle(cos, 0.0)
    }

    /// Rotate the frame by `angle` (rad) first, then project.
    ///
    /// # Errors
    /// `cos` not in (0, 1], non-finite `angle`.
    #[inline]
    pub fn with_angle(cos: f64, angle: f64) -> Result<Self, CovError> {
        spec::ProjectSpec {
            cos,
            angle: Some(angle),
        }
        .build()
    }

    /// From geometry: the ray direction `dir`, the ray frame's `x` axis `frame_x` (both
    /// unit, orthogonal; the frame's `y` is `dir × frame_x`) and the surface normal. The
    /// turn takes `x` into the plane of incidence; at normal incidence it is none. Its
    /// cosine and sine come from the normal's components, without trigonometry.
    ///
    /// # Errors
    /// Non-unit or non-orthogonal inputs (tolerance 1e-9 on `|v|` for a unit vector,
    /// tested as `|v|²` within 2e-9 of 1; 1e-9 on `dir · frame_x`), non-finite components,
    /// or a ray parallel to the surface (`cos = 0`).
    pub fn from_vectors(dir: DVec3, frame_x: DVec3, normal: DVec3) -> Result<Self, CovError> {
        // Each vector named by its identifier.
        for (name, v) in [
            (stringify!(dir), dir),
            (stringify!(frame_x), frame_x),
            (stringify!(normal), normal),
        ] {
            // `|v|² − 1 ≈ 2 (|v| − 1)` near 1: the length's 1e-9, without its square root.
            if !v.is_finite() || (v.length_squared() - 1.0).abs() > 2e-9 {
                return Err(CovError::OutOfRange {
                    operator: Self::NAME.into(),
                    parameter: name.into(),
                    value: v.length(),
                    expected: "a finite unit vector".into(),
                });
            }
        }
        if dir.dot(frame_x).abs() > 1e-9 {
            return Err(CovError::OutOfRange {
                operator: Self::NAME.into(),
                parameter: stringify!(frame_x).into(),
                value: dir.dot(frame_x),
                expected: "orthogonal to dir".into(),
            });
        }
        // Unit vectors' dot product rounds up to a few ulp above 1 at head-on incidence
        // (for about one normalised vector in five, `v · v > 1`): still `|cos θ| = 1`.
        let cos = dir.dot(normal).abs().min(1.0);
        let frame_y = dir.cross(frame_x);
        let p = normal - normal.dot(dir) * dir;
        // At (near-)normal incidence every transverse axis is in the plane of incidence.
        // Elsewhere the turn comes from `p`'s components, without the trigonometry of an
        // angle (`Turn::towards`).
        let turn = if p.length_squared() <= 1e-24 {
            None
        } else {
            Turn::towards(p.dot(frame_x), p.dot(frame_y))
        };
        match turn {
            // `cos ≤ 1` by construction; 0 (a grazing ray) is the spec's error.
            Some(turn) if cos > 0.0 => Ok(Project { cos, turn }),
            _ => Self::new(cos),
        }
    }

    /// `|cos θ|`.
    pub fn cos(&self) -> f64 {
        self.cos
    }

    /// Frame rotation (rad). For a projection from [`Project::from_vectors`], an `atan2`
    /// of the turn's sine and cosine at every call, in `[−π, π]`.
    pub fn angle(&self) -> f64 {
        self.turn.angle()
    }
}

impl Operator for Project {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            rotate(cov, self.turn)?;
            cov.scale(Axis::X, self.cos)
        })
    }
    fn requires(&self) -> AxisSet {
        needs(self.turn)
    }
}

/// Inverse projection from the surface to the outgoing ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unproject {
    cos: f64,
    turn: Turn,
}

impl Unproject {
    /// Operator name.
    pub const NAME: &'static str = "Unproject";

    /// `|cos θ_out|`.
    pub fn cos(&self) -> f64 {
        self.cos
    }

    /// # Errors
    /// `cos` not in (0, 1].
    #[inline]
    pub fn new(cos: f64) -> Result<Self, CovError> {
        Self::with_angle(cos, 0.0)
    }

    /// Unproject, then rotate the frame by `angle` (rad).
    ///
    /// # Errors
    /// `cos` not in (0, 1], non-finite `angle`.
    #[inline]
    pub fn with_angle(cos: f64, angle: f64) -> Result<Self, CovError> {
        spec::UnprojectSpec {
            cos,
            angle: Some(angle),
        }
        .build()
    }
}

impl Operator for Unproject {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            cov.scale(Axis::X, 1.0 / self.cos)?;
            rotate(cov, self.turn)
        })
    }
    fn requires(&self) -> AxisSet {
        needs(self.turn)
    }
}

/// Mirror symmetry: `l'(x,u) = l(x, −u)` (and `v` in 3D).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Mirror;

impl Mirror {
    /// Operator name.
    pub const NAME: &'static str = "Mirror";
}

impl Operator for Mirror {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            // Per axis, not a loop over `direction_axes`: constant axes for a known type.
            cov.scale(Axis::U, -1.0)?;
            if cov.has(Axis::V) {
                cov.scale(Axis::V, -1.0)?;
            }
            Ok(())
        })
    }
}

/// Rotation of the tangent frame by `angle` (rad), `(x,y)` and `(u,v)` together.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotateFrame {
    turn: Turn,
}

impl RotateFrame {
    /// Operator name.
    pub const NAME: &'static str = "RotateFrame";

    /// # Errors
    /// Non-finite `angle`.
    #[inline]
    pub fn new(angle: f64) -> Result<Self, CovError> {
        spec::RotateFrameSpec { angle }.build()
    }
}

impl Operator for RotateFrame {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| cov.rotate_frame_by(self.turn))
    }
    fn requires(&self) -> AxisSet {
        AxisSet::SPACE
    }
}
