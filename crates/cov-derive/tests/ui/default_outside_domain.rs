// A default outside the parameter's own domain: a file that leaves the parameter out
// would be refused at a value it never wrote.
use cov_core::OperatorSpec;

/// `Vignette(strength: 1.0)`.
#[derive(OperatorSpec)]
#[operator(summary = "darkens the edges")]
pub struct VignetteSpec {
    /// How much.
    #[param(default = 0.0, positive)]
    pub strength: f64,
    /// How far out, at most 2.
    #[param(default = 3, le = 2)]
    pub reach: f64,
}

fn main() {}
