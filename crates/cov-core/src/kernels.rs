//! The shared kernels: the four algebraic rules of PHYSICS.md section 2 as in-place
//! operations on [`Cov`]. Operator crates compose these instead of re-deriving them; each
//! kernel is tested against a dense nalgebra reference (`tests/kernels.rs`).
//!
//! Every kernel keeps Σ exactly symmetric (packed storage) and rejects non-finite
//! parameters. Kernels named by primal effect: "shear `target` by `source`" means the
//! primal map `l'(z) = l(z')` with `z'_target = z_target + s·z_source`.

use nalgebra::SMatrix;

use crate::linalg::{MAX, Small, psd_pinv, sym_eigen};
use crate::{Axis, Cov, CovError, PSD_RTOL};

/// Relative level below which a diagonal entry of a Schur complement is rounding noise
/// (dimensionless, relative to the same entry before the update): `64 ε ≈ 1.4e-14`.
/// Cancellation in `Σ_aa − Σ_ap Σ_pp⁻¹ Σ_pa` leaves an error of a few ε × `Σ_aa`; what
/// remains below `64 ε` is not information. See `Cov::convolve` and `Cov::integrate`.
pub const SCHUR_SNAP: f64 = 64.0 * f64::EPSILON;

impl<const N: usize> Cov<N> {
    /// The (position, direction) axis pairs of this layout: `[(x, u)]` in flatland,
    /// `[(x, u), (y, v)]` in 3D. Flatland operator definitions apply to each pair.
    pub fn transverse_pairs() -> &'static [(Axis, Axis)] {
        if N >= 4 {
            &[(Axis::X, Axis::U), (Axis::Y, Axis::V)]
        } else {
            &[(Axis::X, Axis::U)]
        }
    }

    /// The direction axes of this layout: `[u]` or `[u, v]`.
    pub fn direction_axes() -> &'static [Axis] {
        if N >= 4 { &[Axis::U, Axis::V] } else { &[Axis::U] }
    }

    /// The spatial axes of this layout: `[x]` or `[x, y]`.
    pub fn spatial_axes() -> &'static [Axis] {
        if N >= 4 { &[Axis::X, Axis::Y] } else { &[Axis::X] }
    }

    /// Rule 1 with a dense matrix: `l'(z) = l(A z)` gives `Σ' = Aᵀ Σ A`.
    ///
    /// # Errors
    /// A non-finite entry in `a`, or an overflowing result.
    pub fn congruence(&mut self, a: &SMatrix<f64, N, N>) -> Result<(), CovError> {
        if a.iter().any(|v| !v.is_finite()) {
            return Err(CovError::NonFinite {
                operator: "congruence".into(),
                parameter: "A".into(),
                value: a.iter().copied().find(|v| !v.is_finite()).unwrap_or(f64::NAN),
            });
        }
        // B = Σ A, then Σ'_ij = Σ_k A_ki B_kj for i ≤ j only (exact symmetry).
        let mut b = [[0.0; N]; N];
        for (k, row) in b.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..N).map(|l| self.get(k, l) * a[(l, j)]).sum();
            }
        }
        let old = *self;
        for i in 0..N {
            for j in i..N {
                self.set(i, j, (0..N).map(|k| a[(k, i)] * b[k][j]).sum());
            }
        }
        self.finish("congruence", old)
    }

    /// Rule 1, elementary shear: `l'(z) = l(z')` with `z'_target = z_target + s·z_source`.
    ///
    /// In the spectrum this adds `s ×` row/column `target` to row/column `source`.
    /// Travel by `d` is `shear(X, U, −d)`; curvature `k` is `shear(U, X, k)`.
    ///
    /// # Errors
    /// Missing axis, `target == source`, non-finite `s`, or an overflowing result.
    #[inline]
    pub fn shear(&mut self, target: Axis, source: Axis, s: f64) -> Result<(), CovError> {
        CovError::check_finite("shear", "s", s)?;
        let (i, j) = two_axes::<N>("shear", target, source)?;
        if s == 0.0 {
            return Ok(());
        }
        // Compute the new column j, check it, then commit: Σ is untouched on overflow.
        let mut col = [0.0; N];
        for (k, c) in col.iter_mut().enumerate() {
            *c = if k == j {
                self.get(j, j) + s * (2.0 * self.get(i, j) + s * self.get(i, i))
            } else {
                self.get(k, j) + s * self.get(k, i)
            };
        }
        if let Some(k) = col.iter().position(|v| !v.is_finite()) {
            return Err(CovError::Overflow {
                operator: "shear".into(),
                row: k.min(j),
                col: k.max(j),
                value: col[k],
            });
        }
        for (k, c) in col.iter().enumerate() {
            self.set(k, j, *c);
        }
        Ok(())
    }

    /// Rule 1, scaling: `l'(z) = l(z')` with `z'_axis = c·z_axis` (a projection by a
    /// cosine is `scale(X, cos θ)`). Row and column `axis` of Σ are multiplied by `c`.
    ///
    /// # Errors
    /// Missing axis, non-finite `c`, or an overflowing result.
    #[inline]
    pub fn scale(&mut self, axis: Axis, c: f64) -> Result<(), CovError> {
        CovError::check_finite("scale", "c", c)?;
        let i = Self::index(axis)?;
        let old = *self;
        for k in 0..N {
            let v = self.get(k, i) * c;
            self.set(k, i, v);
        }
        let v = self.get(i, i) * c;
        self.set(i, i, v);
        self.finish("scale", old)
    }

    /// Rule 1, rotation in the plane of two axes: `l'(z) = l(z')` with
    /// `(z'_a, z'_b) = (cos α·z_a − sin α·z_b, sin α·z_a + cos α·z_b)`, α in radians.
    ///
    /// # Errors
    /// Missing axis, `a == b`, non-finite `angle`.
    #[inline]
    pub fn rotate(&mut self, a: Axis, b: Axis, angle: f64) -> Result<(), CovError> {
        CovError::check_finite("rotate", "angle", angle)?;
        let (i, j) = two_axes::<N>("rotate", a, b)?;
        let (s, c) = angle.sin_cos();
        let old = *self;
        self.rotate_idx(i, j, c, s);
        self.finish("rotate", old)
    }

    #[inline(always)]
    fn rotate_idx(&mut self, i: usize, j: usize, c: f64, s: f64) {
        let sii = self.get(i, i);
        let sij = self.get(i, j);
        let sjj = self.get(j, j);
        for k in 0..N {
            if k != i && k != j {
                let ki = self.get(k, i);
                let kj = self.get(k, j);
                self.set(k, i, c * ki + s * kj);
                self.set(k, j, c * kj - s * ki);
            }
        }
        let cs = c * s;
        self.set(i, i, c * c * sii + 2.0 * cs * sij + s * s * sjj);
        self.set(j, j, s * s * sii - 2.0 * cs * sij + c * c * sjj);
        self.set(i, j, cs * (sjj - sii) + (c * c - s * s) * sij);
    }

    /// Rotation of the 3D tangent frame by `angle` (radians): `(x, y)` and `(u, v)` turn
    /// together, as [`Cov::rotate`] on both pairs.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] in flatland (N = 2, 3); non-finite `angle`.
    pub fn rotate_frame(&mut self, angle: f64) -> Result<(), CovError> {
        CovError::check_finite("rotate_frame", "angle", angle)?;
        let (x, y, u, v) = (
            Self::index(Axis::X)?,
            Self::index(Axis::Y)?,
            Self::index(Axis::U)?,
            Self::index(Axis::V)?,
        );
        let (s, c) = angle.sin_cos();
        let old = *self;
        self.rotate_idx(x, y, c, s);
        self.rotate_idx(u, v, c, s);
        self.finish("rotate_frame", old)
    }

    /// Rule 2 on one axis: multiplying the primal by a window adds its spectrum variance,
    /// `Σ_aa += w` ((cycles/unit)²). A Gaussian window of std `s` has `w = 1/(4π²s²)`.
    ///
    /// # Errors
    /// Missing axis, `w` negative or non-finite, overflow.
    #[inline]
    pub fn add_variance(&mut self, axis: Axis, w: f64) -> Result<(), CovError> {
        CovError::check_non_negative("add_variance", "w", w)?;
        let i = Self::index(axis)?;
        let old = *self;
        let v = self.get(i, i) + w;
        self.set(i, i, v);
        self.finish("add_variance", old)
    }

    /// Rule 2: `Σ' = Σ + W`, with `W` the spectrum covariance of the window on `axes`,
    /// given row-major as `axes.len()²` numbers (symmetric PSD).
    ///
    /// # Errors
    /// Missing or repeated axis, wrong size, `W` not finite, symmetric and PSD; overflow.
    pub fn add_window(&mut self, axes: &[Axis], w: &[f64]) -> Result<(), CovError> {
        let (idx, k) = resolve::<N>("add_window", axes)?;
        let wm = block_from_slice("add_window", "W", k, w)?;
        let old = *self;
        for a in 0..k {
            for b in a..k {
                let v = self.get(idx[a], idx[b]) + wm[a][b];
                self.set(idx[a], idx[b], v);
            }
        }
        self.finish("add_window", old)
    }

    /// Rule 3: convolution along `axes` with a lobe whose spectrum covariance is `S`
    /// (row-major, `axes.len()²` numbers, symmetric PSD):
    /// `Σ' = Σ − Σ Pᵀ (S + P Σ Pᵀ)⁻¹ P Σ`, computed without inverting Σ.
    ///
    /// The convolved block and the cross terms use the forms `Σ_pp (S+Σ_pp)⁻¹ S` and
    /// `Σ_op (S+Σ_pp)⁻¹ S`, which are exactly zero for `S = 0` (a perfectly diffuse lobe
    /// removes all content on those axes) and tend to the identity as `S → ∞` (a mirror:
    /// callers skip the kernel). A singular `S + Σ_pp` uses the pseudo-inverse.
    ///
    /// # Errors
    /// Missing or repeated axis, wrong size, `S` not finite/symmetric/PSD; overflow.
    #[inline]
    pub fn convolve(&mut self, axes: &[Axis], s: &[f64]) -> Result<(), CovError> {
        if let ([axis], [s1]) = (axes, s) {
            // One axis: S is a non-negative number; no eigen-check needed.
            let p = Self::index(*axis)?;
            CovError::check_non_negative("convolve", "S", *s1)?;
            let old = *self;
            self.lobe_product_1(p, *s1);
            return self.finish("convolve", old);
        }
        let (idx, k) = resolve::<N>("convolve", axes)?;
        let sm = block_from_slice("convolve", "S", k, s)?;
        let old = *self;
        self.lobe_product(&idx[..k], &sm);
        self.finish("convolve", old)
    }

    /// Rule 4, in place: integration of the primal over `axes` (lens, shutter, sensor
    /// angle). The kept block becomes the Schur complement
    /// `Σ_kk − Σ_kr Σ_rr⁺ Σ_rk` (pseudo-inverse where Σ_rr is singular) and the
    /// integrated axes become 0: the integrated field no longer depends on them, i.e. it is
    /// constant along them. The same as [`Cov::convolve`] with `S = 0`.
    ///
    /// An integrated axis with zero variance contributes nothing (`Σ_rr⁺ = 0` there).
    ///
    /// # Errors
    /// Missing or repeated axis.
    #[inline]
    pub fn integrate(&mut self, axes: &[Axis]) -> Result<(), CovError> {
        if let [axis] = axes {
            let p = Self::index(*axis)?;
            self.lobe_product_1(p, 0.0);
            return Ok(());
        }
        let (idx, k) = resolve::<N>("integrate", axes)?;
        let old = *self;
        self.lobe_product(&idx[..k], &[[0.0; MAX]; MAX]);
        self.finish("integrate", old)
    }

    /// Shared by rules 3 and 4; `p` are the convolved indices, `s` the lobe spectrum.
    ///
    /// A diagonal `S` (the usual lobe, and integration) is done as one-axis updates
    /// ([`Cov::lobe_product_1`]), which equal the joint update (in information form each
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
            *b = self.get(i, i);
        }
        let mut m = [[0.0; MAX]; MAX];
        for a in 0..k {
            for b in 0..k {
                m[a][b] = s[a][b] + self.get(p[a], p[b]);
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
                *gc = (0..k).map(|d| old.get(oa, p[d]) * minv[d][c]).sum();
            }
            for &ob in &others[ai..] {
                let corr: f64 = (0..k).map(|c| g[c] * old.get(p[c], ob)).sum();
                self.set(oa, ob, old.get(oa, ob) - corr);
            }
        }
        // Σ_op M⁺ S
        for &o in others {
            for b in 0..k {
                let v: f64 = (0..k).map(|c| old.get(o, p[c]) * t[c][b]).sum();
                self.set(o, p[b], v);
            }
        }
        // ½ (Σ_pp M⁺ S + S M⁺ Σ_pp): symmetrised, PSD analytically.
        for a in 0..k {
            for b in a..k {
                let ab: f64 = (0..k).map(|c| old.get(p[a], p[c]) * t[c][b]).sum();
                let ba: f64 = (0..k).map(|c| old.get(p[b], p[c]) * t[c][a]).sum();
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
            *b = self.get(i, i);
        }
        let spp = self.get(p, p);
        let m = s + spp;
        let (inv, t) = if m > 0.0 { (1.0 / m, s / m) } else { (0.0, 0.0) };
        let mut col = [0.0; N];
        for (o, c) in col.iter_mut().enumerate() {
            *c = self.get(o, p);
        }
        for a in 0..N {
            if a == p {
                continue;
            }
            let ga = col[a] * inv;
            for b in a..N {
                if b != p {
                    let v = self.get(a, b) - ga * col[b];
                    self.set(a, b, v);
                }
            }
            self.set(a, p, col[a] * t);
        }
        self.set(p, p, spp * t);
        self.snap_cancelled(&before, &[p]);
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
    fn snap_cancelled(&mut self, before: &[f64; N], p: &[usize]) {
        for a in 0..N {
            let v = self.get(a, a);
            // A negative diagonal is never information, on any axis; nor is anything on
            // an axis that had no content before (Σ e_a = 0 gives Σ' e_a = 0: a lobe or an
            // integration cannot create content, only the general lobe's rounding can).
            let noise = v < 0.0 || before[a] <= 0.0 || (!p.contains(&a) && v <= SCHUR_SNAP * before[a]);
            if noise {
                for b in 0..N {
                    self.set(a, b, 0.0);
                }
            }
        }
    }

    /// Checks the result of a kernel; on overflow restores the input and reports.
    #[inline]
    fn finish(&mut self, op: &str, old: Self) -> Result<(), CovError> {
        if let Err(e) = self.check_finite(op) {
            *self = old;
            return Err(e);
        }
        Ok(())
    }
}

/// Reads a `k × k` row-major symmetric PSD block (a window or lobe spectrum).
pub(crate) fn block_from_slice(op: &str, name: &str, k: usize, w: &[f64]) -> Result<Small, CovError> {
    if w.len() != k * k {
        return Err(CovError::Shape {
            what: format!("{op}: {name}"),
            expected: format!("{} numbers ({k}×{k} row-major)", k * k),
            got: format!("{} numbers", w.len()),
        });
    }
    let mut m = [[0.0; MAX]; MAX];
    let mut scale = 0.0f64;
    for a in 0..k {
        for b in 0..k {
            let v = CovError::check_finite(op, name, w[a * k + b])?;
            m[a][b] = v;
            scale = scale.max(v.abs());
        }
    }
    for a in 0..k {
        for b in (a + 1)..k {
            if (m[a][b] - m[b][a]).abs() > 1e-12 * scale {
                return Err(CovError::NotSymmetric {
                    row: a,
                    col: b,
                    a: m[a][b],
                    b: m[b][a],
                });
            }
            let avg = 0.5 * (m[a][b] + m[b][a]);
            m[a][b] = avg;
            m[b][a] = avg;
        }
    }
    let (vals, _) = sym_eigen(k, &m);
    let tol = PSD_RTOL * vals[..k].iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    if vals[0] < -tol {
        return Err(CovError::NotPsd {
            min_eigenvalue: vals[0],
            tolerance: -tol,
        });
    }
    Ok(m)
}

/// The indices of `axes` in layout `N` (at most `N`, distinct), for kernel `op`.
pub(crate) fn resolve<const N: usize>(op: &str, axes: &[Axis]) -> Result<([usize; MAX], usize), CovError> {
    let mut idx = [0usize; MAX];
    if axes.is_empty() || axes.len() > N {
        return Err(CovError::Shape {
            what: op.into(),
            expected: format!("1 to {N} axes"),
            got: format!("{} axes", axes.len()),
        });
    }
    for (a, axis) in axes.iter().enumerate() {
        idx[a] = Cov::<N>::index(*axis)?;
        if idx[..a].contains(&idx[a]) {
            return Err(CovError::Shape {
                what: op.into(),
                expected: "distinct axes".into(),
                got: format!("`{axis}` twice"),
            });
        }
    }
    Ok((idx, axes.len()))
}

/// The indices of two different axes `a`, `b` of layout `N`, for kernel `op`.
pub(crate) fn two_axes<const N: usize>(op: &str, a: Axis, b: Axis) -> Result<(usize, usize), CovError> {
    let (i, j) = (Cov::<N>::index(a)?, Cov::<N>::index(b)?);
    if i == j {
        return Err(CovError::Shape {
            what: op.into(),
            expected: "two different axes".into(),
            got: format!("{a} and {b}"),
        });
    }
    Ok((i, j))
}
