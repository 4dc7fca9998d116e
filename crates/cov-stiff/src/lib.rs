//! # cov-stiff: numerical stability on stiff and extreme cases
//!
//! A suite of chains at the extremes (grazing incidence to `cos = 1e-12`, velocities from
//! `1e-3` to `1e6` m/s, distances and
//! curvatures from `1e-9` to `1e9`, Phong exponents from 1 to `1e12` and zero roughness,
//! refraction a hair above the critical angle, a Dirac source, chains of `10⁴` operators,
//! rank-deficient Σ, entries from `1e-300` to `1e300`), each evaluated three ways:
//!
//! - **ours**: the operator crates through `Chain::eval`, in the default square-root form
//!   ([`cov_core::Form::SquareRoot`]), and again in the covariance form
//!   ([`cov_core::Form::Covariance`]: packed kernels with cancellation-free lobe forms);
//! - **plain**: the textbook formulas in dense f64 with nalgebra (`AᵀΣA`, and for lobes
//!   `Σ − ΣPᵀ(S + PΣPᵀ)⁻¹PΣ` with `try_inverse`), as a straightforward implementation
//!   would write them;
//! - **reference**: the same textbook formulas in double-double arithmetic (twofloat,
//!   about 32 significant digits), which is exact to far below f64 for these chains.
//!
//! [`run`] reports, per case, the relative error of ours and of plain against the
//! reference (the larger of the Frobenius error and the error after scaling every axis
//! by the reference's own bandwidth, so a small block is not hidden by a large one), PSD
//! violations and failures. `covtrace stiff` prints it.

#![warn(missing_docs)]

pub mod reference;

use std::f64::consts::PI;

use cov_brdf::{Brdf, Lobe};
use cov_core::{Chain, Cov, CovError, Form};
use cov_curvature::Curvature;
use cov_projection::{Project, Unproject};
use cov_refraction::Refract;
use cov_travel::Travel;
use nalgebra::DMatrix;
use reference::{Dense, Real};
use twofloat::TwoFloat;

/// One event of a stiff chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StiffOp {
    /// Travel (m).
    Travel(f64),
    /// Curvature: principal `kx`, `ky` (1/m), angle (rad).
    Curvature(f64, f64, f64),
    /// Projection with `|cos θ|`.
    Project(f64),
    /// Inverse projection with `|cos θ|`.
    Unproject(f64),
    /// Phong lobe of the given exponent (`f64::INFINITY`: mirror).
    Phong(f64),
    /// Diffuse lobe.
    Diffuse,
    /// Smooth refraction `n1 → n2` at `cos_i`.
    Refract(f64, f64, f64),
    /// A Gaussian window of std `std` (m) on `x` moving at `v` (m/s): enter the moving
    /// frame (`x ← x + v·t`), window, leave (N = 3 only).
    MovingWindow(f64, f64),
    /// A Gaussian window of std `std` (m) on the spatial axes (an occluder's edge).
    Window(f64),
}

/// A stiff case.
#[derive(Clone, Debug)]
pub struct Case {
    /// Name in the report.
    pub name: String,
    /// Layout: 2, 3 or 4.
    pub n: usize,
    /// Σ at the start, row-major.
    pub start: Vec<f64>,
    /// The chain.
    pub ops: Vec<StiffOp>,
    /// Whether the exact answer is well conditioned (the ≤ 1e-9 target applies).
    pub well_posed: bool,
    /// The answer is undefined (e.g. total internal reflection): a typed error is right.
    pub expect_error: bool,
    /// Well conditioned in the operators' parameters but not in Σ's entries (a very sharp
    /// window refocused by a lobe): the square-root form keeps it (the 1e-9 target
    /// applies to it), the covariance form loses it to its cancellation snap, towards a
    /// smaller bandwidth (measured and reported, not asserted).
    pub factor_only: bool,
    /// Compared without the resolution floor of [`rel_error`]: every entry is determined
    /// by the parameters to f64's precision although Σ's entries pass through values far
    /// larger (a beam's angular spread behind a window far below its size), so an answer
    /// that lost it is wrong, not unresolved.
    pub exact: bool,
}

/// Result of one case.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Case name.
    pub name: String,
    /// Number of operators.
    pub ops: usize,
    /// Whether the 1e-9 target applies.
    pub well_posed: bool,
    /// A typed error is the right answer.
    pub expect_error: bool,
    /// The 1e-9 target applies to the square-root form only (see [`Case::factor_only`]).
    pub factor_only: bool,
    /// Relative error of ours (default, square-root form) against the reference (`None`:
    /// ours returned an error).
    pub ours: Option<f64>,
    /// The same in the covariance form (`None`: an error).
    pub ours_cov: Option<f64>,
    /// Ours returned a non-PSD Σ.
    pub ours_non_psd: bool,
    /// Ours' error message, if it failed.
    pub ours_error: Option<String>,
    /// Relative error of the plain implementation (`None`: it failed: NaN, inf or a
    /// singular inverse).
    pub plain: Option<f64>,
    /// The plain result was not PSD.
    pub plain_non_psd: bool,
    /// Why the plain implementation failed (`"singular"`, `"overflow"`), when it did.
    pub plain_failure: Option<&'static str>,
    /// Conditioning: the reference's relative change per unit relative perturbation of
    /// the start Σ (1e-12 applied). Times f64's ε, the error that storing the *input* in
    /// f64 alone can cause; an error far above it comes from the evaluation.
    pub amplification: f64,
}

fn phong_s(e: f64) -> f64 {
    e / (4.0 * PI * PI)
}

fn op_matrix(op: StiffOp, n: usize) -> Option<Vec<f64>> {
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        a[i * n + i] = 1.0;
    }
    let pairs: &[(usize, usize)] = if n == 4 { &[(0, 2), (1, 3)] } else { &[(0, 1)] };
    match op {
        StiffOp::Travel(d) => {
            for &(x, u) in pairs {
                a[x * n + u] = -d;
            }
        }
        StiffOp::Curvature(kx, ky, ang) => {
            let (s, c) = ang.sin_cos();
            let (kxx, kxy, kyy) = (
                c * c * kx + s * s * ky,
                c * s * (kx - ky),
                s * s * kx + c * c * ky,
            );
            if n == 4 {
                a[2 * n] = kxx;
                a[2 * n + 1] = kxy;
                a[3 * n] = kxy;
                a[3 * n + 1] = kyy;
            } else {
                a[n] = kx;
            }
        }
        StiffOp::Project(c) => a[0] = c,
        StiffOp::Unproject(c) => a[0] = 1.0 / c,
        StiffOp::Refract(n1, n2, ci) => {
            let r = Refract::new(n1, n2, ci).ok()?;
            let ui = if n == 4 { 2 } else { 1 };
            a[0] = ci / r.cos_t();
            a[ui * n + ui] = 1.0 / r.angular_scale();
            if n == 4 {
                a[3 * n + 3] = n2 / n1;
            }
        }
        StiffOp::Phong(_) | StiffOp::Diffuse | StiffOp::MovingWindow(..) | StiffOp::Window(_) => return None,
    }
    Some(a)
}

/// The moving-frame shear `x ← x + v·t` of layout 3 (row-major).
fn moving_frame(v: f64) -> Vec<f64> {
    let mut a = vec![0.0; 9];
    for i in 0..3 {
        a[i * 3 + i] = 1.0;
    }
    a[2] = v;
    a
}

fn window_var(std: f64) -> f64 {
    1.0 / (4.0 * PI * PI * std * std)
}

fn spatial_axes(n: usize) -> &'static [usize] {
    if n == 4 { &[0, 1] } else { &[0] }
}

fn lobe_axes(n: usize) -> &'static [usize] {
    if n == 4 { &[2, 3] } else { &[1] }
}

fn lobe_s(op: StiffOp) -> Option<f64> {
    match op {
        StiffOp::Phong(e) if e.is_infinite() => None,
        StiffOp::Phong(e) => Some(phong_s(e)),
        StiffOp::Diffuse => Some(0.0),
        _ => None,
    }
}

/// The chain in the textbook formulas, in the real type `R`.
pub fn dense_eval<R: Real>(case: &Case) -> Dense<R> {
    dense_eval_peak(case).0
}

/// [`dense_eval`] and, per axis, the largest diagonal entry met along the chain.
pub fn dense_eval_peak<R: Real>(case: &Case) -> (Dense<R>, Vec<f64>) {
    let mut d = Dense::<R>::from_f64(case.n, &case.start);
    let mut peak: Vec<f64> = (0..case.n).map(|i| d.at(i, i).to()).collect();
    for &op in &case.ops {
        if let StiffOp::MovingWindow(v, std) = op {
            d.congruence(&moving_frame(v));
            d.window(0, window_var(std));
            d.congruence(&moving_frame(-v));
        } else if let StiffOp::Window(std) = op {
            for &x in spatial_axes(case.n) {
                d.window(x, window_var(std));
            }
        } else if let Some(a) = op_matrix(op, case.n) {
            d.congruence(&a);
        } else if let Some(s) = lobe_s(op) {
            for &p in lobe_axes(case.n) {
                d.lobe(p, s);
            }
        }
        for (i, pk) in peak.iter_mut().enumerate() {
            *pk = pk.max(d.at(i, i).to());
        }
    }
    (d, peak)
}

/// The same formulas in plain dense f64 with nalgebra; `Err` says why they failed:
/// `"singular"` (an inverse failed) or `"overflow"` (a value is not finite).
///
/// # Errors
/// As above.
pub fn plain_eval(case: &Case) -> Result<DMatrix<f64>, &'static str> {
    let n = case.n;
    let mut s = DMatrix::from_row_slice(n, n, &case.start);
    for &op in &case.ops {
        if let StiffOp::MovingWindow(v, std) = op {
            let enter = DMatrix::from_row_slice(3, 3, &moving_frame(v));
            let leave = DMatrix::from_row_slice(3, 3, &moving_frame(-v));
            s = enter.transpose() * &s * enter;
            s[(0, 0)] += window_var(std);
            s = leave.transpose() * &s * leave;
        } else if let StiffOp::Window(std) = op {
            for &x in spatial_axes(n) {
                s[(x, x)] += window_var(std);
            }
        } else if let Some(a) = op_matrix(op, n) {
            let a = DMatrix::from_row_slice(n, n, &a);
            s = a.transpose() * &s * a;
        } else if let Some(sl) = lobe_s(op) {
            let axes = lobe_axes(n);
            let k = axes.len();
            let mut p = DMatrix::zeros(k, n);
            for (r, &ax) in axes.iter().enumerate() {
                p[(r, ax)] = 1.0;
            }
            let inner = DMatrix::identity(k, k) * sl + &p * &s * p.transpose();
            let inv = inner.try_inverse().ok_or("singular")?;
            s = &s - &s * p.transpose() * inv * &p * &s;
        }
        if s.iter().any(|v| !v.is_finite()) {
            return Err("overflow");
        }
    }
    Ok(s)
}

/// The chain through the operator crates, holding Σ in `form`.
///
/// # Errors
/// An operator's error (e.g. overflow, total internal reflection).
pub fn ours_eval(case: &Case, form: Form) -> Result<DMatrix<f64>, CovError> {
    match case.n {
        2 => ours_n::<2>(case, form),
        3 => ours_n::<3>(case, form),
        _ => ours_n::<4>(case, form),
    }
}

fn ours_n<const N: usize>(case: &Case, form: Form) -> Result<DMatrix<f64>, CovError> {
    let m = nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| case.start[i * N + j]);
    let start = Cov::<N>::from_matrix(&m)?;
    let mut chain = Chain::new();
    for &op in &case.ops {
        match op {
            StiffOp::Travel(d) => chain.push(Travel::new(d)?),
            StiffOp::Curvature(kx, ky, a) => chain.push(Curvature::anisotropic(kx, ky, a)?),
            StiffOp::Project(c) => chain.push(Project::new(c)?),
            StiffOp::Unproject(c) => chain.push(Unproject::new(c)?),
            StiffOp::Phong(e) if e.is_infinite() => chain.push(Brdf::new(Lobe::Mirror)?),
            StiffOp::Phong(e) => chain.push(Brdf::new(Lobe::phong(e)?)?),
            StiffOp::Diffuse => chain.push(Brdf::new(Lobe::Diffuse)?),
            StiffOp::Refract(n1, n2, c) => chain.push(Refract::new(n1, n2, c)?),
            StiffOp::Window(std) => chain.push(cov_occlusion::Window::isotropic(std)?),
            StiffOp::MovingWindow(v, std) => {
                let window = cov_occlusion::Window::isotropic(std)?;
                chain.push(cov_motion::Moving::new(
                    [v, 0.0],
                    [0.0, 0.0],
                    cov_core::Chain::new().with(window),
                )?);
            }
        }
    }
    let c = chain.eval_in(form, start)?;
    if !c.validity().psd {
        return Err(CovError::NotPsd {
            min_eigenvalue: c.validity().min_eigenvalue,
            tolerance: -c.validity().tolerance,
        });
    }
    Ok(DMatrix::from_fn(N, N, |i, j| c.get(i, j)))
}

/// Resolution floor of the error measure (dimensionless): an axis whose exact value fell
/// below `RESOLUTION × its peak along the chain` is compared at that level, since f64
/// cannot represent it more finely than its history allows.
pub const RESOLUTION: f64 = 1e-12;

/// Relative error of `m` against `r`: the larger of the Frobenius error and the error
/// after scaling each axis by the reference's bandwidth, floored at [`RESOLUTION`] × the
/// axis' peak along the chain (`peak`), so that a small block is not hidden by a large one
/// and an exactly cancelled one is judged at the precision f64 has there.
pub fn rel_error(m: &DMatrix<f64>, r: &DMatrix<f64>, peak: &[f64]) -> f64 {
    if m.iter().chain(r.iter()).any(|v| !v.is_finite()) {
        return f64::INFINITY;
    }
    let n = r.nrows();
    let scale_max = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let peak_max = peak.iter().fold(0.0f64, |a, v| a.max(*v));
    let denom = r.norm().max(RESOLUTION * peak_max);
    let fro = if denom > 0.0 {
        (m - r).norm() / denom
    } else {
        (m - r).norm()
    };
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let floor = r[(i, i)].max(RESOLUTION * peak[i]);
            if floor > 0.0 { 1.0 / floor.sqrt() } else { 0.0 }
        })
        .collect();
    let mut worst: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            let diff = m[(i, j)] - r[(i, j)];
            let e = if d[i] > 0.0 && d[j] > 0.0 {
                (diff * d[i] * d[j]).abs()
            } else if scale_max > 0.0 {
                (diff / scale_max).abs()
            } else {
                diff.abs()
            };
            worst = worst.max(e);
        }
    }
    fro.max(worst)
}

fn is_psd(m: &DMatrix<f64>) -> bool {
    let norm = m.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if norm == 0.0 {
        return true;
    }
    let scaled = m / norm;
    let fro = scaled.norm().max(1.0);
    scaled.symmetric_eigen().eigenvalues.min() >= -1e-12 * fro
}

/// Runs one case.
pub fn run_case(case: &Case) -> Outcome {
    let (rd, mut peak) = dense_eval_peak::<TwoFloat>(case);
    if case.exact {
        peak.iter_mut().for_each(|p| *p = 0.0);
    }
    let r = DMatrix::from_row_slice(case.n, case.n, &rd.to_f64());
    let mut ours_non_psd = false;
    let mut ours_error = None;
    let mut ours_in = |form| match ours_eval(case, form) {
        Ok(m) => {
            ours_non_psd |= !is_psd(&m);
            Some(rel_error(&m, &r, &peak))
        }
        Err(e) => {
            ours_non_psd |= matches!(e, CovError::NotPsd { .. });
            ours_error.get_or_insert(e.to_string());
            None
        }
    };
    let ours = ours_in(Form::SquareRoot);
    let ours_cov = ours_in(Form::Covariance);
    let mut perturbed = case.clone();
    for (k, v) in perturbed.start.iter_mut().enumerate() {
        *v *= 1.0 + 1e-12 * if k % 3 == 0 { 1.0 } else { -0.7 };
    }
    let (rp, _) = dense_eval_peak::<TwoFloat>(&perturbed);
    let amplification = rel_error(&DMatrix::from_row_slice(case.n, case.n, &rp.to_f64()), &r, &peak) / 1e-12;
    let (plain, plain_non_psd, plain_failure) = match (case.expect_error, plain_eval(case)) {
        (true, _) => (None, false, None),
        (false, Err(why)) => (None, false, Some(why)),
        (false, Ok(m)) => (Some(rel_error(&m, &r, &peak)), !is_psd(&m), None),
    };
    Outcome {
        name: case.name.clone(),
        ops: case.ops.len(),
        well_posed: case.well_posed,
        expect_error: case.expect_error,
        factor_only: case.factor_only,
        ours,
        ours_cov,
        ours_non_psd,
        ours_error,
        plain,
        plain_non_psd,
        plain_failure,
        amplification,
    }
}

/// Runs every case.
pub fn run(cases: &[Case]) -> Vec<Outcome> {
    cases.iter().map(run_case).collect()
}

fn gauss(n: usize, stds: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = if stds[i].is_infinite() {
            0.0
        } else {
            1.0 / (4.0 * PI * PI * stds[i] * stds[i])
        };
    }
    v
}

fn correlated(n: usize, scale: f64) -> Vec<f64> {
    // A well-conditioned correlated Σ times `scale`.
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            v[i * n + j] = scale
                * if i == j {
                    2.0 + i as f64
                } else {
                    0.3 / (1.0 + (i + j) as f64)
                };
        }
    }
    v
}

/// The bundled stiff cases. `long` sets the length of the long chains (10⁴ in the suite).
pub fn cases(long: usize) -> Vec<Case> {
    let mut out = Vec::new();
    let mut add = |name: &str, n: usize, start: Vec<f64>, ops: Vec<StiffOp>, well_posed: bool| {
        let expect_error = !well_posed && name.contains("total internal reflection");
        let exact = name.starts_with("beam") || name.starts_with("source 1e-12 m");
        let factor_only = exact || name.starts_with("window 1e-9 m") || name.starts_with("window 1e-8 m");
        out.push(Case {
            name: format!("{name} (N={n})"),
            n,
            start,
            ops,
            well_posed,
            expect_error,
            factor_only,
            exact,
        });
    };
    for n in [2, 4] {
        let spot = gauss(
            n,
            &if n == 4 {
                [0.01, 0.02, 0.1, 0.2]
            } else {
                [0.01, 0.1, 0.0, 0.0]
            },
        );
        let spot = spot[..n * n].to_vec();
        let dirac = {
            let rel = 1e-6;
            gauss(
                n,
                &if n == 4 {
                    [rel, rel, f64::INFINITY, f64::INFINITY]
                } else {
                    [rel, f64::INFINITY, 0.0, 0.0]
                },
            )[..n * n]
                .to_vec()
        };
        add(
            "travel 1e-9 m",
            n,
            spot.clone(),
            vec![StiffOp::Travel(1e-9)],
            true,
        );
        add("travel 1e9 m", n, spot.clone(), vec![StiffOp::Travel(1e9)], true);
        // A very sharp window, travel, then a glossy or near-diffuse lobe and more travel:
        // Σ after the lobe is small but exactly determined by the parameters (a bright
        // spot seen from far away); a cancellation snap used to zero it.
        let sharp = gauss(
            n,
            &if n == 4 {
                [1e-9, 1e-9, f64::INFINITY, f64::INFINITY]
            } else {
                [1e-9, f64::INFINITY, 0.0, 0.0]
            },
        )[..n * n]
            .to_vec();
        for (lobe, name) in [
            (StiffOp::Phong(50.0), "Phong 50"),
            (StiffOp::Phong(2.0), "Phong 2"),
        ] {
            add(
                &format!("window 1e-9 m, travel 1 m, {name}, travel 10 m"),
                n,
                sharp.clone(),
                vec![StiffOp::Travel(1.0), lobe, StiffOp::Travel(10.0)],
                true,
            );
        }
        // The same class with two lobes in a row, and with a curved reflector between
        // the lobe and the long travel.
        add(
            "window 1e-9 m, travel 0.5 m, Phong 10 twice, travel 100 m",
            n,
            sharp.clone(),
            vec![
                StiffOp::Travel(0.5),
                StiffOp::Phong(10.0),
                StiffOp::Phong(10.0),
                StiffOp::Travel(100.0),
            ],
            true,
        );
        let sharp8 = gauss(
            n,
            &if n == 4 {
                [1e-8, 3e-8, f64::INFINITY, f64::INFINITY]
            } else {
                [1e-8, f64::INFINITY, 0.0, 0.0]
            },
        )[..n * n]
            .to_vec();
        add(
            "window 1e-8 m, travel 3 m, Phong 1, curvature 2/m, travel 5 m",
            n,
            sharp8,
            vec![
                StiffOp::Travel(3.0),
                StiffOp::Phong(1.0),
                StiffOp::Curvature(2.0, 2.0, 0.0),
                StiffOp::Travel(5.0),
            ],
            true,
        );
        // A window far below a beam's size, travel, then a lobe (with or without a very
        // wide window before it): the beam's own angular spread comes back to x behind
        // the lobe, a part of Σ_xx the lobe never touched, next to entries 1e16–1e22
        // larger. And a picometre source seen through a nearly diffuse lobe, far away.
        let beam = |x: f64| {
            gauss(
                n,
                &if n == 4 {
                    [x, x, 0.1, 0.2]
                } else {
                    [x, 0.1, 0.0, 0.0]
                },
            )[..n * n]
                .to_vec()
        };
        for (b, w, huge, e) in [
            (1.0, 1e-9, Some(1e3), 1.0),
            (1e-2, 1e-12, Some(1e2), 1e3),
            (1.0, 1e-9, None, 10.0),
        ] {
            let mut ops = vec![StiffOp::Window(w), StiffOp::Travel(1.0)];
            let mut name = format!("beam {b:e} m, window {w:e} m, travel 1 m");
            if let Some(h) = huge {
                ops.push(StiffOp::Window(h));
                name += &format!(", window {h:e} m");
            }
            ops.push(StiffOp::Phong(e));
            ops.push(StiffOp::Travel(10.0));
            add(&format!("{name}, Phong {e}, travel 10 m"), n, beam(b), ops, true);
        }
        let pico = gauss(
            n,
            &if n == 4 {
                [1e-12, 1e-12, 1.0, 1.0]
            } else {
                [1e-12, 1.0, 0.0, 0.0]
            },
        )[..n * n]
            .to_vec();
        add(
            "source 1e-12 m, travel 1 mm, Phong 1e-3, travel 1 km",
            n,
            pico,
            vec![StiffOp::Travel(1e-3), StiffOp::Phong(1e-3), StiffOp::Travel(1e3)],
            true,
        );
        add("travel 1e6 m", n, spot.clone(), vec![StiffOp::Travel(1e6)], true);
        add(
            "Dirac source, travel 1e3 m",
            n,
            dirac.clone(),
            vec![StiffOp::Travel(1e3)],
            true,
        );
        add(
            "diffuse bounce then travel 1e3 m",
            n,
            spot.clone(),
            vec![StiffOp::Travel(1.0), StiffOp::Diffuse, StiffOp::Travel(1e3)],
            true,
        );
        add(
            "Dirac, travel 2 m, diffuse, travel 1e3 m",
            n,
            dirac.clone(),
            vec![
                StiffOp::Travel(2.0),
                StiffOp::Project(0.5),
                StiffOp::Diffuse,
                StiffOp::Unproject(1.0),
                StiffOp::Travel(1e3),
            ],
            true,
        );
        add(
            "grazing cos 1e-12",
            n,
            spot.clone(),
            vec![
                StiffOp::Project(1e-12),
                StiffOp::Phong(100.0),
                StiffOp::Unproject(1e-12),
            ],
            true,
        );
        add(
            "curvature 1e9 /m",
            n,
            spot.clone(),
            vec![StiffOp::Curvature(1e9, 1e9, 0.0)],
            true,
        );
        add(
            "curvature 1e-9 /m",
            n,
            spot.clone(),
            vec![StiffOp::Curvature(1e-9, 1e-9, 0.0)],
            true,
        );
        if n == 4 {
            add(
                "anisotropic saddle ×50 with travel",
                n,
                correlated(n, 1.0),
                (0..50)
                    .flat_map(|i| {
                        [
                            StiffOp::Curvature(3.0, -2.0, 0.1 * i as f64),
                            StiffOp::Travel(0.3),
                        ]
                    })
                    .collect(),
                true,
            );
        }
        add(
            "Phong 1",
            n,
            spot.clone(),
            vec![StiffOp::Travel(0.5), StiffOp::Phong(1.0)],
            true,
        );
        add(
            "Phong 1e12",
            n,
            spot.clone(),
            vec![StiffOp::Travel(0.5), StiffOp::Phong(1e12)],
            true,
        );
        add(
            "zero roughness (mirror)",
            n,
            spot.clone(),
            vec![StiffOp::Travel(0.5), StiffOp::Phong(f64::INFINITY)],
            true,
        );
        let cc = (1.0f64 - 1.0 / 2.25).sqrt();
        add(
            "refraction 1e-9 above the critical angle",
            n,
            spot.clone(),
            vec![StiffOp::Refract(1.5, 1.0, cc * (1.0 + 1e-9))],
            true,
        );
        add(
            "total internal reflection",
            n,
            spot.clone(),
            vec![StiffOp::Refract(1.5, 1.0, 0.5)],
            false,
        );
        add(
            "total internal reflection at critical angle",
            n,
            spot.clone(),
            vec![StiffOp::Refract(1.5, 1.0, cc)],
            false,
        );
        // Near-normal incidence: cosines are inputs (no acos), so cos = 1 − ε is as
        // harmless as cos = 1.
        let near_one = 1.0 - f64::EPSILON / 2.0;
        add(
            "near-normal incidence, cos = 1 − ε/2",
            n,
            spot.clone(),
            vec![
                StiffOp::Project(near_one),
                StiffOp::Phong(100.0),
                StiffOp::Unproject(near_one),
                StiffOp::Refract(1.0, 1.5, near_one),
                StiffOp::Refract(1.5, 1.0, 1.0),
            ],
            true,
        );
        add(
            "entries 1e-300",
            n,
            correlated(n, 1e-300),
            vec![StiffOp::Travel(2.0), StiffOp::Phong(10.0)],
            true,
        );
        add(
            "entries 1e300",
            n,
            correlated(n, 1e300),
            vec![StiffOp::Travel(2.0), StiffOp::Phong(10.0)],
            true,
        );
        let mut rank1 = vec![0.0; n * n];
        rank1[0] = 1.0;
        add(
            "rank-deficient Σ, lobe and diffuse",
            n,
            rank1,
            vec![StiffOp::Travel(1.0), StiffOp::Phong(5.0), StiffOp::Diffuse],
            true,
        );
        add(
            &format!("{long} operators (bounces)"),
            n,
            spot.clone(),
            // Exactly `long` operators: bounces of four, the last one cut short.
            (0..long.div_ceil(4))
                .flat_map(|i| {
                    [
                        StiffOp::Travel(0.5 + 0.01 * (i % 7) as f64),
                        StiffOp::Curvature(1.0, 1.0, 0.0),
                        StiffOp::Phong(200.0),
                        StiffOp::Curvature(-1.0, -1.0, 0.0),
                    ]
                })
                .take(long)
                .collect(),
            true,
        );
    }
    // Motion (N = 3: x, u, t): velocities from 1e-3 to 1e6 m/s.
    let start3 = gauss(3, &[0.1, 0.2, 0.01]);
    for v in [1e-3, 1.0, 1e3, 1e6] {
        add(
            &format!("occluder moving at {v:e} m/s, then travel"),
            3,
            start3.clone(),
            vec![
                StiffOp::MovingWindow(v, 0.01),
                StiffOp::Travel(1.0),
                StiffOp::Phong(100.0),
            ],
            true,
        );
    }
    out
}

/// The report as text lines.
pub fn report(outcomes: &[Outcome]) -> String {
    // The case column is as wide as the longest name, so the columns stay aligned.
    let w = outcomes
        .iter()
        .map(|o| o.name.chars().count())
        .max()
        .unwrap_or(0)
        .max(4);
    let mut s = format!(
        "{:<w$} {:>6} {:>11} {:>11} {:>9} {:>11} {:>9} {:>8}\n",
        "case", "ops", "ours sqrt", "ours cov", "ours PSD", "plain", "plain PSD", "cond"
    );
    let fmt = |e: Option<f64>| e.map(|v| format!("{v:.2e}")).unwrap_or_else(|| "FAILED".into());
    let ours_cell = |o: &Outcome, e: Option<f64>| match (e, o.expect_error) {
        (None, true) => "typed err".to_string(),
        (None, false) => "error".to_string(),
        (Some(_), _) => fmt(e),
    };
    for o in outcomes {
        s.push_str(&format!(
            "{:<w$} {:>6} {:>11} {:>11} {:>9} {:>11} {:>9} {:>8.1e}\n",
            o.name,
            o.ops,
            ours_cell(o, o.ours),
            ours_cell(o, o.ours_cov),
            if o.ours.is_none() && o.ours_cov.is_none() {
                "n/a"
            } else if o.ours_non_psd {
                "NO"
            } else {
                "yes"
            },
            match (o.expect_error, o.plain_failure) {
                (true, _) => "n/a".to_string(),
                (false, Some(why)) => why.to_string(),
                (false, None) => fmt(o.plain),
            },
            if o.expect_error {
                "n/a"
            } else if o.plain.is_none() {
                "-"
            } else if o.plain_non_psd {
                "NO"
            } else {
                "yes"
            },
            o.amplification,
        ));
    }
    s
}
