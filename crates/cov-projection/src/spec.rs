//! RON parameters of the projection operators.

use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::{Mirror, Project, RotateFrame, Unproject};

/// `Project(cos: 0.5)` or `Project(cos: 0.5, angle: 0.3)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "projection from the ray onto a surface")]
pub struct ProjectSpec {
    /// `|cos θ|`, in (0, 1].
    pub cos: f64,
    /// Frame rotation applied first (3D).
    #[param(unit = "rad", default)]
    pub angle: Option<f64>,
}

impl TryFrom<ProjectSpec> for Project {
    type Error = CovError;
    fn try_from(spec: ProjectSpec) -> Result<Project, CovError> {
        Project::with_angle(spec.cos, spec.angle.unwrap_or(0.0))
    }
}

/// `Unproject(cos: 0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "inverse projection from a surface to the outgoing ray")]
pub struct UnprojectSpec {
    /// `|cos θ_out|`, in (0, 1].
    pub cos: f64,
    /// Frame rotation applied last (3D).
    #[param(unit = "rad", default)]
    pub angle: Option<f64>,
}

impl TryFrom<UnprojectSpec> for Unproject {
    type Error = CovError;
    fn try_from(spec: UnprojectSpec) -> Result<Unproject, CovError> {
        Unproject::with_angle(spec.cos, spec.angle.unwrap_or(0.0))
    }
}

/// `Mirror`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "mirror symmetry of directions, l(x, −u)")]
pub struct MirrorSpec {}

impl TryFrom<MirrorSpec> for Mirror {
    type Error = CovError;
    fn try_from(_: MirrorSpec) -> Result<Mirror, CovError> {
        Ok(Mirror)
    }
}

/// `RotateFrame(angle: 0.5)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "rotation of the tangent frame (3D)")]
pub struct RotateFrameSpec {
    /// Angle, finite, counter-clockwise x → y.
    #[param(unit = "rad")]
    pub angle: f64,
}

impl TryFrom<RotateFrameSpec> for RotateFrame {
    type Error = CovError;
    fn try_from(spec: RotateFrameSpec) -> Result<RotateFrame, CovError> {
        RotateFrame::new(spec.angle)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<ProjectSpec>()
        .add::<UnprojectSpec>()
        .add::<MirrorSpec>()
        .add::<RotateFrameSpec>();
}
