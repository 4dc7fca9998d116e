//! RON parameters of the projection operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Mirror, Project, RotateFrame, Unproject};

/// `Project(cos: 0.5)` or `Project(cos: 0.5, angle: 0.3)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProjectSpec {
    /// `|cos θ|`.
    pub cos: f64,
    /// Frame rotation first (rad).
    #[serde(default)]
    pub angle: Option<f64>,
}

impl OperatorSpec for ProjectSpec {
    const NAME: &'static str = Project::NAME;
    const SUMMARY: &'static str = "projection from the ray onto a surface";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "cos",
            unit: "–",
            doc: "|cos θ| in (0, 1]",
        },
        Param {
            name: "angle",
            unit: "rad",
            doc: "frame rotation applied first (3D), default 0",
        },
    ];
    type Op = Project;
    fn build(self) -> Result<Project, CovError> {
        Project::with_angle(self.cos, self.angle.unwrap_or(0.0))
    }
}

/// `Unproject(cos: 0.5)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnprojectSpec {
    /// `|cos θ_out|`.
    pub cos: f64,
    /// Frame rotation last (rad).
    #[serde(default)]
    pub angle: Option<f64>,
}

impl OperatorSpec for UnprojectSpec {
    const NAME: &'static str = Unproject::NAME;
    const SUMMARY: &'static str = "inverse projection from a surface to the outgoing ray";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "cos",
            unit: "–",
            doc: "|cos θ_out| in (0, 1]",
        },
        Param {
            name: "angle",
            unit: "rad",
            doc: "frame rotation applied last (3D), default 0",
        },
    ];
    type Op = Unproject;
    fn build(self) -> Result<Unproject, CovError> {
        Unproject::with_angle(self.cos, self.angle.unwrap_or(0.0))
    }
}

/// `Mirror`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MirrorSpec {}

impl OperatorSpec for MirrorSpec {
    const NAME: &'static str = Mirror::NAME;
    const SUMMARY: &'static str = "mirror symmetry of directions, l(x, −u)";
    const PARAMS: &'static [Param] = &[];
    const UNIT: bool = true;
    type Op = Mirror;
    fn build(self) -> Result<Mirror, CovError> {
        Ok(Mirror)
    }
    fn unit() -> Option<Self> {
        Some(MirrorSpec {})
    }
}

/// `RotateFrame(angle: 0.5)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotateFrameSpec {
    /// Angle (rad).
    pub angle: f64,
}

impl OperatorSpec for RotateFrameSpec {
    const NAME: &'static str = RotateFrame::NAME;
    const SUMMARY: &'static str = "rotation of the tangent frame (3D)";
    const PARAMS: &'static [Param] = &[Param {
        name: "angle",
        unit: "rad",
        doc: "finite, counter-clockwise x → y",
    }];
    type Op = RotateFrame;
    fn build(self) -> Result<RotateFrame, CovError> {
        RotateFrame::new(self.angle)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<ProjectSpec>()
        .register::<UnprojectSpec>()
        .register::<MirrorSpec>()
        .register::<RotateFrameSpec>();
}
