//! Inputs shared by the benches: seeded random Σ, so no result can be constant-folded.

use covtrace::Cov;
use nalgebra::SMatrix;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Inputs per measured batch.
pub const BATCH: usize = 256;

/// `BATCH` random full-rank Σ = L Lᵀ + 0.01 I with L uniform in [−1, 1).
pub fn random_covs<const N: usize>(rng: &mut ChaCha8Rng) -> Vec<Cov<N>> {
    (0..BATCH)
        .map(|_| {
            let l = SMatrix::<f64, N, N>::from_fn(|_, _| rng.random_range(-1.0..1.0));
            let m = l * l.transpose() + SMatrix::<f64, N, N>::identity() * 0.01;
            Cov::from_matrix(&m).expect("L Lᵀ + εI is PSD")
        })
        .collect()
}
