// Two lower bounds on one parameter.
use cov_core::OperatorSpec;

/// `Vignette(strength: 1.0)`.
#[derive(OperatorSpec)]
#[operator(summary = "darkens the edges")]
pub struct VignetteSpec {
    /// How much.
    #[param(positive, ge = 1)]
    pub strength: f64,
}

fn main() {}
