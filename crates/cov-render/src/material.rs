//! Materials: the BRDF the path tracer evaluates and samples, and the cov-brdf lobe the
//! covariance pass traces for the same material (one definition of each lobe).
//!
//! Directions point away from the surface: `wo` towards the viewer, `wi` towards the
//! light. `n` is the shading normal on the viewer's side.

use std::f64::consts::PI;

use cov_brdf::Lobe;
use glam::DVec3;

/// A reflecting material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian, `f = albedo/π`.
    Diffuse {
        /// Reflectance.
        albedo: DVec3,
    },
    /// Normalised modified Phong around the mirror direction `r`:
    /// `f = albedo·(e+2)/(2π)·max(0, r·wi)^e`. Its angular profile `cos^e α ≈
    /// exp(−e α²/2)` is the Gaussian of variance `1/e` that `Lobe::Phong` traces.
    Phong {
        /// Reflectance.
        albedo: DVec3,
        /// Exponent.
        exponent: f64,
    },
    /// GGX microfacets with Smith shadowing, no Fresnel: `f = albedo·D·G/(4 cos_i cos_o)`;
    /// traced as `Lobe::Ggx`.
    Ggx {
        /// Reflectance.
        albedo: DVec3,
        /// Roughness.
        alpha: f64,
    },
}

/// Luminance (Rec. 709 weights).
pub fn luminance(c: DVec3) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// An orthonormal basis around `n`.
pub fn basis(n: DVec3) -> (DVec3, DVec3) {
    let a = if n.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
    let t = n.cross(a).normalize();
    (t, n.cross(t))
}

/// `v` reflected about `n`.
pub fn reflect(v: DVec3, n: DVec3) -> DVec3 {
    2.0 * v.dot(n) * n - v
}

fn ggx_d(cos_h: f64, a2: f64) -> f64 {
    let c2 = cos_h * cos_h;
    let den = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * den * den)
}

fn smith_g1(cos: f64, a2: f64) -> f64 {
    let c2 = cos * cos;
    2.0 * cos / (cos + (a2 + (1.0 - a2) * c2).sqrt())
}

impl Material {
    /// The reflectance (the albedo a denoiser is given).
    pub fn albedo(&self) -> DVec3 {
        match *self {
            Material::Diffuse { albedo } | Material::Phong { albedo, .. } | Material::Ggx { albedo, .. } => {
                albedo
            }
        }
    }

    /// The same material with another reflectance (a texture's value at a hit).
    pub fn with_albedo(&self, albedo: DVec3) -> Material {
        match *self {
            Material::Diffuse { .. } => Material::Diffuse { albedo },
            Material::Phong { exponent, .. } => Material::Phong { albedo, exponent },
            Material::Ggx { alpha, .. } => Material::Ggx { albedo, alpha },
        }
    }

    /// The lobe the covariance pass traces for this material.
    pub fn lobe(&self) -> Lobe {
        match *self {
            Material::Diffuse { .. } => Lobe::Diffuse,
            Material::Phong { exponent, .. } => Lobe::Phong { exponent },
            Material::Ggx { alpha, .. } => Lobe::Ggx {
                alpha_u: alpha,
                alpha_v: alpha,
            },
        }
    }

    /// The BRDF value `f(wo, wi)` per channel (0 below the surface).
    pub fn eval(&self, n: DVec3, wo: DVec3, wi: DVec3) -> DVec3 {
        let (ci, co) = (n.dot(wi), n.dot(wo));
        if ci <= 0.0 || co <= 0.0 {
            return DVec3::ZERO;
        }
        match *self {
            Material::Diffuse { albedo } => albedo / PI,
            Material::Phong { albedo, exponent } => {
                let c = reflect(wo, n).dot(wi).max(0.0);
                albedo * ((exponent + 2.0) / (2.0 * PI) * c.powf(exponent))
            }
            Material::Ggx { albedo, alpha } => {
                let a2 = alpha * alpha;
                let h = (wi + wo).normalize();
                let g = smith_g1(ci, a2) * smith_g1(co, a2);
                albedo * (ggx_d(n.dot(h), a2) * g / (4.0 * ci * co))
            }
        }
    }

    /// The density (solid angle) with which [`Material::sample`] picks `wi`.
    pub fn pdf(&self, n: DVec3, wo: DVec3, wi: DVec3) -> f64 {
        let ci = n.dot(wi);
        if ci <= 0.0 || n.dot(wo) <= 0.0 {
            return 0.0;
        }
        match *self {
            Material::Diffuse { .. } => ci / PI,
            Material::Phong { exponent, .. } => {
                let c = reflect(wo, n).dot(wi).max(0.0);
                (exponent + 1.0) / (2.0 * PI) * c.powf(exponent)
            }
            Material::Ggx { alpha, .. } => {
                let h = (wi + wo).normalize();
                let oh = wo.dot(h);
                if oh <= 0.0 {
                    return 0.0;
                }
                ggx_d(n.dot(h), alpha * alpha) * n.dot(h) / (4.0 * oh)
            }
        }
    }

    /// A direction `wi` drawn from the material's lobe with the uniforms `u1, u2`
    /// (`None` when it falls below the surface).
    pub fn sample(&self, n: DVec3, wo: DVec3, u1: f64, u2: f64) -> Option<DVec3> {
        let phi = 2.0 * PI * u2;
        let wi = match *self {
            Material::Diffuse { .. } => {
                let (t, b) = basis(n);
                let r = u1.sqrt();
                t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()
            }
            Material::Phong { exponent, .. } => {
                let r = reflect(wo, n);
                let (t, b) = basis(r);
                let c = u1.powf(1.0 / (exponent + 1.0));
                let s = (1.0 - c * c).max(0.0).sqrt();
                t * (s * phi.cos()) + b * (s * phi.sin()) + r * c
            }
            Material::Ggx { alpha, .. } => {
                let (t, b) = basis(n);
                let tan2 = alpha * alpha * u1 / (1.0 - u1).max(1e-300);
                let c = 1.0 / (1.0 + tan2).sqrt();
                let s = (1.0 - c * c).max(0.0).sqrt();
                let h = t * (s * phi.cos()) + b * (s * phi.sin()) + n * c;
                reflect(wo, h)
            }
        };
        (wi.dot(n) > 0.0).then(|| wi.normalize())
    }
}
