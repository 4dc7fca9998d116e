//! RON parameters of the refraction operators.

use cov_brdf::Lobe;
use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};

use crate::{Refract, RoughRefract};

/// `Refract(n1: 1.0, n2: 1.5, cos_i: 0.9)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "smooth refraction (Snell) at an interface")]
pub struct RefractSpec {
    /// Refractive index on the incident side.
    #[param(positive)]
    pub n1: f64,
    /// Refractive index on the transmitted side.
    #[param(positive)]
    pub n2: f64,
    /// `|cos θ_i|`; total internal reflection is an error.
    #[param(gt = 0, le = 1)]
    pub cos_i: f64,
}

impl Build for RefractSpec {
    type Op = Refract;
    fn make(spec: Checked<Self>) -> Result<Refract, CovError> {
        Refract::snell(spec.n1, spec.n2, spec.cos_i)
    }
}

/// `RoughRefract(n1: 1.0, n2: 1.5, cos_i: 0.9, lobe: Beckmann(alpha_u: 0.1, alpha_v: 0.1))`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "rough refraction: Snell then a transmission lobe")]
pub struct RoughRefractSpec {
    /// Refractive index on the incident side.
    #[param(positive)]
    pub n1: f64,
    /// Refractive index on the transmitted side.
    #[param(positive)]
    pub n2: f64,
    /// `|cos θ_i|`.
    #[param(gt = 0, le = 1)]
    pub cos_i: f64,
    /// Transmission lobe, as in `Brdf`.
    pub lobe: Lobe,
}

impl Build for RoughRefractSpec {
    type Op = RoughRefract;
    fn make(spec: Checked<Self>) -> Result<RoughRefract, CovError> {
        Ok(RoughRefract {
            refract: Refract::snell(spec.n1, spec.n2, spec.cos_i)?,
            lobe: spec.lobe.validated()?,
        })
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<RefractSpec>().add::<RoughRefractSpec>();
}
