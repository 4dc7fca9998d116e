// The operator type given on the spec, as older covtrace versions had it.
use cov_core::OperatorSpec;

/// `Vignette(strength: 1.0)`.
#[derive(OperatorSpec)]
#[operator(op = VignetteOp, summary = "darkens the edges")]
pub struct VignetteSpec {
    /// How much.
    pub strength: f64,
}

fn main() {}
