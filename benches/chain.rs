//! Speed against the baseline (`common/baseline.rs`: textbook closed-form updates of the
//! packed numbers, no checks). Every figure is per 256 seeded random states and per-ray
//! parameters; compare ratios within one run (`cargo bench --bench chain`).
//!
//! - `chain/op/N=4`: each operator of the bounce chain, built per ray and applied to
//!   `Cov<4>` and `CovFactor<4>` through `Operator::apply` (checked: parameters, axes,
//!   overflow), next to the baseline's update.
//! - `chain/bounce/N=2|4|5`: the 10-operator bounce chain (travel, projection from
//!   vectors, curvature, mirror, Phong lobe, curvature back, unprojection, rotation,
//!   travel, window; at N = 2 the rotations are identities). Per-ray parameters: the
//!   baseline; the operators built per ray and applied one by one through
//!   `Operator::apply` (each kernel checked), and pushed on a `Chain` built per ray and
//!   applied (the unchecked kernels, one finiteness check at the end: what the renderer
//!   does). Fixed parameters: the baseline with coefficients computed once, and one
//!   `Chain` applied to every state.

use std::f64::consts::PI;
use std::hint::black_box;

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::Curvature;
use covtrace::projection::{Mirror, Project, RotateFrame};
use covtrace::travel::Travel;
use covtrace::{Cov, CovFactor, Operator};
use criterion::{BatchSize, Bencher, Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "common/baseline.rs"]
mod baseline;
mod common;
#[path = "common/ops.rs"]
mod ops;
use baseline::{Fixed, Packed, Ray};
use common::{BATCH, random_covs};
use ops::Ops;

fn unit(rng: &mut ChaCha8Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if v.length() > 0.1 && v.length() < 1.0 {
            return v.normalize();
        }
    }
}

fn rays(rng: &mut ChaCha8Rng) -> Vec<Ray> {
    (0..BATCH)
        .map(|_| {
            let dir = unit(rng);
            let fx = dir.any_orthonormal_vector();
            let mut n = unit(rng);
            if n.dot(dir) > -0.1 {
                n = (n - dir * (n.dot(dir) + 0.5)).normalize();
            }
            Ray {
                d1: rng.random_range(0.1..10.0),
                dir: dir.to_array(),
                fx: fx.to_array(),
                n: n.to_array(),
                k: rng.random_range(-3.0..3.0),
                e: rng.random_range(1.0..1000.0),
                cos_out: rng.random_range(0.1..1.0),
                angle_out: rng.random_range(-PI..PI),
                turn: rng.random_range(-PI..PI),
                d2: rng.random_range(0.1..10.0),
                std: rng.random_range(0.01..1.0),
            }
        })
        .collect()
}

fn packed<const N: usize>(c: &Cov<N>) -> Packed<N> {
    let mut p = [0.0; 15];
    p[..c.packed().len()].copy_from_slice(c.packed());
    Packed { p }
}

/// The baseline computes what the library computes (to rounding), before any timing.
fn same_as_library<const N: usize>(covs: &[Cov<N>], rays: &[Ray]) {
    for (c, r) in covs.iter().zip(rays) {
        let mut b = packed(c);
        baseline::bounce(&mut b, r);
        let mut f = packed(c);
        Fixed::new(r).run(&mut f);
        let mut l = *c;
        assert!(Ops::new(r, N).apply(&mut l));
        let scale = l.max_abs();
        for (k, want) in l.packed().iter().enumerate() {
            for got in [b.p[k], f.p[k]] {
                assert!(
                    (got - want).abs() <= 1e-9 * scale,
                    "N={N} entry {k}: baseline {got} vs library {want}"
                );
            }
        }
    }
}

/// Times `f` on every state of a fresh copy of `input`, in place (the copy is made outside
/// the timing, and every state's full result is kept: nothing the library or the
/// baseline computes can be dropped as dead code).
fn each<T: Clone>(b: &mut Bencher<'_>, input: &[T], mut f: impl FnMut(usize, &mut T)) {
    b.iter_batched_ref(
        || input.to_vec(),
        |work| {
            for (i, s) in work.iter_mut().enumerate() {
                f(i, s);
            }
            black_box(&*work);
        },
        BatchSize::SmallInput,
    )
}

/// The baseline's packed copies of `covs`.
fn packs<const N: usize>(covs: &[Cov<N>]) -> Vec<Packed<N>> {
    covs.iter().map(packed).collect()
}

fn ops(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<4>(rng);
    let facs: Vec<CovFactor<4>> = covs.iter().map(CovFactor::from_cov).collect();
    let rays = rays(rng);
    let mut g = c.benchmark_group("chain/op/N=4");
    g.throughput(Throughput::Elements(BATCH as u64));
    let base = packs(&covs);
    macro_rules! op {
        ($name:expr, |$p:ident, $r:ident| $base:expr, |$rr:ident| $lib:expr) => {
            g.bench_function(concat!($name, ": baseline"), |b| {
                each(b, &base, |i, $p| {
                    let $r = &rays[i];
                    $base;
                })
            });
            g.bench_function(concat!($name, ": Cov<4>"), |b| {
                each(b, &covs, |i, x| {
                    let $rr = &rays[i];
                    let _ = black_box($lib.apply(x));
                })
            });
            g.bench_function(concat!($name, ": CovFactor<4>"), |b| {
                each(b, &facs, |i, x| {
                    let $rr = &rays[i];
                    let _ = black_box($lib.apply(x));
                })
            });
        };
    }
    op!("travel", |p, r| p.travel(r.d1), |r| Travel::new(r.d1).expect("d"));
    op!("curvature", |p, r| p.curvature(r.k), |r| Curvature::isotropic(
        r.k
    )
    .expect("k"));
    op!(
        "frame rotation",
        |p, r| {
            let (s, c) = r.turn.sin_cos();
            p.rotate_frame(c, s)
        },
        |r| RotateFrame::new(r.turn).expect("angle")
    );
    op!("Phong lobe", |p, r| p.phong(r.e), |r| Brdf::new(Lobe::Phong {
        exponent: r.e
    })
    .expect("e"));
    op!("mirror", |p, _r| p.mirror(), |_r| Mirror);
    op!(
        "projection from vectors",
        |p, r| {
            let (cos, angle) = baseline::projection_angles(r.dir, r.fx, r.n);
            p.project(cos, angle)
        },
        |r| Project::from_vectors(
            DVec3::from_array(r.dir),
            DVec3::from_array(r.fx),
            DVec3::from_array(r.n)
        )
        .expect("unit vectors")
    );
    g.finish();
}

fn bounce_n<const N: usize>(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<N>(rng);
    let facs: Vec<CovFactor<N>> = covs.iter().map(CovFactor::from_cov).collect();
    let base = packs(&covs);
    let rays = rays(rng);
    same_as_library(&covs, &rays);
    let mut g = c.benchmark_group(format!("chain/bounce/N={N}"));
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("per-ray: baseline", |b| {
        each(b, &base, |i, p| baseline::bounce(p, &rays[i]))
    });
    g.bench_function("per-ray: Operator::apply (covariance)", |b| {
        each(b, &covs, |i, x| {
            black_box(Ops::new(&rays[i], N).apply(x));
        })
    });
    g.bench_function("per-ray: Operator::apply (square root)", |b| {
        each(b, &facs, |i, x| {
            black_box(Ops::new(&rays[i], N).apply(x));
        })
    });
    g.bench_function("per-ray: Chain::apply (covariance)", |b| {
        each(b, &covs, |i, x| {
            black_box(Ops::new(&rays[i], N).chain().apply(x).is_ok());
        })
    });
    g.bench_function("per-ray: Chain::apply (square root)", |b| {
        each(b, &facs, |i, x| {
            black_box(Ops::new(&rays[i], N).chain().apply(x).is_ok());
        })
    });
    let fixed = Fixed::new(&rays[0]);
    g.bench_function("fixed: baseline", |b| each(b, &base, |_, p| fixed.run(p)));
    let chain = Ops::new(&rays[0], N).chain();
    g.bench_function("fixed: Chain::apply (covariance)", |b| {
        each(b, &covs, |_, x| {
            black_box(chain.apply(x).is_ok());
        })
    });
    g.bench_function("fixed: Chain::apply (square root)", |b| {
        each(b, &facs, |_, x| {
            black_box(chain.apply(x).is_ok());
        })
    });
    g.finish();
}

fn bounce(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    ops(c, &mut rng);
    bounce_n::<2>(c, &mut rng);
    bounce_n::<4>(c, &mut rng);
    bounce_n::<5>(c, &mut rng);
}

criterion_group!(benches, bounce);
criterion_main!(benches);
