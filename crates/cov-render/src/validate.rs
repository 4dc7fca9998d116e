//! Predictions against images: the local spectrum of a reference image, tile by tile,
//! compared with the covariance pass's prediction.
//!
//! For each tile of `T × T` pixels of two independent references (same scene, other
//! seeds), multiply by a Hann window, FFT (rustfft), and take the **cross** spectrum
//! `Re(F_a · conj F_b)`: the two renders' Monte Carlo noise is independent, so its
//! expectation is the image's own power spectrum with no noise term (fireflies included).
//!
//! **The measurement is in covtrace's convention** (docs/physics.md section 1): Σ is the
//! second moment of the *amplitude* spectrum of the windowed field, its mean included, so
//! a low-contrast texture weighs less than the same texture at full contrast (exactly
//! `|a| f² / (|m| + |a|)` for `m + a·cos(2π f x)`, as cov-occlusion's `Texture` gives). The
//! amplitude of a bin is `√max(cross, 0)`; the moment is taken over the bins of the tile's
//! mean (the window's own spectrum) and those of the variation's band (below), less the
//! window's own amplitude moment. Restricting it to significant bins keeps the root's bias
//! on noise-only bins out.
//!
//! **The variation's band** is found on the tile with its mean removed, over [`RINGS`]
//! rings of frequency: the contiguous band of rings, around the most significant one,
//! whose cross power is above [`SIGNIFICANCE`] standard deviations of its estimate (signal
//! × noise and noise × noise terms, see `band`). A significant ring cut off from that band
//! is heavy-tailed Monte Carlo noise: on the glossy scene's wall, four 2048-spp references
//! gave isolated rings at 0.6–0.7 cycles/px at 11–31 "σ" in one pair and below 0 in the
//! other, which read as detail of 0.13–0.19 cycles/px. (A tile whose content is two bands
//! with nothing between, a gradient under a fine texture, reads as its stronger band.)
//! Twice the power moment over that band, less the window's, is the **variation's
//! bandwidth** (for a Gaussian bump on zero, the amplitude Σ; whatever the contrast
//! otherwise): it decides whether a tile has detail, and is reported beside the
//! measurement, with the tiles' **contrast** (the variation's share of the amplitude).
//!
//! The predicted Σ is the mean of the covariance pass's per-pixel Σ over the tile, minus
//! the pixel filter's own window (the sensor adds `1/(4π² f²)` per axis for a filter of std
//! `f` px), so that both describe the image's content.
//!
//! Bandwidths are `√tr Σ` (cycles/px); predictions are capped at [`NYQUIST_CAP`], the
//! most an image can show. A tile **has detail** when its luminance std is at least
//! [`DETAIL`] of the image's mean luminance, its signal power is at least twice its noise
//! power (estimated from the difference of the two references), and its variation's
//! bandwidth is above [`RESOLVED`], what a `T`-pixel tile resolves beyond its first
//! frequency bins (a smooth gradient is not detail). A tile is **under-sampled** when the
//! predicted bandwidth is below half the measured one: the prediction would give it too
//! few samples.

use std::f64::consts::PI;

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use crate::covpass::CovMaps;
use crate::film::Image;
use crate::trace::luminance;

/// Tile side (px) of the comparison.
pub const T: usize = 16;
/// A tile has detail when its luminance std is at least this fraction of the image mean.
pub const DETAIL: f64 = 0.02;
/// A ring's cross power counts when above this many standard deviations of its noise (5:
/// caustic fireflies are heavy-tailed, far from the Gaussian that 3σ assumes).
pub const SIGNIFICANCE: f64 = 5.0;
/// Rings of frequency over which the cross power is tested for significance.
pub const RINGS: usize = 8;
/// Bandwidth a tile resolves beyond its first bins, `2/T` cycles/px.
pub const RESOLVED: f64 = 2.0 / T as f64;
/// The largest bandwidth an image of box-filtered pixels can show, `√(2·0.5²)` cycles/px.
pub const NYQUIST_CAP: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// One tile's comparison.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TileCheck {
    /// Tile column and row.
    pub tile: (usize, usize),
    /// Predicted bandwidth of the content (cycles/px).
    pub predicted: f64,
    /// Measured bandwidth in covtrace's convention, what `predicted` estimates
    /// (cycles/px): the amplitude spectrum's, the tile's mean included.
    pub measured: f64,
    /// Bandwidth of the tile's variation alone, its mean removed (cycles/px): twice the
    /// power spectrum's moment, which reads a Gaussian's Σ whatever its contrast. It
    /// decides whether the tile has detail.
    pub variation: f64,
    /// The variation's share of the tile's amplitude, `√(2P) / (|mean| + √(2P))` with `P`
    /// its power (0 to 1): what weighs the measurement down from `variation`.
    pub contrast: f64,
    /// Whether the tile has detail.
    pub detail: bool,
}

/// The comparison over an image.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Agreement {
    /// Every tile.
    pub tiles: Vec<TileCheck>,
    /// Tiles with detail.
    pub detail_tiles: usize,
    /// Median of predicted/measured over tiles with detail.
    pub median_ratio: f64,
    /// Spearman rank correlation of predicted and measured over tiles with detail.
    pub rank_correlation: f64,
    /// Spearman rank correlation of predicted and the variation's bandwidth (the mean
    /// removed) over tiles with detail: how well the prediction orders the content's
    /// bandwidth alone, whatever its contrast.
    pub variation_correlation: f64,
    /// Spearman rank correlation of the tiles' contrast and the measurement over tiles
    /// with detail: what the contrast alone, read off the references, would score. A
    /// prediction that does not beat it adds nothing to it about bandwidth.
    pub contrast_correlation: f64,
    /// Fraction of tiles with detail whose prediction is below half the measurement.
    pub undersampled: f64,
}

/// The Hann window of `T` points.
fn hann() -> [f64; T] {
    let mut w = [0.0; T];
    for (i, v) in w.iter_mut().enumerate() {
        *v = 0.5 - 0.5 * (2.0 * PI * (i as f64 + 0.5) / T as f64).cos();
    }
    w
}

/// Frequency of FFT bin `k` (cycles/px), in `[-1/2, 1/2)`.
fn freq(k: usize) -> f64 {
    let k = k as f64;
    if k < T as f64 / 2.0 {
        k / T as f64
    } else {
        (k - T as f64) / T as f64
    }
}

/// The 2D spectrum of a `T × T` tile (row-major).
fn spectrum(tile: &[f64]) -> Vec<Complex<f64>> {
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(T);
    let mut buf: Vec<Complex<f64>> = tile.iter().map(|&v| Complex::new(v, 0.0)).collect();
    for row in buf.chunks_exact_mut(T) {
        fft.process(row);
    }
    let mut col = vec![Complex::new(0.0, 0.0); T];
    for x in 0..T {
        for y in 0..T {
            col[y] = buf[y * T + x];
        }
        fft.process(&mut col);
        for y in 0..T {
            buf[y * T + x] = col[y];
        }
    }
    buf
}

/// The normalised second moment `tr Σ` of the spectrum `value(k)` over the bins `(kx,
/// ky)` that `counted` keeps (`k = ky·T + kx`); `None` when their total is not positive.
fn moment(counted: impl Fn(usize, usize) -> bool, value: impl Fn(usize) -> f64) -> Option<f64> {
    let (mut s, mut m) = (0.0, 0.0);
    for ky in 0..T {
        for kx in 0..T {
            if counted(kx, ky) {
                let a = value(ky * T + kx);
                s += a;
                m += a * (freq(kx).powi(2) + freq(ky).powi(2));
            }
        }
    }
    (s > 0.0).then(|| m / s)
}

/// The ring (of [`RINGS`]) that frequency bin `(kx, ky)` falls in.
fn ring_of(kx: usize, ky: usize) -> usize {
    let (fx, fy) = (freq(kx), freq(ky));
    let r = (fx * fx + fy * fy).sqrt() / std::f64::consts::FRAC_1_SQRT_2;
    ((r * RINGS as f64) as usize).min(RINGS - 1)
}

/// The band of rings `lo..=hi` that holds the content of the variation spectra `fa`, `fb`
/// (tile mean removed; DC excluded): the contiguous run of significant rings around the
/// most significant one. `None` when no ring is significant.
///
/// A ring is significant when its cross power exceeds [`SIGNIFICANCE`] standard deviations
/// of its estimate. Per bin, with `F_a = S + A`, `F_b = S + B` and independent noises of
/// power `N`, `Re(F_a·conj F_b)` has mean `|S|²` and variance `|S|²·N + N²/2`; over a ring
/// of `m` bins of estimated noise `N` and cross power `C` (a plug-in for `Σ|S|²`), the std
/// is `√(N·max(C, 0) + m·N²/2)`. Content is a band (an image's spectrum falls off from the
/// content's frequencies into the noise): a significant ring separated from the band by an
/// insignificant one is Monte Carlo noise, which is heavy-tailed where caustic paths reach a
/// surface and passes a Gaussian test far more often than its nominal rate.
fn band(fa: &[Complex<f64>], fb: &[Complex<f64>]) -> Option<(usize, usize)> {
    let mut c = [0.0; RINGS];
    let mut noise = [0.0; RINGS];
    let mut m = [0usize; RINGS];
    for ky in 0..T {
        for kx in 0..T {
            if kx == 0 && ky == 0 {
                continue;
            }
            let (ring, k) = (ring_of(kx, ky), ky * T + kx);
            c[ring] += (fa[k] * fb[k].conj()).re;
            noise[ring] += (fa[k] - fb[k]).norm_sqr() / 2.0;
            m[ring] += 1;
        }
    }
    // Significance of each ring, in standard deviations of its estimate (0 when empty).
    let mut z = [0.0; RINGS];
    for r in 0..RINGS {
        if m[r] == 0 {
            continue;
        }
        let per_bin = noise[r] / m[r] as f64;
        let var = per_bin * c[r].max(0.0) + m[r] as f64 * per_bin * per_bin / 2.0;
        z[r] = if var > 0.0 {
            c[r] / var.sqrt()
        } else if c[r] > 0.0 {
            f64::INFINITY // noiseless content
        } else {
            0.0
        };
    }
    let peak = (0..RINGS).max_by(|&a, &b| z[a].total_cmp(&z[b]))?;
    if !(z[peak] > SIGNIFICANCE && c[peak] > 0.0) {
        return None;
    }
    let significant = |r: usize| z[r] > SIGNIFICANCE && c[r] > 0.0;
    let lo = (0..=peak)
        .rev()
        .take_while(|&r| significant(r))
        .last()
        .unwrap_or(peak);
    let hi = (peak..RINGS)
        .take_while(|&r| significant(r))
        .last()
        .unwrap_or(peak);
    Some((lo, hi))
}

/// The second moment of the cross power of the variation spectra `fa`, `fb` over their
/// [`band`] `lo..=hi` (DC excluded): what the variation alone shows, whatever its contrast.
fn power_moment(fa: &[Complex<f64>], fb: &[Complex<f64>], (lo, hi): (usize, usize)) -> Option<f64> {
    moment(
        |kx, ky| (kx, ky) != (0, 0) && (lo..=hi).contains(&ring_of(kx, ky)),
        |k| (fa[k] * fb[k].conj()).re,
    )
    .map(|m| m.max(0.0))
}

/// Whether bin `k` holds the window's own spectrum: the Hann window of [`hann`] has its
/// spectrum on bins 0 and ±1 of each axis, where a tile's mean lands.
fn in_mean(k: usize) -> bool {
    k <= 1 || k == T - 1
}

/// `tr Σ` of the tile in covtrace's convention (docs/physics.md section 1: the second
/// moment of the *amplitude* spectrum, the mean included) from the full windowed spectra
/// `ga`, `gb` (mean kept), over the bins of the mean and those of the variation's `band`,
/// less the window's own moment `own`. The amplitude of a bin is `√max(Re(G_a·conj G_b), 0)`,
/// whose noise term vanishes in expectation before the root; restricting it to the
/// significant band keeps the root's bias on noise-only bins out.
fn amplitude_moment(ga: &[Complex<f64>], gb: &[Complex<f64>], (lo, hi): (usize, usize), own: f64) -> f64 {
    moment(
        |kx, ky| (in_mean(kx) && in_mean(ky)) || (lo..=hi).contains(&ring_of(kx, ky)),
        |k| (ga[k] * gb[k].conj()).re.max(0.0).sqrt(),
    )
    .map_or(0.0, |m| (m - own).max(0.0))
}

/// Ranks (average ranks for ties) of `v`.
fn ranks(v: &[f64]) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..v.len()).collect();
    idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
    let mut r = vec![0.0; v.len()];
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
            j += 1;
        }
        for k in i..=j {
            r[idx[k]] = (i + j) as f64 / 2.0;
        }
        i = j + 1;
    }
    r
}

/// Spearman's rank correlation (0 when undefined).
pub fn spearman(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 0.0;
    }
    let (ra, rb) = (ranks(&a[..n]), ranks(&b[..n]));
    let ma = ra.iter().sum::<f64>() / n as f64;
    let mb = rb.iter().sum::<f64>() / n as f64;
    let (mut c, mut va, mut vb) = (0.0, 0.0, 0.0);
    for i in 0..n {
        c += (ra[i] - ma) * (rb[i] - mb);
        va += (ra[i] - ma).powi(2);
        vb += (rb[i] - mb).powi(2);
    }
    if va <= 0.0 || vb <= 0.0 {
        0.0
    } else {
        c / (va * vb).sqrt()
    }
}

/// Compares the covariance pass's `maps` with two independent renders `a`, `b` of the same
/// scene (other seeds, same sample counts); `pixel_filter` is the sensor's filter std (px).
pub fn compare(a: &Image, b: &Image, maps: &CovMaps, pixel_filter: f64) -> Agreement {
    let (w, h) = (a.width as usize, a.height as usize);
    let win = hann();
    let mut wtile = vec![0.0; T * T];
    for y in 0..T {
        for x in 0..T {
            wtile[y * T + x] = win[x] * win[y];
        }
    }
    let wspec = spectrum(&wtile);
    // The window's power moment (DC excluded, as for the variation), and its amplitude
    // moment (DC included, as the tile's mean is).
    let own = moment(|kx, ky| (kx, ky) != (0, 0), |k| wspec[k].norm_sqr()).unwrap_or(0.0);
    let own_amp = moment(|_, _| true, |k| wspec[k].norm()).unwrap_or(0.0);
    let n_px = a.pixels.len().max(1) as f64;
    let mean_l = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| 0.5 * (luminance(*p) + luminance(*q)))
        .sum::<f64>()
        / n_px;
    let px_window = 1.0 / (4.0 * PI * PI * pixel_filter * pixel_filter);
    // The tile's luminance, its mean, and the variation windowed.
    let windowed = |img: &Image, tx: usize, ty: usize| -> (Vec<f64>, f64, Vec<f64>) {
        let mut lum = vec![0.0; T * T];
        for y in 0..T {
            for x in 0..T {
                lum[y * T + x] = luminance(img.pixels[(ty * T + y) * w + tx * T + x]);
            }
        }
        let mean = lum.iter().sum::<f64>() / (T * T) as f64;
        let w = |k: usize| win[k % T] * win[k / T];
        let var = lum.iter().enumerate().map(|(k, v)| (v - mean) * w(k)).collect();
        (lum, mean, var)
    };
    let mut tiles = Vec::new();
    for ty in 0..h / T {
        for tx in 0..w / T {
            let (la, ma, wa) = windowed(a, tx, ty);
            let (lb, mb, wb) = windowed(b, tx, ty);
            let sd =
                |l: &[f64], m: f64| (l.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (T * T) as f64).sqrt();
            let (sa, sb) = (sd(&la, ma), sd(&lb, mb));
            // The variation's power from the two renders' covariance (no noise term in
            // expectation), and its share of the amplitude as for a sinusoid (cov-occlusion's
            // `Texture::from_moments`).
            let cov_ab = la.iter().zip(&lb).map(|(p, q)| (p - ma) * (q - mb)).sum::<f64>() / (T * T) as f64;
            let amp = (2.0 * cov_ab.max(0.0)).sqrt();
            let mean = 0.5 * (ma + mb);
            let contrast = if amp > 0.0 { amp / (mean.abs() + amp) } else { 0.0 };
            let (fa, fb) = (spectrum(&wa), spectrum(&wb));
            let cross: Vec<f64> = fa.iter().zip(&fb).map(|(p, q)| (p * q.conj()).re).collect();
            // Noise power from the difference of the two renders: E|F_a − F_b|² = 2 N.
            let noise: f64 = fa.iter().zip(&fb).map(|(p, q)| (p - q).norm_sqr()).sum::<f64>() / 2.0;
            let signal: f64 = cross.iter().sum::<f64>();
            let (variation, measured) = match band(&fa, &fb) {
                Some(b) => {
                    // The whole tile's spectra, the mean put back by linearity: G = F + m·Ŵ.
                    let whole = |f: &[Complex<f64>], m: f64| -> Vec<Complex<f64>> {
                        f.iter().zip(&wspec).map(|(v, wk)| v + wk * m).collect()
                    };
                    let (ga, gb) = (whole(&fa, ma), whole(&fb, mb));
                    let power = power_moment(&fa, &fb, b).map_or(0.0, |m| (2.0 * (m - own)).max(0.0).sqrt());
                    (power, amplitude_moment(&ga, &gb, b, own_amp).sqrt())
                }
                None => (0.0, 0.0),
            };
            let mut pred = 0.0;
            for y in 0..T {
                for x in 0..T {
                    let s = maps.pixels[(ty * T + y) * w + tx * T + x].sigma;
                    pred += s[0] + s[2];
                }
            }
            let predicted = (pred / (T * T) as f64 - 2.0 * px_window)
                .max(0.0)
                .sqrt()
                .min(NYQUIST_CAP);
            let detail =
                0.5 * (sa + sb) >= DETAIL * mean_l.max(1e-12) && signal > noise && variation > RESOLVED;
            tiles.push(TileCheck {
                tile: (tx, ty),
                predicted,
                measured,
                variation,
                contrast,
                detail,
            });
        }
    }
    let det: Vec<&TileCheck> = tiles.iter().filter(|t| t.detail).collect();
    let mut ratios: Vec<f64> = det
        .iter()
        .filter(|t| t.measured > 0.0)
        .map(|t| t.predicted / t.measured)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let median_ratio = if ratios.is_empty() {
        f64::NAN
    } else {
        ratios[ratios.len() / 2]
    };
    let pv: Vec<f64> = det.iter().map(|t| t.predicted).collect();
    let mv: Vec<f64> = det.iter().map(|t| t.measured).collect();
    let under = det.iter().filter(|t| t.predicted < 0.5 * t.measured).count();
    let varv: Vec<f64> = det.iter().map(|t| t.variation).collect();
    let cv: Vec<f64> = det.iter().map(|t| t.contrast).collect();
    Agreement {
        detail_tiles: det.len(),
        median_ratio,
        rank_correlation: spearman(&pv, &mv),
        variation_correlation: spearman(&pv, &varv),
        contrast_correlation: spearman(&cv, &mv),
        undersampled: if det.is_empty() {
            0.0
        } else {
            under as f64 / det.len() as f64
        },
        tiles,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// One tile's image from a function of the pixel centre, plus seeded white noise of
    /// std `noise`.
    fn tile_image(f: impl Fn(f64, f64) -> f64, noise: f64, seed: u64) -> Image {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut img = Image::new(T as u32, T as u32);
        for y in 0..T {
            for x in 0..T {
                let n = noise * (rng.random::<f64>() - 0.5) * 12f64.sqrt();
                img.pixels[y * T + x] = DVec3::splat(f(x as f64 + 0.5, y as f64 + 0.5) + n);
            }
        }
        img
    }

    fn flat_maps() -> CovMaps {
        CovMaps {
            width: T as u32,
            height: T as u32,
            pixels: vec![Default::default(); T * T],
            paths_per_block: 1,
            stride: 1,
            layout: 4,
        }
    }

    fn measure(f: impl Fn(f64, f64) -> f64 + Copy, noise: f64) -> TileCheck {
        let a = tile_image(f, noise, 1);
        let b = tile_image(f, noise, 2);
        compare(&a, &b, &flat_maps(), 0.5).tiles[0]
    }

    #[test]
    fn a_smooth_gradient_is_not_detail() {
        for t in [
            measure(|x, _| 1.0 + 0.05 * x, 0.0),
            measure(|x, y| 1.0 + 0.03 * x + 0.02 * y, 0.01),
            measure(|x, y| 1.0 + 0.002 * (x - 3.0).powi(2) + 0.001 * y * y, 0.0),
        ] {
            assert!(t.measured < RESOLVED, "{t:?}");
            assert!(!t.detail, "{t:?}");
        }
    }

    /// A cosine of frequency `f` has its power at `f`: the doubled power moment reads
    /// `√2·f` (the Gaussian convention), with or without independent noise.
    #[test]
    fn a_cosine_reads_at_its_frequency() {
        for (f, noise) in [(0.25, 0.0), (0.3, 0.05), (0.4, 0.02), (0.18, 0.05)] {
            let t = measure(|x, _| 1.0 + 0.2 * (2.0 * PI * f * x).cos(), noise);
            let want = 2f64.sqrt() * f;
            assert!((t.variation / want - 1.0).abs() < 0.12, "f {f}: {t:?}");
            assert!(t.detail);
        }
        // Nothing but noise: no significant ring, no bandwidth.
        let t = measure(|_, _| 1.0, 0.05);
        assert_eq!(t.variation, 0.0, "{t:?}");
        assert_eq!(t.measured, 0.0, "{t:?}");
    }

    /// In covtrace's convention a cosine `m + a·cos(2π f x)` has `Σxx = |a| f² / (|m| +
    /// |a|)`, what cov-occlusion's `Texture::from_moments` gives a texture of the same
    /// statistics: the measurement reads it, so render-check and the texture operator
    /// speak of the same quantity. Exact on a frequency bin without noise; with noise of 1%
    /// the root of the cross power moves it by up to 2%, and off a bin the window's leakage
    /// by up to 6%.
    #[test]
    fn a_cosine_reads_in_the_amplitude_convention() {
        for (m, a, f, noise, tol) in [
            (1.0, 0.2, 0.25, 0.0, 1e-9),
            (1.0, 1.0, 0.1875, 0.0, 1e-9),
            (0.5, 0.3, 0.3125, 0.0, 1e-9),
            (1.0, 0.2, 0.25, 0.01, 0.03),
            (0.5, 0.3, 0.3125, 0.01, 0.03),
            (1.0, 0.4, 0.3, 0.01, 0.08),
            (2.0, 0.5, 0.18, 0.01, 0.08),
        ] {
            let t = measure(|x, _| m + a * (2.0 * PI * f * x).cos(), noise);
            let k = 2.0 * PI * f;
            let texture =
                cov_occlusion::Texture::from_moments(m, m * m + a * a / 2.0, [a * a * k * k / 2.0, 0.0, 0.0])
                    .expect("a valid texture");
            let want = texture.spectrum()[0];
            assert!((want / (a * f * f / (m + a)) - 1.0).abs() < 1e-12);
            let got = t.measured * t.measured;
            assert!(
                (got / want - 1.0).abs() < tol,
                "m {m} a {a} f {f}: {got} vs {want}"
            );
            assert!((t.contrast / (a / (m + a)) - 1.0).abs() < 0.01, "{t:?}");
        }
    }

    /// The variation's power moment over its band.
    fn ring_moment(fa: &[Complex<f64>], fb: &[Complex<f64>]) -> Option<f64> {
        power_moment(fa, fb, band(fa, fb)?)
    }

    /// Spectra of a tile: `content` (the same in both) plus, in `fa` only, `extra`.
    fn spectra(
        content: &[(usize, usize, f64)],
        extra: &[(usize, usize, f64)],
    ) -> (Vec<Complex<f64>>, Vec<Complex<f64>>) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let mut noise = || Complex::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        let mut fa: Vec<Complex<f64>> = (0..T * T).map(|_| noise()).collect();
        let mut fb: Vec<Complex<f64>> = (0..T * T).map(|_| noise()).collect();
        for &(kx, ky, a) in content {
            fa[ky * T + kx] += a;
            fb[ky * T + kx] += a;
        }
        for &(kx, ky, a) in extra {
            fa[ky * T + kx] += a;
            fb[ky * T + kx] += a * 0.5;
        }
        (fa, fb)
    }

    #[test]
    fn an_isolated_significant_ring_is_noise() {
        let band = [(1, 0, 30.0), (0, 1, 30.0), (1, 1, 20.0), (2, 0, 10.0)];
        let (fa, fb) = spectra(&band, &[]);
        let clean = ring_moment(&fa, &fb).expect("content");
        // A heavy-tailed outlier correlated by chance in one ring at 0.6 cycles/px.
        let (fa, fb) = spectra(&band, &[(7, 6, 10.0)]);
        let with_outlier = ring_moment(&fa, &fb).expect("content");
        assert!(
            (with_outlier / clean - 1.0).abs() < 1e-9,
            "{clean} vs {with_outlier}"
        );
        // The same power next to the band extends it.
        let (fa, fb) = spectra(&band, &[(3, 0, 10.0), (4, 1, 10.0)]);
        assert!(ring_moment(&fa, &fb).expect("content") > 1.2 * clean);
    }

    #[test]
    fn a_band_without_low_frequencies_is_kept() {
        // A texture at 0.25–0.31 cycles/px: rings 2–3, nothing below.
        let (fa, fb) = spectra(&[(4, 0, 20.0), (0, 4, 20.0), (5, 0, 15.0), (4, 3, 10.0)], &[]);
        let m = ring_moment(&fa, &fb).expect("content");
        assert!(m > 0.0625 && m < 0.16, "{m}");
    }
}
