//! The 10-operator bounce chain of `benches/chain.rs` at N = 4 with fixed parameters, run
//! on 4,096 states (`mode` picks what runs; each `*none` mode is the same loop without
//! the chain). Run under `valgrind --tool=callgrind` by `count.sh`, which subtracts the
//! loop and divides by the states.

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{Chain, Cov, CovFactor, Operator};
use glam::DVec3;
use std::hint::black_box;

#[allow(dead_code)]
#[path = "../../../benches/common/baseline.rs"]
mod baseline;

const STATES: usize = 4096;

fn main() {
    let mode = std::env::args().nth(1).unwrap_or_default();
    let dir = DVec3::new(0.3, -0.2, -0.9).normalize();
    let fx = dir.any_orthonormal_vector();
    let n = DVec3::new(0.1, 0.2, 1.0).normalize();
    let ray = baseline::Ray {
        d1: 1.3,
        dir: dir.to_array(),
        fx: fx.to_array(),
        n: n.to_array(),
        k: 0.7,
        e: 80.0,
        cos_out: 0.6,
        angle_out: 0.4,
        turn: 0.9,
        d2: 2.1,
        std: 0.2,
    };
    let mut chain = Chain::new();
    chain.push(Travel::new(ray.d1).expect("distance"));
    chain.push(Project::from_vectors(dir, fx, n).expect("unit vectors"));
    chain.push(Curvature::isotropic(ray.k).expect("curvature"));
    chain.push(Mirror);
    chain.push(Brdf::new(Lobe::Phong { exponent: ray.e }).expect("lobe"));
    chain.push(Curvature::isotropic(-ray.k).expect("curvature"));
    chain.push(Unproject::with_angle(ray.cos_out, ray.angle_out).expect("cosine"));
    chain.push(RotateFrame::new(ray.turn).expect("angle"));
    chain.push(Travel::new(ray.d2).expect("distance"));
    chain.push(Window::isotropic(ray.std).expect("std"));
    let covs: Vec<Cov<4>> = (0..STATES)
        .map(|i| {
            let f = 1.0 + (i % 17) as f64 * 0.1;
            Cov::<4>::gaussian([0.1 * f, 0.2, 3.0 / f, 1.5]).expect("finite stds")
        })
        .collect();
    match mode.as_str() {
        "cov" | "cov-none" => {
            let mut s = covs.clone();
            // Two evaluations compile the chain for this layout and form.
            chain.apply(&mut s[0]).expect("finite");
            s.copy_from_slice(&covs);
            chain.apply(&mut s[0]).expect("finite");
            s.copy_from_slice(&covs);
            if mode == "cov" {
                for c in s.iter_mut() {
                    black_box(chain.apply(c).is_ok());
                }
            }
            black_box(&s);
        }
        "sqrt" | "sqrt-none" => {
            let start: Vec<CovFactor<4>> = covs.iter().map(CovFactor::from_cov).collect();
            let mut s = start.clone();
            chain.apply(&mut s[0]).expect("finite");
            s.copy_from_slice(&start);
            chain.apply(&mut s[0]).expect("finite");
            s.copy_from_slice(&start);
            if mode == "sqrt" {
                for f in s.iter_mut() {
                    black_box(chain.apply(f).is_ok());
                }
            }
            black_box(&s);
        }
        "base" | "base-none" => {
            let fixed = baseline::Fixed::new(&ray);
            let mut s: Vec<baseline::Packed<4>> = covs
                .iter()
                .map(|c| {
                    let mut p = [0.0; 15];
                    p[..10].copy_from_slice(c.packed());
                    baseline::Packed { p }
                })
                .collect();
            if mode == "base" {
                for p in s.iter_mut() {
                    fixed.run(black_box(p));
                }
            }
            black_box(&s);
        }
        _ => {
            eprintln!("usage: chain-probe base|base-none|cov|cov-none|sqrt|sqrt-none");
            std::process::exit(2);
        }
    }
}
