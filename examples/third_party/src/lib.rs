//! A third-party operator, written as a user of covtrace would: `Sparkle`, a glittery
//! surface whose flakes (of size `flake`, m) modulate the reflectance like a texture
//! (rule 2) and whose facets spread the reflection in angle (rule 3, variance `spread`).
//! Nothing in the covtrace crates knows about it: [`register`] adds it to a registry.

use covtrace::{Build, Checked, CovError, FOUR_PI_SQ, Operator, OperatorSpec, Registrar, Spectrum};

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
    /// Flake size.
    #[param(unit = "m", positive)]
    pub flake: f64,
    /// Angular variance of the facets.
    #[param(unit = "tan²", positive)]
    pub spread: f64,
}

/// The operator this spec builds, from parameters already checked against their domains.
impl Build for SparkleSpec {
    type Op = Sparkle;
    fn make(p: Checked<Self>) -> Result<Sparkle, CovError> {
        let window = 1.0 / (FOUR_PI_SQ * p.flake * p.flake);
        if !window.is_finite() {
            return Err(SparkleSpec::FLAKE.error(p.flake, "too small: 1/(4π² flake²) overflows"));
        }
        let lobe = 1.0 / (FOUR_PI_SQ * p.spread);
        if !lobe.is_finite() {
            return Err(SparkleSpec::SPREAD.error(p.spread, "too small: 1/(4π² spread) overflows"));
        }
        Ok(Sparkle { window, lobe })
    }
}

impl Sparkle {
    /// For Rust callers: the same checks as a file's.
    ///
    /// # Errors
    /// A parameter out of its domain, named.
    pub fn new(flake: f64, spread: f64) -> Result<Sparkle, CovError> {
        SparkleSpec { flake, spread }.build()
    }
}

/// The one call a user makes (with `covtrace::registry()` or any other [`Registrar`]).
pub fn register<R: Registrar>(registry: &mut R) {
    registry.add::<SparkleSpec>();
}
