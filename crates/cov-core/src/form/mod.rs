//! The two forms Σ is held in, each implementing the raw kernels of [`crate::Spectrum`]:
//! the covariance itself ([`crate::Cov`], `cov.rs`) and its square-root factor
//! ([`CovFactor`], `factor.rs`).

pub(crate) mod cov;
mod factor;

pub use cov::SCHUR_SNAP;
pub(crate) use factor::psd_factor;
pub use factor::{CovFactor, ROW_SNAP};

/// Where a form's finiteness check failed, as (row, column, value).
pub(crate) fn overflow_at(check: Result<(), crate::CovError>) -> Option<(usize, usize, f64)> {
    check.err().map(|e| match e {
        crate::CovError::Overflow { row, col, value, .. } => (row, col, value),
        _ => (0, 0, f64::NAN),
    })
}

/// Checks a new row or column before a kernel writes it: the first non-finite entry is
/// an overflow of `op`, at the (row, column) `at(k)` gives for position `k`.
#[inline(always)]
pub(crate) fn require_finite_line(
    op: &str,
    line: &[f64],
    at: impl Fn(usize) -> (usize, usize),
) -> Result<(), crate::CovError> {
    match line.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(k) => {
            let (row, col) = at(k);
            Err(crate::CovError::Overflow {
                operator: op.into(),
                row,
                col,
                value: line[k],
            })
        }
    }
}

/// The unchecked in-place kernels of a concrete form, for compiled chains
/// ([`crate::Tape`]). Indices are resolved and parameters checked when the tape is
/// recorded; these kernels do not check their output: ∞ and NaN propagate, and the tape
/// checks finiteness where a later kernel could hide them and at the end. Each computes
/// exactly what the matching checked `raw_*` kernel of [`crate::Spectrum`] computes, so a
/// compiled chain and a checked one give the same bits.
pub(crate) trait Kernels: crate::Spectrum + Copy + Send + Sync + 'static {
    /// The form.
    const FORM: crate::Form;
    /// The layout size.
    const DIM: usize;
    /// Whether [`Kernels::k_lobe_1`] leaves some entry non-finite whenever its input
    /// held one (its snap cannot hide an ∞), so that a compiled chain need not check
    /// finiteness before it: the check at the end sees the overflow.
    const LOBE_1_KEEPS_NON_FINITE: bool;
    fn k_shear(&mut self, i: usize, j: usize, s: f64);
    fn k_scale(&mut self, i: usize, c: f64);
    fn k_rotate(&mut self, i: usize, j: usize, c: f64, s: f64);
    fn k_add_variance(&mut self, i: usize, w: f64);
    fn k_lobe_1(&mut self, p: usize, s: f64);
    fn k_add_window(&mut self, p: &[usize], w: &crate::linalg::Small);
    /// [`Kernels::k_add_window`] given a factor `F` of the window (`W = F Fᵀ`, `k × k`),
    /// as a compiled chain holds it: the square-root form appends `F`'s columns without
    /// factoring `W` again.
    fn k_add_window_factor(&mut self, p: &[usize], f: &crate::linalg::Small) {
        let k = p.len();
        let mut w = [[0.0; crate::linalg::MAX]; crate::linalg::MAX];
        for a in 0..k {
            for b in 0..k {
                w[a][b] = (0..k).map(|c| f[a][c] * f[b][c]).sum();
            }
        }
        self.k_add_window(p, &w);
    }
    fn k_lobe(&mut self, p: &[usize], s: &crate::linalg::Small);
    fn k_congruence(&mut self, a: &crate::linalg::Small);
    /// Whether every stored number is finite.
    fn all_finite(&self) -> bool;
}
