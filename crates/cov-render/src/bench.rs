//! Adaptive sampling and reconstruction from the covariance maps, the baselines a user
//! would pick without covariance tracing, and image error against run time.
//!
//! Every method renders through the same [`Film`] and the same per-pixel Sobol sequences;
//! they differ only in how many samples each pixel takes and how samples are
//! reconstructed:
//!
//! | method | samples per pixel | reconstruction |
//! |---|---|---|
//! | `uniform` | the budget, everywhere | box (a pixel's own samples) |
//! | `gauss` | the budget, everywhere | a fixed Gaussian of [`FIXED_STD`] px |
//! | `variance` | a pilot pass, then the rest ∝ relative variance (two passes) | box |
//! | `cov-density` | ∝ the predicted density over pixel × lens × time | box |
//! | `cov-filter` | the budget, everywhere | each pixel's Gaussian from Σ |
//! | `cov` | ∝ the predicted density | each pixel's Gaussian from Σ |
//!
//! A covariance method's time includes the covariance pass (traced once per scene and
//! budget-independent; its time is added to every covariance run).

use std::time::Instant;

use crate::covpass::PixelCov;
use crate::film::{Film, Filter, Gaussian};
use crate::render::{CovMaps, Image, MAX_SPP, Progress, content, image_filter};
use crate::trace::luminance;
use crate::world::World;

/// Std of the fixed Gaussian filter of the `gauss` baseline (px).
pub const FIXED_STD: f64 = 1.0;
/// A pixel's filter may reach (at this many of its own std) no pixel whose own filter is
/// narrower than the distance to it divided by this: a wide filter stops short of an edge
/// that the covariance pass saw a few pixels away.
pub const EDGE_REACH: f64 = 2.0;
/// Largest reconstruction filter std from Σ (px): the sensor's default `max_filter`.
pub const MAX_FILTER: f64 = 8.0;
/// Pixel filter std the sensor assumed (px): the sensor's default `filter`.
pub const PIXEL_FILTER: f64 = 0.5;
/// An adaptive pixel takes at most this many times the average budget.
pub const MAX_RATIO: f64 = 16.0;
/// The `relMSE` denominator's offset: `(I − R)² / (R² + ε)` per channel.
pub const REL_EPS: f64 = 0.01;

/// A sampling and reconstruction method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Uniform samples, box filter: plain Monte Carlo.
    Uniform,
    /// Uniform samples, a fixed Gaussian filter of [`FIXED_STD`] px.
    Gauss,
    /// Two passes: a pilot, then samples ∝ the pilot's relative variance (box filter).
    Variance,
    /// Samples ∝ the covariance density, box filter (ablation).
    CovDensity,
    /// Uniform samples, the covariance filter (ablation).
    CovFilter,
    /// Samples ∝ the covariance density and the covariance filter.
    Cov,
}

impl Method {
    /// Every method, baselines first.
    pub const ALL: [Method; 6] = [
        Method::Uniform,
        Method::Gauss,
        Method::Variance,
        Method::CovDensity,
        Method::CovFilter,
        Method::Cov,
    ];

    /// Its name in tables and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Uniform => "uniform",
            Method::Gauss => "gauss",
            Method::Variance => "variance",
            Method::CovDensity => "cov-density",
            Method::CovFilter => "cov-filter",
            Method::Cov => "cov",
        }
    }

    /// The method of a name.
    pub fn from_name(s: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s)
    }

    /// Whether it needs the covariance pass.
    pub fn uses_covariance(self) -> bool {
        matches!(self, Method::CovDensity | Method::CovFilter | Method::Cov)
    }
}

/// Distributes `total` samples over pixels in proportion to `weights`, each pixel
/// getting between `lo` and `hi` (water-filling: the clamped pixels' share goes to the
/// others). Non-finite or negative weights count as 0. Rounding carries the fractions
/// along the pixels, so the counts sum to `total` within one sample per clamped run.
pub fn allocate(weights: &[f64], total: f64, lo: u32, hi: u32) -> Vec<u32> {
    let n = weights.len();
    let (lo_f, hi_f) = (f64::from(lo), f64::from(hi.max(lo)));
    let w: Vec<f64> = weights
        .iter()
        .map(|&v| if v.is_finite() && v > 0.0 { v } else { 0.0 })
        .collect();
    let total = total.clamp(lo_f * n as f64, hi_f * n as f64);
    let sum = |scale: f64| -> f64 { w.iter().map(|&v| (v * scale).clamp(lo_f, hi_f)).sum() };
    let wsum: f64 = w.iter().sum();
    let mut counts = Vec::with_capacity(n);
    if wsum <= 0.0 {
        let each = total / n.max(1) as f64;
        let mut carry = 0.0;
        for _ in 0..n {
            let v = each + carry;
            let c = v.floor();
            carry = v - c;
            counts.push(c as u32);
        }
        return counts;
    }
    // The scale s with Σ clamp(s·wᵢ) = total, by bisection on a log scale.
    let (mut a, mut b) = (1e-300f64, 1e300f64);
    for _ in 0..200 {
        let m = (a * b).sqrt();
        if sum(m) < total {
            a = m;
        } else {
            b = m;
        }
        if b / a < 1.0 + 1e-12 {
            break;
        }
    }
    let mut carry = 0.0;
    for &v in &w {
        let x = (v * b).clamp(lo_f, hi_f) + carry;
        let c = x.floor().clamp(lo_f, hi_f);
        carry = x - c;
        counts.push(c as u32);
    }
    counts
}

/// The reconstruction filter covariance `[xx, xy, yy]` (px²) of one pixel's Σ: the
/// Gaussian whose spectrum matches the image's content ([`content`]), from the core's
/// `reconstruction_filter` (clamped at [`MAX_FILTER`]).
pub fn filter_cov(p: &PixelCov) -> [f64; 3] {
    match image_filter(content(p.sigma, PIXEL_FILTER), MAX_FILTER) {
        Some(f) => [f.covariance[(0, 0)], f.covariance[(0, 1)], f.covariance[(1, 1)]],
        None => [MAX_FILTER * MAX_FILTER, 0.0, MAX_FILTER * MAX_FILTER],
    }
}

/// The pixels of a `w × h` image within `r` pixels (a square) of pixel `i`, with their
/// squared distance to it.
fn around(w: i64, h: i64, i: i64, r: i64) -> impl Iterator<Item = (usize, i64)> {
    let (x, y) = (i % w, i / w);
    ((y - r).max(0)..=(y + r).min(h - 1)).flat_map(move |yy| {
        ((x - r).max(0)..=(x + r).min(w - 1))
            .map(move |xx| ((yy * w + xx) as usize, (xx - x).pow(2) + (yy - y).pow(2)))
    })
}

/// Narrows every filter so that it does not reach, at [`EDGE_REACH`] of its own std, a
/// pixel whose filter is narrower than the distance to it over [`EDGE_REACH`]: a wide
/// filter stops short of an edge the covariance pass saw a few pixels away.
pub fn edge_clamp(width: u32, height: u32, raw: &[Gaussian]) -> Vec<Gaussian> {
    use rayon::prelude::*;
    let (w, h) = (i64::from(width), i64::from(height));
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let g = raw[i as usize];
            let s = g.std_max();
            let mut limit = s;
            for (j, d2) in around(w, h, i, (EDGE_REACH * s).ceil() as i64) {
                let sk = raw[j].std_max();
                if sk < limit {
                    limit = limit.min(sk.max((d2 as f64).sqrt() / EDGE_REACH));
                }
            }
            if limit < s {
                let k = (limit / s).powi(2);
                let c = g.cov();
                Gaussian::from_cov([c[0] * k, c[1] * k, c[2] * k])
            } else {
                g
            }
        })
        .collect()
}

/// The largest scale `k²` of a pixel's matched filter `F₀` ([`filter_cov`]): `k = 1` is
/// the Gaussian whose spectrum matches the content's, where the model's relative bias is
/// already `1 − 1/(1 + k²)` = 50%.
pub const K2_MAX: f64 = 1.0;

/// The share `m²` of a pixel's squared signal that its local spectrum's detail carries,
/// in the bias term of [`adapted_filters`]. Σ gives the spread of the local spectrum, not
/// how much of the signal lies away from its mean; `m² = 1` (all of it) is the pessimistic
/// bound. 0.1 was chosen on the bundled Cornell scene at 256×192 from {1, 0.1, 0.01,
/// 0.001} (relMSE at 2 to 64 spp; 0.01 is within 10% of it, 1 and 0.001 are 20–130% worse),
/// and is kept for every scene.
pub const MODULATION: f64 = 0.1;

/// Each pixel's filter for the samples in `film`: its matched filter `F₀` scaled by the
/// `k²` that minimises the predicted squared error
///
/// ```text
/// MSE(k) = m² k⁴ I² + v / (4π n k² √det F₀)
/// ```
///
/// (the bias of a filter `k² F₀` on a Gaussian spectrum is `1 − 1/(1 + k²) ≈ k²` of the
/// detail `m I` ([`MODULATION`]); the noise of `n` samples of variance `v` averaged by a
/// normalised Gaussian of covariance `k² F₀` px² is `v / (4π n k² √det F₀)`), so
/// `k⁶ = v / (8π m² n (I² + ε) √det F₀)`, capped at [`K2_MAX`]. `v` is the 3×3 mean of the pixels' sample variances (from the
/// spread of the 3×3 pixel means where pixels hold one sample), `I` the 3×3 largest
/// luminance; then [`edge_clamp`]. More samples or less noise give narrower filters.
pub fn adapted_filters(guide: &Guide, film: &Film) -> Vec<Gaussian> {
    use rayon::prelude::*;
    let (w, h) = (i64::from(film.width), i64::from(film.height));
    let var = film.variance();
    let img = film.box_image();
    let lum: Vec<f64> = img.pixels.iter().map(|p| luminance(*p)).collect();
    let raw: Vec<Gaussian> = (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (mut v, mut imax, mut m1, mut m2, mut k) = (0.0, 0.0f64, 0.0, 0.0, 0.0);
            for (j, _) in around(w, h, i, 1) {
                v += var[j];
                imax = imax.max(lum[j]);
                m1 += lum[j];
                m2 += lum[j] * lum[j];
                k += 1.0;
            }
            let n = f64::from(film.count[i as usize].max(1));
            let v = if film.count[i as usize] >= 2 {
                v / k
            } else {
                n * ((m2 - m1 * m1 / k) / (k - 1.0).max(1.0)).max(0.0)
            };
            let f0 = guide.matched[i as usize];
            let det = (f0[0] * f0[2] - f0[1] * f0[1]).max(1e-12);
            let k6 = v / (8.0 * std::f64::consts::PI * n * (imax * imax + REL_EPS) * det.sqrt());
            let k2 = (k6 / MODULATION).cbrt().min(K2_MAX);
            Gaussian::from_cov([f0[0] * k2, f0[1] * k2, f0[2] * k2])
        })
        .collect();
    edge_clamp(film.width, film.height, &raw)
}

/// The covariance pass's products a method uses: sample weights and matched filters.
#[derive(Clone, Debug)]
pub struct Guide {
    /// Predicted samples per pixel (relative weights for allocation).
    pub density: Vec<f64>,
    /// Per-pixel matched filter covariance `F₀` `[xx, xy, yy]` (px², [`filter_cov`]).
    pub matched: Vec<[f64; 3]>,
    /// Seconds the covariance pass took.
    pub secs: f64,
}

impl Guide {
    /// The guide of `maps`, which took `pass_secs` to trace.
    pub fn new(maps: &CovMaps, pass_secs: f64) -> Guide {
        use rayon::prelude::*;
        let t = Instant::now();
        // Rows in parallel; a pixel equal to its left neighbour (a block of the strided
        // grid) reuses its filter.
        let w = maps.width as usize;
        let matched: Vec<[f64; 3]> = maps
            .pixels
            .par_chunks(w.max(1))
            .flat_map_iter(|row| {
                let mut last: Option<(PixelCov, [f64; 3])> = None;
                row.iter()
                    .map(|p| match last {
                        Some((q, f)) if q == *p => f,
                        _ => {
                            let f = filter_cov(p);
                            last = Some((*p, f));
                            f
                        }
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        Guide {
            density: maps.pixels.iter().map(|p| p.spp).collect(),
            matched,
            secs: pass_secs + t.elapsed().as_secs_f64(),
        }
    }
}

/// Where a run spent its time (wall-clock seconds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// The covariance pass (with the filters), for the covariance methods.
    pub covariance: f64,
    /// Tracing samples (every pass).
    pub sampling: f64,
    /// Reconstructing the image from the film (the filters' splat).
    pub reconstruction: f64,
    /// Allocating samples to pixels (the variance method's analysis of its pilot pass).
    pub allocation: f64,
}

impl Timing {
    /// The run's total.
    pub fn total(&self) -> f64 {
        self.covariance + self.sampling + self.reconstruction + self.allocation
    }

    fn sample(&mut self, f: impl FnOnce()) {
        let t = Instant::now();
        f();
        self.sampling += t.elapsed().as_secs_f64();
    }
}

/// One method's image at one budget.
#[derive(Clone, Debug)]
pub struct Run {
    /// The method.
    pub method: Method,
    /// Average samples per pixel asked for.
    pub budget: f64,
    /// Samples actually taken.
    pub samples: u64,
    /// The image.
    pub image: Image,
    /// Where the time went.
    pub timing: Timing,
}

/// Renders `world` with `method` at an average of `budget` samples per pixel. The
/// covariance methods need `guide`.
///
/// # Errors
/// A covariance method without a guide, or a guide of another size.
pub fn run(
    world: &World,
    method: Method,
    budget: f64,
    guide: Option<&Guide>,
    seed: u64,
    progress: Progress<'_>,
) -> Result<Run, String> {
    let (w, h) = (world.camera.width, world.camera.height);
    let n = w as usize * h as usize;
    let budget = budget.clamp(1.0, f64::from(MAX_SPP));
    let total = budget * n as f64;
    let hi = ((budget * MAX_RATIO).ceil() as u32).clamp(1, MAX_SPP);
    let guide = match (method.uses_covariance(), guide) {
        (true, Some(g)) if g.matched.len() == n && g.density.len() == n => Some(g),
        (true, _) => {
            return Err(format!(
                "method `{}` needs the covariance maps of this {w}x{h} image",
                method.name()
            ));
        }
        (false, _) => None,
    };
    let mut timing = Timing {
        covariance: guide.map_or(0.0, |g| g.secs),
        ..Timing::default()
    };
    let uniform = || allocate(&vec![1.0; n], total, 1, MAX_SPP);
    let mut film = Film::new(w, h);
    let filter = match method {
        Method::Gauss => Filter::Fixed(Gaussian::isotropic(FIXED_STD)),
        _ => Filter::Box,
    };
    match method {
        Method::Uniform | Method::Gauss | Method::CovFilter => {
            timing.sample(|| film.render(world, &uniform(), seed, f64::INFINITY, progress));
        }
        Method::CovDensity | Method::Cov => {
            let t = Instant::now();
            let lo = ((budget / 4.0).floor() as u32).max(1);
            let counts = allocate(
                &guide.map(|g| g.density.clone()).unwrap_or_default(),
                total,
                lo,
                hi,
            );
            timing.allocation = t.elapsed().as_secs_f64();
            timing.sample(|| film.render(world, &counts, seed, f64::INFINITY, progress));
        }
        Method::Variance => {
            // A pilot of a quarter of the budget (at least 2 samples, for a variance),
            // then counts ∝ the relative standard deviation (blurred over 3×3 pixels),
            // at least the pilot: the allocation that minimises the summed relative
            // variance Σ σᵢ²/(nᵢ(μᵢ² + ε)) for a fixed total.
            let pilot = (budget / 4.0).floor().max(2.0);
            if budget < pilot + 1.0 {
                timing.sample(|| film.render(world, &uniform(), seed, f64::INFINITY, progress));
            } else {
                let first = vec![pilot as u32; n];
                timing.sample(|| film.render(world, &first, seed, f64::INFINITY, progress));
                let t = Instant::now();
                let weights = relative_variance(&film);
                let p = pilot as u32;
                let rest: Vec<u32> = allocate(&weights, total, p, hi.max(p))
                    .into_iter()
                    .map(|c| c.saturating_sub(p))
                    .collect();
                timing.allocation = t.elapsed().as_secs_f64();
                timing.sample(|| film.render(world, &rest, seed, f64::INFINITY, progress));
            }
        }
    }
    let t = Instant::now();
    let filter = match (method, guide) {
        (Method::CovFilter | Method::Cov, Some(g)) => Filter::PerPixel(adapted_filters(g, &film)),
        _ => filter,
    };
    let image = film.image(&filter);
    timing.reconstruction += t.elapsed().as_secs_f64();
    Ok(Run {
        method,
        budget,
        samples: film.count.iter().map(|&c| u64::from(c)).sum(),
        image,
        timing,
    })
}

/// Per pixel, the relative standard deviation of a sample, `√(σ² / (μ² + ε))`, blurred
/// over 3×3 pixels (a pilot's variances are noisy).
fn relative_variance(film: &Film) -> Vec<f64> {
    let (w, h) = (film.width as i64, film.height as i64);
    let var = film.variance();
    let box_img = film.box_image();
    let raw: Vec<f64> = var
        .iter()
        .zip(&box_img.pixels)
        .map(|(&v, p)| {
            let m = luminance(*p);
            (v / (m * m + REL_EPS)).sqrt()
        })
        .collect();
    (0..w * h)
        .map(|i| {
            let (s, k) = around(w, h, i, 1).fold((0.0, 0.0), |(s, k), (j, _)| (s + raw[j], k + 1.0));
            s / k
        })
        .collect()
}

/// Image errors against a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Error {
    /// Root mean square error over pixels and channels.
    pub rmse: f64,
    /// Mean of `(I − R)² / (R² + ε)` over pixels and channels ([`REL_EPS`]).
    pub relmse: f64,
}

/// The errors of `img` against `reference` (same size).
///
/// # Errors
/// Images of different sizes.
pub fn error(img: &Image, reference: &Image) -> Result<Error, String> {
    if (img.width, img.height) != (reference.width, reference.height) {
        return Err(format!(
            "image {}x{} against a reference of {}x{}",
            img.width, img.height, reference.width, reference.height
        ));
    }
    let (mut se, mut rel) = (0.0, 0.0);
    for (a, r) in img.pixels.iter().zip(&reference.pixels) {
        for k in 0..3 {
            let d = a[k] - r[k];
            se += d * d;
            rel += d * d / (r[k] * r[k] + REL_EPS);
        }
    }
    let n = (3 * img.pixels.len()).max(1) as f64;
    Ok(Error {
        rmse: (se / n).sqrt(),
        relmse: rel / n,
    })
}

/// The per-pixel relative squared error of `img` against `reference` (mean over
/// channels of `(I − R)² / (R² + ε)`), as a heat map: log scale from 1e-4 (dark) to 1
/// (yellow) and above.
///
/// # Errors
/// Images of different sizes.
pub fn error_map(img: &Image, reference: &Image) -> Result<image::RgbImage, String> {
    if (img.width, img.height) != (reference.width, reference.height) {
        return Err("error map: images of different sizes".into());
    }
    Ok(image::RgbImage::from_fn(img.width, img.height, |x, y| {
        let (a, r) = (img.get(x, y), reference.get(x, y));
        let e = (0..3)
            .map(|k| (a[k] - r[k]).powi(2) / (r[k] * r[k] + REL_EPS))
            .sum::<f64>()
            / 3.0;
        image::Rgb(crate::render::colormap((e.max(1e-4).log10() + 4.0) / 4.0))
    }))
}

/// A least-squares line `log e = a + b log t` through `(t, e)` points (positive only);
/// `None` with fewer than two distinct times.
pub fn fit_loglog(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let p: Vec<(f64, f64)> = points
        .iter()
        .filter(|(t, e)| *t > 0.0 && *e > 0.0 && t.is_finite() && e.is_finite())
        .map(|(t, e)| (t.ln(), e.ln()))
        .collect();
    let n = p.len() as f64;
    if p.len() < 2 {
        return None;
    }
    let (mx, my) = (
        p.iter().map(|v| v.0).sum::<f64>() / n,
        p.iter().map(|v| v.1).sum::<f64>() / n,
    );
    let sxx: f64 = p.iter().map(|v| (v.0 - mx).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = p.iter().map(|v| (v.0 - mx) * (v.1 - my)).sum();
    let b = sxy / sxx;
    Some((my - b * mx, b))
}

/// The time a curve of `(seconds, error)` points needs to reach error `e`, interpolated
/// linearly in log–log between the two points around it (the curve ordered by time), and
/// whether it was interpolated: a curve whose first point is already below `e` gives that
/// point's time and `false` (an upper bound). `None` when the curve never reaches `e`.
pub fn time_to_reach(curve: &[(f64, f64)], e: f64) -> Option<(f64, bool)> {
    let mut p: Vec<(f64, f64)> = curve
        .iter()
        .copied()
        .filter(|(t, v)| *t > 0.0 && *v > 0.0 && t.is_finite() && v.is_finite())
        .collect();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    if e.is_nan() || e <= 0.0 {
        return None;
    }
    if let Some(first) = p.first()
        && first.1 <= e
    {
        return Some((first.0, false));
    }
    p.windows(2).find_map(|w| {
        let ((t0, e0), (t1, e1)) = (w[0], w[1]);
        if e0 > e && e1 <= e {
            let f = (e.ln() - e0.ln()) / (e1.ln() - e0.ln());
            Some(((t0.ln() + f * (t1.ln() - t0.ln())).exp(), true))
        } else {
            None
        }
    })
}

/// The equal-error speed-up of a run `(t, e)` over a baseline curve: the time the
/// baseline's log–log fit needs to reach error `e`, divided by `t`. `None` when the
/// baseline's error does not fall with time.
pub fn speedup(baseline: &[(f64, f64)], t: f64, e: f64) -> Option<f64> {
    let (a, b) = fit_loglog(baseline)?;
    if b >= 0.0 || t <= 0.0 || e <= 0.0 {
        return None;
    }
    let t_base = ((e.ln() - a) / b).exp();
    let s = t_base / t;
    s.is_finite().then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn allocation_is_proportional_clamped_and_sums_to_the_total() {
        let w = [1.0, 2.0, 3.0, 4.0];
        let c = allocate(&w, 100.0, 1, 1000);
        assert_eq!(c.iter().sum::<u32>(), 100);
        assert_eq!(c, vec![10, 20, 30, 40]);
        // A clamp at 35: the 4th pixel's excess goes to the others in proportion.
        let c = allocate(&w, 100.0, 1, 35);
        assert_eq!(c[3], 35);
        assert_eq!(c.iter().sum::<u32>(), 100);
        assert!(c[2] > 30 && c[0] >= 10);
        // Zero, NaN and negative weights get the minimum.
        let c = allocate(&[0.0, f64::NAN, -1.0, 1.0], 40.0, 2, 100);
        assert_eq!(&c[..3], &[2, 2, 2]);
        assert_eq!(c[3], 34);
        // All zero: uniform.
        assert_eq!(allocate(&[0.0; 4], 10.0, 0, 100).iter().sum::<u32>(), 10);
    }

    #[test]
    fn time_to_reach_interpolates_in_log_log() {
        let c = [(1.0, 1.0), (4.0, 0.25), (16.0, 0.0625)];
        let (t, exact) = time_to_reach(&c, 0.5).unwrap();
        assert!((t - 2.0).abs() < 1e-12 && exact);
        assert_eq!(time_to_reach(&c, 2.0), Some((1.0, false)));
        assert_eq!(time_to_reach(&c, 0.01), None);
        assert_eq!(time_to_reach(&c, f64::NAN), None);
    }

    #[test]
    fn speedup_reads_the_baseline_fit() {
        // Error ∝ 1/t: the baseline reaches e = 0.01 at t = 100.
        let base: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&t| (t, 1.0 / t)).collect();
        let (a, b) = fit_loglog(&base).unwrap();
        assert!(a.abs() < 1e-12 && (b + 1.0).abs() < 1e-12);
        let s = speedup(&base, 10.0, 0.01).unwrap();
        assert!((s - 10.0).abs() < 1e-9, "{s}");
        assert_eq!(speedup(&[(1.0, 1.0), (2.0, 2.0)], 1.0, 0.5), None);
    }

    #[test]
    fn errors_are_zero_on_the_reference_and_scale_as_expected() {
        let r = Image {
            width: 2,
            height: 1,
            pixels: vec![glam::DVec3::splat(1.0), glam::DVec3::splat(0.0)],
        };
        assert_eq!(
            error(&r, &r).unwrap(),
            Error {
                rmse: 0.0,
                relmse: 0.0
            }
        );
        let mut a = r.clone();
        a.pixels[1] = glam::DVec3::splat(0.1);
        let e = error(&a, &r).unwrap();
        assert!((e.rmse - (0.01f64 * 3.0 / 6.0).sqrt()).abs() < 1e-12);
        assert!((e.relmse - 0.5).abs() < 1e-12, "{}", e.relmse);
    }
}
