//! Core kernels at N = 2..5 over seeded random inputs (no constant folding): the sparse
//! kernels (shear = travel/curvature, rotation, lobe product, integration, window) next
//! to the dense congruence `AᵀΣA` that any operator could fall back to, and nalgebra's
//! dense `AᵀΣA` as the outside reference.
//!
//! Run: `cargo bench --bench kernels`. Compare ratios within one run.

use std::hint::black_box;

use covtrace::{Axis, Spectrum};
use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::SMatrix;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;
use common::{BATCH, random_covs};

fn bench_n<const N: usize>(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<N>(rng);
    let params: Vec<f64> = (0..BATCH).map(|_| rng.random_range(0.1..10.0)).collect();
    let mut g = c.benchmark_group(format!("kernels/N={N}"));
    g.bench_function("travel (sparse shear)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, d) in covs.iter().zip(&params) {
                let mut x = *cv;
                x.shear(Axis::X, Axis::U, -d).ok();
                if N >= 4 {
                    x.shear(Axis::Y, Axis::V, -d).ok();
                }
                acc += x.get(N - 1, N - 1);
            }
            black_box(acc)
        })
    });
    g.bench_function("travel (dense congruence)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, d) in covs.iter().zip(&params) {
                let mut a = SMatrix::<f64, N, N>::identity();
                a[(0, if N >= 4 { 2 } else { 1 })] = -d;
                if N >= 4 {
                    a[(1, 3)] = -d;
                }
                let mut x = *cv;
                x.congruence(a.transpose().as_slice()).ok();
                acc += x.get(N - 1, N - 1);
            }
            black_box(acc)
        })
    });
    g.bench_function("travel (nalgebra AᵀΣA)", |b| {
        let dense: Vec<SMatrix<f64, N, N>> = covs.iter().map(|c| c.to_matrix()).collect();
        b.iter(|| {
            let mut acc = 0.0;
            for (m, d) in dense.iter().zip(&params) {
                let mut a = SMatrix::<f64, N, N>::identity();
                a[(0, if N >= 4 { 2 } else { 1 })] = -d;
                if N >= 4 {
                    a[(1, 3)] = -d;
                }
                let r = a.transpose() * m * a;
                acc += r[(N - 1, N - 1)];
            }
            black_box(acc)
        })
    });
    g.bench_function("rotate (x,u)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, a) in covs.iter().zip(&params) {
                let mut x = *cv;
                x.rotate(Axis::X, Axis::U, *a).ok();
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("lobe product (u)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, s) in covs.iter().zip(&params) {
                let mut x = *cv;
                x.convolve(&[Axis::U], &[*s]).ok();
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("integrate (u)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for cv in &covs {
                let mut x = *cv;
                x.integrate(&[Axis::U]).ok();
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("window (x)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, w) in covs.iter().zip(&params) {
                let mut x = *cv;
                x.add_variance(Axis::X, *w).ok();
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.finish();
}

fn kernels(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    bench_n::<2>(c, &mut rng);
    bench_n::<3>(c, &mut rng);
    bench_n::<4>(c, &mut rng);
    bench_n::<5>(c, &mut rng);
}

criterion_group!(benches, kernels);
criterion_main!(benches);
