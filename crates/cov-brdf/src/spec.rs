//! RON parameters of the BRDF operators.

use cov_core::{Build, Checked, CovError, OperatorSpec, Registrar};
use cov_curvature::spec::CurvatureSpec;

use crate::{Brdf, Lobe, Reflect};

/// `Brdf(lobe: Phong(exponent: 100))`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "an angular lobe (BRDF, BTDF) convolving directions")]
pub struct BrdfSpec {
    /// The lobe: `Diffuse`, `Mirror`, `Phong(exponent)`, `Gaussian(var_u, var_v)`, `Beckmann(alpha_u, alpha_v)` or `Ggx(alpha_u, alpha_v)`.
    pub lobe: Lobe,
}

impl Build for BrdfSpec {
    type Op = Brdf;
    fn make(spec: Checked<Self>) -> Result<Brdf, CovError> {
        Brdf::new(spec.lobe)
    }
}

/// `Reflect(cos_in: 0.8, cos_out: 0.8, curvature: (k: 2.0), lobe: Phong(exponent: 200))`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "reflection at a curved surface (projection, curvature, symmetry, lobe, back)")]
pub struct ReflectSpec {
    /// `|cos θ_in|`.
    #[param(gt = 0, le = 1)]
    pub cos_in: f64,
    /// `|cos θ_out|`.
    #[param(gt = 0, le = 1)]
    pub cos_out: f64,
    /// Surface curvature, `(k: …)` or `(kx: …, ky: …, angle: …)`; flat when left out.
    #[param(unit = "1/m", default)]
    pub curvature: CurvatureSpec,
    /// The lobe, as in `Brdf`.
    pub lobe: Lobe,
    /// Turn of the surface frame from the plane of incidence to the outgoing ray's (3D).
    #[param(unit = "rad", default)]
    pub turn: f64,
}

impl Build for ReflectSpec {
    type Op = Reflect;
    fn make(spec: Checked<Self>) -> Result<Reflect, CovError> {
        Reflect::checked(
            spec.cos_in,
            spec.cos_out,
            spec.curvature.to_curvature()?,
            spec.lobe,
            spec.turn,
        )
    }
}

/// Registers this crate's operators.
pub fn register<R: Registrar>(r: &mut R) {
    r.add::<BrdfSpec>().add::<ReflectSpec>();
}
