//! # cov-brdf: reflectance lobes and reflection at a curved surface
//!
//! **Primal definition** (docs/physics.md section 3): a BRDF lobe `ρ` convolves the light field
//! in angle, `l'(x,u) = ∫ l(x,u') ρ(u − u') du'`. By rule 3, with `S` the spectrum
//! covariance of `ρ` on the direction axes, `Σ' = Σ − Σ Pᵀ (S + PΣPᵀ)⁻¹ P Σ` (computed by
//! cov-core without inverting Σ). A Gaussian lobe of variance `var` (tangent units²) has
//! `S = 1 / (4π² var)`.
//!
//! | lobe | parameter | unit | domain | Gaussian variance of the lobe (per axis) |
//! |---|---|---|---|---|
//! | [`Lobe::Diffuse`] | – | | | ∞ (`S = 0`: all angular content removed) |
//! | [`Lobe::Mirror`] | – | | | 0 (identity) |
//! | [`Lobe::Phong`] | `exponent` | – | ≥ 0 | `1/e` (`cos^e θ ≈ exp(−e θ²/2)`); `e = 0` is diffuse |
//! | [`Lobe::Gaussian`] | `var_u`, `var_v` | tan² | ≥ 0 | as given (0 = mirror on that axis) |
//! | [`Lobe::Beckmann`] | `alpha_u`, `alpha_v` | – | ≥ 0 | `2α²`: Beckmann slopes are Gaussian with variance `α²/2`, and a reflected direction turns by twice the slope |
//! | [`Lobe::Ggx`] | `alpha_u`, `alpha_v` | – | ≥ 0 | `α²`: fit of the curvature at the peak (slope variance `α²/4`, doubled angle); GGX tails are heavy, so this is an approximation whose error the tests measure |
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Brdf` | `lobe` | – | required | – | The lobe: `Diffuse`, `Mirror`, `Phong(exponent)`, `Gaussian(var_u, var_v)`, `Beckmann(alpha_u, alpha_v)` or `Ggx(alpha_u, alpha_v)`. |
//! | `Reflect` | `cos_in` | – | required | in (0, 1] | `\|cos θ_in\|`. |
//! |  | `cos_out` | – | required | in (0, 1] | `\|cos θ_out\|`. |
//! |  | `curvature` | 1/m | optional | – | Surface curvature, `(k: …)` or `(kx: …, ky: …, angle: …)`; flat when left out. |
//! |  | `lobe` | – | required | – | The lobe, as in `Brdf`. |
//! |  | `turn` | rad | optional | finite | Turn of the surface frame from the plane of incidence to the outgoing ray's (3D). |
//! <!-- end of parameters -->
//!
//! Zero roughness is the mirror, exactly. Anisotropic roughness is along the frame's
//! `u` and `v` (rotate the frame first with cov-projection's `RotateFrame`).
//!
//! [`Reflect`] is the composite reflection at a curved surface, in order: projection
//! (`cos_in`), curvature, mirror symmetry, lobe, a turn of the surface frame by `turn`
//! (rule 1, a rotation of `(x, y)` and `(u, v)`: from the plane of incidence to the plane of
//! the outgoing ray, 0 when they coincide), inverse curvature, inverse projection
//! (`cos_out`); the frame's `x` must lie in the plane of incidence.
//!
//! **Surface frame convention.** Rays carry `u` in the direction of propagation (travel is
//! `l(x − d·u, u)`). In the surface frame, incident light is indexed by the direction it
//! comes from, pointing away from the surface like a BRDF's `ω_i`; entering that frame is
//! therefore one more symmetry `u → −u` before the curvature. Without it a flat mirror
//! would flip the sign of `Σ_xu` (turn a converging beam into a diverging one). With it,
//! the composite reproduces ray-traced reflection off curved mirrors, including
//! anisotropic ones, to finite-difference accuracy (`tests/geometry.rs`): a ray at offset
//! `x` on a mirror of curvature `k` turns by `2kx` (`k > 0` convex: diverging). At
//! oblique incidence the curvature across the plane of incidence is seen scaled by
//! `cos θ` (cov-curvature's `Curvature::apply_oblique`), which gives the tangential and
//! sagittal focal lengths `R cos θ / 2` and `R / (2 cos θ)`.
//!
//! **Handedness.** The incident frame has `y = n × t` (`t` the tangent direction of its
//! `x`, `n` the normal), which for a ray arriving at the surface is `−(d × x)`; the
//! reflected frame has `y = d × x`. A renderer that frames every ray as `(x, d × x)`
//! therefore flips `y` and `v` after the composite, with the turn measured in its own
//! frames (docs/physics.md section 3): a mirror reverses handedness.
//!
//! ```
//! use cov_brdf::{Lobe, Reflect};
//! use cov_core::{Cov, Operator};
//! use cov_curvature::Curvature;
//!
//! let mut c = Cov::<2>::gaussian([0.01, 0.05])?;
//! let r = Reflect::new(0.8, 0.8, Curvature::isotropic(2.0)?, Lobe::phong(100.0)?)?;
//! Operator::apply(&r, &mut c)?;
//! assert!(c.validity().is_valid());
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Brdf, Reflect; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_brdf::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.1),
//!     operators: [
//!         Brdf(lobe: Ggx(alpha_u: 0.2, alpha_v: 0.2)),
//!         Reflect(cos_in: 0.8, cos_out: 0.8, curvature: (k: 2.0), lobe: Phong(exponent: 200)),
//!     ],
//! )
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 2); // inferred from what the operators need
//! // An outgoing ray out of the plane of incidence: the turn needs the 3D frame.
//! let turned = "Path(source: Gaussian(x: 0.1), operators: [Reflect(cos_in: 0.8, cos_out: 0.6, lobe: Diffuse, turn: 0.3)])";
//! assert_eq!(cov_path::Path::parse(turned, &registry)?.eval()?.layout, 4);
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, CovError, FOUR_PI_SQ, Operator, OperatorSpec, Spectrum, Turn, arg};
use cov_curvature::{Curvature, spec::CurvatureSpec};
use cov_projection::{Mirror, Project, Unproject};

/// A reflectance (or transmittance) lobe over the outgoing direction. In RON:
/// `Diffuse`, `Mirror`, `Phong(exponent: 100)`, `Gaussian(var_u: 0.01, var_v: 0.01)`,
/// `Beckmann(alpha_u: 0.1, alpha_v: 0.1)`, `Ggx(alpha_u: 0.1, alpha_v: 0.2)`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub enum Lobe {
    /// Lambertian: removes all angular content.
    Diffuse,
    /// Perfect specular: leaves Σ unchanged.
    Mirror,
    /// Phong lobe of the given exponent.
    Phong {
        /// Exponent `e ≥ 0`.
        exponent: f64,
    },
    /// Gaussian lobe with the given variances (tangent units²) along `u` and `v`.
    Gaussian {
        /// Variance along `u`.
        var_u: f64,
        /// Variance along `v`.
        var_v: f64,
    },
    /// Beckmann microfacet lobe.
    Beckmann {
        /// Roughness along `u`.
        alpha_u: f64,
        /// Roughness along `v`.
        alpha_v: f64,
    },
    /// GGX (Trowbridge–Reitz) microfacet lobe, Gaussian fit at the peak.
    Ggx {
        /// Roughness along `u`.
        alpha_u: f64,
        /// Roughness along `v`.
        alpha_v: f64,
    },
}

impl Lobe {
    /// A Phong lobe.
    ///
    /// # Errors
    /// Negative or non-finite exponent.
    pub fn phong(exponent: f64) -> Result<Lobe, CovError> {
        Lobe::Phong { exponent }.validated()
    }

    /// An isotropic Beckmann lobe.
    ///
    /// # Errors
    /// Negative or non-finite roughness.
    pub fn beckmann(alpha: f64) -> Result<Lobe, CovError> {
        Lobe::Beckmann {
            alpha_u: alpha,
            alpha_v: alpha,
        }
        .validated()
    }

    /// An isotropic GGX lobe.
    ///
    /// # Errors
    /// Negative or non-finite roughness.
    pub fn ggx(alpha: f64) -> Result<Lobe, CovError> {
        Lobe::Ggx {
            alpha_u: alpha,
            alpha_v: alpha,
        }
        .validated()
    }

    /// Checks the parameters (for lobes built as enum literals).
    ///
    /// # Errors
    /// Negative or non-finite parameters.
    #[inline(always)]
    pub fn validated(self) -> Result<Lobe, CovError> {
        // Each value named by its field (`arg!`), under the variant's name.
        let params = match self {
            Lobe::Diffuse | Lobe::Mirror => return Ok(self),
            Lobe::Phong { exponent } => [arg!("Phong", exponent); 2],
            Lobe::Gaussian { var_u, var_v } => [arg!("Gaussian", var_u), arg!("Gaussian", var_v)],
            Lobe::Beckmann { alpha_u, alpha_v } => [arg!("Beckmann", alpha_u), arg!("Beckmann", alpha_v)],
            Lobe::Ggx { alpha_u, alpha_v } => [arg!("Ggx", alpha_u), arg!("Ggx", alpha_v)],
        };
        for p in params {
            p.non_negative()?;
        }
        Ok(self)
    }

    /// Primal variance of the lobe along `u` and `v` (tangent units²): 0 for a mirror,
    /// infinite for diffuse.
    #[inline(always)]
    pub fn variances(&self) -> (f64, f64) {
        match *self {
            Lobe::Diffuse => (f64::INFINITY, f64::INFINITY),
            Lobe::Mirror => (0.0, 0.0),
            Lobe::Phong { exponent } => {
                let v = if exponent == 0.0 {
                    f64::INFINITY
                } else {
                    1.0 / exponent
                };
                (v, v)
            }
            Lobe::Gaussian { var_u, var_v } => (var_u, var_v),
            Lobe::Beckmann { alpha_u, alpha_v } => (2.0 * alpha_u * alpha_u, 2.0 * alpha_v * alpha_v),
            Lobe::Ggx { alpha_u, alpha_v } => (alpha_u * alpha_u, alpha_v * alpha_v),
        }
    }

    /// The lobe's spectrum variance `S = 1/(4π² var)` along `u` and `v`
    /// ((cycles/tangent unit)²): 0 for diffuse, `∞` for a mirror (nothing to convolve),
    /// and at most `f64::MAX` for any other (a tiny variance gives a large finite `S`).
    /// Phong's is `exponent/(4π²)`, one product (its variance is `1/exponent`).
    #[inline(always)]
    pub fn spectra(&self) -> (f64, f64) {
        let of = |var: f64| {
            if var == 0.0 {
                return f64::INFINITY;
            }
            let s = 1.0 / (FOUR_PI_SQ * var);
            if s.is_finite() { s } else { f64::MAX }
        };
        match *self {
            Lobe::Phong { exponent } => {
                let s = exponent * (1.0 / FOUR_PI_SQ);
                (s, s)
            }
            _ => {
                let (vu, vv) = self.variances();
                (of(vu), of(vv))
            }
        }
    }

    /// Applies the lobe on the direction axes (rule 3). Axes with a zero variance (mirror)
    /// are skipped; an infinite variance (diffuse) uses `S = 0`.
    ///
    /// # Errors
    /// Overflow.
    #[inline(always)]
    pub fn convolve<S: Spectrum + ?Sized>(&self, cov: &mut S) -> Result<(), CovError> {
        let (su, sv) = self.spectra();
        // Written out per axis (not a loop over `direction_axes`), so that a caller that
        // knows its spectrum type gets each lobe with a constant axis.
        lobe_on(cov, Axis::U, su)?;
        if cov.has(Axis::V) {
            lobe_on(cov, Axis::V, sv)?;
        }
        Ok(())
    }
}

/// The lobe of spectrum variance `s` ([`Lobe::spectra`]) on direction axis `axis`:
/// skipped for `∞` (a mirror).
#[inline(always)]
fn lobe_on<S: Spectrum + ?Sized>(cov: &mut S, axis: Axis, s: f64) -> Result<(), CovError> {
    if s == f64::INFINITY {
        return Ok(());
    }
    cov.convolve(&[axis], &[s])
}

/// A lobe applied on its own (e.g. a phase function or a rough transmission).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brdf {
    lobe: Lobe,
}

impl Brdf {
    /// Operator name.
    pub const NAME: &'static str = "Brdf";

    /// # Errors
    /// Invalid lobe parameters.
    #[inline]
    pub fn new(lobe: Lobe) -> Result<Self, CovError> {
        Ok(Brdf {
            lobe: lobe.validated()?,
        })
    }

    /// The lobe.
    pub fn lobe(&self) -> Lobe {
        self.lobe
    }
}

impl Operator for Brdf {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| self.lobe.convolve(cov))
    }
}

/// Reflection at a curved surface: projection, curvature, mirror symmetry, lobe, a turn of
/// the surface frame from the plane of incidence to the plane of the outgoing ray (0 when
/// the outgoing ray lies in the plane of incidence), inverse curvature (the same
/// surface's, its principal directions read in the turned frame), inverse projection to
/// the outgoing direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reflect {
    project: Project,
    curvature: Curvature,
    /// The same curvature in the outgoing plane's frame (after the turn).
    curvature_out: Curvature,
    lobe: Lobe,
    turn: Turn,
    unproject: Unproject,
}

impl Reflect {
    /// Operator name.
    pub const NAME: &'static str = "Reflect";

    /// # Errors
    /// `cos_in`, `cos_out` not in (0, 1]; invalid lobe.
    pub fn new(cos_in: f64, cos_out: f64, curvature: Curvature, lobe: Lobe) -> Result<Self, CovError> {
        Self::with_turn(cos_in, cos_out, curvature, lobe, 0.0)
    }

    /// Reflection whose outgoing ray leaves the plane of incidence: after the lobe, the
    /// surface frame turns by `turn` (rad, about the normal, from the incident plane's
    /// tangent towards the outgoing plane's) before the inverse curvature and projection.
    /// A renderer computes it from the two directions; `turn = 0` is [`Reflect::new`].
    ///
    /// # Errors
    /// As [`Reflect::new`]; a non-finite `turn`.
    pub fn with_turn(
        cos_in: f64,
        cos_out: f64,
        curvature: Curvature,
        lobe: Lobe,
        turn: f64,
    ) -> Result<Self, CovError> {
        // The spec's checks, under the names the user wrote (the projections would name
        // `cos`); the curvature is given built.
        spec::ReflectSpec {
            cos_in,
            cos_out,
            curvature: CurvatureSpec::default(),
            lobe,
            turn,
        }
        .check()?;
        Self::checked(cos_in, cos_out, curvature, lobe, turn)
    }

    /// [`Reflect::with_turn`] on checked cosines.
    fn checked(
        cos_in: f64,
        cos_out: f64,
        curvature: Curvature,
        lobe: Lobe,
        turn: f64,
    ) -> Result<Self, CovError> {
        let turn = Turn::new(spec::ReflectSpec::TURN.of(turn))?;
        Ok(Reflect {
            project: Project::new(cos_in)?,
            curvature,
            curvature_out: curvature.in_turned_frame(turn),
            lobe: lobe.validated()?,
            turn,
            unproject: Unproject::new(cos_out)?,
        })
    }
}

impl Operator for Reflect {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        Operator::apply(&self.project, cov)?;
        // Incident directions in the surface frame point back toward the light.
        Operator::apply(&Mirror, cov)?;
        self.curvature.apply_oblique(cov, self.project.cos(), 1.0)?;
        Operator::apply(&Mirror, cov)?;
        self.lobe.convolve(cov)?;
        if !self.turn.is_zero() {
            cov.rotate_frame_by(self.turn)?;
        }
        self.curvature_out
            .apply_oblique(cov, self.unproject.cos(), -1.0)?;
        Operator::apply(&self.unproject, cov)
    }
    fn requires(&self) -> cov_core::AxisSet {
        let r = Operator::requires(&self.curvature);
        if !self.turn.is_zero() {
            r.union(cov_core::AxisSet::SPACE)
        } else {
            r
        }
    }
}
