//! The covariance form: the raw index kernels of [`Cov`] behind [`Spectrum`]. Parameters
//! arrive checked and axes resolved ([`Spectrum`]'s provided methods); each kernel computes
//! in place, keeps Σ exactly symmetric (packed storage) and restores Σ on overflow. Each
//! is tested against a dense nalgebra reference (`tests/kernels.rs`).

use super::Kernels;
use crate::linalg::{MAX, Small, psd_pinv};
use crate::{AnyCov, AnySpectrum, Cov, CovError, Form, Spectrum};

/// Relative level below which a diagonal entry of a Schur complement is rounding noise
/// (dimensionless, relative to the same entry before the update): `64 ε ≈ 1.4e-14`.
/// Cancellation in `Σ_aa − Σ_ap Σ_pp⁻¹ Σ_pa` leaves an error of a few ε × `Σ_aa`; what
/// remains below `64 ε` is not information. The snap sets such an entry to 0 with its row
/// and column: it errs towards a smaller bandwidth, and is exact when the true value is 0
/// (a point light through a diffuse bounce). Where the true value is small but well
/// determined by the parameters (a 1e-9 m window refocused by a lobe), it is lost here
/// and kept by the square-root form, whose [`crate::ROW_SNAP`] drops only the part of a
/// cancelled row orthogonal to the lobe's row. See [`Spectrum::convolve`] and
/// [`Spectrum::integrate`].
pub const SCHUR_SNAP: f64 = 64.0 * f64::EPSILON;

/// A new diagonal entry computed as a quadratic form `xᵀ Σ x` of a PSD Σ: never negative
/// in exact arithmetic, so a negative result is cancellation below rounding (`Travel`
/// then `Curvature` refocusing a ray gives `Σ_xx = −4.4e-16` for a true 0). Its magnitude
/// is kept, not zeroed: the error stays within the rounding band and errs towards a
/// larger bandwidth (more samples), never towards a negative or a zero one.
#[inline(always)]
fn quadratic(v: f64) -> f64 {
    v.abs()
}

impl<const N: usize> Spectrum for Cov<N> {
    #[inline(always)]
    fn dim(&self) -> usize {
        N
    }
    fn form(&self) -> Form {
        Form::Covariance
    }
    fn cov(&self) -> Result<AnyCov, CovError> {
        Ok(AnyCov::from(*self))
    }
    fn assign(&mut self, c: &AnyCov) -> Result<(), CovError> {
        let c = c.to::<N>().ok_or_else(|| layout_mismatch(N, c.dim()))?;
        c.check_finite("assign")?;
        *self = c;
        Ok(())
    }
    fn snapshot(&self) -> AnySpectrum {
        AnySpectrum::Covariance(AnyCov::from(*self))
    }
    fn restore(&mut self, s: &AnySpectrum) {
        if let Some(c) = s.to_cov::<N>() {
            *self = c;
        }
    }
    fn first_non_finite(&self) -> Option<(usize, usize, f64)> {
        super::overflow_at(self.check_finite(""))
    }
    fn concrete(&mut self) -> crate::Concrete<'_> {
        crate::direct::concrete_cov(self)
    }

    super::checked_kernels!(entry);
}

impl<const N: usize> Kernels for Cov<N> {
    // `snap_cancelled` writes `v − v`, NaN for a non-finite `v`; every other entry of
    // the lobe is a product or difference with the non-finite input (`∞·0` is NaN).
    const LOBE_1_KEEPS_NON_FINITE: bool = true;
    const ROTATION_STAYS_FINITE: bool = false;

    #[inline(always)]
    fn sheared(&self, i: usize, j: usize, s: f64) -> [f64; MAX] {
        let mut col = [0.0; MAX];
        for (k, c) in col.iter_mut().enumerate().take(N) {
            *c = if k == j {
                quadratic(self.load(j, j) + s * (2.0 * self.load(i, j) + s * self.load(i, i)))
            } else {
                self.load(k, j) + s * self.load(k, i)
            };
        }
        col
    }
    #[inline(always)]
    fn scaled(&self, i: usize, c: f64) -> [f64; MAX] {
        let mut col = [0.0; MAX];
        for (k, v) in col.iter_mut().enumerate().take(N) {
            *v = self.load(k, i) * if k == i { c * c } else { c };
        }
        col
    }
    #[inline(always)]
    fn k_rotate(&mut self, i: usize, j: usize, c: f64, s: f64) {
        self.rotate_idx(i, j, c, s);
    }
    #[inline(always)]
    fn k_add_variance(&mut self, i: usize, w: f64) {
        let v = self.load(i, i) + w;
        self.set(i, i, v);
    }
    #[inline(always)]
    fn k_lobe_1(&mut self, p: usize, s: f64) {
        self.lobe_product_1(p, s);
    }
    fn k_add_window(&mut self, p: &[usize], w: &Small) {
        self.add_window_in_place(p, w);
    }
    fn k_lobe(&mut self, p: &[usize], s: &Small) {
        self.lobe_in_place(p, s);
    }
    fn k_congruence(&mut self, a: &Small) {
        self.congruence_in_place(a);
    }
    #[inline(always)]
    fn line(&self, j: usize) -> [f64; MAX] {
        let mut line = [0.0; MAX];
        for (k, v) in line.iter_mut().enumerate().take(N) {
            *v = self.load(k, j);
        }
        line
    }
    #[inline(always)]
    fn set_line(&mut self, j: usize, line: &[f64; MAX]) {
        for (k, v) in line.iter().enumerate().take(N) {
            self.set(k, j, *v);
        }
    }
    #[inline(always)]
    fn all_finite(&self) -> bool {
        super::finite(self.packed())
    }
}

/// The error of a Σ handed to a spectrum of another layout.
pub(crate) fn layout_mismatch(have: usize, got: usize) -> CovError {
    CovError::Shape {
        what: "Spectrum::assign".into(),
        expected: format!("a Σ of layout {have}"),
        got: format!("layout {got}"),
    }
}

impl<const N: usize> Cov<N> {
    /// `Σ ← Aᵀ Σ A`: `B = Σ A`, then `Σ'_ij = Σ_k A_ki B_kj` for `i ≤ j` only (exact
    /// symmetry).
    fn congruence_in_place(&mut self, a: &Small) {
        let mut b = [[0.0; N]; N];
        for (k, row) in b.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..N).map(|l| self.load(k, l) * a[l][j]).sum();
            }
        }
        for i in 0..N {
            for j in i..N {
                let v: f64 = (0..N).map(|k| a[k][i] * b[k][j]).sum();
                // A diagonal is the quadratic form a_iᵀ Σ a_i ≥ 0 (see `quadratic`).
                self.set(i, j, if i == j { quadratic(v) } else { v });
            }
        }
    }

    /// `Σ_pp += W`.
    fn add_window_in_place(&mut self, p: &[usize], w: &Small) {
        for a in 0..p.len() {
            for b in a..p.len() {
                let v = self.load(p[a], p[b]) + w[a][b];
                self.set(p[a], p[b], v);
            }
        }
    }

    /// Rule 3 along `p` (one axis or several).
    fn lobe_in_place(&mut self, p: &[usize], s: &Small) {
        if let [p1] = p {
            self.lobe_product_1(*p1, s[0][0]);
        } else {
            self.lobe_product(p, s);
        }
    }

    #[inline(always)]
    fn rotate_idx(&mut self, i: usize, j: usize, c: f64, s: f64) {
        let sii = self.load(i, i);
        let sij = self.load(i, j);
        let sjj = self.load(j, j);
        for k in 0..N {
            if k != i && k != j {
                let ki = self.load(k, i);
                let kj = self.load(k, j);
                self.set(k, i, c * ki + s * kj);
                self.set(k, j, c * kj - s * ki);
            }
        }
        let cs = c * s;
        self.set(i, i, quadratic(c * c * sii + 2.0 * cs * sij + s * s * sjj));
        self.set(j, j, quadratic(s * s * sii - 2.0 * cs * sij + c * c * sjj));
        self.set(i, j, cs * (sjj - sii) + (c * c - s * s) * sij);
    }

    /// Shared by rules 3 and 4; `p` are the convolved indices, `s` the lobe spectrum.
    ///
    /// A diagonal `S` (the usual lobe, and integration) is done as one-axis updates
    /// (`lobe_product_1`), which equal the joint update (in information form each
    /// adds `e_a e_aᵀ/S_aa`) and keep each axis' cancellation-free form. A correlated `S`
    /// takes the joint form with a diagonally scaled `k × k` pseudo-inverse of `S + Σ_pp`
    /// ([`psd_pinv`]): turning Σ into `S`'s eigenframe instead would mix axes of very
    /// different content (measured: `Σ_uu = 2e-6` next to `Σ_vv = 5e4` lost 6 digits).
    fn lobe_product(&mut self, p: &[usize], s: &Small) {
        let k = p.len();
        let diagonal = (0..k).all(|a| (0..k).all(|b| a == b || s[a][b] == 0.0));
        if diagonal {
            for a in 0..k {
                self.lobe_product_1(p[a], s[a][a]);
            }
            return;
        }
        let mut before = [0.0; N];
        for (i, b) in before.iter_mut().enumerate() {
            *b = self.load(i, i);
        }
        let mut m = [[0.0; MAX]; MAX];
        for a in 0..k {
            for b in 0..k {
                m[a][b] = s[a][b] + self.load(p[a], p[b]);
            }
        }
        let (minv, _) = psd_pinv(k, &m);
        // T = M⁺ S (k×k).
        let mut t = [[0.0; MAX]; MAX];
        for a in 0..k {
            for b in 0..k {
                t[a][b] = (0..k).map(|c| minv[a][c] * s[c][b]).sum();
            }
        }
        let mut others_buf = [0usize; MAX];
        let mut no = 0;
        for i in 0..N {
            if !p.contains(&i) {
                others_buf[no] = i;
                no += 1;
            }
        }
        let others = &others_buf[..no];
        let old = *self;
        // Σ_oo − Σ_op M⁺ Σ_po
        for (ai, &oa) in others.iter().enumerate() {
            // g = Σ_{oa,p} M⁺
            let mut g = [0.0; MAX];
            for (c, gc) in g.iter_mut().enumerate().take(k) {
                *gc = (0..k).map(|d| old.load(oa, p[d]) * minv[d][c]).sum();
            }
            for &ob in &others[ai..] {
                let corr: f64 = (0..k).map(|c| g[c] * old.load(p[c], ob)).sum();
                self.set(oa, ob, old.load(oa, ob) - corr);
            }
        }
        // Σ_op M⁺ S
        for &o in others {
            for b in 0..k {
                let v: f64 = (0..k).map(|c| old.load(o, p[c]) * t[c][b]).sum();
                self.set(o, p[b], v);
            }
        }
        // ½ (Σ_pp M⁺ S + S M⁺ Σ_pp): symmetrised, PSD analytically.
        for a in 0..k {
            for b in a..k {
                let ab: f64 = (0..k).map(|c| old.load(p[a], p[c]) * t[c][b]).sum();
                let ba: f64 = (0..k).map(|c| old.load(p[b], p[c]) * t[c][a]).sum();
                self.set(p[a], p[b], 0.5 * (ab + ba));
            }
        }
        self.snap_cancelled(&before, p);
    }

    /// One convolved axis `p` with lobe spectrum `s ≥ 0` (the common case: a lobe on u,
    /// or integration over one axis). Same forms as the general path, with
    /// `m = s + Σ_pp`, `t = s/m`: `Σ_pp' = Σ_pp t`, `Σ_op' = Σ_op t`,
    /// `Σ_oo' = Σ_oo − Σ_op Σ_po / m`. For `m = 0` (no content and a diffuse lobe) the
    /// generalised inverse is 0 and only the axis itself is cleared.
    #[inline(always)]
    fn lobe_product_1(&mut self, p: usize, s: f64) {
        let mut before = [0.0; N];
        for (i, b) in before.iter_mut().enumerate() {
            *b = self.load(i, i);
        }
        let spp = self.load(p, p);
        let m = s + spp;
        let (inv, t) = if m > 0.0 { (1.0 / m, s / m) } else { (0.0, 0.0) };
        let mut col = [0.0; N];
        for (o, c) in col.iter_mut().enumerate() {
            *c = self.load(o, p);
        }
        for a in 0..N {
            if a == p {
                continue;
            }
            let ga = col[a] * inv;
            if ga.is_finite() {
                for b in a..N {
                    if b != p {
                        let v = self.load(a, b) - ga * col[b];
                        self.set(a, b, v);
                    }
                }
            } else {
                self.lobe_row_by_halves(p, a, m, &col);
            }
            self.set(a, p, col[a] * t);
        }
        self.set(p, p, spp * t);
        self.snap_cancelled(&before, &[p]);
    }

    /// Row `a` of [`Cov::lobe_product_1`] where `Σ_ap / m` overflows: `(Σ_ap/√m)(Σ_bp/√m)`
    /// cannot (each half ≤ `√Σ_aa`). Out of line: its root and division stay off the hot path.
    #[cold]
    #[inline(never)]
    fn lobe_row_by_halves(&mut self, p: usize, a: usize, m: f64, col: &[f64; N]) {
        let r = 1.0 / m.sqrt();
        let ha = col[a] * r;
        for b in a..N {
            if b != p {
                let v = self.load(a, b) - ha * (col[b] * r);
                self.set(a, b, v);
            }
        }
    }

    /// Scale-aware clean-up after a Schur complement: a diagonal entry that cancelled to
    /// at most [`SCHUR_SNAP`] times its value before the update holds nothing but rounding
    /// noise (f64 cannot resolve it), and may even be slightly negative. It is set to 0
    /// with its row and column, which keeps Σ exactly PSD-consistent. This is what makes
    /// a point light seen through a diffuse bounce exactly smooth (Σ_xx = 0), and a
    /// rank-deficient Σ through a diffuse lobe exactly 0, instead of ±1e-16 noise that
    /// later travel would amplify.
    ///
    /// The convolved axes `p` are exempt unless negative: their entries are products
    /// (`Σ_pp (S+Σ_pp)⁻¹ S`), not differences, so a large drop is information (a lobe of
    /// spectrum `S` on an angular spectrum `Σ_uu ≫ S` leaves `≈ S`), not cancellation.
    #[inline(always)]
    #[allow(clippy::eq_op)] // `v − v` is the point: +0, or NaN for a non-finite `v`.
    fn snap_cancelled(&mut self, before: &[f64; N], p: &[usize]) {
        for a in 0..N {
            let v = self.load(a, a);
            // A negative diagonal is never information, on any axis; nor is anything on
            // an axis that had no content before (Σ e_a = 0 gives Σ' e_a = 0: a lobe or an
            // integration cannot create content, only the general lobe's rounding can).
            let noise = v < 0.0 || before[a] <= 0.0 || (!p.contains(&a) && v <= SCHUR_SNAP * before[a]);
            if noise {
                // `v − v`: +0 for a finite entry, NaN for ∞ or NaN, so a snap never
                // hides an overflow (a chain's fast path checks only at the end).
                for b in 0..N {
                    let v = self.load(a, b);
                    self.set(a, b, v - v);
                }
            }
        }
    }
}
