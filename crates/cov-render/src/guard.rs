//! The guard: the samples check the covariance pass's prediction, pixel by pixel.
//!
//! A filter chosen from Σ alone is only as good as what the pass models: where it is blind
//! (a texture it does not know, an inter-reflection it does not follow) the filter blurs
//! real detail, and more samples do not remove that bias. The guard reconstructs the image
//! with a family of filters, the matched filter `F₀` of every pixel scaled by each of
//! [`SCALES`] (then kept off the edges the pass saw, [`crate::adaptive::edge_clamp`]), and
//! the box; each pixel takes the candidate whose error, estimated from the samples
//! themselves, is smallest.
//!
//! **The error estimate: leave-one-out cross-validation across pixels.** Each pixel's
//! samples come from its own scrambled sequence, so different pixels' means `xⱼ` are
//! independent. A candidate's estimate at pixel `p` mixes the pixel's own mean with the
//! others': `ŷ = α x_p + (1 − α) ŷ₋ₚ`, where `α` is the share of `p`'s own samples in the
//! filter's weight and `ŷ₋ₚ` the estimate without them. With `σ²` the variance of `x_p`,
//!
//! ```text
//! E[(ŷ₋ₚ − x_p)²] = E[(ŷ₋ₚ − μ)²] + σ²        (independence)
//! MSE(ŷ) = α² σ² + (1 − α)² E[(ŷ₋ₚ − μ)²]
//!        ≈ α² σ² + (1 − α)² max((ŷ₋ₚ − x_p)² − σ², 0)
//! MSE(box) = σ²
//! ```
//!
//! The first line is what makes the check work: a filter that blurs detail the pass did
//! not see predicts `x_p` badly from the neighbours, whatever Σ said.
//!
//! **Which `σ²`.** In the box's error, `σ²` is the sample variance of the pixel's
//! luminance over its count, Monte Carlo's `s²/n`. It overstates the variance of a
//! quasi-Monte Carlo mean, which makes the box look worse than it is, so the guard leans
//! towards filtering where it cannot tell. The box is the fall-back whose error rests on
//! that one pixel's samples; where they missed a rare bright path (a caustic's
//! fireflies), a smaller reading would keep the box exactly where it errs most (measured:
//! reading the box's error as below raised `cov`'s error by up to 26%). Inside a filter's
//! estimate, both `σ²` (its own share, `α² σ²`, and the noise taken off the residual)
//! are the estimate that sees the net's convergence ([`Film::variance_of_mean`]). They
//! are the variance of the same mean: an overstated noise taken off the residual would
//! hide the bias of a filter that blurs a faint texture (a felt directly lit, whose pixel
//! means err 20 times less at 16 samples than at 4), and an overstated own share makes a
//! narrow filter, which keeps the texture, look worse than a wide one that blurs it (the
//! unit test `a_converged_texture_is_not_blurred`). The narrowest candidate, which only
//! stands in for the box ([`PILOT_SCALES`]), is judged on the box's terms, `s²/n`:
//! judged as the others are, it took the box's place on the edges of a checker the pass
//! was blind to, at 1.12× uniform sampling's error (`the_guard_protects_a_blind_pass`;
//! 1.03× as it is, 0.99× before the own share was read as the net's convergence).
//!
//! A pixel with a single sample has no sample variance; it takes its neighbourhood's
//! noise (the least, over four directions, of the neighbouring pixels' squared
//! differences; see `one_sample_variance`). The estimates are relative (divided by the
//! squared 3×3 mean luminance plus [`crate::metrics::REL_EPS`], the error the benchmarks
//! report) and averaged over 3×3 pixels before each pixel picks the smallest: one pixel's
//! squared residual is too noisy to decide alone (Stein's unbiased risk estimate, tried
//! for the same choice, needs the variance of the estimate itself, which is as noisy).
//!
//! Its cost, one splat per candidate and 3×3 sums, counts in the reconstruction time.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

use crate::adaptive::{Guide, edge_clamp};
use crate::film::{Film, Gaussian};
use crate::metrics::REL_EPS;
use crate::trace::luminance;

/// The candidates' scales of each pixel's matched filter covariance `F₀` (a scale of 4
/// doubles the std; 1/16 quarters it), widest first; the box is the last candidate.
pub const SCALES: [f64; 4] = [1.0, 0.25, 0.0625, 0.015625];

/// How many of [`SCALES`] (the widest) compete for every pixel.
///
/// The narrowest, `F₀/64` (std at most 1 px), only stands in for the box. The
/// reconstruction ([`guarded`]) takes it where the box would win and its estimated error
/// is lower still: the last step before the box where the guard rejects the wider
/// filters. Where a wider filter wins, it would be one more noisy estimate to win by
/// chance (measured: competing with them, it raised glossy's error by 3–6% from 16 spp
/// up). It needs a pixel of two samples or more: with one, the box's error is read off
/// the neighbourhood, and a fine checker the pass was blind to then lost to the stand-in
/// (1.84× uniform sampling's error at 1 spp in `the_guard_protects_a_blind_pass`, against
/// 1.10× without it). A pilot's choice ([`chosen_filters`]) does not consider it: the
/// allocation would take it for a filter, and the pixel would lose the floor of samples
/// that a pixel choosing the box keeps.
pub const PILOT_SCALES: usize = 3;

/// What the guard chose, per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Guarded {
    /// The reflected radiance reconstructed with each pixel's chosen candidate (the box
    /// mean for the box).
    pub reflected: Vec<DVec3>,
    /// The filter each pixel chose (`None`: the box).
    pub filters: Vec<Option<Gaussian>>,
}

/// The per-pixel filters of every candidate but the box, in the order of [`SCALES`]
/// ([`candidate`]). They depend on the guide alone, so a render makes them once.
/// Only the pixels of `rows` are kept off the edges ([`edge_clamp`]).
pub fn candidates(guide: &Guide, rows: Range<u32>) -> Vec<Vec<Gaussian>> {
    SCALES
        .par_iter()
        .map(|&s| candidate(guide, s, rows.clone()))
        .collect()
}

/// The per-pixel filters of candidate `scale`: `scale · F₀`, kept off the pass's edges
/// in `rows`.
pub fn candidate(guide: &Guide, scale: f64, rows: Range<u32>) -> Vec<Gaussian> {
    // A block of the covariance grid shares one matched filter: a pixel equal to its left
    // neighbour reuses its Gaussian.
    let mut last: Option<([f64; 3], Gaussian)> = None;
    let raw: Vec<Gaussian> = guide
        .matched
        .iter()
        .map(|f| match last {
            Some((q, g)) if q == *f => g,
            _ => {
                let g = Gaussian::from_cov(f.map(|v| v * scale));
                last = Some((*f, g));
                g
            }
        })
        .collect();
    edge_clamp(guide.width, guide.height, &raw, rows)
}

/// Reconstructs `film`'s reflected light with the guard (module docs).
///
/// `candidates` are [`candidates`] of the film's guide (the first [`SCALES`]`.len()` of
/// them are read); with more than [`PILOT_SCALES`] of them, the last only stands in for
/// the box. Only the pixels of `rows` are
/// estimated and chosen (a part of a render, the `parts` module); the others take the box.
pub fn guarded(candidates: &[Vec<Gaussian>], film: &Film, rows: Range<u32>) -> Guarded {
    let candidates = &candidates[..candidates.len().min(SCALES.len())];
    let sums: Vec<Vec<(DVec3, f64)>> = candidates.iter().map(|f| film.splat_each(f)).collect();
    let lum: Vec<Vec<[f64; 2]>> = sums
        .iter()
        .map(|acc| acc.par_iter().map(|&(s, n)| [luminance(s), n]).collect())
        .collect();
    let choice = choose(
        &lum,
        candidates,
        film,
        0.0,
        &rows,
        candidates.len() > PILOT_SCALES,
    );
    let reflected = (0..film.count.len())
        .into_par_iter()
        .map(|p| match sums.get(choice[p] as usize) {
            Some(acc) if acc[p].1 > 0.0 => acc[p].0 / acc[p].1,
            _ => match film.count[p] {
                0 => DVec3::ZERO,
                c => film.reflected[p] / f64::from(c),
            },
        })
        .collect();
    Guarded {
        reflected,
        filters: filters_of(&choice, candidates),
    }
}

/// The filters the guard would choose at `target` samples per pixel, from a film with
/// fewer (a pilot deciding where the rest of the budget goes): the variance terms shrink
/// to `n/target` of the pilot's, while all of the cross-validation residual above the
/// noise is taken for bias, which more samples do not remove (the conservative reading: a
/// pilot's noise must not hide detail the full budget will show). Only the widest
/// [`PILOT_SCALES`] candidates are considered, and only luminance is splatted, which is
/// all the choice reads. `None`: the box.
pub fn chosen_filters(
    candidates: &[Vec<Gaussian>],
    film: &Film,
    target: f64,
    rows: Range<u32>,
) -> Vec<Option<Gaussian>> {
    let candidates = &candidates[..PILOT_SCALES.min(candidates.len())];
    let lum: Vec<Vec<[f64; 2]>> = candidates
        .iter()
        .map(|f| film.splat_values_each(f, |i| [luminance(film.reflected[i]), f64::from(film.count[i])]))
        .collect();
    filters_of(&choose(&lum, candidates, film, target, &rows, false), candidates)
}

/// Each pixel's chosen filter (`None`: the box).
fn filters_of(choice: &[u8], candidates: &[Vec<Gaussian>]) -> Vec<Option<Gaussian>> {
    (0..choice.len())
        .map(|p| candidates.get(choice[p] as usize).map(|f| f[p]))
        .collect()
}

/// Per pixel, the index of the candidate of least estimated error (module docs;
/// `candidates.len()`: the box), given each candidate's splatted luminance and weight
/// (`lum`), at `target` samples per pixel (0: the film's own counts). With
/// `stand_in`, the last candidate only stands in for the box ([`PILOT_SCALES`]).
fn choose(
    lum: &[Vec<[f64; 2]>],
    candidates: &[Vec<Gaussian>],
    film: &Film,
    target: f64,
    rows: &Range<u32>,
    stand_in: bool,
) -> Vec<u8> {
    let (w, h) = (film.width as i64, film.height as i64);
    let inside = |p: usize| rows.contains(&((p as i64 / w.max(1)) as u32));
    let n = film.count.len();
    let own = film.variance();
    let var = one_sample_variance(film, &own);
    // The noise that the cross-validation residual carries, taken off it to leave the
    // filter's bias: the estimate that sees the net's convergence, so that Monte
    // Carlo's overstated noise does not hide a bias (module docs).
    let of_mean = film.variance_of_mean_from(&own);
    // Per pixel, in one pass: [PX_MEAN] the mean luminance; [PX_NOISE] the noise taken
    // off the residual (Monte Carlo's `s²/n` where one sample gives no split);
    // [PX_MC_AT] the variance of the pixel's mean in the box's error, Monte Carlo's
    // `s²/n` (an upper bound for a scrambled net's mean), and [PX_NOISE_AT] the noise, at
    // the target count: `n/target` of the film's (the second in a filter's own share of
    // its estimate, `α² σ²`, read as the noise is: module docs).
    let px: Vec<[f64; 4]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let count = film.count[i];
            let mean = match count {
                0 => 0.0,
                c => luminance(film.reflected[i] / f64::from(c)),
            };
            let c = f64::from(count.max(1));
            let s2 = var[i] / c;
            let noise = if count >= 2 { of_mean[i] } else { s2 };
            let at_target = c / target.max(c);
            [mean, noise, s2 * at_target, noise * at_target]
        })
        .collect();
    // The normaliser of the relative error: the squared 3×3 mean luminance.
    let norm: Vec<f64> = box3(w, h, rows, |j| [px[j][PX_MEAN]])
        .par_iter()
        .map(|[m]| m * m + REL_EPS)
        .collect();
    // Each candidate's estimated relative error per pixel, the box's last (at
    // `candidates.len()`), before the 3×3 mean.
    let boxed = candidates.len();
    let raw: Vec<[f64; MAX_CHOICES]> = (0..n)
        .into_par_iter()
        .map(|p| {
            let mut r = [0.0; MAX_CHOICES];
            let c = f64::from(film.count[p]);
            for (k, (filters, acc)) in candidates.iter().zip(lum).enumerate() {
                // The stand-in for the box is judged on the box's terms.
                let own_target = if stand_in && k + 1 == boxed {
                    px[p][PX_MC_AT]
                } else {
                    px[p][PX_NOISE_AT]
                };
                let [sum, wsum] = acc[p];
                r[k] = if c == 0.0 || wsum <= 0.0 || !inside(p) {
                    f64::INFINITY
                } else {
                    let own = filters[p].peak();
                    let (loo_w, alpha) = (wsum - own * c, (own * c / wsum).clamp(0.0, 1.0));
                    // Below this share the others carry no weight: nothing to cross-validate.
                    if loo_w <= 1e-9 * wsum {
                        own_target / norm[p]
                    } else {
                        let loo = (sum - luminance(film.reflected[p]) * own) / loo_w;
                        let cv = (loo - px[p][PX_MEAN]).powi(2);
                        (alpha * alpha * own_target + (1.0 - alpha).powi(2) * (cv - px[p][PX_NOISE]).max(0.0))
                            / norm[p]
                    }
                };
            }
            r[boxed] = px[p][PX_MC_AT] / norm[p];
            r
        })
        .collect();
    let risks = box3(w, h, rows, |j| raw[j]);
    (0..n)
        .into_par_iter()
        .map(|p| {
            let risk = &risks[p];
            let free = boxed - usize::from(stand_in);
            let mut best = boxed;
            for k in (0..free).filter(|_| inside(p)) {
                if risk[k] < risk[best] {
                    best = k;
                }
            }
            // With one sample the box's error is its neighbourhood's noise, which a
            // texture the pass is blind to inflates (`one_sample_variance`): the box stays.
            let own_variance = film.count[p] >= 2;
            if best == boxed && free < boxed && own_variance && inside(p) && risk[free] < risk[boxed] {
                best = free;
            }
            best as u8
        })
        .collect()
}

/// The columns of `choose`'s per-pixel quantities.
const PX_MEAN: usize = 0;
/// See [`PX_MEAN`].
const PX_NOISE: usize = 1;
/// See [`PX_MEAN`].
const PX_MC_AT: usize = 2;
/// See [`PX_MEAN`].
const PX_NOISE_AT: usize = 3;
/// The most candidates a pixel chooses among: every scale and the box.
const MAX_CHOICES: usize = SCALES.len() + 1;

/// The reach (px) of [`one_sample_variance`]'s differences: a 3×3 neighbourhood.
const ONE_SAMPLE_REACH: i64 = 1;
/// The expectation of [`one_sample_variance`]'s least directional estimate over the
/// variance, for independent Gaussian noise (the least of four noisy estimates is low):
/// measured on 65,536 pixels of it by the unit test
/// `one_sample_variance_reads_noise_not_edges` (uniform noise reads 0.505). The estimate is divided by it, so that flat noise reads as
/// its variance, as a pixel's own sample variance does.
const LEAST_OF_FOUR: f64 = 0.535;

/// The variance of one sample of each pixel's luminance: the pixel's own sample variance,
/// from two samples on.
///
/// A pixel with one sample (a budget of 1 spp) has no variance of its own; 0 would make
/// the box look exact everywhere, and the guard a costly box. It takes the noise of its
/// neighbourhood instead: independent noise makes neighbouring means (of the samples'
/// luminance, as the pixel's own variance reads) differ alike in every direction,
/// `E[(x_a − x_b)²] = σ² (1/n_a + 1/n_b)` where the image is flat, while an edge or a
/// texture adds its variation to the directions that cross it. So, per direction (rows,
/// columns and the two diagonals), the mean of `(x_a − x_b)² / (1/n_a + 1/n_b)` over
/// neighbouring pixels within [`ONE_SAMPLE_REACH`] of the pixel, and the least of the
/// four (along an edge, the direction that does not cross it), over [`LEAST_OF_FOUR`].
/// Measured against the alternatives (docs/render-bench.md): the sample variance of the
/// 3×3 means counts a texture the pass did not see as noise and blurs it (2.4× uniform
/// sampling's error on a blind checker at 1 spp, against 1.1× with this), and the median
/// absolute deviation misses the heavy tail of path-traced noise.
fn one_sample_variance(film: &Film, own: &[f64]) -> Vec<f64> {
    const R: i64 = ONE_SAMPLE_REACH;
    let (w, h) = (film.width as i64, film.height as i64);
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            if film.count[i as usize] != 1 {
                return own[i as usize];
            }
            let (x, y) = (i % w, i / w);
            // A neighbour's mean luminance (the same samples' luminance as `own`'s) and
            // the inverse of its count: two means of `a` and `b` samples differ by
            // `σ² (1/a + 1/b)` in expectation where the image is flat.
            let at = |xx: i64, yy: i64| {
                let j = (yy * w + xx) as usize;
                let inside = xx >= 0 && yy >= 0 && xx < w && yy < h;
                (inside && film.count[j] > 0).then(|| {
                    let n = f64::from(film.count[j]);
                    (film.lum[j][0] / n, 1.0 / n)
                })
            };
            let mut best = f64::INFINITY;
            for (dx, dy) in [(1, 0), (0, 1), (1, 1), (1, -1)] {
                let (mut sum, mut k) = (0.0, 0.0);
                for yy in y - R..=y + R {
                    for xx in x - R..=x + R {
                        let (qx, qy) = (xx + dx, yy + dy);
                        if (qx - x).abs() > R || (qy - y).abs() > R {
                            continue;
                        }
                        if let (Some((a, ia)), Some((b, ib))) = (at(xx, yy), at(qx, qy)) {
                            sum += (a - b).powi(2) / (ia + ib);
                            k += 1.0;
                        }
                    }
                }
                if k >= 2.0 {
                    best = best.min(sum / k);
                }
            }
            // No two neighbours with samples (an image of one pixel): nothing to tell.
            if best.is_finite() {
                best / LEAST_OF_FOUR
            } else {
                0.0
            }
        })
        .collect()
}

/// The 3×3 mean of `v(j)` in `rows`, each of its `K` values on its own (fewer pixels at
/// the borders; an infinite value stays infinite); 0 outside `rows`.
fn box3<const K: usize>(
    w: i64,
    h: i64,
    rows: &Range<u32>,
    v: impl Fn(usize) -> [f64; K] + Sync,
) -> Vec<[f64; K]> {
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if !rows.contains(&(y as u32)) {
                return [0.0; K];
            }
            let (mut s, mut k) = ([0.0; K], 0.0);
            for yy in (y - 1).max(0)..=(y + 1).min(h - 1) {
                for xx in (x - 1).max(0)..=(x + 1).min(w - 1) {
                    let vj = v((yy * w + xx) as usize);
                    for c in 0..K {
                        s[c] += vj[c];
                    }
                    k += 1.0;
                }
            }
            s.map(|sc| sc / k)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A standard normal number (Box–Muller).
    fn normal(rng: &mut impl rand::Rng) -> f64 {
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// A film of one sample per pixel whose luminance is `f(x, y)` (grey radiance; the
    /// luminance of grey `v` is `v`).
    fn one_sample(w: u32, h: u32, f: impl Fn(u32, u32) -> f64) -> Film {
        let mut film = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let v = f(x, y);
                film.count[i] = 1;
                film.reflected[i] = DVec3::splat(v);
                film.lum[i] = [v, v * v];
            }
        }
        film
    }

    /// A film of `n` samples per pixel whose luminances are `samples(x, y)` (grey
    /// radiance), with the second half's sum for the split estimate.
    fn film_of(w: u32, h: u32, n: u32, mut samples: impl FnMut(u32, u32) -> Vec<f64>) -> Film {
        let mut film = Film::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let v = samples(x, y);
                assert_eq!(v.len(), n as usize);
                let s: f64 = v.iter().sum();
                film.count[i] = n;
                film.reflected[i] = DVec3::splat(s);
                film.lum[i] = [s, v.iter().map(|a| a * a).sum()];
                film.lum_top[i] = v[n as usize / 2..].iter().sum();
            }
        }
        film
    }

    /// The guard's candidates for a matched filter `var · I` (px²) at every pixel.
    fn isotropic_candidates(w: u32, h: u32, var: f64) -> Vec<Vec<Gaussian>> {
        SCALES
            .iter()
            .map(|&k| vec![Gaussian::from_cov([var * k, 0.0, var * k]); (w * h) as usize])
            .collect()
    }

    /// The mean squared error of an image's red channel against `truth(x)`, over the
    /// pixels at least `margin` from the borders.
    fn interior_mse(img: &[DVec3], w: u32, h: u32, margin: u32, truth: impl Fn(u32) -> f64) -> f64 {
        let (mut e, mut k) = (0.0, 0.0);
        for y in margin..h - margin {
            for x in margin..w - margin {
                e += (img[(y * w + x) as usize].x - truth(x)).powi(2);
                k += 1.0;
            }
        }
        e / k
    }

    /// A noisy film of 16 samples per pixel over stripes of period 8 px, with every
    /// pixel's matched filter 8 px wide: the stripes keep 73% of their amplitude through
    /// a 1-px filter (`F₀/64`) and 29% through a 2-px one, and a pixel's mean has a noise
    /// of a third of their amplitude. The wider three lose to the box there, and the
    /// narrowest candidate stands in for it: the reconstruction beats the box and the
    /// wider three alone. The pilot's choice never takes it.
    #[test]
    fn the_narrowest_candidate_is_the_reconstructions_alone() {
        use rand::SeedableRng;
        let (w, h, n) = (64u32, 48u32, 16u32);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let truth = |x: u32| 2.0 + 0.3 * (std::f64::consts::TAU * (f64::from(x) + 0.5) / 8.0).sin();
        let film = film_of(w, h, n, |x, _| {
            (0..n).map(|_| truth(x) + 0.4 * normal(&mut rng)).collect()
        });
        let cands = isotropic_candidates(w, h, 64.0);
        // The mean squared error over the pixels away from the borders.
        let err = |img: &[DVec3]| interior_mse(img, w, h, 8, truth);
        let all = guarded(&cands, &film, 0..h);
        let wider = guarded(&cands[..PILOT_SCALES], &film, 0..h);
        let boxed: Vec<DVec3> = (0..(w * h) as usize)
            .map(|i| film.reflected[i] / f64::from(n))
            .collect();
        let narrowest = all
            .filters
            .iter()
            .zip(&cands[PILOT_SCALES])
            .filter(|(f, c)| f.as_ref() == Some(*c))
            .count();
        assert!(
            narrowest * 2 > (w * h) as usize,
            "{narrowest} of {} pixels",
            w * h
        );
        let (e_all, e_wider, e_box) = (err(&all.reflected), err(&wider.reflected), err(&boxed));
        assert!(
            e_all < 0.8 * e_box && e_all < 0.8 * e_wider,
            "{e_all} {e_wider} {e_box}"
        );
        // The pilot's choice, at the budget or beyond it, considers the wider three only.
        for target in [16.0, 64.0] {
            let chosen = chosen_filters(&cands, &film, target, 0..h);
            assert!(
                chosen
                    .iter()
                    .zip(&cands[PILOT_SCALES])
                    .all(|(f, c)| f.as_ref() != Some(c))
            );
        }
    }

    /// A fine texture (period 4 px) under a scrambled net's samples: each pixel's 16
    /// samples spread widely (a sample variance of 0.32) but every half of them is
    /// stratified, so a pixel's mean errs by a std of 0.0025 where Monte Carlo's `s²/n`
    /// reads 0.14. Read that way, a narrow filter's own share of the noise looks thousands
    /// of times larger than it is, and `F₀/4` (1 px), which keeps 29% of the texture,
    /// wins everywhere; read as the net's convergence, the narrower `F₀/16` keeps 73%
    /// and the error halves at least.
    #[test]
    fn a_converged_texture_is_not_blurred() {
        use rand::{Rng, SeedableRng};
        let (w, h, n) = (64u32, 48u32, 16u32);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let truth = |x: u32| 2.0 + 0.1 * (std::f64::consts::TAU * (f64::from(x) + 0.5) / 4.0).sin();
        let film = film_of(w, h, n, |x, _| {
            let phase: f64 = rng.random();
            (0..n)
                .map(|k| {
                    let spread = 0.8 * (std::f64::consts::TAU * (f64::from(k) + phase) / 8.0).sin();
                    truth(x) + spread + 0.01 * normal(&mut rng)
                })
                .collect()
        });
        let cands = isotropic_candidates(w, h, 4.0);
        let err = |img: &[DVec3]| interior_mse(img, w, h, 4, truth);
        let got = err(&guarded(&cands, &film, 0..h).reflected);
        let alone: Vec<f64> = cands
            .iter()
            .map(|c| err(&film.image(&crate::film::Filter::PerPixel(c.clone())).pixels))
            .collect();
        assert!(got < 0.5 * alone[1], "{got} against {alone:?}");
    }

    /// One sample per pixel: a clean step reads as no noise beside it (the direction
    /// along the edge does not cross it), and independent Gaussian noise reads as its
    /// variance ([`LEAST_OF_FOUR`] corrects the least of four directions).
    #[test]
    fn one_sample_variance_reads_noise_not_edges() {
        let film = one_sample(32, 32, |x, _| if x < 16 { 0.2 } else { 1.0 });
        let v = one_sample_variance(&film, &film.variance());
        for y in 1..31 {
            for x in 14..18 {
                assert_eq!(v[y * 32 + x], 0.0, "({x}, {y})");
            }
        }
        use rand::SeedableRng;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let n = 256;
        let gauss: Vec<f64> = (0..n * n).map(|_| normal(&mut rng)).collect();
        let film = one_sample(n as u32, n as u32, |x, y| {
            1.0 + 0.1 * gauss[(y * n as u32 + x) as usize]
        });
        let v = one_sample_variance(&film, &film.variance());
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        // Unit-variance noise scaled by 0.1: the estimates' mean is its variance.
        assert!((mean / 0.01 - 1.0).abs() < 0.02, "{mean} against 0.01");
        // Neighbours of two samples (a budget between 1 and 2 spp): their means are half
        // as noisy, and each difference is weighed by its pair's counts.
        let mut mixed = film.clone();
        for y in 0..n {
            for x in (y % 2..n).step_by(2) {
                let i = y * n + x;
                mixed.count[i] = 2;
                mixed.lum[i][0] = 2.0 * (1.0 + 0.1 * gauss[i] / 2f64.sqrt());
            }
        }
        let v = one_sample_variance(&mixed, &mixed.variance());
        let ones: Vec<f64> = (0..n * n)
            .filter(|&i| mixed.count[i] == 1)
            .map(|i| v[i])
            .collect();
        let mean = ones.iter().sum::<f64>() / ones.len() as f64;
        assert!(
            (mean / 0.01 - 1.0).abs() < 0.05,
            "{mean} against 0.01 (mixed counts)"
        );
        // From two samples on, a pixel keeps its own sample variance.
        let mut film = film;
        film.count[100] = 2;
        film.lum[100] = [2.0, 2.5];
        let v = one_sample_variance(&film, &film.variance());
        assert_eq!(v[100], film.variance()[100]);
        assert!((v[100] - 0.5).abs() < 1e-12);
    }
}
