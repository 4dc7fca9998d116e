//! The 10-operator bounce chain of `benches/chain.rs` on 4,096 states (`mode` picks what
//! runs; each `*-none` mode is the same loop without the chain). At N = 4 with fixed
//! parameters: the baseline, `Chain::apply` in both forms. With per-state parameters
//! (each state's operators built for it) at N = 2, 4, 5: `eval_batch_with` (a closure
//! over `dyn Spectrum`) and `eval_batch_typed` (`StateOps`, the operators' typed bodies),
//! covariance form. Run under `valgrind --tool=callgrind` by `count.sh` (one rayon
//! thread), which subtracts the loop and divides by the states.

use covtrace::brdf::{Brdf, Lobe};
use covtrace::curvature::Curvature;
use covtrace::occlusion::Window;
use covtrace::projection::{Mirror, Project, RotateFrame, Unproject};
use covtrace::travel::Travel;
use covtrace::{Chain, Cov, CovError, CovFactor, Form, Operator, Spectrum, StateOps};
use glam::DVec3;
use std::hint::black_box;

#[allow(dead_code)]
#[path = "../../../benches/common/baseline.rs"]
mod baseline;

const STATES: usize = 4096;

/// State `i`'s bounce chain: the fixed ray with its distances varied per state.
struct PerState {
    dir: DVec3,
    fx: DVec3,
    n: DVec3,
    dim: usize,
}

/// One state's operators.
struct Built {
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

impl PerState {
    #[inline(always)]
    fn build(&self, i: usize) -> Result<Built, CovError> {
        let d = 1.0 + (i % 13) as f64 * 0.1;
        let mut project = Project::from_vectors(self.dir, self.fx, self.n)?;
        let mut out = 0.4;
        if self.dim < 4 {
            project = Project::new(project.cos())?;
            out = 0.0;
        }
        Ok(Built {
            t1: Travel::new(d)?,
            project,
            k: Curvature::isotropic(0.7)?,
            lobe: Brdf::new(Lobe::Phong { exponent: 80.0 })?,
            k_back: Curvature::isotropic(-0.7)?,
            unproject: Unproject::with_angle(0.6, out)?,
            turn: if self.dim >= 4 {
                Some(RotateFrame::new(0.9)?)
            } else {
                None
            },
            t2: Travel::new(2.0 * d)?,
            window: Window::isotropic(0.2)?,
        })
    }
}

impl Built {
    /// Through the typed bodies.
    #[inline(always)]
    fn typed<S: Spectrum>(&self, s: &mut S) -> Result<(), CovError> {
        self.t1.apply_to(s)?;
        self.project.apply_to(s)?;
        self.k.apply_to(s)?;
        Mirror.apply_to(s)?;
        self.lobe.apply_to(s)?;
        self.k_back.apply_to(s)?;
        self.unproject.apply_to(s)?;
        if let Some(t) = &self.turn {
            t.apply_to(s)?;
        }
        self.t2.apply_to(s)?;
        self.window.apply_to(s)
    }

    /// Through `Operator::apply`.
    fn dynamic(&self, s: &mut dyn Spectrum) -> Result<(), CovError> {
        let ops: [Option<&dyn Operator>; 10] = [
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
        ];
        ops.into_iter().flatten().try_for_each(|op| op.apply(s))
    }
}

impl StateOps for PerState {
    fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
        self.build(i)?.typed(s)
    }
}

/// `eval_batch_with` (`typed` false) or `eval_batch_typed` over 4,096 states of layout `N`.
fn per_state<const N: usize>(p: &PerState, run: bool, typed: bool) {
    let mut s: Vec<Cov<N>> = (0..STATES)
        .map(|i| {
            let f = 1.0 + (i % 17) as f64 * 0.1;
            let mut d = [1.5; N];
            d[0] = 0.1 * f;
            d[N / 2] = 3.0 / f;
            Cov::<N>::gaussian(d).expect("finite stds")
        })
        .collect();
    if run {
        let failed = if typed {
            covtrace::eval_batch_typed(Form::Covariance, &mut s, p)
        } else {
            covtrace::eval_batch_with(Form::Covariance, &mut s, |i, c| p.build(i)?.dynamic(c))
        };
        assert!(failed.is_empty());
    }
    black_box(&s);
}

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
        m if m.starts_with("with-") || m.starts_with("typed-") => {
            let dim = m.chars().find_map(|c| c.to_digit(10)).unwrap_or(4) as usize;
            let p = PerState { dir, fx, n, dim };
            let run = !m.ends_with("-none");
            let typed = m.starts_with("typed");
            match dim {
                2 => per_state::<2>(&p, run, typed),
                5 => per_state::<5>(&p, run, typed),
                _ => per_state::<4>(&p, run, typed),
            }
        }
        _ => {
            eprintln!(
                "usage: chain-probe base|cov|sqrt|with-2|typed-2|with-4|typed-4|with-5|typed-5 (or its -none loop)"
            );
            std::process::exit(2);
        }
    }
}
