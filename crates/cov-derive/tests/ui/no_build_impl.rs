// A spec with no `impl Build`; the operator type is also named differently from the
// spec (`Vignette` vs `VignetteOp`), which the derive never guesses.
use cov_core::{CovError, Operator, OperatorSpec, Spectrum};

#[derive(Debug)]
pub struct VignetteOp;

impl Operator for VignetteOp {
    fn apply(&self, _: &mut dyn Spectrum) -> Result<(), CovError> {
        Ok(())
    }
}

/// `Vignette(strength: 1.0)`.
#[derive(OperatorSpec)]
#[operator(summary = "darkens the edges")]
pub struct VignetteSpec {
    /// How much.
    #[param(positive)]
    pub strength: f64,
}

fn main() {}
