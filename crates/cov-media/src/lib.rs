//! # cov-media: participating media
//!
//! **Absorption** (docs/physics.md section 3: transmittance is a primal product, rule 2). Across
//! the ray, the extinction coefficient is expanded to second order,
//! `σ_t(p) ≈ σ₀ + gᵀp + ½ pᵀ H p` (`p` the transverse position, `σ_t` in 1/m, `g` in 1/m²,
//! `H` in 1/m³). A ray with coordinates `(x, u)` at the start of a segment of length `L`
//! sees the optical depth `τ(x,u) = ∫₀ᴸ σ_t(x + s·u) ds`, and the transmittance
//! `exp(−τ)` multiplies the light field. Its constant part scales radiance (Σ is
//! normalised: no change), its linear part is an exponential ramp (a shift of a Gaussian:
//! no change), and its quadratic part is a Gaussian window of precision
//! `Q = [[L, L²/2], [L²/2, L³/3]] ⊗ H` on `(x, y, u, v)`, so `Σ' = Σ + Q/4π²`. A homogeneous
//! medium (`H = 0`) leaves Σ unchanged; `σ_t → 0` is the identity; a very large `H` is a
//! very narrow window (finite, PSD). Where `H` has negative eigenvalues (extinction at a
//! maximum on the ray, transmittance growing away from it) there is no window: only the
//! PSD part of `H` is kept, as documented and tested.
//!
//! **Scattering** at a point by the angle `θ` (in the plane of `x`): the outgoing ray's
//! transverse plane meets the incoming field at `x = cos θ · x'` (to first order), a
//! spatial rescaling `l'(x', ·) = l(cos θ·x', ·)`, with no curvature; the phase function
//! `p` then convolves directions as a lobe around the scattering direction (rule 3). The
//! lobe is fitted by a Gaussian in two ways, compared against the brute-force convolution
//! in `tests/validate.rs`:
//!
//! - [`Fit::Curvature`]: `var = −1/(ln p)''` at `θ` (per axis; for Henyey–Greenstein
//!   `(ln p)''_θθ = −3g(cos θ·D − 2g sin²θ)/D²` and `(ln p)''_vv = −3g cos θ / D`,
//!   `D = 1 + g² − 2g cos θ`); no peak there (`(ln p)'' ≥ 0`, e.g. `g = 0`) means no angular
//!   structure: the lobe removes all angular content;
//! - [`Fit::Moment`]: the second moment of the lobe `p(θ + w)` over `w ∈ [−π/2, π/2]`.
//!
//! Measured against the brute-force convolution (scaled relative error of Σ, grid 64,
//! `tests/validate.rs`): at the forward peak (`θ = 0`) with `g ≥ 0.5` the curvature fit
//! wins (0.10–0.15 against 0.25–0.73); off the peak (`θ = 0.5`) or for small `g` the
//! moment fit wins (0.64–3.6 against 1.5–18); mean over the 8 cases 1.21 (moment) against
//! 4.30 (curvature). The **moment fit is the default**. Both are crude: the HG lobe is
//! heavy-tailed and, off its peak, asymmetric.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Absorption` | `length` | m | required | ≥ 0 | Length of the segment. |
//! |  | `hessian` | 1/m³ | required | finite | Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`. |
//! | `Segment` | `length` | m | required | ≥ 0 | Length of the segment. |
//! |  | `hessian` | 1/m³ | required | finite | Hessian of σ_t across the ray: `[hxx]` or `[hxx, hxy, hyy]`. |
//! | `Scatter` | `angle` | rad | required | in [0, π] | Scattering angle. |
//! |  | `phase` | – | required | – | Phase function: `HenyeyGreenstein(g)` or `Tabulated(angles, values)`. |
//! |  | `fit` | – | optional | – | How the phase lobe is fitted: `Moment` (default) or `Curvature`. |
//! |  | `azimuth` | rad | optional | finite | Frame rotation into the scattering plane (3D). |
//! <!-- end of parameters -->
//!
//! **Worked example**: fog with `H = 0.5 /m³` over `L = 2 m`: `Q_xx = L·H = 1`, `Q_xu = 1`,
//! `Q_uu = 4/3`, i.e. `Σ_xx += 1/4π² = 0.0253 (cycles/m)²`. A forward HG scatter with
//! `g = 0.8` at `θ = 0`: `(ln p)'' = −3·0.8/0.04 = −60`, a lobe of variance `1/60`
//! (std 0.13 rad).
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_media::{Absorption, Fit, Phase, Scatter};
//!
//! let mut c = Cov::<2>::gaussian([0.1, 0.2])?;
//! let before = c.get(0, 0);
//! Operator::apply(&Absorption::new(2.0, [0.5, 0.0, 0.0])?, &mut c)?;
//! assert!((c.get(0, 0) - before - 1.0 / (4.0 * std::f64::consts::PI.powi(2))).abs() < 1e-12);
//! Operator::apply(&Scatter::new(0.0, Phase::henyey_greenstein(0.8)?, Fit::Moment, 0.0)?, &mut c)?;
//! assert!(c.validity().is_valid());
//! # Ok::<(), cov_core::CovError>(())
//! ```
//!
//! In RON:
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_media::spec::register(&mut registry);
//! let text = "Path(source: Gaussian(x: 0.1), operators: [
//!     Segment(length: 2.0, hessian: [0.5]),
//!     Scatter(angle: 0.3, phase: HenyeyGreenstein(g: 0.7)),
//!     Segment(length: 1.0, hessian: [0.0]),
//! ])";
//! let result = cov_path::Path::parse(text, &registry)?.eval()?;
//! assert_eq!(result.layout, 2);
//! # Ok::<(), cov_path::PathError>(())
//! ```

#![warn(missing_docs)]

pub mod spec;

use std::f64::consts::{FRAC_PI_2, PI};

use cov_core::{Axis, AxisSet, CovError, FOUR_PI_SQ, Operator, OperatorSpec, Spectrum, Turn, arg};

/// Absorption over a segment of a heterogeneous medium, as a window at its start.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Absorption {
    length: f64,
    h: [f64; 3],
}

impl Absorption {
    /// Operator name.
    pub const NAME: &'static str = "Absorption";

    /// `hessian = [hxx, hxy, hyy]` of σ_t across the ray (1/m³); only its PSD part acts.
    ///
    /// # Errors
    /// Negative or non-finite length, non-finite Hessian.
    pub fn new(length: f64, hessian: [f64; 3]) -> Result<Self, CovError> {
        spec::AbsorptionSpec {
            length,
            hessian: hessian.to_vec(),
        }
        .build()
    }

    /// The PSD part of the Hessian actually used.
    pub fn hessian(&self) -> [f64; 3] {
        self.h
    }
}

/// The PSD part of a symmetric 2×2 `[a, b, c]` (negative eigenvalues set to 0).
fn psd_part([a, b, c]: [f64; 3]) -> [f64; 3] {
    let tr = 0.5 * (a + c);
    let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = (tr + disc, tr - disc);
    if l2 >= 0.0 {
        return [a, b, c];
    }
    if l1 <= 0.0 {
        return [0.0; 3];
    }
    // Keep λ1 along its eigenvector (b, λ1 − a) or (λ1 − c, b).
    let (vx, vy) = if b.abs() > 0.0 {
        (b, l1 - a)
    } else if a >= c {
        (1.0, 0.0)
    } else {
        (0.0, 1.0)
    };
    let n2 = vx * vx + vy * vy;
    [l1 * vx * vx / n2, l1 * vx * vy / n2, l1 * vy * vy / n2]
}

impl Operator for Absorption {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        let l = self.length;
        let (q0, q1, q2) = (l, 0.5 * l * l, l * l * l / 3.0);
        let [hxx, hxy, hyy] = self.h;
        if cov.has(Axis::Y) {
            let hm = [[hxx, hxy], [hxy, hyy]];
            let qk = [[q0, q1], [q1, q2]];
            // Axes (x, y, u, v): entry (2a+i, 2b+j) ordering → ((pos/dir a, axis i), …).
            let axes = [Axis::X, Axis::Y, Axis::U, Axis::V];
            let mut w = [0.0; 16];
            for (r, wrow) in w.chunks_mut(4).enumerate() {
                for (c, wv) in wrow.iter_mut().enumerate() {
                    *wv = qk[r / 2][c / 2] * hm[r % 2][c % 2] / FOUR_PI_SQ;
                }
            }
            cov.add_window(&axes, &w)
        } else {
            let w = [q0 * hxx, q1 * hxx, q1 * hxx, q2 * hxx].map(|v| v / FOUR_PI_SQ);
            cov.add_window(&[Axis::X, Axis::U], &w)
        }
    }
    fn requires(&self) -> AxisSet {
        if self.h[1] != 0.0 || self.h[2] != 0.0 {
            AxisSet::SPACE
        } else {
            AxisSet::FLAT
        }
    }
}

/// A segment of a volumetric path: absorption over `length`, then travel by `length`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    absorption: Absorption,
}

impl Segment {
    /// Operator name.
    pub const NAME: &'static str = "Segment";

    /// # Errors
    /// As [`Absorption::new`].
    pub fn new(length: f64, hessian: [f64; 3]) -> Result<Self, CovError> {
        spec::SegmentSpec {
            length,
            hessian: hessian.to_vec(),
        }
        .build()
    }
}

impl Operator for Segment {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        Operator::apply(&self.absorption, cov)?;
        for &(p, d) in cov.transverse_pairs() {
            cov.shear(p, d, -self.absorption.length)?;
        }
        Ok(())
    }
    fn requires(&self) -> AxisSet {
        Operator::requires(&self.absorption)
    }
}

/// A phase function.
#[derive(Clone, Debug, PartialEq, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub enum Phase {
    /// Henyey–Greenstein with asymmetry `g ∈ (−1, 1)`.
    HenyeyGreenstein {
        /// Asymmetry.
        g: f64,
    },
    /// Tabulated: `values[k]` at `angles[k]` (rad, 0 to π, increasing, covering the angles
    /// used); linear interpolation, values > 0.
    Tabulated {
        /// Angles (rad).
        angles: Vec<f64>,
        /// Phase function values.
        values: Vec<f64>,
    },
}

impl Phase {
    /// Henyey–Greenstein.
    ///
    /// # Errors
    /// `g` outside (−1, 1).
    pub fn henyey_greenstein(g: f64) -> Result<Phase, CovError> {
        Phase::HenyeyGreenstein { g }.validated()
    }

    /// Checks the parameters.
    ///
    /// # Errors
    /// `g` outside (−1, 1); a table that is empty, of mismatched lengths, not increasing,
    /// with an angle outside 0 to π, or with non-positive or non-finite values.
    pub fn validated(self) -> Result<Phase, CovError> {
        match &self {
            &Phase::HenyeyGreenstein { g } => {
                arg!("HenyeyGreenstein", g)
                    .require(|g| g > -1.0 && g < 1.0, || "must be in (−1, 1)".into())?;
            }
            Phase::Tabulated { angles, values } => {
                if angles.len() < 3 || angles.len() != values.len() {
                    return Err(CovError::Shape {
                        what: "Tabulated phase".into(),
                        expected: "at least 3 angles and as many values".into(),
                        got: format!("{} angles, {} values", angles.len(), values.len()),
                    });
                }
                for k in 0..angles.len() {
                    // A scattering angle: 0 (forward) to π (back), π as written with three
                    // decimals or more (3.1416) included.
                    arg!("Tabulated", angles[k]).require(
                        |a| (0.0..=PI + 1e-3).contains(&a),
                        || "must be 0 to π (rad)".into(),
                    )?;
                    arg!("Tabulated", values[k]).positive()?;
                    if k > 0 && angles[k] <= angles[k - 1] {
                        return Err(arg!("Tabulated", angles[k]).error("strictly increasing angles"));
                    }
                }
            }
        }
        Ok(self)
    }

    /// The phase function at angle `a` (rad), up to a constant factor.
    pub fn eval(&self, a: f64) -> f64 {
        match self {
            Phase::HenyeyGreenstein { g } => (1.0 + g * g - 2.0 * g * a.cos()).powf(-1.5),
            Phase::Tabulated { angles, values } => {
                let a = a.abs().min(PI);
                let k = angles.partition_point(|x| *x < a).clamp(1, angles.len() - 1);
                let (a0, a1, v0, v1) = (angles[k - 1], angles[k], values[k - 1], values[k]);
                let t = ((a - a0) / (a1 - a0)).clamp(0.0, 1.0);
                v0 + t * (v1 - v0)
            }
        }
    }

    /// `(ln p)''` along the in-plane (`u`) and out-of-plane (`v`) directions at `θ`.
    pub fn log_curvature(&self, theta: f64) -> (f64, f64) {
        match self {
            Phase::HenyeyGreenstein { g } => {
                let (s, c) = theta.sin_cos();
                let d = 1.0 + g * g - 2.0 * g * c;
                (-3.0 * g * (c * d - 2.0 * g * s * s) / (d * d), -3.0 * g * c / d)
            }
            Phase::Tabulated { .. } => {
                // Finite differences of ln p with a step of 0.01 rad, many table spacings for
                // any reasonable table (the second difference of a piecewise-linear table
                // is meaningless at the scale of one spacing). Across the plane, a
                // deviation v makes the angle α(v) with cos α = cos θ · cos v.
                let h = 1e-2;
                let lp = |a: f64| self.eval(a).ln();
                let uu = (lp(theta + h) - 2.0 * lp(theta) + lp(theta - h)) / (h * h);
                let ang = |v: f64| (theta.cos() * v.cos()).clamp(-1.0, 1.0).acos();
                let vv = (lp(ang(h)) - 2.0 * lp(ang(0.0)) + lp(ang(-h))) / (h * h);
                (uu, vv)
            }
        }
    }

    /// Second moment of the lobe `p(θ + w)` over `w ∈ [−π/2, π/2]` (in-plane; used for
    /// both axes). A flat lobe (max/min − 1 below 1e-9, e.g. HG with `g = 0`) has no
    /// angular structure: infinite variance.
    pub fn moment_variance(&self, theta: f64) -> f64 {
        let n = 2001;
        let h = PI / (n - 1) as f64;
        let (mut m0, mut m2) = (0.0, 0.0);
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for k in 0..n {
            let w = -FRAC_PI_2 + k as f64 * h;
            let wt = if k == 0 || k == n - 1 { 0.5 } else { 1.0 };
            let v = self.eval(theta + w);
            lo = lo.min(v);
            hi = hi.max(v);
            m0 += v * wt;
            m2 += v * wt * w * w;
        }
        if hi <= lo * (1.0 + 1e-9) {
            f64::INFINITY
        } else {
            m2 / m0
        }
    }
}

/// How the phase-function lobe is fitted by a Gaussian.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
pub enum Fit {
    /// `var = −1/(ln p)''` at the scattering angle: best at a sharp forward peak.
    Curvature,
    /// The lobe's second moment over ±π/2 (default: the more accurate on average).
    #[default]
    Moment,
}

/// Scattering at a point by angle `θ`.
#[derive(Clone, Debug, PartialEq)]
pub struct Scatter {
    cos: f64,
    azimuth: Turn,
    var: [f64; 2],
}

impl Scatter {
    /// Operator name.
    pub const NAME: &'static str = "Scatter";

    /// # Errors
    /// `angle` outside [0, π], non-finite `azimuth`, invalid phase function.
    pub fn new(angle: f64, phase: Phase, fit: Fit, azimuth: f64) -> Result<Self, CovError> {
        spec::ScatterSpec {
            angle,
            phase,
            fit: Some(fit),
            azimuth: Some(azimuth),
        }
        .build()
    }

    /// From parameters checked by the spec.
    fn checked(angle: f64, phase: Phase, fit: Fit, azimuth: f64) -> Result<Self, CovError> {
        let azimuth = Turn::new(spec::ScatterSpec::AZIMUTH.of(azimuth))?;
        let phase = phase.validated()?;
        let var = match fit {
            Fit::Curvature => {
                let (cu, cv) = phase.log_curvature(angle);
                let v = |c: f64| if c < 0.0 { -1.0 / c } else { f64::INFINITY };
                [v(cu), v(cv)]
            }
            Fit::Moment => {
                let m = phase.moment_variance(angle);
                [m, m]
            }
        };
        Ok(Scatter {
            cos: angle.cos().abs(),
            azimuth,
            var,
        })
    }

    /// The fitted lobe variances along `u` and `v` (rad²; infinite: no angular structure).
    pub fn variances(&self) -> [f64; 2] {
        self.var
    }
}

impl Operator for Scatter {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        if !self.azimuth.is_zero() {
            cov.rotate_frame_by(self.azimuth)?;
        }
        cov.scale(Axis::X, self.cos)?;
        for (&axis, var) in cov.direction_axes().iter().zip(self.var) {
            // S = 1/(4π² var): 0 when the lobe has no peak (var = ∞).
            let s = if var.is_infinite() {
                0.0
            } else {
                (1.0 / (FOUR_PI_SQ * var)).min(f64::MAX)
            };
            cov.convolve(&[axis], &[s])?;
        }
        Ok(())
    }
    fn requires(&self) -> AxisSet {
        if !self.azimuth.is_zero() {
            AxisSet::SPACE
        } else {
            AxisSet::FLAT
        }
    }
}
