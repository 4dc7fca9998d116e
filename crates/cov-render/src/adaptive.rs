//! Adaptive sampling and reconstruction from the covariance maps: how many samples each
//! pixel takes and how wide its reconstruction filter is.
//!
//! The covariance pass predicts, per pixel, the image-space Σ of the image's content and
//! the samples per pixel it needs over pixel × lens × time ([`crate::covpass`]). This
//! module turns those predictions into decisions: [`allocate`] distributes a budget in
//! proportion to a density, [`Guide`] holds each pixel's matched Gaussian (the filter
//! whose spectrum matches the predicted content, [`filter_cov`]), and [`edge_clamp`] keeps
//! wide filters off the edges the pass saw; the `guard` module checks the filters against
//! the samples.

use std::ops::Range;
use std::time::Instant;

use crate::covpass::{CovMaps, PixelCov};
use crate::film::{Film, Gaussian};
use crate::metrics::REL_EPS;
use crate::trace::luminance;

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
/// Distributes `total` samples over pixels in proportion to `weights`, each pixel
/// getting between `lo` and `hi` ([`allocate_floors`] with the same floor everywhere).
pub fn allocate(weights: &[f64], total: f64, lo: u32, hi: u32) -> Vec<u32> {
    allocate_floors(weights, total, &vec![lo; weights.len()], hi, false)
}

/// Distributes `total` samples over pixels in proportion to `weights`, pixel `i` getting
/// between `floors[i]` and `hi` (water-filling: the clamped pixels' share goes to the
/// others). Non-finite or negative weights count as 0. With `pow2`, each count is
/// rounded to a power of two (unless a floor or `hi` is not one); the rounding carries the
/// difference along the pixels, so the counts sum to `total` within about one pixel's
/// count.
pub fn allocate_floors(weights: &[f64], total: f64, floors: &[u32], hi: u32, pow2: bool) -> Vec<u32> {
    let n = weights.len();
    let lo = |i: usize| f64::from(floors.get(i).copied().unwrap_or(0));
    let hi_f = f64::from(hi);
    let w: Vec<f64> = weights
        .iter()
        .map(|&v| if v.is_finite() && v > 0.0 { v } else { 0.0 })
        .collect();
    let least: f64 = (0..n).map(|i| lo(i).min(hi_f)).sum();
    let total = total.clamp(least, hi_f * n as f64);
    let sum = |scale: f64| -> f64 {
        w.iter()
            .enumerate()
            .map(|(i, &v)| (v * scale).clamp(lo(i).min(hi_f), hi_f))
            .sum()
    };
    let wsum: f64 = w.iter().sum();
    let mut counts = Vec::with_capacity(n);
    // Without weights, the floors and an equal share of the rest.
    let (scale, flat) = if wsum <= 0.0 {
        (0.0, (total - least) / n.max(1) as f64)
    } else {
        (scale_for(sum, total, wsum), 0.0)
    };
    let mut carry = 0.0;
    for (i, &v) in w.iter().enumerate() {
        let (l, top) = (lo(i).min(hi_f), hi_f);
        let x = if wsum <= 0.0 {
            l + flat
        } else {
            (v * scale).clamp(l, top)
        } + carry;
        // A power of two (the nearer in proportion; the difference is carried to the next
        // pixel): a prefix of a pixel's Sobol sequence is a (t, m, s)-net only at powers of
        // two, and a count in between can give a larger error than the power below it.
        let c = if pow2 && x >= 1.0 {
            let a = 2f64.powi(x.log2().floor() as i32);
            if x >= 1.5 * a { 2.0 * a } else { a }.clamp(l, top).floor()
        } else {
            x.floor().clamp(l, top)
        };
        carry = x - c;
        counts.push(c as u32);
    }
    counts
}

/// The scale `s` at which `sum(s) = Σ clamp(s·wᵢ, loᵢ, hi)`, continuous, nondecreasing
/// and piecewise linear, reaches `total` (from above: `sum(s) ≥ total`), given
/// `wsum = Σ wᵢ > 0` and `sum(0) ≤ total ≤ sum(∞)`.
///
/// The root is bracketed from `total / wsum` by steps of 16, then found by the Illinois
/// variant of false position, which a piecewise linear function lets converge in a few
/// steps (bisection took about 50 sums of every pixel). It stops when the sum is within
/// `10⁻⁹ · total` of `total` (0.016 samples on a budget of 16 samples for each of a
/// million pixels) or the bracket within 10⁻¹² of its size. A `total` above `sum(∞)`
/// (pixels of weight 0 stay at their floor) gives the largest scale tried, 10³⁰⁰, as the
/// bisection it replaces did.
fn scale_for(sum: impl Fn(f64) -> f64, total: f64, wsum: f64) -> f64 {
    const LOW: f64 = 1e-300;
    const HIGH: f64 = 1e300;
    let f = |s: f64| sum(s) - total;
    let s0 = (total / wsum).clamp(LOW, HIGH);
    let (mut a, mut b) = (s0, s0);
    let (mut fa, mut fb) = (f(a), f(b));
    // The bracket: f(a) < 0 ≤ f(b). `f` is nondecreasing, so where even the ends of the
    // walk would not close it (the floors alone reach the total, or every weighted pixel
    // at `hi` does not), the walk's answer is that end: one sum tells, instead of the
    // walk's 250 (`a_total_the_floors_reach_takes_few_sums`).
    if fa >= 0.0 && f(LOW) >= 0.0 {
        return LOW;
    }
    if fb < 0.0 && f(HIGH) < 0.0 {
        return HIGH;
    }
    while fa >= 0.0 {
        (b, fb) = (a, fa);
        a = (a / 16.0).max(LOW);
        fa = f(a);
    }
    while fb < 0.0 && b < HIGH {
        (a, fa) = (b, fb);
        b = (b * 16.0).min(HIGH);
        fb = f(b);
    }
    let tol = 1e-9 * total.abs().max(1.0);
    // `fa` and `fb` are the ends' values, one of them halved by the Illinois step; `at_b`
    // is f(b) itself.
    let (mut side, mut at_b) = (0, fb);
    for _ in 0..200 {
        if at_b <= tol || b - a <= 1e-12 * b {
            break;
        }
        // False position, kept strictly inside the bracket.
        let mut s = b - fb * (b - a) / (fb - fa);
        if !(s > a && s < b) {
            s = 0.5 * (a + b);
        }
        let fs = f(s);
        if fs >= 0.0 {
            (b, fb, at_b) = (s, fs, fs);
            // The same end twice: halve the other's value (Illinois), so that it moves.
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            (a, fa) = (s, fs);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    b
}

/// How many pixels' noise a normalised Gaussian filter of covariance `f` `[xx, xy, yy]`
/// (px²) averages: `1/Σw² = 4π √det f`, at least 1 (a filter narrower than a pixel
/// averages nothing).
pub fn filter_area(f: [f64; 3]) -> f64 {
    let det = f[0] * f[2] - f[1] * f[1];
    let a = 4.0 * std::f64::consts::PI * det.max(0.0).sqrt();
    if a.is_finite() { a.max(1.0) } else { 1.0 }
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

/// Side (px) of the tiles [`edge_clamp`] prunes with: the covariance grid's default block
/// (where its filters are one per block, a tile takes the clamp's closed form).
const CLAMP_TILE: i64 = 4;

/// Narrows every filter so that it does not reach, at [`EDGE_REACH`] of its own std, a
/// pixel whose filter is narrower than the distance to it over [`EDGE_REACH`]: a wide
/// filter stops short of an edge the covariance pass saw a few pixels away. Each std
/// becomes `min(s_p, min_q max(s_q, d(p, q) / EDGE_REACH))` over every pixel `q`.
///
/// The minimum is taken over tiles of 4×4 pixels first. Each tile lists, nearest first,
/// the tiles that could lower the limit of one of its pixels (their smallest std below
/// its largest, within `EDGE_REACH` times that); a pixel walks its tile's list until the
/// next tile is too far to matter, skips a tile whose smallest std and nearest pixel
/// cannot lower its limit, and takes a tile of one std as `max(s, d_nearest /
/// EDGE_REACH)` without visiting its pixels. All of it gives the per-pixel minimum bit
/// for bit (`max` and `min` are exact, and the distances are the same square roots of
/// integers): the unit test `edge_clamp_is_its_definition` checks it against the
/// definition.
///
/// Only the pixels of `rows` are narrowed (a part of a render, the `parts` module); the
/// others keep their raw filter.
pub fn edge_clamp(width: u32, height: u32, raw: &[Gaussian], rows: Range<u32>) -> Vec<Gaussian> {
    use rayon::prelude::*;
    let (w, h) = (i64::from(width), i64::from(height));
    let t = CLAMP_TILE;
    let stds: Vec<f64> = raw.iter().map(Gaussian::std_max).collect();
    // Per tile: the least and the greatest std of its pixels.
    let tw = (w + t - 1) / t;
    let th = (h + t - 1) / t;
    let span = move |k: i64, n: i64| (k * t, (k * t + t).min(n) - 1);
    let tiles: Vec<(f64, f64)> = (0..tw * th)
        .map(|k| {
            let ((x0, x1), (y0, y1)) = (span(k % tw, w), span(k / tw, h));
            (y0..=y1)
                .flat_map(|y| (x0..=x1).map(move |x| (y * w + x) as usize))
                .map(|j| stds[j])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                    (lo.min(s), hi.max(s))
                })
        })
        .collect();
    let (r0, r1) = (i64::from(rows.start) * w, i64::from(rows.end.min(height)) * w);
    // Per tile, the tiles that may lower the limit of one of its pixels, nearest first
    // (with the square of the gap between the two): a tile whose least std is at least
    // the widest here, or farther than EDGE_REACH times it, cannot (the pixel's own std
    // is the limit it starts from). The pixels of a tile share the list.
    let lists: Vec<Vec<(i64, usize)>> = (0..tw * th)
        .into_par_iter()
        .map(|k| {
            let (_, hi) = tiles[k as usize];
            let ((x0, x1), (y0, y1)) = (span(k % tw, w), span(k / tw, h));
            let r = (EDGE_REACH * hi).ceil() as i64;
            if r < 1 || y1 * w + x1 < r0 || y0 * w + x0 >= r1 {
                return Vec::new();
            }
            // Beyond this squared gap (px²) a tile is farther than EDGE_REACH · hi, with a
            // margin of one part in 10⁹ over the rounding of the comparison.
            let far = (EDGE_REACH * hi).powi(2) * (1.0 + 1e-9);
            let mut list = Vec::new();
            for ty in (y0 - r).max(0) / t..=(y1 + r).min(h - 1) / t {
                for tx in (x0 - r).max(0) / t..=(x1 + r).min(w - 1) / t {
                    let u = ty * tw + tx;
                    let ((u0, u1), (v0, v1)) = (span(tx, w), span(ty, h));
                    let (gx, gy) = ((u0 - x1).max(x0 - u1).max(0), (v0 - y1).max(y0 - v1).max(0));
                    let gap = gx * gx + gy * gy;
                    if tiles[u as usize].0 < hi && (gap as f64) <= far {
                        list.push((gap, u as usize));
                    }
                }
            }
            list.sort_unstable();
            list
        })
        .collect();
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let g = raw[i as usize];
            let s = stds[i as usize];
            if i < r0 || i >= r1 {
                return g;
            }
            let (x, y) = (i % w, i / w);
            let dist = |dx: i64, dy: i64| ((dx * dx + dy * dy) as f64).sqrt();
            let mut limit = s;
            for &(gap, u) in &lists[((y / t) * tw + x / t) as usize] {
                // The pixel is at least the gap away from every cell of `u`, and the
                // tiles come nearest first: none after this one can lower the limit.
                if (gap as f64).sqrt() / EDGE_REACH >= limit {
                    break;
                }
                let (tx, ty) = (u as i64 % tw, u as i64 / tw);
                let ((x0, x1), (y0, y1)) = (span(tx, w), span(ty, h));
                let (lo, hi) = tiles[u];
                let near = dist((x0 - x).max(x - x1).max(0), (y0 - y).max(y - y1).max(0));
                let bound = lo.max(near / EDGE_REACH);
                if bound >= limit {
                    continue;
                }
                if lo == hi {
                    limit = bound;
                    continue;
                }
                for yy in y0..=y1 {
                    for xx in x0..=x1 {
                        let sq = stds[(yy * w + xx) as usize];
                        limit = limit.min(sq.max(dist(xx - x, yy - y) / EDGE_REACH));
                    }
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

/// The covariance pass's products a method uses: sample weights and matched filters.
#[derive(Clone, Debug)]
pub struct Guide {
    /// Width of the image (px).
    pub width: u32,
    /// Height of the image (px).
    pub height: u32,
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
            width: maps.width,
            height: maps.height,
            density: maps.pixels.iter().map(|p| p.spp).collect(),
            matched,
            secs: pass_secs + t.elapsed().as_secs_f64(),
        }
    }
}

/// Per pixel of `rows` (0 elsewhere), the relative standard deviation of a sample,
/// `√(σ² / (μ² + ε))`, blurred over 3×3 pixels (a pilot's variances are noisy).
pub(crate) fn relative_variance(film: &Film, rows: Range<u32>) -> Vec<f64> {
    use rayon::prelude::*;
    let (w, h) = (film.width as i64, film.height as i64);
    let var = film.variance();
    let box_img = film.box_image();
    let raw: Vec<f64> = var
        .par_iter()
        .zip(&box_img.pixels)
        .map(|(&v, p)| {
            let m = luminance(*p);
            (v / (m * m + REL_EPS)).sqrt()
        })
        .collect();
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            if !rows.contains(&((i / w) as u32)) {
                return 0.0;
            }
            let (s, k) = around(w, h, i, 1).fold((0.0, 0.0), |(s, k), (j, _)| (s + raw[j], k + 1.0));
            s / k
        })
        .collect()
}

/// Per pixel, whether it or one of its 3×3 neighbours has a sample that saw a light
/// directly: the neighbourhood over which [`relative_variance`] blurs the pilot's
/// variance (a light's edge swept by motion reaches pixels whose few pilot samples all
/// missed it).
pub(crate) fn sees_light(film: &Film) -> Vec<bool> {
    use rayon::prelude::*;
    let (w, h) = (film.width as i64, film.height as i64);
    (0..w * h)
        .into_par_iter()
        .map(|i| around(w, h, i, 1).any(|(j, _)| film.emitted[j].max_element() > 0.0))
        .collect()
}

/// The image's own content: the sensor's image-space Σ `[xx, xy, yy]` less the pixel
/// filter's window (`1/(4π² f²)` per axis for a filter of std `f` px, which the sensor adds
/// because it describes the integrand a pixel's samples see), clamped to PSD. Reconstruction
/// filters are made from this: the sensor's Σ would never allow a filter wider than the
/// pixel filter itself.
pub fn content(s: [f64; 3], pixel_filter: f64) -> [f64; 3] {
    let w = 1.0 / (cov_core::FOUR_PI_SQ * pixel_filter * pixel_filter);
    let (a, b, c) = ((s[0] - w).max(0.0), s[1], (s[2] - w).max(0.0));
    let lim = (a * c).sqrt();
    [a, b.clamp(-lim, lim), c]
}

/// The reconstruction filter of an image-space Σ `[xx, xy, yy]` (cycles/px)²: the
/// sensor's rule (`CovBlock::reconstruction_filter`: the Gaussian whose spectrum matches,
/// clamped at `max_filter` px where Σ is small or singular). `None` for a Σ the rule
/// rejects (not finite).
pub fn image_filter(s: [f64; 3], max_filter: f64) -> Option<cov_core::Filter> {
    let mut c = cov_core::Cov::<2>::zeros();
    c.set(0, 0, s[0]);
    c.set(0, 1, s[1]);
    c.set(1, 1, s[2]);
    c.block().reconstruction_filter(&[max_filter; 2]).ok()
}

/// The reconstruction filter's larger std (px) for an image-space Σ ([`image_filter`]).
pub fn filter_std(s: [f64; 3], max_filter: f64) -> f64 {
    image_filter(s, max_filter).map_or(max_filter, |f| {
        f.extents.iter().fold(0.0, |m: f64, v| m.max(*v)).min(max_filter)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clamp is the definition taken over every pixel of the image: each filter's
    /// std becomes min(its std, min over pixels q of max(std_q, d(p, q) / EDGE_REACH)),
    /// bit for bit, on fields of random stds, steps, isolated narrow pixels, and blocks of
    /// one filter each (aligned with the clamp's 4×4 tiles, as the covariance grid's are,
    /// and not).
    #[test]
    fn edge_clamp_is_its_definition() {
        let (w, h) = (37u32, 29u32);
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut rnd = move || rng.random::<f64>();
        let blocks: Vec<f64> = (0..w * h).map(|_| 0.3 + 9.0 * rnd() * rnd()).collect();
        for field in 0..8 {
            let raw: Vec<Gaussian> = (0..w * h)
                .map(|i| {
                    let (x, y) = (i % w, i / w);
                    let s = match field {
                        0 => 8.0,
                        1 => 0.3 + 9.0 * rnd(),
                        2 => {
                            if x < 20 {
                                8.0
                            } else {
                                1.0
                            }
                        }
                        3 => {
                            if (x / 4 + y / 4) % 3 == 0 {
                                0.5 + rnd()
                            } else {
                                16.0
                            }
                        }
                        4 => {
                            if rnd() < 0.01 {
                                0.3
                            } else {
                                12.0
                            }
                        }
                        5 => 2.0 + 6.0 * f64::from(x / 4 % 2),
                        6 => blocks[(y / 4 * w + x / 4) as usize],
                        _ => blocks[(y / 5 * w + x / 3) as usize],
                    };
                    // Blocks of one filter each, as the covariance grid's are: the clamp's
                    // tiles of one std (its closed form) among them.
                    if field >= 6 {
                        return Gaussian::from_cov([s * s, 0.2 * s * s, 0.6 * s * s]);
                    }
                    Gaussian::from_cov([s * s, 0.3 * s * s * rnd(), s * s * (0.5 + 0.5 * rnd())])
                })
                .collect();
            let got = edge_clamp(w, h, &raw, 0..h);
            for p in 0..(w * h) as i64 {
                let g = raw[p as usize];
                let mut limit = g.std_max();
                for q in 0..(w * h) as i64 {
                    let dx = (p % i64::from(w) - q % i64::from(w)) as f64;
                    let dy = (p / i64::from(w) - q / i64::from(w)) as f64;
                    let d = (dx * dx + dy * dy).sqrt();
                    limit = limit.min(raw[q as usize].std_max().max(d / EDGE_REACH));
                }
                let want = if limit < g.std_max() {
                    let k = (limit / g.std_max()).powi(2);
                    let c = g.cov();
                    Gaussian::from_cov([c[0] * k, c[1] * k, c[2] * k])
                } else {
                    g
                };
                assert_eq!(got[p as usize], want, "field {field}, pixel {p}");
            }
            // Rows outside the given range keep their raw filters.
            let part = edge_clamp(w, h, &raw, 10..20);
            for p in 0..(w * h) as usize {
                let inside = (10..20).contains(&(p as u32 / w));
                assert_eq!(
                    part[p],
                    if inside { got[p] } else { raw[p] },
                    "field {field}, pixel {p}"
                );
            }
        }
    }

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
        // Powers of two, per-pixel floors, the total kept within a pixel's count.
        let w: Vec<f64> = (0..64).map(|i| 1.0 + f64::from(i % 7)).collect();
        let mut floors = vec![4; 64];
        floors[0] = 16;
        let c = allocate_floors(&w, 64.0 * 16.0, &floors, 256, true);
        assert!(c.iter().all(|&v| v.is_power_of_two() && v >= 4), "{c:?}");
        assert!(c[0] >= 16);
        let sum: u32 = c.iter().sum();
        assert!(sum.abs_diff(1024) <= 64, "{sum}");
    }

    /// The water level is the root of Σ clamp(s·wᵢ, loᵢ, hi) = total, reached from above,
    /// against bisection, on weights spread over twelve decades with zeros among them,
    /// random floors, and totals from the floors' sum to the most the weights can reach.
    #[test]
    fn the_scale_is_the_root() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for case in 0..40 {
            let n = 1 + case * 37;
            let w: Vec<f64> = (0..n)
                .map(|_| {
                    if rng.random::<f64>() < 0.1 {
                        0.0
                    } else {
                        10f64.powf(12.0 * rng.random::<f64>() - 6.0)
                    }
                })
                .collect();
            let lo: Vec<f64> = (0..n).map(|_| f64::from(rng.random_range(0..8u32))).collect();
            let hi = 64.0;
            let sum = |s: f64| -> f64 { w.iter().zip(&lo).map(|(&v, &l)| (v * s).clamp(l, hi)).sum() };
            let wsum: f64 = w.iter().sum();
            // Pixels of weight 0 stay at their floor: the most is the sum at an infinite scale.
            let (least, most) = (lo.iter().sum::<f64>(), sum(1e300));
            for t in [0.0, 1e-6, 0.3, 0.5, 0.9, 1.0] {
                let total = least + t * (most - least);
                let s = scale_for(sum, total, wsum);
                let got = sum(s);
                assert!(
                    got >= total - 1e-9 * total.max(1.0),
                    "case {case}, t {t}: {got} < {total}"
                );
                // Bisection's answer, from above.
                let (mut a, mut b) = (1e-300f64, 1e300f64);
                for _ in 0..400 {
                    let m = (a * b).sqrt();
                    if sum(m) < total { a = m } else { b = m }
                }
                assert!(
                    (got - sum(b)).abs() <= 1e-8 * total.max(1.0),
                    "case {case}, t {t}: {got} vs {}",
                    sum(b)
                );
            }
        }
    }
    #[test]
    fn a_total_the_floors_reach_takes_few_sums() {
        use std::cell::Cell;
        // A uniform first pass of 1 spp: every floor is 1 and the total is their sum. The
        // walk down from `total / wsum` used to sum every pixel about 250 times (16 a step
        // down to 10⁻³⁰⁰); a total beyond every weighted pixel at `hi` walked up as far.
        let n = 1000;
        let w: Vec<f64> = (0..n)
            .map(|i| if i % 10 == 0 { 1.0 + i as f64 } else { 0.0 })
            .collect();
        let (lo, hi) = (1.0, 8.0);
        let calls = Cell::new(0u32);
        let sum = |s: f64| -> f64 {
            calls.set(calls.get() + 1);
            w.iter().map(|&v| (v * s).clamp(lo, hi)).sum()
        };
        let wsum: f64 = w.iter().sum();
        let least = lo * n as f64;
        let most = sum(1e300);
        for (total, want) in [(least, 1e-300), (most + 1.0, 1e300)] {
            calls.set(0);
            assert_eq!(scale_for(sum, total, wsum), want, "total {total}");
            assert!(calls.get() <= 3, "total {total}: {} sums", calls.get());
        }
        // The counts: the floors exactly, and every weighted pixel at `hi`.
        let floors = vec![1u32; n];
        assert_eq!(allocate_floors(&w, least, &floors, 8, false), floors);
        let top = allocate_floors(&w, 10.0 * least, &floors, 8, false);
        for (c, v) in top.iter().zip(&w) {
            assert_eq!(*c, if *v > 0.0 { 8 } else { 1 });
        }
    }
}
