//! A third-party operator, written as a user of covtrace would: `Sparkle`, a glittery
//! surface whose flakes (of size `flake`, m) modulate the reflectance like a texture
//! (rule 2) and whose facets spread the reflection in angle (rule 3, variance `spread`).
//! Nothing in the covtrace crates knows about it: [`register`] adds it to a registry.

use covtrace::path::{OperatorSpec, Param, Registry};
use covtrace::{Cov, CovError, FOUR_PI_SQ, Operator, Spectrum};
use serde::Deserialize;

/// The operator.
#[derive(Clone, Copy, Debug)]
pub struct Sparkle {
    window: f64,
    lobe: f64,
}

impl<const N: usize> Operator<N> for Sparkle {
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        for &x in Cov::<N>::spatial_axes() {
            cov.add_variance(x, self.window)?;
        }
        for &u in Cov::<N>::direction_axes() {
            cov.convolve(&[u], &[self.lobe])?;
        }
        Ok(())
    }
    fn name(&self) -> &str {
        "Sparkle"
    }
}

/// `Sparkle(flake: 0.001, spread: 0.02)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SparkleSpec {
    /// Flake size (m).
    pub flake: f64,
    /// Angular variance of the facets (tan²).
    pub spread: f64,
}

impl OperatorSpec for SparkleSpec {
    const NAME: &'static str = "Sparkle";
    const SUMMARY: &'static str = "glitter: flake texture and facet spread (third-party example)";
    const PARAMS: &'static [Param] = &[
        Param {
            name: "flake",
            unit: "m",
            doc: "> 0",
        },
        Param {
            name: "spread",
            unit: "tan²",
            doc: "> 0",
        },
    ];
    type Op = Sparkle;
    fn build(self) -> Result<Sparkle, CovError> {
        CovError::check_positive("Sparkle", "flake", self.flake)?;
        CovError::check_positive("Sparkle", "spread", self.spread)?;
        Ok(Sparkle {
            window: 1.0 / (FOUR_PI_SQ * self.flake * self.flake),
            lobe: 1.0 / (FOUR_PI_SQ * self.spread),
        })
    }
}

/// The one call a user makes.
pub fn register(registry: &mut Registry) {
    registry.register::<SparkleSpec>();
}
