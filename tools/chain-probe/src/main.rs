//! The 10-operator bounce chain of `benches/chain.rs` on 4,096 states (`mode` picks what
//! runs; each `*-none` mode is the same loop without the chain). At N = 4 with fixed
//! parameters: the baseline, `Chain::apply` in both forms, and `eval_batch_typed` with
//! the operators built once and shared (`fixed-typed`). With per-state parameters
//! (each state's operators built for it) at N = 2, 4, 5: `eval_batch_with` (a closure
//! over `dyn Spectrum`) and `eval_batch_typed` (`StateOps`, the operators' typed bodies),
//! covariance form. Run under `valgrind --tool=callgrind` by `count.sh` (one rayon
//! thread), which subtracts the loop and divides by the states.

use covtrace::{Cov, CovError, CovFactor, Form, Operator, Spectrum, StateOps};
use glam::DVec3;
use std::hint::black_box;

#[allow(dead_code)]
#[path = "../../../benches/common/baseline.rs"]
mod baseline;
#[allow(dead_code)]
#[path = "../../../benches/common/ops.rs"]
mod ops;

use baseline::Ray;
use ops::{Ops, Shared};

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

/// Per-state operators for `eval_batch_typed`.
struct PerState(usize);

impl StateOps for PerState {
    fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
        Ops::new(&ray(i), self.0).try_typed(s)
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

/// `eval_batch_with` (`typed` false) or `eval_batch_typed` over 4,096 states of layout `N`.
fn per_state<const N: usize>(run: bool, typed: bool) {
    let mut s = covs::<N>();
    let batch = |s: &mut [Cov<N>]| {
        if typed {
            covtrace::eval_batch_typed(Form::Covariance, s, &PerState(N))
        } else {
            covtrace::eval_batch_with(Form::Covariance, s, |i, c| Ops::new(&ray(i), N).try_dyn(c))
        }
    };
    // Extra repetitions (CHAIN_PROBE_REPS) run on the evolving states; a failure would
    // time the checked re-run instead of the fast path, so it is reported.
    let reps = reps();
    let failed: usize = (1..reps).map(|_| batch(&mut s).len()).sum();
    if failed > 0 {
        eprintln!("{failed} states failed over {reps} repetitions");
    }
    if run {
        assert!(batch(&mut s).is_empty());
    }
    black_box(&s);
}

/// `Chain::apply` over the states in place, after two evaluations that compile it.
fn chain_over<S: Spectrum + Copy>(start: &[S], run: bool) {
    let chain = Ops::new(&ray(0), 4).chain();
    let mut s = start.to_vec();
    chain.apply(&mut s[0]).expect("finite");
    s.copy_from_slice(start);
    chain.apply(&mut s[0]).expect("finite");
    s.copy_from_slice(start);
    if run {
        for c in s.iter_mut() {
            black_box(chain.apply(c).is_ok());
        }
    }
    black_box(&s);
}

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_default();
    let run = !mode.ends_with("-none");
    match mode.as_str() {
        "cov" | "cov-none" => chain_over(&covs::<4>(), run),
        "sqrt" | "sqrt-none" => {
            let start: Vec<CovFactor<4>> = covs::<4>().iter().map(CovFactor::from_cov).collect();
            chain_over(&start, run);
        }
        "fixed-typed" | "fixed-typed-none" => {
            let ops = Shared(Ops::new(&ray(0), 4));
            let mut s = covs::<4>();
            if run {
                assert!(covtrace::eval_batch_typed(Form::Covariance, &mut s, &ops).is_empty());
            }
            black_box(&s);
        }
        "ray-typed" | "ray-typed-none" | "ray-dyn" | "ray-dyn-none" => {
            let typed = mode.starts_with("ray-typed");
            let mut s = covs::<4>();
            let start = s.clone();
            for _ in 0..reps() {
                s.copy_from_slice(&start);
                if run {
                    for (i, c) in s.iter_mut().enumerate() {
                        let ops = Ops::new(&ray(i), 4);
                        black_box(if typed { ops.apply_typed(c) } else { ops.apply(c) });
                    }
                }
                black_box(&s);
            }
            black_box(&s);
        }
        "base" | "base-none" => {
            let fixed = baseline::Fixed::new(&ray(0));
            let mut s: Vec<baseline::Packed<4>> = covs::<4>()
                .iter()
                .map(|c| {
                    let mut p = [0.0; 15];
                    p[..10].copy_from_slice(c.packed());
                    baseline::Packed { p }
                })
                .collect();
            if run {
                for p in s.iter_mut() {
                    fixed.run(black_box(p));
                }
            }
            black_box(&s);
        }
        m if m.starts_with("with-") || m.starts_with("typed-") => {
            let typed = m.starts_with("typed");
            match m.chars().find_map(|c| c.to_digit(10)) {
                Some(2) => per_state::<2>(run, typed),
                Some(5) => per_state::<5>(run, typed),
                _ => per_state::<4>(run, typed),
            }
        }
        _ => {
            eprintln!(
                "usage: chain-probe base|cov|sqrt|fixed-typed|with-2|typed-2|with-4|typed-4|with-5|typed-5 (or its -none loop)"
            );
            std::process::exit(2);
        }
    }
}
