//! The two forms of Σ side by side, over seeded random inputs (no constant folding):
//!
//! - `forms/kernels/N=…`: each kernel on `Cov` (covariance form) and on `CovFactor`
//!   (square-root form);
//! - `forms/path`: a glossy bounce path of built-in operators (travel, reflection off a
//!   curved glossy surface, travel, occluder window, travel, sensor integration over
//!   angle) through `Chain::eval_in` in both forms; and one kernel called through
//!   `&mut dyn Spectrum` (what the indirection that operators use costs).
//!
//! Run: `cargo bench --bench forms`. Compare ratios within one run.

use std::hint::black_box;

use covtrace::brdf::{Lobe, Reflect};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::sensor::Integrate;
use covtrace::travel::Travel;
use covtrace::{Axis, Chain, CovFactor, Form, Spectrum};
use criterion::{Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;
use common::{BATCH, random_covs};

macro_rules! both {
    ($g:ident, $name:literal, $covs:ident, $facs:ident, $params:ident, |$x:ident, $p:ident| $body:expr) => {
        $g.bench_function(concat!($name, " (covariance)"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for (cv, $p) in $covs.iter().zip(&$params) {
                    let mut $x = *cv;
                    $body;
                    acc += $x.get(0, 0);
                }
                black_box(acc)
            })
        });
        $g.bench_function(concat!($name, " (square root)"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for (f, $p) in $facs.iter().zip(&$params) {
                    let mut $x = *f;
                    $body;
                    acc += $x.rows()[0][0];
                }
                black_box(acc)
            })
        });
    };
}

fn kernels_n<const N: usize>(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<N>(rng);
    let facs: Vec<CovFactor<N>> = covs.iter().map(CovFactor::from_cov).collect();
    let params: Vec<f64> = (0..BATCH).map(|_| rng.random_range(0.1..10.0)).collect();
    let mut g = c.benchmark_group(format!("forms/kernels/N={N}"));
    both!(g, "travel (shear)", covs, facs, params, |x, d| x
        .shear(Axis::X, Axis::U, -d)
        .ok());
    both!(g, "lobe (u)", covs, facs, params, |x, s| x
        .convolve(&[Axis::U], &[*s])
        .ok());
    both!(g, "integrate (u)", covs, facs, params, |x, _s| x
        .integrate(&[Axis::U])
        .ok());
    both!(g, "window (x)", covs, facs, params, |x, w| x
        .add_variance(Axis::X, *w)
        .ok());
    g.bench_function("travel (shear) through &mut dyn Spectrum (covariance)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, d) in covs.iter().zip(&params) {
                let mut x = *cv;
                let s: &mut dyn Spectrum = black_box(&mut x);
                s.shear(Axis::X, Axis::U, -d).ok();
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("to_cov (square root)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for f in &facs {
                acc += f.to_cov().map(|c| c.get(0, 0)).unwrap_or(0.0);
            }
            black_box(acc)
        })
    });
    g.bench_function("from_cov (square root)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for cv in &covs {
                acc += CovFactor::from_cov(cv).rows()[0][0];
            }
            black_box(acc)
        })
    });
    g.finish();
}

fn glossy_path() -> Chain {
    let reflect = Reflect::new(
        0.8,
        0.9,
        Curvature::anisotropic(2.0, 0.5, 0.3).expect("finite curvature"),
        Lobe::phong(200.0).expect("valid exponent"),
    )
    .expect("valid cosines");
    Chain::new()
        .with(Travel::new(1.5).expect("finite distance"))
        .with(reflect)
        .with(Travel::new(0.7).expect("finite distance"))
        .with(Window::isotropic(0.05).expect("positive size"))
        .with(Travel::new(2.0).expect("finite distance"))
        .with(Integrate::new(vec![Axis::U, Axis::V]).expect("non-empty axes"))
}

fn path(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<4>(rng);
    let chain = glossy_path();
    let mut g = c.benchmark_group("forms/path");
    for (name, form) in [
        ("covariance", Form::Covariance),
        ("square root", Form::SquareRoot),
    ] {
        g.bench_function(format!("glossy bounce, 6 operators ({name})"), |b| {
            b.iter(|| {
                let mut acc = 0.0;
                for cv in &covs {
                    acc += chain.eval_in(form, *cv).map(|r| r.get(0, 0)).unwrap_or(0.0);
                }
                black_box(acc)
            })
        });
    }
    g.finish();
}

fn forms(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed);
    kernels_n::<2>(c, &mut rng);
    kernels_n::<4>(c, &mut rng);
    kernels_n::<5>(c, &mut rng);
    path(c, &mut rng);
}

criterion_group!(benches, forms);
criterion_main!(benches);
