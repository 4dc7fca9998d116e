//! Speed against the baseline (`common/baseline.rs`: textbook closed-form updates of the
//! packed numbers, no checks). Every figure is per 256 seeded random states and per-ray
//! parameters; compare ratios within one run (`cargo bench --bench chain`).
//!
//! - `chain/op/N=4`: each operator of the bounce chain, built per ray and applied to
//!   `Cov<4>` and `CovFactor<4>` (checked: parameters, axes, overflow), next to the
//!   baseline's update.
//! - `chain/bounce/N=2|4|5`: the 10-operator bounce chain (travel, projection from
//!   vectors, curvature, mirror, Phong lobe, curvature back, unprojection, rotation,
//!   travel, window; at N = 2 the rotations are identities). Per-ray parameters: the
//!   baseline; operators built per ray and applied checked; the same recorded on a
//!   reused `Tape` and run. Fixed parameters: the baseline with coefficients computed
//!   once; the public `Chain::apply` (compiled tape); `Chain::eval_batch` on one core
//!   and on every core. Per-ray parameters, batched: `eval_batch_with` building and
//!   applying each state's operators, on one core and on every core, next to the
//!   per-ray baseline over the same 4,096 states.

use std::f64::consts::PI;
use std::hint::black_box;

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{Chain, Cov, CovFactor, Form, Operator, Spectrum, Tape};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

#[path = "common/baseline.rs"]
mod baseline;
mod common;
use baseline::{Fixed, Packed, Ray};
use common::{BATCH, random_covs};

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

/// The library's 10 operators for ray `r` in layout `n`.
struct Ops {
    t1: Travel,
    project: Project,
    k: Curvature,
    lobe: Brdf,
    k_back: Curvature,
    unproject: Unproject,
    turn: Option<RotateFrame>,
    t2: Travel,
    window: Window,
}

impl Ops {
    #[inline(always)]
    fn new(r: &Ray, n: usize) -> Ops {
        let v = |a: [f64; 3]| DVec3::from_array(a);
        let mut project = Project::from_vectors(v(r.dir), v(r.fx), v(r.n)).expect("unit vectors");
        let mut out = r.angle_out;
        if n < 4 {
            project = Project::new(project.cos()).expect("cosine");
            out = 0.0;
        }
        Ops {
            t1: Travel::new(r.d1).expect("distance"),
            project,
            k: Curvature::isotropic(r.k).expect("curvature"),
            lobe: Brdf::new(Lobe::Phong { exponent: r.e }).expect("lobe"),
            k_back: Curvature::isotropic(-r.k).expect("curvature"),
            unproject: Unproject::with_angle(r.cos_out, out).expect("cosine"),
            turn: (n >= 4).then(|| RotateFrame::new(r.turn).expect("angle")),
            t2: Travel::new(r.d2).expect("distance"),
            window: Window::isotropic(r.std).expect("std"),
        }
    }

    #[inline(always)]
    fn list(&self) -> [Option<&dyn Operator>; 10] {
        [
            Some(&self.t1),
            Some(&self.project),
            Some(&self.k),
            Some(&Mirror),
            Some(&self.lobe),
            Some(&self.k_back),
            Some(&self.unproject),
            self.turn.as_ref().map(|t| t as &dyn Operator),
            Some(&self.t2),
            Some(&self.window),
        ]
    }

    #[inline(always)]
    fn apply(&self, s: &mut dyn Spectrum) -> bool {
        self.list().into_iter().flatten().all(|op| op.apply(s).is_ok())
    }

    fn chain(&self) -> Chain {
        let mut c = Chain::new();
        c.push(self.t1);
        c.push(self.project);
        c.push(self.k);
        c.push(Mirror);
        c.push(self.lobe);
        c.push(self.k_back);
        c.push(self.unproject);
        if let Some(t) = self.turn {
            c.push(t);
        }
        c.push(self.t2);
        c.push(self.window);
        c
    }
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

fn ops(c: &mut Criterion, rng: &mut ChaCha8Rng) {
    let covs = random_covs::<4>(rng);
    let facs: Vec<CovFactor<4>> = covs.iter().map(CovFactor::from_cov).collect();
    let rays = rays(rng);
    let mut g = c.benchmark_group("chain/op/N=4");
    g.throughput(Throughput::Elements(BATCH as u64));
    macro_rules! op {
        ($name:expr, |$p:ident, $r:ident| $base:expr, |$rr:ident| $lib:expr) => {
            g.bench_function(concat!($name, ": baseline"), |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for (cv, $r) in covs.iter().zip(&rays) {
                        let mut $p = packed(cv);
                        $base;
                        acc += $p.p[9];
                    }
                    black_box(acc)
                })
            });
            g.bench_function(concat!($name, ": Cov<4>"), |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for (cv, $rr) in covs.iter().zip(&rays) {
                        let mut x = *cv;
                        let _ = black_box($lib.apply(&mut x));
                        acc += x.get(3, 3);
                    }
                    black_box(acc)
                })
            });
            g.bench_function(concat!($name, ": CovFactor<4>"), |b| {
                b.iter(|| {
                    let mut acc = 0.0;
                    for (f, $rr) in facs.iter().zip(&rays) {
                        let mut x = *f;
                        let _ = black_box($lib.apply(&mut x));
                        acc += x.rows()[3][3];
                    }
                    black_box(acc)
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
    let rays = rays(rng);
    same_as_library(&covs, &rays);
    let mut g = c.benchmark_group(format!("chain/bounce/N={N}"));
    g.throughput(Throughput::Elements(BATCH as u64));
    g.bench_function("per-ray: baseline", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, r) in covs.iter().zip(&rays) {
                let mut p = packed(cv);
                baseline::bounce(&mut p, r);
                acc += p.p[0];
            }
            black_box(acc)
        })
    });
    g.bench_function("per-ray: operators applied (covariance)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (cv, r) in covs.iter().zip(&rays) {
                let mut x = *cv;
                black_box(Ops::new(r, N).apply(&mut x));
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("per-ray: operators applied (square root)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (f, r) in facs.iter().zip(&rays) {
                let mut x = *f;
                black_box(Ops::new(r, N).apply(&mut x));
                acc += x.rows()[0][0];
            }
            black_box(acc)
        })
    });
    for (name, form) in [
        ("covariance", Form::Covariance),
        ("square root", Form::SquareRoot),
    ] {
        g.bench_function(format!("per-ray: recorded on a Tape ({name})"), |b| {
            let mut tape = Tape::new(N, form).expect("layout");
            b.iter(|| {
                let mut acc = 0.0;
                for (i, (cv, r)) in covs.iter().zip(&rays).enumerate() {
                    tape.clear();
                    let ops = Ops::new(r, N);
                    for op in ops.list().into_iter().flatten() {
                        tape.record(op).expect("recordable");
                    }
                    acc += match form {
                        Form::Covariance => tape.run_cov(*cv).map_or(0.0, |x| x.get(0, 0)),
                        Form::SquareRoot => tape.run_factor(facs[i]).map_or(0.0, |x| x.rows()[0][0]),
                    };
                }
                black_box(acc)
            })
        });
    }
    let fixed = Fixed::new(&rays[0]);
    g.bench_function("fixed: baseline", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for cv in &covs {
                let mut p = packed(cv);
                fixed.run(&mut p);
                acc += p.p[0];
            }
            black_box(acc)
        })
    });
    let chain = Ops::new(&rays[0], N).chain();
    g.bench_function("fixed: Chain::apply (covariance)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for cv in &covs {
                let mut x = *cv;
                black_box(chain.apply(&mut x).is_ok());
                acc += x.get(0, 0);
            }
            black_box(acc)
        })
    });
    g.bench_function("fixed: Chain::apply (square root)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for f in &facs {
                let mut x = *f;
                black_box(chain.apply(&mut x).is_ok());
                acc += x.rows()[0][0];
            }
            black_box(acc)
        })
    });
    // Batches: 4,096 states per call (16 × the scalar rows' 256; compare throughputs).
    let many: Vec<Cov<N>> = (0..16).flat_map(|_| covs.iter().copied()).collect();
    g.throughput(Throughput::Elements(many.len() as u64));
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    for (name, form) in [
        ("covariance", Form::Covariance),
        ("square root", Form::SquareRoot),
    ] {
        g.bench_function(format!("fixed: Chain::eval_batch ({name}, 1 thread)"), |b| {
            b.iter(|| {
                let mut states = many.clone();
                let failed = one.install(|| chain.eval_batch(form, &mut states));
                black_box((failed.len(), states[0].get(0, 0)))
            })
        });
        g.bench_function(format!("fixed: Chain::eval_batch ({name}, all threads)"), |b| {
            b.iter(|| {
                let mut states = many.clone();
                let failed = chain.eval_batch(form, &mut states);
                black_box((failed.len(), states[0].get(0, 0)))
            })
        });
    }
    // Per-ray parameters, batched: each state's operators built and applied in parallel.
    for (name, form) in [
        ("covariance", Form::Covariance),
        ("square root", Form::SquareRoot),
    ] {
        let per_ray = |i: usize, s: &mut dyn covtrace::Spectrum| {
            let ops = Ops::new(&rays[i % rays.len()], N);
            for op in ops.list().into_iter().flatten() {
                op.apply(s)?;
            }
            Ok(())
        };
        for (threads, pool) in [("1 thread", Some(&one)), ("all threads", None)] {
            g.bench_function(format!("per-ray: eval_batch_with ({name}, {threads})"), |b| {
                b.iter(|| {
                    let mut states = many.clone();
                    let failed = match pool {
                        Some(p) => p.install(|| covtrace::eval_batch_with(form, &mut states, per_ray)),
                        None => covtrace::eval_batch_with(form, &mut states, per_ray),
                    };
                    black_box((failed.len(), states[0].get(0, 0)))
                })
            });
        }
    }
    g.bench_function("per-ray: baseline (4,096 states)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (i, cv) in many.iter().enumerate() {
                let mut p = packed(cv);
                baseline::bounce(&mut p, &rays[i % rays.len()]);
                acc += p.p[0];
            }
            black_box(acc)
        })
    });
    g.bench_function("fixed: baseline (4,096 states)", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for cv in &many {
                let mut p = packed(cv);
                fixed.run(&mut p);
                acc += p.p[0];
            }
            black_box(acc)
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
