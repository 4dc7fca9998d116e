//! RON parameters of the refraction operators.

use cov_brdf::Lobe;
use cov_core::CovError;
use cov_path::{OperatorSpec, Param, Registry};
use serde::Deserialize;

use crate::{Refract, RoughRefract};

/// `Refract(n1: 1.0, n2: 1.5, cos_i: 0.9)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefractSpec {
    /// Index on the incident side.
    pub n1: f64,
    /// Index on the transmitted side.
    pub n2: f64,
    /// `|cos θ_i|`.
    pub cos_i: f64,
}

const PARAMS: &[Param] = &[
    Param {
        name: "n1",
        unit: "–",
        doc: "> 0, incident side",
    },
    Param {
        name: "n2",
        unit: "–",
        doc: "> 0, transmitted side",
    },
    Param {
        name: "cos_i",
        unit: "–",
        doc: "(0, 1]; total internal reflection is an error",
    },
];

impl OperatorSpec for RefractSpec {
    const NAME: &'static str = Refract::NAME;
    const SUMMARY: &'static str = "smooth refraction (Snell) at an interface";
    const PARAMS: &'static [Param] = PARAMS;
    type Op = Refract;
    fn build(self) -> Result<Refract, CovError> {
        Refract::new(self.n1, self.n2, self.cos_i)
    }
}

/// `RoughRefract(n1: 1.0, n2: 1.5, cos_i: 0.9, lobe: Beckmann(alpha_u: 0.1, alpha_v: 0.1))`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoughRefractSpec {
    /// Index on the incident side.
    pub n1: f64,
    /// Index on the transmitted side.
    pub n2: f64,
    /// `|cos θ_i|`.
    pub cos_i: f64,
    /// Transmission lobe.
    pub lobe: Lobe,
}

impl OperatorSpec for RoughRefractSpec {
    const NAME: &'static str = RoughRefract::NAME;
    const SUMMARY: &'static str = "rough refraction: Snell then a transmission lobe";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "n1",
            unit: "–",
            doc: "> 0",
        },
        Param {
            name: "n2",
            unit: "–",
            doc: "> 0",
        },
        Param {
            name: "cos_i",
            unit: "–",
            doc: "(0, 1]",
        },
        Param {
            name: "lobe",
            unit: "",
            doc: "as in Brdf",
        },
    ];
    type Op = RoughRefract;
    fn build(self) -> Result<RoughRefract, CovError> {
        RoughRefract::new(self.n1, self.n2, self.cos_i, self.lobe)
    }
}

/// Registers this crate's operators.
pub fn register(r: &mut Registry) {
    r.register::<RefractSpec>().register::<RoughRefractSpec>();
}
