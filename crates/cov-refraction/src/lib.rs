//! # cov-refraction: Snell interfaces, smooth and rough
//!
//! **Primal definition** (docs/physics.md section 3), frame `x` in the plane of incidence:
//! spatially, a projection with `cos_i` then an inverse projection with `cos_t`, i.e.
//! `l'(x,u) = l(x·cos_i/cos_t, u)`; in angle, `u_t = a·u_i` with
//! `a = n1 cos_i / (n2 cos_t)`, i.e. `l'(x,u) = l(x, u/a)`.
//!
//! In 3D the axis across the plane of incidence (`y`, `v`) is not foreshortened, and its
//! angle scales by `n1/n2` (the tangential part of the direction scales by `n1/n2`, vector
//! Snell). Both facts are checked against a ray-traced Jacobian of vector Snell's law.
//!
//! Total internal reflection transmits nothing: [`Refract::new`] returns
//! [`CovError::NoTransport`], never NaN. Near the critical angle `cos_t → 0` and the
//! angular scale `a` grows without bound; it stays finite while `cos_t > 0`. The indices may
//! be in any unit, but their ratio `n1/n2` must be 1e-6 to 1e6: beyond, `a` overflows or
//! vanishes.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Refract` | `n1` | – | required | > 0 | Refractive index on the incident side. |
//! |  | `n2` | – | required | > 0 | Refractive index on the transmitted side. |
//! |  | `cos_i` | – | required | in (0, 1] | `\|cos θ_i\|`; total internal reflection is an error. |
//! | `RoughRefract` | `n1` | – | required | > 0 | Refractive index on the incident side. |
//! |  | `n2` | – | required | > 0 | Refractive index on the transmitted side. |
//! |  | `cos_i` | – | required | in (0, 1] | `\|cos θ_i\|`. |
//! |  | `lobe` | – | required | – | Transmission lobe, as in `Brdf`. |
//! <!-- end of parameters -->
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_refraction::Refract;
//!
//! let glass = Refract::new(1.0, 1.5, 0.9)?;
//! let mut c = Cov::<2>::gaussian([0.01, 0.1])?;
//! Operator::apply(&glass, &mut c)?;
//! // Entering glass narrows the angular spread: angular frequencies go up.
//! assert!(c.get(1, 1) > Cov::<2>::gaussian([0.01, 0.1])?.get(1, 1));
//! // Leaving glass at a grazing angle: total internal reflection is an error.
//! assert!(Refract::new(1.5, 1.0, 0.3).is_err());
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Refract, RoughRefract; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_refraction::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.02),
//!     operators: [
//!         Refract(n1: 1.0, n2: 1.5, cos_i: 0.8),
//!         RoughRefract(n1: 1.5, n2: 1.0, cos_i: 0.9, lobe: Beckmann(alpha_u: 0.05, alpha_v: 0.05)),
//!     ],
//! )
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 2); // inferred from what the operators need
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_brdf::Lobe;
use cov_core::{Axis, CovError, Operator, OperatorSpec, Spectrum};

/// A smooth interface between media of indices `n1` (incident side) and `n2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refract {
    n1: f64,
    n2: f64,
    cos_i: f64,
    cos_t: f64,
}

impl Refract {
    /// Operator name.
    pub const NAME: &'static str = "Refract";

    /// # Errors
    /// Non-positive or non-finite indices, `cos_i` not in (0, 1], or total internal
    /// reflection ([`CovError::NoTransport`]).
    pub fn new(n1: f64, n2: f64, cos_i: f64) -> Result<Self, CovError> {
        spec::RefractSpec { n1, n2, cos_i }.build()
    }

    /// Snell's law on parameters checked by the spec: only total internal reflection
    /// is left to report.
    fn snell(n1: f64, n2: f64, cos_i: f64) -> Result<Self, CovError> {
        let eta = n1 / n2;
        // Indices in any unit, but a ratio an interface can have: past 1e6 the angular
        // scale `a` (and Σ's) overflows or vanishes for grazing rays.
        if !(1e-6..=1e6).contains(&eta) {
            return Err(spec::RefractSpec::N2
                .error(n2, format!("n1/n2 = {} must be 1e-6 to 1e6", cov_core::num(eta))));
        }
        // sin²θ_i = (1 − cos)(1 + cos): no cancellation near normal incidence.
        let sin2_i = (1.0 - cos_i) * (1.0 + cos_i);
        let cos2_t = 1.0 - eta * eta * sin2_i;
        if cos2_t <= 0.0 {
            return Err(CovError::NoTransport {
                operator: Self::NAME.into(),
                reason: format!(
                    "total internal reflection: n1/n2 = {} and cos_i = {} give sin θ_t = {} ≥ 1",
                    cov_core::num(eta),
                    cov_core::num(cos_i),
                    cov_core::num(eta * sin2_i.sqrt())
                ),
            });
        }
        Ok(Refract {
            n1,
            n2,
            cos_i,
            cos_t: cos2_t.sqrt(),
        })
    }

    /// `|cos θ_t|` of the transmitted ray.
    pub fn cos_t(&self) -> f64 {
        self.cos_t
    }

    /// The angular scale in the plane of incidence, `a = n1 cos_i / (n2 cos_t)`.
    pub fn angular_scale(&self) -> f64 {
        self.n1 * self.cos_i / (self.n2 * self.cos_t)
    }
}

impl Operator for Refract {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov.scale(Axis::X, self.cos_i / self.cos_t)?;
        cov.scale(Axis::U, 1.0 / self.angular_scale())?;
        if cov.has(Axis::V) {
            cov.scale(Axis::V, self.n2 / self.n1)?;
        }
        Ok(())
    }
}

/// A rough interface: refraction then a lobe on the transmitted side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughRefract {
    refract: Refract,
    lobe: Lobe,
}

impl RoughRefract {
    /// Operator name.
    pub const NAME: &'static str = "RoughRefract";

    /// # Errors
    /// As [`Refract::new`], or invalid lobe parameters.
    pub fn new(n1: f64, n2: f64, cos_i: f64, lobe: Lobe) -> Result<Self, CovError> {
        spec::RoughRefractSpec { n1, n2, cos_i, lobe }.build()
    }
}

impl Operator for RoughRefract {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        Operator::apply(&self.refract, cov)?;
        self.lobe.convolve(cov)
    }
}
