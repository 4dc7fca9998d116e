//! RON parameters of the BRDF operators.

use cov_core::CovError;
use cov_curvature::spec::CurvatureSpec;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Brdf, Lobe, Reflect};

/// `Brdf(lobe: Phong(exponent: 100))`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrdfSpec {
    /// The lobe: `Diffuse`, `Mirror`, `Phong(exponent:)`, `Gaussian(var_u:, var_v:)`,
    /// `Beckmann(alpha_u:, alpha_v:)`, `Ggx(alpha_u:, alpha_v:)`.
    pub lobe: Lobe,
}

impl OperatorSpec for BrdfSpec {
    const NAME: &'static str = Brdf::NAME;
    const SUMMARY: &'static str = "an angular lobe (BRDF, BTDF) convolving directions";
    const PARAMS: &'static [Param] = &[Param {
        name: "lobe",
        unit: "",
        doc: "Diffuse | Mirror | Phong(exponent) | Gaussian(var_u, var_v) | Beckmann(alpha_u, alpha_v) | Ggx(alpha_u, alpha_v)",
    }];
    type Op = Brdf;
    fn build(self) -> Result<Brdf, CovError> {
        Brdf::new(self.lobe)
    }
}

/// `Reflect(cos_in: 0.8, cos_out: 0.8, curvature: (k: 2.0), lobe: Phong(exponent: 200))`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReflectSpec {
    /// `|cos θ_in|`.
    pub cos_in: f64,
    /// `|cos θ_out|`.
    pub cos_out: f64,
    /// Surface curvature (default flat).
    #[serde(default)]
    pub curvature: CurvatureSpec,
    /// The lobe.
    pub lobe: Lobe,
}

impl OperatorSpec for ReflectSpec {
    const NAME: &'static str = Reflect::NAME;
    const SUMMARY: &'static str =
        "reflection at a curved surface (projection, curvature, symmetry, lobe, back)";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "cos_in",
            unit: "–",
            doc: "(0, 1]",
        },
        Param {
            name: "cos_out",
            unit: "–",
            doc: "(0, 1]",
        },
        Param {
            name: "curvature",
            unit: "1/m",
            doc: "(k: …) or (kx: …, ky: …, angle: …), default flat",
        },
        Param {
            name: "lobe",
            unit: "",
            doc: "as in Brdf",
        },
    ];
    type Op = Reflect;
    fn build(self) -> Result<Reflect, CovError> {
        Reflect::new(
            self.cos_in,
            self.cos_out,
            self.curvature.to_curvature()?,
            self.lobe,
        )
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<BrdfSpec>().register::<ReflectSpec>();
}
