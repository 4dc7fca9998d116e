//! A third-party operator, written as a user of covtrace would: `Sparkle`, a glittery
//! surface whose flakes (of size `flake`, m) modulate the reflectance like a texture
//! (rule 2) and whose facets spread the reflection in angle (rule 3, variance `spread`).
//! Nothing in the covtrace crates knows about it: [`register`] adds it to a registry.

use covtrace::{CovError, FOUR_PI_SQ, Operator, OperatorSpec, Registrar, Spectrum};

/// The operator.
#[derive(Clone, Copy, Debug)]
pub struct Sparkle {
    window: f64,
    lobe: f64,
}

impl Operator for Sparkle {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        for &x in cov.spatial_axes() {
            cov.add_variance(x, self.window)?;
        }
        for &u in cov.direction_axes() {
            cov.convolve(&[u], &[self.lobe])?;
        }
        Ok(())
    }
}

/// `Sparkle(flake: 0.001, spread: 0.02)`.
#[derive(Debug, OperatorSpec)]
#[operator(summary = "glitter: flake texture and facet spread (third-party example)")]
pub struct SparkleSpec {
    /// Flake size, > 0.
    #[param(unit = "m")]
    pub flake: f64,
    /// Angular variance of the facets, > 0.
    #[param(unit = "tan²")]
    pub spread: f64,
}

impl TryFrom<SparkleSpec> for Sparkle {
    type Error = CovError;
    fn try_from(p: SparkleSpec) -> Result<Sparkle, CovError> {
        let flake = CovError::require_positive("Sparkle", "flake", p.flake)?;
        let spread = CovError::require_positive("Sparkle", "spread", p.spread)?;
        Ok(Sparkle {
            window: 1.0 / (FOUR_PI_SQ * flake * flake),
            lobe: 1.0 / (FOUR_PI_SQ * spread),
        })
    }
}

/// The one call a user makes (with `covtrace::registry()` or any other [`Registrar`]).
pub fn register<R: Registrar>(registry: &mut R) {
    registry.add::<SparkleSpec>();
}
