//! The square-root form of the spectrum covariance: `Σ = L Lᵀ`, with `L` an `N × N`
//! factor that is updated in place of Σ (the array algorithms of square-root Kalman
//! filtering).
//!
//! Why: a chain that turns Σ into a frame where one block dwarfs another (a curvature
//! before a lobe and its inverse after, say) and back loses, in the covariance form, the
//! small block's digits to cancellation: the error grows like `ε · Σ_big/Σ_small` per
//! event. The factor holds `√Σ`, so the same cancellation costs `ε · √(Σ_big/Σ_small)`,
//! and Σ = L Lᵀ is symmetric and PSD by construction. The stiff suite (`cov-stiff`)
//! measures the difference; see docs/stability.md.
//!
//! The rules, on `L` (rows are axes, columns are independent "sources"):
//!
//! - rule 1, `Σ' = Aᵀ Σ A`: `L' = Aᵀ L` (a shear adds one row to another);
//! - rule 2, `Σ' = Σ + W`: append the columns of a factor of `W`, then fold the factor
//!   back to `N` columns with Householder reflections from the right (an LQ step);
//! - rule 3, `Σ' = Σ − Σ Pᵀ (S + PΣPᵀ)⁻¹ P Σ`: for each axis of a diagonal `S`, Potter's
//!   update `L' = L (I − γ a aᵀ)` with `a` the axis' row and `γ = 1/(m + √(s m))`; for a
//!   correlated `S`, the pre-array `[[√S, P L], [0, L]]` brought to `[[α, 0], [β, L']]`
//!   by reflections from the right (`α αᵀ = S + PΣPᵀ`, `β αᵀ = Σ Pᵀ`). Nothing is
//!   inverted;
//! - rule 4 is rule 3 with `S = 0`.

use crate::form::Kernels;
use crate::form::cov::{SCHUR_SNAP, layout_mismatch};
use crate::linalg::{MAX, Small, sym_eigen};
use crate::{AnyCov, AnySpectrum, Cov, CovError, Form, Spectrum};

/// The factor's rank decision after a Schur update, on row norms (dimensionless): a row
/// whose norm fell to at most `ROW_SNAP ×` its norm before holds rounding only in its part
/// orthogonal to the updated row, and that part becomes exactly 0. `ROW_SNAP = √SCHUR_SNAP
/// ≈ 1.2e-7`, so `Σ_aa` itself fell to at most [`SCHUR_SNAP`] of its value: the same
/// decision as the covariance form, in Σ terms. After Potter's update the row's component
/// along the lobe's row is kept (it is scaled exactly, with no cancellation), so a small
/// variance the parameters determine survives (a refocused 1e-9 m window); with a
/// diffuse lobe or an integration that component is 0 and the whole row is.
/// A finer threshold (`64 ε` on the row) was measured to keep accumulated rounding of
/// 67 ε as "content", and a later integration along that noise removed 99.9995% of an
/// unrelated axis (the row's noise lay along it).
pub const ROW_SNAP: f64 = 1.1920928955078125e-7;

/// Columns of the largest pre-array: `N` plus up to `N` appended or lobe columns.
const W: usize = 2 * MAX;

/// A work array for a fold: the factor's `N` rows with up to `2N` columns.
type Work<const N: usize> = [[f64; W]; N];

/// Σ in square-root form: `Σ = L Lᵀ`, `L` an `N × N` real matrix, row `i` for axis `i`.
///
/// Every [`Cov`] has a factor ([`CovFactor::from_cov`], a pivoted Cholesky that accepts
/// singular Σ), and every factor gives back a PSD Σ ([`CovFactor::to_cov`]). The factor
/// is not unique (any `L Q` with `Q` orthogonal is the same Σ); only Σ is compared.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, CovFactor, Spectrum};
///
/// let start = Cov::<2>::gaussian([1e-3, 0.05])?;
/// let mut f = CovFactor::from_cov(&start);
/// f.shear(Axis::X, Axis::U, -0.5)?; // travel 0.5 m
/// f.convolve(&[Axis::U], &[100.0])?; // a glossy lobe
/// let mut c = start;
/// c.shear(Axis::X, Axis::U, -0.5)?;
/// c.convolve(&[Axis::U], &[100.0])?;
/// approx::assert_relative_eq!(f.to_cov()?, c, max_relative = 1e-12);
/// # Ok::<(), CovError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CovFactor<const N: usize> {
    l: [[f64; N]; N],
}

impl<const N: usize> Default for CovFactor<N> {
    fn default() -> Self {
        Self::zeros()
    }
}

impl<const N: usize> CovFactor<N> {
    /// The factor of Σ = 0.
    pub fn zeros() -> Self {
        CovFactor { l: [[0.0; N]; N] }
    }

    /// A factor with the given rows (`Σ = L Lᵀ`).
    ///
    /// # Errors
    /// A non-finite entry.
    pub fn from_rows(l: [[f64; N]; N]) -> Result<Self, CovError> {
        let f = CovFactor { l };
        f.check_finite("CovFactor::from_rows")?;
        Ok(f)
    }

    /// The factor's rows.
    pub fn rows(&self) -> &[[f64; N]; N] {
        &self.l
    }

    /// A factor of `c` by Cholesky with diagonal pivoting on the diagonally scaled Σ, so
    /// the result does not depend on the axes' units and entries from `1e-300` to
    /// `1e300` neither overflow nor underflow. Singular Σ is fine: the factorisation stops
    /// when the largest remaining pivot of the unit-diagonal matrix is at most
    /// [`SCHUR_SNAP`] (`64 ε`): what remains is rounding (a rank-deficient Σ leaves pivots
    /// of a few ε, and dividing by their square roots would blow the noise up), so the
    /// round trip is exact to about `64 ε` in correlation terms, leaving zero columns.
    pub fn from_cov(c: &Cov<N>) -> Self {
        let mut d = [0.0; N];
        let mut act = [0usize; N];
        let mut na = 0;
        for i in 0..N {
            let v = c.get(i, i);
            if v > 0.0 {
                d[i] = v.sqrt();
                act[na] = i;
                na += 1;
            }
        }
        // Scaled (unit diagonal) active block.
        let mut a = [[0.0; N]; N];
        for x in 0..na {
            for y in 0..na {
                let (i, j) = (act[x], act[y]);
                a[x][y] = if x == y { 1.0 } else { (c.get(i, j) / d[i]) / d[j] };
            }
        }
        let mut g = [[0.0; N]; N];
        let mut done = [false; N];
        for k in 0..na {
            let mut p = usize::MAX;
            for x in 0..na {
                if !done[x] && (p == usize::MAX || a[x][x] > a[p][p]) {
                    p = x;
                }
            }
            // `p` is set: `na − k ≥ 1` rows are not done.
            let piv = a[p][p];
            if piv.is_nan() || piv <= SCHUR_SNAP {
                break;
            }
            let r = piv.sqrt();
            done[p] = true;
            for y in 0..na {
                if y == p {
                    g[y][k] = r;
                } else if !done[y] {
                    g[y][k] = a[y][p] / r;
                }
            }
            // The Schur update of the rows not done, written without branches over the
            // whole N × N array so that it unrolls: rows and columns done before have
            // `g = 0` (left as they were), rows beyond `na` are 0, and row and column `p`
            // are never read again. The entries read later get the same operations.
            for y in 0..N {
                let gy = g[y][k];
                for z in 0..N {
                    a[y][z] -= gy * g[z][k];
                }
            }
        }
        let mut l = [[0.0; N]; N];
        for x in 0..na {
            for k in 0..na {
                l[act[x]][k] = d[act[x]] * g[x][k];
            }
        }
        CovFactor { l }
    }

    /// Σ = L Lᵀ, exactly symmetric and PSD up to the rounding of the products.
    ///
    /// # Errors
    /// [`CovError::Overflow`] when an entry of Σ exceeds the f64 range (the factor holds
    /// √Σ, so it can carry entries up to about `1e308` where Σ would be `1e616`).
    pub fn to_cov(&self) -> Result<Cov<N>, CovError> {
        let mut c = Cov::<N>::zeros();
        for i in 0..N {
            for j in i..N {
                c.set(i, j, self.dot(i, j));
            }
        }
        c.check_finite("Σ")?;
        Ok(c)
    }

    /// Entry `(i, j)` of Σ.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.dot(i, j)
    }

    #[inline]
    fn dot(&self, i: usize, j: usize) -> f64 {
        (0..N).map(|c| self.l[i][c] * self.l[j][c]).sum()
    }

    /// Checks every entry of the factor is finite.
    ///
    /// # Errors
    /// [`CovError::Overflow`] naming `operator` and the row and column of the first
    /// non-finite entry of `L`.
    pub fn check_finite(&self, operator: &str) -> Result<(), CovError> {
        for i in 0..N {
            for c in 0..N {
                if !self.l[i][c].is_finite() {
                    return Err(CovError::overflow(operator, (i, c, self.l[i][c])));
                }
            }
        }
        Ok(())
    }
}

impl<const N: usize> Spectrum for CovFactor<N> {
    #[inline(always)]
    fn dim(&self) -> usize {
        N
    }
    fn form(&self) -> Form {
        Form::SquareRoot
    }
    fn cov(&self) -> Result<AnyCov, CovError> {
        self.to_cov().map(AnyCov::from)
    }
    fn assign(&mut self, c: &AnyCov) -> Result<(), CovError> {
        let c = c.to::<N>().ok_or_else(|| layout_mismatch(N, c.dim()))?;
        c.check_finite("assign")?;
        *self = CovFactor::from_cov(&c);
        Ok(())
    }
    fn snapshot(&self) -> AnySpectrum {
        AnySpectrum::from(*self)
    }
    fn restore(&mut self, s: &AnySpectrum) {
        if let Some(f) = s.to_factor::<N>() {
            *self = f;
        }
    }
    fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        super::overflow_at(self.check_finite(""))
    }
    fn concrete(&mut self) -> crate::Concrete<'_> {
        crate::direct::concrete_factor(self)
    }

    super::checked_kernels!(whole);
}

impl<const N: usize> Kernels for CovFactor<N> {
    // Potter's update and its row snap are not audited for this: check before the lobe.
    const LOBE_1_KEEPS_NON_FINITE: bool = false;
    const ROTATION_STAYS_FINITE: bool = true;

    #[inline(always)]
    fn sheared(&self, i: usize, j: usize, s: f64) -> [f64; MAX] {
        let mut row = [0.0; MAX];
        for c in 0..N {
            row[c] = self.l[j][c] + s * self.l[i][c];
        }
        row
    }
    #[inline(always)]
    fn scaled(&self, i: usize, c: f64) -> [f64; MAX] {
        let mut row = [0.0; MAX];
        for (v, l) in row.iter_mut().zip(&self.l[i]) {
            *v = l * c;
        }
        row
    }
    #[inline(always)]
    fn k_rotate(&mut self, i: usize, j: usize, c: f64, s: f64) {
        self.rotate_rows(i, j, c, s);
    }
    #[inline]
    fn k_add_variance(&mut self, i: usize, w: f64) {
        self.l = self.add_variance_new(i, w);
    }
    #[inline]
    fn k_lobe_1(&mut self, p: usize, s: f64) {
        potter_axis(&mut self.l, p, s.max(0.0));
    }
    fn k_add_window(&mut self, p: &[usize], w: &Small) {
        self.l = self.add_window_new(p, w);
    }
    fn k_lobe(&mut self, p: &[usize], s: &Small) {
        self.l = self.lobe_new(p, s);
    }
    fn k_congruence(&mut self, a: &Small) {
        self.l = self.congruence_new(a);
    }
    #[inline(always)]
    fn line(&self, j: usize) -> [f64; MAX] {
        let mut line = [0.0; MAX];
        line[..N].copy_from_slice(&self.l[j]);
        line
    }
    #[inline(always)]
    fn set_line(&mut self, j: usize, line: &[f64; MAX]) {
        self.l[j].copy_from_slice(&line[..N]);
    }
    #[inline(always)]
    fn all_finite(&self) -> bool {
        super::finite(self.l.as_flattened())
    }
}

impl<const N: usize> CovFactor<N> {
    /// Rotation of rows `i` and `j` by (cos, sin); inlined, so that a typed body's
    /// constant indices reach it (it was a call per plane: 6 per bounce chain).
    #[inline(always)]
    fn rotate_rows(&mut self, i: usize, j: usize, c: f64, s: f64) {
        for k in 0..N {
            let (x, y) = (self.l[i][k], self.l[j][k]);
            self.l[i][k] = c * x + s * y;
            self.l[j][k] = c * y - s * x;
        }
    }

    /// The same factor as a `CovFactor<M>` when `M == N` (`None` otherwise).
    pub fn cast<const M: usize>(&self) -> Option<CovFactor<M>> {
        if M != N {
            return None;
        }
        let mut l = [[0.0; M]; M];
        for i in 0..M {
            l[i].copy_from_slice(&self.l[i][..M]);
        }
        Some(CovFactor { l })
    }

    /// The factor in a work array, columns `0..N`.
    #[inline(always)]
    fn work(&self) -> Work<N> {
        let mut m = [[0.0; W]; N];
        for i in 0..N {
            m[i][..N].copy_from_slice(&self.l[i]);
        }
        m
    }

    /// Folds the `N × cols` array `m` back to `N` columns (`L' L'ᵀ = M Mᵀ`). When at most
    /// `N` columns are non-zero (a rank-deficient Σ has free columns: a source constant
    /// along an axis, an integrated axis), they are only packed side by side, exactly;
    /// otherwise Householder reflections from the right triangularise `M`.
    fn fold_new(mut m: Work<N>, cols: usize) -> [[f64; N]; N] {
        let mut used = [0usize; W];
        let mut n_used = 0;
        for c in 0..cols {
            if (0..N).any(|i| m[i][c] != 0.0) {
                used[n_used] = c;
                n_used += 1;
            }
        }
        if n_used <= N {
            let mut new = [[0.0; N]; N];
            for (to, &from) in used[..n_used].iter().enumerate() {
                for i in 0..N {
                    new[i][to] = m[i][from];
                }
            }
            return new;
        }
        match cols - N {
            1 => lq_fold::<N, 1>(&mut m),
            2 => lq_fold::<N, 2>(&mut m),
            _ => lq(&mut m, 0, N, N, cols),
        }
        let mut new = [[0.0; N]; N];
        for i in 0..N {
            new[i].copy_from_slice(&m[i][..N]);
        }
        new
    }

    /// `L' = Aᵀ L`.
    fn congruence_new(&self, a: &Small) -> [[f64; N]; N] {
        let mut new = [[0.0; N]; N];
        for (i, row) in new.iter_mut().enumerate() {
            for (c, v) in row.iter_mut().enumerate() {
                *v = (0..N).map(|k| a[k][i] * self.l[k][c]).sum();
            }
        }
        new
    }

    /// The factor of `Σ + W` on the indices `p`.
    fn add_window_new(&self, p: &[usize], w: &Small) -> [[f64; N]; N] {
        self.add_columns_new(p, &psd_factor(p.len(), w))
    }

    /// The factor of `Σ + F Fᵀ` on the indices `p` (`F` is `k × k`): `F`'s columns
    /// appended to `L`, then folded back to `N` columns.
    fn add_columns_new(&self, p: &[usize], f: &Small) -> [[f64; N]; N] {
        let k = p.len();
        let mut m = self.work();
        for a in 0..k {
            for c in 0..k {
                m[p[a]][N + c] = f[a][c];
            }
        }
        Self::fold_new(m, N + k)
    }

    /// The factor of `Σ + w e_i e_iᵀ`.
    #[inline]
    fn add_variance_new(&self, i: usize, w: f64) -> [[f64; N]; N] {
        let mut m = self.work();
        m[i][N] = w.sqrt();
        Self::fold_new(m, N + 1)
    }

    /// Rule 3. A diagonal `S` (the usual lobe, and integration) is done as one-axis
    /// updates ([`potter`]), which equal the joint update (in information form each adds
    /// `e_a e_aᵀ/S_aa`). A correlated `S` takes the array algorithm: the pre-array
    /// `[[√S, P L], [0, L]]` is brought to `[[α, 0], [β, L']]` by Householder reflections
    /// from the right, so `α αᵀ = S + PΣPᵀ`, `β αᵀ = Σ Pᵀ` and `L' L'ᵀ` is the update;
    /// it mixes the factor's columns, never its rows (axes), and inverts nothing.
    fn lobe_new(&self, p: &[usize], s: &Small) -> [[f64; N]; N] {
        let k = p.len();
        let diagonal = (0..k).all(|a| (0..k).all(|b| a == b || s[a][b] == 0.0));
        let mut new = self.l;
        if diagonal {
            for a in 0..k {
                potter_axis(&mut new, p[a], s[a][a].max(0.0));
            }
            return new;
        }
        let sf = psd_factor(k, s);
        let mut m = [[0.0; W]; W];
        for a in 0..k {
            m[a][..k].copy_from_slice(&sf[a][..k]);
            m[a][k..k + N].copy_from_slice(&self.l[p[a]]);
        }
        for i in 0..N {
            m[k + i][k..k + N].copy_from_slice(&self.l[i]);
        }
        lq(&mut m, 0, k, k + N, k + N);
        for i in 0..N {
            new[i].copy_from_slice(&m[k + i][k..k + N]);
            // Σ e_a = 0 gives Σ' e_a = 0; and a row that cancelled to ROW_SNAP of its norm
            // holds rounding only (as in `potter_axis`).
            let empty = self.l[i].iter().all(|v| *v == 0.0);
            if empty || (!p.contains(&i) && cancelled(&new[i], &self.l[i])) {
                new[i] = [0.0; N];
            }
        }
        new
    }
}

/// Potter's square-root update for a lobe on axis `p` with spectrum variance `s ≥ 0`:
/// with `a = L_pᵀ` (row `p`) and `m = s + |a|²`, `L' = L (I − γ a aᵀ)`,
/// `γ = 1/(m + √(s m))`, which squares to `I − a aᵀ/m`, i.e.
/// `Σ' = Σ − Σ e_p e_pᵀ Σ/(s + Σ_pp)`. `γ` has no cancellation, and row `p` becomes
/// exactly `L_p √(s/m)` (the covariance form's `Σ_pp s/m`, to relative accuracy; exactly
/// 0 for a diffuse lobe). When `|a|² + s` would overflow or underflow, `a` and `s` are
/// scaled by `max(|a_i|, √s)` first.
#[inline]
fn potter<const N: usize>(l: &mut [[f64; N]; N], p: usize, s: f64) {
    let mut a = l[p];
    let mut sh = s;
    let mut mh = s + a.iter().map(|v| v * v).sum::<f64>();
    if !(mh.is_finite() && mh > 1e-290) {
        let scale = a.iter().fold(s.sqrt(), |m, v| m.max(v.abs()));
        if scale == 0.0 || !scale.is_finite() {
            // No content along p and a diffuse lobe: nothing to remove.
            return;
        }
        let inv = 1.0 / scale;
        for v in a.iter_mut() {
            *v *= inv;
        }
        sh = (s * inv) * inv;
        mh = sh + a.iter().map(|v| v * v).sum::<f64>();
    }
    let gamma = 1.0 / (mh + (sh * mh).sqrt());
    let keep = (sh / mh).sqrt();
    for (i, row) in l.iter_mut().enumerate() {
        if i == p {
            for v in row.iter_mut() {
                *v *= keep;
            }
            continue;
        }
        let g = gamma * row.iter().zip(&a).map(|(x, y)| x * y).sum::<f64>();
        for (v, ac) in row.iter_mut().zip(&a) {
            *v -= g * ac;
        }
    }
}

/// [`potter`] along axis `p`, then the clean-up of rows that cancelled. Potter's update
/// scales a row's component along row `p` by `√(s/m)`, exactly as it scales row `p`, and
/// leaves the part orthogonal to row `p` unchanged. A row whose norm fell to at most
/// [`ROW_SNAP`] of its norm before lost its digits to that subtraction, so it is rebuilt
/// from the two parts, each computed without cancellation: `c·L'_p` (`c` the row's
/// coefficient on row `p` before), plus the orthogonal part taken from the row before
/// through the antisymmetric products `x_k a_j − x_j a_k` ([`orthogonal_part`]). Those
/// products cancel only where the row before was nearly parallel to row `p` in a plane;
/// an orthogonal part that does not stand above their rounding by [`KEEP_MARGIN`] is
/// noise and becomes exactly 0, as the whole orthogonal part did before (a sharp window
/// under a diffuse lobe). One that does is information Potter never touched: a beam's
/// own angular spread behind a window far below the beam's size (the stiff suite's
/// "window far below the beam" cases, lost to 99% when it was dropped). Row `p` is
/// exempt: Potter scales it, so a large drop is the lobe's information. The clean-up runs
/// after every axis, so that a later axis never updates along a noise direction (a
/// zero-`s` update along noise would remove a random part of every other row).
#[inline]
fn potter_axis<const N: usize>(l: &mut [[f64; N]; N], p: usize, s: f64) {
    let old = *l;
    potter(l, p, s);
    // Row p before, scaled to unit largest entry (its direction; no overflow in a·a),
    // with that scale and a·a: computed once, when a row first cancels.
    let mut dir: Option<([f64; N], f64, f64)> = None;
    for i in 0..N {
        if i != p && cancelled(&l[i], &old[i]) {
            let (a, scale, aa) = *dir.get_or_insert_with(|| {
                let scale = old[p].iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let a = old[p].map(|v| v / scale);
                (a, scale, a.iter().map(|v| v * v).sum())
            });
            // Row i's component along row p, `c·L_p`, is scaled exactly as row p was
            // (by √(s/m)): keep it, computed without cancellation as `c·L'_p`. What
            // cancelled is the part orthogonal to row p, which the lobe does not touch
            // and which is here below ROW_SNAP: rounding noise, dropped. (A row cancels
            // only when row p had content, so `scale` and `aa` are > 0; a non-finite
            // coefficient falls back to 0.)
            let c = a.iter().zip(&old[i]).map(|(x, y)| x * y).sum::<f64>() / aa / scale;
            let perp = orthogonal_part(&old[i], &a, aa);
            let mut row = [0.0; N];
            for k in 0..N {
                row[k] = perp[k] + c * l[p][k];
            }
            l[i] = if row.iter().all(|v| v.is_finite()) {
                row
            } else {
                [0.0; N]
            };
        }
    }
}

/// How far above its rounding bound an orthogonal part must stand to be kept
/// ([`orthogonal_part`]), dimensionless: 64, a margin over the first-order bound for the
/// rounding a row carries in from earlier events (a finer test kept accumulated rounding
/// of 67 ε as content, which a later integration then removed from an unrelated axis).
pub(crate) const KEEP_MARGIN: f64 = 64.0;

/// The part of `x` orthogonal to `a` (`aa = a·a > 0`), as `Σ_j (x_k a_j − x_j a_k) a_j /
/// aa`: each antisymmetric product is exact where `x` has no component along `a` in that
/// plane, so a small orthogonal part next to a large parallel one keeps its digits
/// (`x − (x·a) a/aa` would lose them to the subtraction). Set to 0 unless its norm stands
/// [`KEEP_MARGIN`] times above the rounding bound of those products.
#[inline]
fn orthogonal_part<const N: usize>(x: &[f64; N], a: &[f64; N], aa: f64) -> [f64; N] {
    let mut perp = [0.0; N];
    let mut noise = [0.0; N];
    for k in 0..N {
        for j in 0..N {
            let (xa, ax) = (x[k] * a[j], x[j] * a[k]);
            perp[k] += (xa - ax) * a[j];
            noise[k] += (xa.abs() + ax.abs()) * a[j].abs();
        }
        perp[k] /= aa;
        noise[k] *= f64::EPSILON / aa;
    }
    if sum_sq(&perp) > KEEP_MARGIN * KEEP_MARGIN * sum_sq(&noise) {
        perp
    } else {
        [0.0; N]
    }
}

/// The plain sum of squares of a row (may overflow to ∞ or underflow: see [`cancelled`]).
#[inline]
fn sum_sq<const N: usize>(r: &[f64; N]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// Whether `row` cancelled to at most [`ROW_SNAP`] of the norm of `before` (a row that
/// was 0 does not count): compared on squares (`≤ SCHUR_SNAP ×`) when both are in range,
/// else on scaled norms.
#[inline]
fn cancelled<const N: usize>(row: &[f64; N], before: &[f64; N]) -> bool {
    let (now, was) = (sum_sq(row), sum_sq(before));
    if was.is_finite() && was > 1e-290 && now.is_finite() {
        return now <= SCHUR_SNAP * was;
    }
    let was = row_norm(before);
    was > 0.0 && row_norm(row) <= ROW_SNAP * was
}

#[inline]
fn row_norm<const N: usize>(r: &[f64; N]) -> f64 {
    // Fast path: the plain sum of squares, when it neither overflowed nor lost the
    // smallest entries to underflow (threshold 1e-290, far above the subnormal range).
    let sq: f64 = r.iter().map(|v| v * v).sum();
    if sq.is_finite() && sq > 1e-290 {
        return sq.sqrt();
    }
    let scale = r.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    scale * r.iter().map(|v| (v / scale) * (v / scale)).sum::<f64>().sqrt()
}

/// Triangularises rows `r0..r1` of `m` (columns `r0..cols`) by Householder reflections
/// applied from the right to rows `r0..rows`: afterwards row `r` has no entry right of
/// column `r`. Rows above `r0` must already be zero in columns `≥ r0`.
///
/// Each reflection is built from the row scaled by its largest entry, so rows anywhere in
/// `1e-300 … 1e300` neither overflow nor underflow; a zero row is skipped.
fn lq<const R: usize>(m: &mut [[f64; W]; R], r0: usize, r1: usize, rows: usize, cols: usize) {
    for r in r0..r1 {
        householder_row(m, r, rows, cols);
    }
}

/// [`lq`] of a fold (`N` rows, `N + K` columns) with every size and row index a
/// constant, so that the compiler unrolls each reflection: the same operations in the
/// same order (the same bits), fewer instructions.
fn lq_fold<const N: usize, const K: usize>(m: &mut Work<N>) {
    householder_row(m, 0, N, N + K);
    if N > 1 {
        householder_row(m, 1, N, N + K);
    }
    if N > 2 {
        householder_row(m, 2, N, N + K);
    }
    if N > 3 {
        householder_row(m, 3, N, N + K);
    }
    if N > 4 {
        householder_row(m, 4, N, N + K);
    }
}

/// The reflection of [`lq`] for row `r` (inlined where `r` is a constant).
#[inline(always)]
fn householder_row<const R: usize>(m: &mut [[f64; W]; R], r: usize, rows: usize, cols: usize) {
    let mut v = [0.0; W];
    v[r..cols].copy_from_slice(&m[r][r..cols]);
    // Scale only when the plain sum of squares would overflow or underflow.
    let mut scale = 1.0;
    let mut sq: f64 = v[r..cols].iter().map(|x| x * x).sum();
    if !(sq.is_finite() && sq > 1e-290) {
        scale = v[r..cols].iter().fold(0.0f64, |a, x| a.max(x.abs()));
        if scale == 0.0 {
            return;
        }
        let inv = 1.0 / scale;
        for x in v[r..cols].iter_mut() {
            *x *= inv;
        }
        sq = v[r..cols].iter().map(|x| x * x).sum();
    }
    let norm = sq.sqrt();
    // α = −sign(v_r)·‖v‖ avoids cancellation in v_r − α.
    let alpha = if v[r] >= 0.0 { -norm } else { norm };
    v[r] -= alpha;
    let vv: f64 = v[r..cols].iter().map(|x| x * x).sum();
    if vv == 0.0 {
        return;
    }
    let two_over = 2.0 / vv;
    for row in &mut m[r + 1..rows] {
        let t = two_over * (r..cols).map(|c| row[c] * v[c]).sum::<f64>();
        for c in r..cols {
            row[c] -= t * v[c];
        }
    }
    m[r][r] = alpha * scale;
    for c in (r + 1)..cols {
        m[r][c] = 0.0;
    }
}

/// A factor `F` (k × k) of a symmetric PSD block, `F Fᵀ = S`, from its eigenvectors
/// (negative rounding eigenvalues count as 0). A diagonal block is factored exactly.
pub(crate) fn psd_factor(k: usize, s: &Small) -> Small {
    let mut f = [[0.0; MAX]; MAX];
    let diagonal = (0..k).all(|a| (0..k).all(|b| a == b || s[a][b] == 0.0));
    if diagonal {
        for a in 0..k {
            f[a][a] = s[a][a].max(0.0).sqrt();
        }
        return f;
    }
    let (vals, vecs) = sym_eigen(k, s);
    for c in 0..k {
        let r = vals[c].max(0.0).sqrt();
        for a in 0..k {
            f[a][c] = vecs[a][c] * r;
        }
    }
    f
}
