//! RON parameters of the projection operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar, Turn};

use crate::{Mirror, Project, RotateFrame, Unproject};

/// `Project(cos: 0.5)` or `Project(cos: 0.5, angle: 0.3)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "projection from the ray onto a surface")]
pub struct ProjectSpec {
    /// `|cos θ|`.
    #[param(gt = 0, le = 1)]
    pub cos: f64,
    /// Frame rotation applied first (3D).
    #[param(unit = "rad", default)]
    pub angle: Option<f64>,
}

impl Build for ProjectSpec {
    type Op = Project;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Project, CovError> {
        Ok(Project {
            cos: spec.cos,
            turn: Turn::new(ProjectSpec::ANGLE.of(spec.angle.unwrap_or(0.0)))?,
        })
    }
}

/// `Unproject(cos: 0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "inverse projection from a surface to the outgoing ray")]
pub struct UnprojectSpec {
    /// `|cos θ_out|`.
    #[param(gt = 0, le = 1)]
    pub cos: f64,
    /// Frame rotation applied last (3D).
    #[param(unit = "rad", default)]
    pub angle: Option<f64>,
}

impl Build for UnprojectSpec {
    type Op = Unproject;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<Unproject, CovError> {
        Ok(Unproject {
            cos: spec.cos,
            turn: Turn::new(UnprojectSpec::ANGLE.of(spec.angle.unwrap_or(0.0)))?,
        })
    }
}

/// `Mirror`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "mirror symmetry of directions, l(x, −u)")]
pub struct MirrorSpec {}

impl Build for MirrorSpec {
    type Op = Mirror;
    fn make(_: Checked<Self>) -> Result<Mirror, CovError> {
        Ok(Mirror)
    }
}

/// `RotateFrame(angle: 0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "rotation of the tangent frame (3D)")]
pub struct RotateFrameSpec {
    /// Angle, counter-clockwise x → y.
    #[param(unit = "rad")]
    pub angle: f64,
}

impl Build for RotateFrameSpec {
    type Op = RotateFrame;
    #[inline]
    fn make(spec: Checked<Self>) -> Result<RotateFrame, CovError> {
        Ok(RotateFrame {
            turn: Turn::new(RotateFrameSpec::ANGLE.of(spec.angle))?,
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<ProjectSpec>()
        .add::<UnprojectSpec>()
        .add::<MirrorSpec>()
        .add::<RotateFrameSpec>();
}
