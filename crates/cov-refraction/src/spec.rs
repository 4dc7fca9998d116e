//! RON parameters of the refraction operators.

use cov_brdf::Lobe;
use cov_core::CovError;
use cov_core::{OperatorSpec, Registrar};

use crate::{Refract, RoughRefract};

/// `Refract(n1: 1.0, n2: 1.5, cos_i: 0.9)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "smooth refraction (Snell) at an interface")]
pub struct RefractSpec {
    /// Refractive index on the incident side, > 0.
    pub n1: f64,
    /// Refractive index on the transmitted side, > 0.
    pub n2: f64,
    /// `|cos θ_i|`, in (0, 1]; total internal reflection is an error.
    pub cos_i: f64,
}

impl TryFrom<RefractSpec> for Refract {
    type Error = CovError;
    fn try_from(spec: RefractSpec) -> Result<Refract, CovError> {
        Refract::new(spec.n1, spec.n2, spec.cos_i)
    }
}

/// `RoughRefract(n1: 1.0, n2: 1.5, cos_i: 0.9, lobe: Beckmann(alpha_u: 0.1, alpha_v: 0.1))`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "rough refraction: Snell then a transmission lobe")]
pub struct RoughRefractSpec {
    /// Refractive index on the incident side, > 0.
    pub n1: f64,
    /// Refractive index on the transmitted side, > 0.
    pub n2: f64,
    /// `|cos θ_i|`, in (0, 1].
    pub cos_i: f64,
    /// Transmission lobe, as in `Brdf`.
    pub lobe: Lobe,
}

impl TryFrom<RoughRefractSpec> for RoughRefract {
    type Error = CovError;
    fn try_from(spec: RoughRefractSpec) -> Result<RoughRefract, CovError> {
        RoughRefract::new(spec.n1, spec.n2, spec.cos_i, spec.lobe)
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<RefractSpec>().add::<RoughRefractSpec>();
}
