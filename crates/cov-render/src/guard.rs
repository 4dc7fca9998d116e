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
//! not see predicts `x_p` badly from the neighbours, whatever Σ said. `σ²` is the sample
//! variance of the pixel's luminance over its count; it overstates the variance of a
//! quasi-Monte Carlo mean, which makes the box look worse than it is, so the guard leans
//! towards filtering where it cannot tell. The estimates are relative (divided by the
//! squared 3×3 mean luminance plus [`crate::metrics::REL_EPS`], the error the benchmarks
//! report) and averaged over 3×3 pixels before each pixel picks the smallest: one pixel's
//! squared residual is too noisy to decide alone (Stein's unbiased risk estimate, tried
//! for the same choice, needs the variance of the estimate itself, which is as noisy).
//!
//! Its cost, one splat per candidate and 3×3 sums, counts in the reconstruction time.

use glam::DVec3;
use rayon::prelude::*;

use crate::adaptive::{Guide, edge_clamp};
use crate::film::{Film, Filter, Gaussian};
use crate::metrics::REL_EPS;
use crate::trace::luminance;

/// The candidates' scales of each pixel's matched filter covariance `F₀` (a scale of 4
/// doubles the std; 1/16 quarters it), widest first; the box is the last candidate.
pub const SCALES: [f64; 3] = [1.0, 0.25, 0.0625];

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
pub fn candidates(guide: &Guide) -> Vec<Vec<Gaussian>> {
    SCALES.iter().map(|&s| candidate(guide, s)).collect()
}

/// The per-pixel filters of candidate `scale`: `scale · F₀`, kept off the pass's edges.
pub fn candidate(guide: &Guide, scale: f64) -> Vec<Gaussian> {
    let raw: Vec<Gaussian> = guide
        .matched
        .iter()
        .map(|f| Gaussian::from_cov(f.map(|v| v * scale)))
        .collect();
    edge_clamp(guide.width, guide.height, &raw)
}

/// Reconstructs `film`'s reflected light with the guard (module docs). With `target`
/// samples per pixel above a pixel's count (a pilot deciding where the rest of the budget
/// goes), the choice is the one the guard would make at `target` samples: the variance
/// terms shrink to `n/target` of the pilot's, while all of the cross-validation residual
/// above the noise is taken for bias, which more samples do not remove (the conservative
/// reading: a pilot's noise must not hide detail the full budget will show).
///
/// `candidates` are [`candidates`] of the film's guide.
pub fn guarded(candidates: &[Vec<Gaussian>], film: &Film, target: f64) -> Guarded {
    let (choice, images) = choose(candidates, film, target, 1);
    let n = film.count.len();
    let reflected = (0..n)
        .map(|p| match images.get(choice[p] as usize) {
            Some(acc) if acc[p].1 > 0.0 => acc[p].0 / acc[p].1,
            _ => match film.count[p] {
                0 => DVec3::ZERO,
                c => film.reflected[p] / f64::from(c),
            },
        })
        .collect();
    let filters = (0..n)
        .map(|p| candidates.get(choice[p] as usize).map(|f| f[p]))
        .collect();
    Guarded { reflected, filters }
}

/// The filter each pixel would choose ([`guarded`]'s `filters`, `None` for the box),
/// decided on the grid of every [`PILOT_STEP`]-th pixel in each direction, each pixel
/// taking its grid pixel's choice: what a pilot needs to place the rest of the budget, for
/// about `1/PILOT_STEP²` of the splatting (the choice is a 3×3 average of risks already,
/// so a coarser grid changes it only where it changes between neighbours).
pub fn guard_filters(candidates: &[Vec<Gaussian>], film: &Film, target: f64) -> Vec<Option<Gaussian>> {
    let (choice, _) = choose(candidates, film, target, PILOT_STEP);
    (0..film.count.len())
        .map(|p| candidates.get(choice[p] as usize).map(|f| f[p]))
        .collect()
}

/// The grid step of [`guard_filters`].
pub const PILOT_STEP: usize = 2;

/// Each pixel's choice (an index into `candidates`; their number for the box) with the
/// guard's risks evaluated on the pixels whose column and row are multiples of `step`
/// (every pixel for 1), and each candidate's splatted sums there.
fn choose(
    candidates: &[Vec<Gaussian>],
    film: &Film,
    target: f64,
    step: usize,
) -> (Vec<u8>, Vec<Vec<(DVec3, f64)>>) {
    let (w, h) = (film.width as i64, film.height as i64);
    let st = step.max(1) as i64;
    let n = film.count.len();
    let on_grid = |p: usize| (p as i64 % w) % st == 0 && (p as i64 / w) % st == 0;
    let var = film.variance();
    let lx: Vec<f64> = (0..n)
        .map(|i| match film.count[i] {
            0 => 0.0,
            c => luminance(film.reflected[i] / f64::from(c)),
        })
        .collect();
    let s2: Vec<f64> = (0..n).map(|i| var[i] / f64::from(film.count[i].max(1))).collect();
    // The variance of the pixel's mean at the target count.
    let s2_target: Vec<f64> = (0..n)
        .map(|i| {
            let c = f64::from(film.count[i].max(1));
            s2[i] * (c / target.max(c))
        })
        .collect();
    // The normaliser of the relative error: the squared 3×3 mean luminance.
    let norm: Vec<f64> = box3(w, h, &lx, 1).iter().map(|m| m * m + REL_EPS).collect();
    let mut risks: Vec<Vec<f64>> = Vec::with_capacity(candidates.len() + 1);
    let mut images: Vec<Vec<(DVec3, f64)>> = Vec::with_capacity(candidates.len());
    for filters in candidates {
        let acc = film.splat_on(&Filter::PerPixel(filters.clone()), step);
        let risk: Vec<f64> = (0..n)
            .into_par_iter()
            .map(|p| {
                let c = f64::from(film.count[p]);
                let (sum, wsum) = acc[p];
                if !on_grid(p) {
                    return 0.0;
                }
                if c == 0.0 || wsum <= 0.0 {
                    return f64::INFINITY;
                }
                let own = filters[p].peak();
                let (loo_w, alpha) = (wsum - own * c, (own * c / wsum).clamp(0.0, 1.0));
                // Below this share the others carry no weight: nothing to cross-validate.
                if loo_w <= 1e-9 * wsum {
                    return s2_target[p] / norm[p];
                }
                let loo = luminance(sum - film.reflected[p] * own) / loo_w;
                let cv = (loo - lx[p]).powi(2);
                (alpha * alpha * s2_target[p] + (1.0 - alpha).powi(2) * (cv - s2[p]).max(0.0)) / norm[p]
            })
            .collect();
        risks.push(box3(w, h, &risk, st));
        images.push(acc);
    }
    risks.push(box3(
        w,
        h,
        &(0..n).map(|p| s2_target[p] / norm[p]).collect::<Vec<_>>(),
        st,
    ));
    let choice: Vec<u8> = (0..n)
        .map(|p| {
            // The pixel's grid pixel.
            let (x, y) = (p as i64 % w, p as i64 / w);
            let g = ((y - y % st) * w + (x - x % st)) as usize;
            let mut best = candidates.len();
            for k in 0..candidates.len() {
                if risks[k][g] < risks[best][g] {
                    best = k;
                }
            }
            best as u8
        })
        .collect();
    (choice, images)
}

/// The 3×3 mean of `v` over the grid of every `step`-th pixel (neighbours `step` apart;
/// every pixel for 1), at the grid's pixels (0 elsewhere); fewer pixels at the borders,
/// and an infinite value stays infinite.
fn box3(w: i64, h: i64, v: &[f64], step: i64) -> Vec<f64> {
    (0..w * h)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if x % step != 0 || y % step != 0 {
                return 0.0;
            }
            let (mut s, mut k) = (0.0, 0.0);
            for yy in ((y - step).max(0)..=(y + step).min(h - 1)).step_by(step as usize) {
                for xx in ((x - step).max(0)..=(x + step).min(w - 1)).step_by(step as usize) {
                    s += v[(yy * w + xx) as usize];
                    k += 1.0;
                }
            }
            s / k
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 48 × 24 film of 16 samples a pixel: the left half flat with noise (filtering
    /// wins), the right half a 2-px checker with little noise (every filter blurs it).
    fn film() -> Film {
        let (w, h, n) = (48u32, 24u32, 16u32);
        let mut f = Film::new(w, h);
        let mut state = 12345u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                let (mean, spread) = if x < w / 2 {
                    (1.0, 0.8)
                } else if (x / 2 + y / 2) % 2 == 0 {
                    (0.2, 0.05)
                } else {
                    (1.8, 0.05)
                };
                for _ in 0..n {
                    let v = mean + spread * noise();
                    let c = DVec3::splat(v);
                    f.reflected[i] += c;
                    let l = luminance(c);
                    f.lum[i][0] += l;
                    f.lum[i][1] += l * l;
                }
                f.count[i] = n;
            }
        }
        f
    }

    #[test]
    fn the_pilot_choice_on_a_coarser_grid_agrees_with_the_full_one() {
        let f = film();
        let n = f.count.len();
        let cands: Vec<Vec<Gaussian>> = [3.0, 1.5, 0.75]
            .iter()
            .map(|&s| vec![Gaussian::isotropic(s); n])
            .collect();
        let full = guarded(&cands, &f, 16.0).filters;
        let coarse = guard_filters(&cands, &f, 16.0);
        let w = f.width as usize;
        // Away from the border between the halves, both read the halves alike: mostly a
        // filter on the flat half (its noise makes the box win at a few pixels), the box
        // on the checker.
        let share = |choice: &[Option<Gaussian>], flat: bool| {
            let px: Vec<usize> = (0..n)
                .filter(|p| {
                    if flat {
                        p % w < w / 2 - 6
                    } else {
                        p % w >= w / 2 + 6
                    }
                })
                .collect();
            px.iter().filter(|&&p| choice[p].is_some() == flat).count() as f64 / px.len() as f64
        };
        for (name, c) in [("full", &full), ("coarse", &coarse)] {
            assert!(
                share(c, true) >= 0.8,
                "{name}: flat half filtered at {}",
                share(c, true)
            );
            assert!(
                share(c, false) >= 0.95,
                "{name}: checker kept at {}",
                share(c, false)
            );
        }
        // Filter or box, the decision that sets a pixel's floor, agrees almost everywhere
        // (which filter, among near ties on the flat half, is left to the noise).
        let same = (0..n)
            .filter(|&p| full[p].is_some() == coarse[p].is_some())
            .count();
        assert!(same as f64 >= 0.9 * n as f64, "{same} of {n} pixels decide alike");
    }
}
