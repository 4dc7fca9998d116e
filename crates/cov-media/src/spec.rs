//! RON parameters of the media operators.

use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Absorption, Fit, Phase, Scatter, Segment};

fn hessian(op: &str, h: &[f64]) -> Result<[f64; 3], CovError> {
    match h {
        [a] => Ok([*a, 0.0, 0.0]),
        [a, b, c] => Ok([*a, *b, *c]),
        _ => Err(CovError::Shape {
            what: format!("{op}: hessian"),
            expected: "[hxx] or [hxx, hxy, hyy]".into(),
            got: format!("{} numbers", h.len()),
        }),
    }
}

/// `Absorption(length: 2.0, hessian: [0.5])`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AbsorptionSpec {
    /// m.
    pub length: f64,
    /// 1/m³: `[hxx]` or `[hxx, hxy, hyy]`.
    pub hessian: Vec<f64>,
}

const ABS_PARAMS: &[Param] = &[
    Param {
        name: "length",
        unit: "m",
        doc: "≥ 0",
    },
    Param {
        name: "hessian",
        unit: "1/m³",
        doc: "[hxx] or [hxx, hxy, hyy] of σ_t across the ray",
    },
];

impl OperatorSpec for AbsorptionSpec {
    const NAME: &'static str = Absorption::NAME;
    const SUMMARY: &'static str = "absorption across a heterogeneous segment (a window)";
    const PARAMS: &'static [Param] = ABS_PARAMS;
    type Op = Absorption;
    fn build(self) -> Result<Absorption, CovError> {
        Absorption::new(self.length, hessian(Absorption::NAME, &self.hessian)?)
    }
}

/// `Segment(length: 2.0, hessian: [0.5])`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentSpec {
    /// m.
    pub length: f64,
    /// 1/m³.
    pub hessian: Vec<f64>,
}

impl OperatorSpec for SegmentSpec {
    const NAME: &'static str = Segment::NAME;
    const SUMMARY: &'static str = "a volumetric segment: absorption then travel";
    const PARAMS: &'static [Param] = ABS_PARAMS;
    type Op = Segment;
    fn build(self) -> Result<Segment, CovError> {
        Segment::new(self.length, hessian(Segment::NAME, &self.hessian)?)
    }
}

/// `Scatter(angle: 0.3, phase: HenyeyGreenstein(g: 0.7), fit: Curvature, azimuth: 0.0)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScatterSpec {
    /// rad.
    pub angle: f64,
    /// Phase function.
    pub phase: Phase,
    /// Fit (default Moment).
    #[serde(default)]
    pub fit: Option<Fit>,
    /// rad (3D), default 0.
    #[serde(default)]
    pub azimuth: Option<f64>,
}

impl OperatorSpec for ScatterSpec {
    const NAME: &'static str = Scatter::NAME;
    const SUMMARY: &'static str = "scattering at a point: frame alignment and the phase function lobe";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "angle",
            unit: "rad",
            doc: "[0, π]",
        },
        Param {
            name: "phase",
            unit: "",
            doc: "HenyeyGreenstein(g) | Tabulated(angles, values)",
        },
        Param {
            name: "fit",
            unit: "",
            doc: "Moment (default) | Curvature",
        },
        Param {
            name: "azimuth",
            unit: "rad",
            doc: "frame rotation into the scattering plane (3D)",
        },
    ];
    type Op = Scatter;
    fn build(self) -> Result<Scatter, CovError> {
        Scatter::new(
            self.angle,
            self.phase,
            self.fit.unwrap_or_default(),
            self.azimuth.unwrap_or(0.0),
        )
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<AbsorptionSpec>()
        .register::<SegmentSpec>()
        .register::<ScatterSpec>();
}
