//! The two forms Σ is held in, each implementing the raw kernels of [`crate::Spectrum`]:
//! the covariance itself ([`crate::Cov`], `cov.rs`) and its square-root factor
//! ([`CovFactor`], `factor.rs`).

pub(crate) mod cov;
mod factor;

use crate::linalg::MAX;

pub use cov::SCHUR_SNAP;
pub use factor::{CovFactor, ROW_SNAP};

/// Where a form's finiteness check failed, as (row, column, value).
pub(crate) fn overflow_at(check: Result<(), crate::CovError>) -> Option<(usize, usize, f64)> {
    check.err().map(|e| match e {
        crate::CovError::Overflow { row, col, value, .. } => (row, col, value),
        _ => (0, 0, f64::NAN),
    })
}

/// The unchecked in-place kernels of a concrete form, for the fast path of a
/// [`crate::Chain`] (`Direct`). Indices arrive resolved and parameters checked; these
/// kernels do not check their output: ∞ and NaN propagate, and the chain checks
/// finiteness where a later kernel could hide them and at the end. The checked `raw_*`
/// kernels of [`crate::Spectrum`] are these kernels plus a check ([`checked_kernels!`]),
/// so the fast and the checked path give the same bits.
pub(crate) trait Kernels: crate::Spectrum + Copy + Send + Sync + 'static {
    /// Whether [`Kernels::k_lobe_1`] leaves some entry non-finite whenever its input
    /// held one (its snap cannot hide an ∞), so that a chain's fast path need not check
    /// finiteness before it: the check at the end sees the overflow.
    const LOBE_1_KEEPS_NON_FINITE: bool;
    /// Whether the checked rotation may skip its check: the square-root form rotates rows
    /// of `L` (an orthogonal map keeps their norms, so an entry overflows only within √2
    /// of f64's largest, which a chain's end check and `CovFactor::to_cov` report).
    const ROTATION_STAYS_FINITE: bool;
    /// Line `j` ([`Kernels::line`]) after the shear `z'_i = z_i + s·z_j`.
    fn sheared(&self, i: usize, j: usize, s: f64) -> [f64; MAX];
    /// Line `i` after scaling axis `i` by `c`.
    fn scaled(&self, i: usize, c: f64) -> [f64; MAX];
    #[inline(always)]
    fn k_shear(&mut self, i: usize, j: usize, s: f64) {
        self.set_line(j, &self.sheared(i, j, s));
    }
    #[inline(always)]
    fn k_scale(&mut self, i: usize, c: f64) {
        self.set_line(i, &self.scaled(i, c));
    }
    fn k_rotate(&mut self, i: usize, j: usize, c: f64, s: f64);
    fn k_add_variance(&mut self, i: usize, w: f64);
    fn k_lobe_1(&mut self, p: usize, s: f64);
    fn k_add_window(&mut self, p: &[usize], w: &crate::linalg::Small);
    fn k_lobe(&mut self, p: &[usize], s: &crate::linalg::Small);
    fn k_congruence(&mut self, a: &crate::linalg::Small);
    /// Whether every stored number is finite.
    fn all_finite(&self) -> bool;
    /// Line `j` as stored, what a one-line kernel (shear, scale) writes: Σ's column `j`
    /// in the covariance form, `L`'s row `j` in the square-root form.
    fn line(&self, j: usize) -> [f64; MAX];
    /// Writes back a [`Kernels::line`].
    fn set_line(&mut self, j: usize, line: &[f64; MAX]);

    /// Writes line `j` if all of `line` is finite (tested in registers, no copy of Σ);
    /// otherwise reports its first non-finite entry as an overflow of `op`, Σ unchanged.
    #[inline(always)]
    fn commit_line(&mut self, op: &str, j: usize, line: [f64; MAX]) -> Result<(), crate::CovError> {
        if finite(&line[..self.dim()]) {
            self.set_line(j, &line);
            return Ok(());
        }
        line_overflowed(self, op, j, &line)
    }

    /// The end of a checked kernel: `Ok` if every stored number is finite; otherwise Σ is
    /// restored to `old` and the first non-finite entry is reported as an overflow of `op`.
    #[inline(always)]
    fn checked(&mut self, op: &str, old: Self) -> Result<(), crate::CovError> {
        // The branch-free test first; the search for the entry to report only on failure.
        if self.all_finite() {
            return Ok(());
        }
        overflowed(self, op, old)
    }
}

/// Whether every value is finite: `v · 0` is ±0 for a finite `v`, NaN otherwise, so the OR
/// of the products' bits less the sign is 0 exactly then (branch-free; it vectorises).
#[inline(always)]
pub(crate) fn finite(values: &[f64]) -> bool {
    let mut bits = 0u64;
    for v in values {
        bits |= (v * 0.0).to_bits() << 1;
    }
    bits == 0
}

/// The error of [`Kernels::commit_line`], found with `line` written; Σ is left as it was.
#[cold]
#[inline(never)]
fn line_overflowed<K: Kernels>(
    k: &mut K,
    op: &str,
    j: usize,
    line: &[f64; MAX],
) -> Result<(), crate::CovError> {
    let old = *k;
    k.set_line(j, line);
    overflowed(k, op, old)
}

/// The error of [`Kernels::checked`], with Σ restored to `old`.
#[cold]
#[inline(never)]
fn overflowed<K: Kernels>(k: &mut K, op: &str, old: K) -> Result<(), crate::CovError> {
    let at = k.first_non_finite().unwrap_or((0, 0, f64::NAN));
    *k = old;
    Err(crate::CovError::overflow(op, at))
}

/// The checked raw kernels of [`crate::Spectrum`] for a form, each from the form's
/// unchecked kernel ([`Kernels`]): it runs in place and [`Kernels::checked`] restores Σ and
/// reports if the result overflowed; a one-line kernel's line is computed first and written
/// only if finite ([`Kernels::commit_line`]). So each rule's arithmetic is written once per
/// form, and the checked and unchecked paths give the same bits.
macro_rules! checked_kernels {
    ($add_variance:ident) => {
        $crate::form::checked_kernels!(@add_variance $add_variance);
        #[inline(always)]
        fn raw_rotate(&mut self, op: &str, planes: &[(usize, usize)], c: f64, s: f64) -> Result<(), CovError> {
            let old = *self;
            // One or two planes written out, so that constant indices reach the kernel.
            match *planes {
                [(i, j)] => self.k_rotate(i, j, c, s),
                [(i, j), (k, l)] => {
                    self.k_rotate(i, j, c, s);
                    self.k_rotate(k, l, c, s);
                }
                _ => planes.iter().for_each(|&(i, j)| self.k_rotate(i, j, c, s)),
            }
            if Self::ROTATION_STAYS_FINITE {
                return Ok(());
            }
            self.checked(op, old)
        }
        fn raw_congruence(&mut self, op: &str, a: &Small) -> Result<(), CovError> {
            let old = *self;
            self.k_congruence(a);
            self.checked(op, old)
        }
        #[inline(always)]
        fn raw_shear(&mut self, op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError> {
            let line = self.sheared(i, j, s);
            self.commit_line(op, j, line)
        }
        #[inline(always)]
        fn raw_scale(&mut self, op: &str, i: usize, c: f64) -> Result<(), CovError> {
            let line = self.scaled(i, c);
            self.commit_line(op, i, line)
        }
        #[inline]
        fn raw_add_window(&mut self, op: &str, p: &[usize], w: &Small) -> Result<(), CovError> {
            let old = *self;
            self.k_add_window(p, w);
            self.checked(op, old)
        }
        #[inline(always)]
        fn raw_lobe_1(&mut self, op: &str, p: usize, s: f64) -> Result<(), CovError> {
            // Checked for every `s`, integration too: a Schur complement of a PSD Σ
            // shrinks it, but its rounding near f64's range is not bounded by that.
            let old = *self;
            self.k_lobe_1(p, s);
            self.checked(op, old)
        }
        #[inline]
        fn raw_lobe(&mut self, op: &str, p: &[usize], s: &Small) -> Result<(), CovError> {
            let old = *self;
            self.k_lobe(p, s);
            self.checked(op, old)
        }
    };
    // A variance that touches one entry (the covariance form's `Σ_ii`) or the whole
    // factor (the square-root form folds it in).
    (@add_variance entry) => {
        #[inline(always)]
        fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError> {
            let old = self.get(i, i);
            self.k_add_variance(i, w);
            if self.get(i, i).is_finite() {
                return Ok(());
            }
            let line = self.line(i);
            self.set(i, i, old);
            self.commit_line(op, i, line)
        }
    };
    (@add_variance whole) => {
        #[inline(always)]
        fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError> {
            let old = *self;
            self.k_add_variance(i, w);
            self.checked(op, old)
        }
    };
}
pub(crate) use checked_kernels;
