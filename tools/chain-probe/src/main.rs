//! The 10-operator bounce chain of `benches/chain.rs` on 4,096 states at N = 2, 4, 5
//! (`mode-N` picks what runs; each `*-none` mode is the same loop without the chain).
//! Per-ray parameters (each state's operators built for it, as a renderer does): the
//! closed-form baseline (`base`), the operators applied one by one through
//! `Operator::apply` (`apply`, covariance form; `apply-sqrt`, square-root form) and
//! pushed on a `Chain` built per ray (`chain`, `chain-sqrt`). Fixed parameters at N = 4:
//! the baseline (`fixed-base`) and one `Chain` applied to every state (`fixed-chain`).
//! Run under `valgrind --tool=callgrind` by `count.sh`, which subtracts the loop and
//! divides by the states.

use covtrace::{Cov, CovFactor, Operator};
use glam::DVec3;
use std::hint::black_box;

#[allow(dead_code)]
#[path = "../../../benches/common/baseline.rs"]
mod baseline;
#[allow(dead_code)]
#[path = "../../../benches/common/ops.rs"]
mod ops;

use baseline::Ray;
use ops::Ops;

const STATES: usize = 4096;

/// The probe's ray: fixed parameters, with its distances varied by `i` per state.
fn ray(i: usize) -> Ray {
    let dir = DVec3::new(0.3, -0.2, -0.9).normalize();
    let d = 1.0 + (i % 13) as f64 * 0.1;
    Ray {
        d1: 1.3 * d,
        dir: dir.to_array(),
        fx: dir.any_orthonormal_vector().to_array(),
        n: DVec3::new(0.1, 0.2, 1.0).normalize().to_array(),
        k: 0.7,
        e: 80.0,
        cos_out: 0.6,
        angle_out: 0.4,
        turn: 0.9,
        d2: 2.1 * d,
        std: 0.2,
    }
}

/// `CHAIN_PROBE_REPS` (default 1): how many times a timed mode runs its loop, for
/// wall-clock timing outside callgrind.
fn reps() -> usize {
    std::env::var("CHAIN_PROBE_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1)
}

fn covs<const N: usize>() -> Vec<Cov<N>> {
    (0..STATES)
        .map(|i| {
            let f = 1.0 + (i % 17) as f64 * 0.1;
            let mut d = [1.5; N];
            d[0] = 0.1 * f;
            d[N / 2] = 3.0 / f;
            Cov::<N>::gaussian(d).expect("finite stds")
        })
        .collect()
}

fn packed<const N: usize>(c: &Cov<N>) -> baseline::Packed<N> {
    let mut p = [0.0; 15];
    p[..c.packed().len()].copy_from_slice(c.packed());
    baseline::Packed { p }
}

/// Runs `f` on every state of a fresh copy of `start`, `reps()` times.
fn over<S: Clone>(start: &[S], run: bool, mut f: impl FnMut(usize, &mut S)) {
    let mut s = start.to_vec();
    for _ in 0..reps() {
        s.clone_from_slice(start);
        if run {
            for (i, c) in s.iter_mut().enumerate() {
                f(i, c);
            }
        }
        black_box(&s);
    }
}

/// Per-ray `what` at layout `N`.
fn per_ray<const N: usize>(what: &str, run: bool) {
    let covs = covs::<N>();
    let facs: Vec<CovFactor<N>> = covs.iter().map(CovFactor::from_cov).collect();
    match what {
        "base" => over(&covs.iter().map(packed).collect::<Vec<_>>(), run, |i, p| {
            baseline::bounce(black_box(p), &black_box(ray(i)))
        }),
        "apply" => over(&covs, run, |i, c| {
            black_box(Ops::new(&black_box(ray(i)), N).apply(c));
        }),
        "ray" => over(&covs, run, |i, _| {
            black_box(ray(i));
        }),
        "build" => over(&covs, run, |i, _| {
            black_box(Ops::new(&black_box(ray(i)), N));
        }),
        "apply-sqrt" => over(&facs, run, |i, c| {
            black_box(Ops::new(&black_box(ray(i)), N).apply(c));
        }),
        "chain" => over(&covs, run, |i, c| {
            black_box(Ops::new(&black_box(ray(i)), N).chain().apply(c).is_ok());
        }),
        "chain-sqrt" => over(&facs, run, |i, c| {
            black_box(Ops::new(&black_box(ray(i)), N).chain().apply(c).is_ok());
        }),
        "fixed-base" => {
            let fixed = baseline::Fixed::new(&black_box(ray(0)));
            over(&covs.iter().map(packed).collect::<Vec<_>>(), run, |_, p| {
                fixed.run(black_box(p))
            })
        }
        "fixed-chain" => {
            let chain = Ops::new(&black_box(ray(0)), N).chain();
            over(&covs, run, |_, c| {
                black_box(chain.apply(c).is_ok());
            })
        }
        _ => usage(),
    }
}

fn usage() {
    eprintln!(
        "usage: chain-probe MODE-N[-none], MODE one of base, apply, apply-sqrt, chain, chain-sqrt, fixed-base, fixed-chain; N one of 2, 4, 5"
    );
    std::process::exit(2);
}

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_default();
    let run = !mode.ends_with("-none");
    let mode = mode.trim_end_matches("-none");
    let Some((what, n)) = mode.rsplit_once('-') else {
        return usage();
    };
    match n {
        "2" => per_ray::<2>(what, run),
        "4" => per_ray::<4>(what, run),
        "5" => per_ray::<5>(what, run),
        _ => usage(),
    }
}
