//! # cov-curvature: curved surfaces
//!
//! **Primal definition** (docs/physics.md section 3), in the surface frame after projection:
//! `l'(x,u) = l(x, u + k·x)`. In 3D a surface has a curvature tensor `K` (symmetric
//! 2×2, 1/m) and `(u,v) ← (u,v) + K (x,y)`; with principal curvatures `kx ≠ ky` along a
//! principal direction at angle `α` from the frame's `x`, `K = R(α) diag(kx, ky) R(α)ᵀ`.
//!
//! **Sign**: `k > 0` for a convex surface seen from the side the light arrives on (a
//! sphere of radius `R` seen from outside: `k = 1/R`), as fixed in cov-core. Checked
//! against ray tracing: a convex mirror (curvature, mirror symmetry, inverse curvature)
//! turns parallel rays at offset `x` by `2x/R` away from the axis.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Curvature` | `k` | 1/m | optional | finite | Isotropic curvature (> 0 convex). |
//! |  | `kx` | 1/m | optional | finite | First principal curvature, along `angle`. |
//! |  | `ky` | 1/m | optional | finite | Second principal curvature, across `angle`. |
//! |  | `angle` | rad | optional | finite | Angle of the first principal direction from x. |
//! | `CurvatureTensor` | `kxx` | 1/m | required | finite | `K_xx`. |
//! |  | `kxy` | 1/m | optional | finite | `K_xy`. |
//! |  | `kyy` | 1/m | optional | finite | `K_yy`. |
//! <!-- end of parameters -->
//!
//! An anisotropic curvature (`kx ≠ ky` or `angle ≠ 0`) needs the 3D layout; an isotropic
//! one works in every layout.
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_curvature::Curvature;
//!
//! let mut c = Cov::<4>::gaussian([0.01, 0.01, f64::INFINITY, f64::INFINITY])?;
//! Operator::apply(&Curvature::anisotropic(2.0, -0.5, 0.3)?, &mut c)?;
//! assert!(c.validity().is_valid());
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Curvature, CurvatureTensor; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_curvature::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.02, y: 0.02),
//!     operators: [Curvature(k: 2.0), Curvature(kx: 5.0, ky: -2.0, angle: 0.5), CurvatureTensor(kxx: 1.0, kxy: 0.1, kyy: 0.0)],
//! )
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 4); // inferred from what the operators need
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, AxisSet, CovError, Operator, OperatorSpec, Spectrum, Turn, arg};

/// Curvature by principal curvatures and direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Curvature {
    kx: f64,
    ky: f64,
    /// Into the principal frame (its trigonometry done once; back is its inverse).
    turn: Turn,
}

impl Curvature {
    /// Operator name.
    pub const NAME: &'static str = "Curvature";

    /// The same curvature `k` (1/m) in every direction.
    ///
    /// # Errors
    /// Non-finite `k`.
    #[inline]
    pub fn isotropic(k: f64) -> Result<Self, CovError> {
        Self::anisotropic(k, k, 0.0)
    }

    /// Principal curvatures `kx` along the direction at `angle` (rad) from the frame's `x`,
    /// and `ky` across it.
    ///
    /// # Errors
    /// Non-finite parameters.
    #[inline]
    pub fn anisotropic(kx: f64, ky: f64, angle: f64) -> Result<Self, CovError> {
        // The spec's checks; the principal form needs none of `make`'s choice of form.
        spec::CurvatureSpec {
            k: None,
            kx: Some(kx),
            ky: Some(ky),
            angle: Some(angle),
        }
        .check()?;
        Self::checked(kx, ky, angle)
    }

    /// From curvatures checked by the spec.
    #[inline]
    fn checked(kx: f64, ky: f64, angle: f64) -> Result<Self, CovError> {
        Ok(Curvature {
            kx,
            ky,
            turn: Turn::new(spec::CurvatureSpec::ANGLE.of(angle))?,
        })
    }

    /// The same curvature with opposite sign (used to leave the surface frame).
    pub fn inverse(&self) -> Self {
        Curvature {
            kx: -self.kx,
            ky: -self.ky,
            turn: self.turn,
        }
    }

    /// The same surface's curvature in the frame turned by `turn` (as
    /// `Spectrum::rotate_frame_by` turns it): the principal direction's angle less the
    /// turn. An isotropic curvature is the same in every frame and is returned as it is.
    pub fn in_turned_frame(&self, turn: Turn) -> Self {
        if self.kx == self.ky {
            return *self;
        }
        let (c, s) = (self.turn.cos(), self.turn.sin());
        let (ct, st) = (turn.cos(), turn.sin());
        Curvature {
            turn: Turn::towards(c * ct + s * st, s * ct - c * st).unwrap_or(self.turn),
            ..*self
        }
    }

    /// The tensor `K = R(α) diag(kx, ky) R(α)ᵀ` in the frame: `(kxx, kxy, kyy)`.
    pub fn tensor(&self) -> (f64, f64, f64) {
        let (s, c) = (self.turn.sin(), self.turn.cos());
        (
            c * c * self.kx + s * s * self.ky,
            c * s * (self.kx - self.ky),
            s * s * self.kx + c * c * self.ky,
        )
    }

    /// Applies the curvature as seen by a ray at `|cos θ| = cos` to the normal, in the
    /// surface frame with the frame's `x` in the plane of incidence, with directions in
    /// ray-angle units, scaled by `sign` (+1 entering the surface frame, −1 leaving it).
    ///
    /// A normal tilt `δ` in the plane of incidence turns a ray by `δ`, but a tilt across
    /// the plane turns it by `cos θ·δ`, so the `v` row of the tensor is scaled by `cos θ`:
    /// `(u, v) ← (u, v) + sign · diag(1, cos θ) K (x, y)`. This reproduces the tangential
    /// and sagittal focal lengths of a curved mirror (`R cos θ / 2`, `R / (2 cos θ)`). At
    /// normal incidence it is the operator itself; in flatland `cos` plays no role.
    ///
    /// # Errors
    /// `cos` not in (0, 1], `sign` not finite, overflow.
    pub fn apply_oblique(&self, cov: &mut dyn Spectrum, cos: f64, sign: f64) -> Result<(), CovError> {
        arg!(Self::NAME, cos).require(|c| c > 0.0 && c <= 1.0, || "must be in (0, 1]".into())?;
        arg!(Self::NAME, sign).finite()?;
        let (kxx, kxy, kyy) = self.tensor();
        if !cov.has(Axis::Y) {
            if !self.is_isotropic() {
                return Err(CovError::MissingAxis {
                    axis: Axis::Y,
                    layout: cov.dim(),
                });
            }
            return cov.shear(Axis::U, Axis::X, sign * kxx);
        }
        // The four shears commute: each adds position to direction.
        cov.shear(Axis::U, Axis::X, sign * kxx)?;
        cov.shear(Axis::U, Axis::Y, sign * kxy)?;
        cov.shear(Axis::V, Axis::X, sign * cos * kxy)?;
        cov.shear(Axis::V, Axis::Y, sign * cos * kyy)
    }

    #[inline]
    fn is_isotropic(&self) -> bool {
        self.kx == self.ky
    }
}

impl Curvature {
    /// The anisotropic case of [`Curvature`]'s body, out of line so that the common
    /// isotropic case stays small enough to inline.
    #[inline(never)]
    fn apply_principal<S: Spectrum + ?Sized>(&self, cov: &mut S) -> Result<(), CovError> {
        // Principal frame: rotate, shear each pair by its curvature, rotate back.
        cov.rotate_frame_by(self.turn)?;
        cov.shear(Axis::U, Axis::X, self.kx)?;
        cov.shear(Axis::V, Axis::Y, self.ky)?;
        cov.rotate_frame_by(self.turn.inverse())
    }
}

impl Operator for Curvature {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            if self.is_isotropic() {
                // Each plane written out, for constant axes (as `Travel`).
                cov.shear(Axis::U, Axis::X, self.kx)?;
                if cov.has(Axis::Y) {
                    cov.shear(Axis::V, Axis::Y, self.kx)?;
                }
                return Ok(());
            }
            self.apply_principal(cov)
        })
    }
    fn requires(&self) -> AxisSet {
        if self.is_isotropic() {
            AxisSet::FLAT
        } else {
            AxisSet::SPACE
        }
    }
}

/// Curvature given by its tensor in the frame. Flatland uses `kxx` and needs
/// `kxy = kyy = 0`; otherwise the 3D layout.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvatureTensor {
    k: [f64; 3],
}

impl CurvatureTensor {
    /// Operator name.
    pub const NAME: &'static str = "CurvatureTensor";

    /// # Errors
    /// Non-finite entries.
    #[inline]
    pub fn new(kxx: f64, kxy: f64, kyy: f64) -> Result<Self, CovError> {
        spec::CurvatureTensorSpec { kxx, kxy, kyy }.build()
    }
}

impl Operator for CurvatureTensor {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            let [kxx, kxy, kyy] = self.k;
            cov.shear(Axis::U, Axis::X, kxx)?;
            if cov.has(Axis::Y) {
                // The four shears commute: each adds position to direction.
                cov.shear(Axis::U, Axis::Y, kxy)?;
                cov.shear(Axis::V, Axis::X, kxy)?;
                cov.shear(Axis::V, Axis::Y, kyy)?;
            } else if kxy != 0.0 || kyy != 0.0 {
                return Err(CovError::MissingAxis {
                    axis: Axis::Y,
                    layout: cov.dim(),
                });
            }
            Ok(())
        })
    }
    fn requires(&self) -> AxisSet {
        if self.k[1] != 0.0 || self.k[2] != 0.0 {
            AxisSet::SPACE
        } else {
            AxisSet::FLAT
        }
    }
}
