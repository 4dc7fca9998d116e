//! The covariance type [`Cov<N>`].

use std::f64::consts::PI;
use std::fmt;

use nalgebra::SMatrix;

use crate::CovError;
use crate::axis::{Axis, axis_index, layout_axes};
use crate::linalg::{MAX, Small, sym_eigen};

/// `4π²`: the factor between a Gaussian's primal covariance and its spectrum covariance
/// (`Σ = C⁻¹ / 4π²`, docs/physics.md section 1).
pub const FOUR_PI_SQ: f64 = 4.0 * PI * PI;

/// Relative tolerance of the positive semi-definiteness checks (dimensionless): a
/// symmetric matrix counts as PSD when its smallest eigenvalue is at least
/// `−PSD_RTOL × ‖Σ‖₂`.
pub const PSD_RTOL: f64 = 1e-12;

/// Default relative size of a Dirac-like source: its primal std is
/// `DIRAC_RELATIVE_SIZE × scene_scale` (see [`Cov::dirac`]).
pub const DIRAC_RELATIVE_SIZE: f64 = 1e-6;

/// Packed storage size: the upper triangle of a 5×5 matrix.
const PACKED: usize = MAX * (MAX + 1) / 2;

/// The covariance Σ of the local amplitude spectrum of radiance around a ray, for the
/// layout of size `N` (2: x,u; 3: x,u,t; 4: x,y,u,v; 5: x,y,u,v,t).
///
/// Entries are in (cycles per unit)² of the axes involved (docs/physics.md section 1).
/// Storage is the packed upper triangle, so Σ is symmetric by construction: every setter
/// writes `Σ_ij` and `Σ_ji` at once. Only `N ∈ {2, 3, 4, 5}` compiles.
#[derive(Clone, Copy, PartialEq)]
pub struct Cov<const N: usize> {
    p: [f64; PACKED],
}

impl<const N: usize> Cov<N> {
    /// Compile-time guard: only the four layouts of docs/physics.md exist.
    const LAYOUT_OK: () = assert!(N >= 2 && N <= 5, "covtrace layouts have N = 2, 3, 4 or 5");

    /// Number of packed entries, `N(N+1)/2`.
    pub const PACKED_LEN: usize = N * (N + 1) / 2;

    #[inline(always)]
    pub(crate) const fn idx(i: usize, j: usize) -> usize {
        let (i, j) = if i <= j { (i, j) } else { (j, i) };
        i * N - i * (i + 1) / 2 + j
    }

    /// [`Cov::idx`] as a table, for indices known only at run time (the checked kernels):
    /// one load instead of a swap, a multiply and a shift. Entries beyond `N` are unused.
    const IX: [[u8; MAX]; MAX] = {
        let mut t = [[0; MAX]; MAX];
        let mut i = 0;
        while i < N && i < MAX {
            let mut j = 0;
            while j < N && j < MAX {
                t[i][j] = Self::idx(i, j) as u8;
                j += 1;
            }
            i += 1;
        }
        t
    };

    /// Σ = 0: a field constant along every axis (no frequency content).
    pub fn zeros() -> Self {
        #[allow(clippy::let_unit_value)]
        let () = Self::LAYOUT_OK;
        Cov { p: [0.0; PACKED] }
    }

    /// The axes of this layout, in order.
    pub fn axes() -> &'static [Axis] {
        // Invariant: LAYOUT_OK restricts N to 2..=5, for which layout_axes is Some.
        layout_axes(N).unwrap_or(&[])
    }

    /// Index of `axis` in this layout.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] if the layout has no such axis (e.g. `t` when `N = 4`).
    #[inline]
    pub fn index(axis: Axis) -> Result<usize, CovError> {
        axis_index(N, axis)
    }

    /// Entry `Σ_ij` by index. Indices must be `< N` (panics otherwise: a programming error,
    /// never user input; use [`Cov::at`] for axis names).
    #[inline(always)]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < N && j < N, "index ({i},{j}) out of range for N = {N}");
        self.p[Self::IX[i][j] as usize]
    }

    /// [`Cov::get`] for the kernels: one 8-byte load, never merged with a neighbour's
    /// into a 16-byte load, which could not be forwarded from the two 8-byte stores of the
    /// kernel before and would wait for them (docs/speed.md, "Store forwarding").
    #[inline(always)]
    pub(crate) fn load(&self, i: usize, j: usize) -> f64 {
        assert!(i < N && j < N, "index ({i},{j}) out of range for N = {N}");
        // SAFETY: a reference to an element of `self.p`, valid and aligned for the read.
        unsafe { std::ptr::read_volatile(&self.p[Self::IX[i][j] as usize]) }
    }

    /// Sets `Σ_ij = Σ_ji = value` by index. Indices must be `< N`. This does not check
    /// positive semi-definiteness; kernels and [`Cov::from_matrix`] are the safe ways in.
    #[inline(always)]
    pub fn set(&mut self, i: usize, j: usize, value: f64) {
        assert!(i < N && j < N, "index ({i},{j}) out of range for N = {N}");
        self.p[Self::IX[i][j] as usize] = value;
    }

    /// Entry `Σ_ab` by axis.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] if either axis is not in the layout.
    pub fn at(&self, a: Axis, b: Axis) -> Result<f64, CovError> {
        Ok(self.get(Self::index(a)?, Self::index(b)?))
    }

    /// The same matrix as a `Cov<M>` when `M == N` (`None` otherwise): lets code that
    /// dispatches on the layout at run time move between a generic `N` and a concrete
    /// size without copying entry by entry.
    #[inline]
    pub fn cast<const M: usize>(&self) -> Option<Cov<M>> {
        (M == N).then_some(Cov { p: self.p })
    }

    /// The packed upper triangle, row by row (`N(N+1)/2` values).
    pub fn packed(&self) -> &[f64] {
        &self.p[..Self::PACKED_LEN]
    }

    /// Diagonal Σ from per-axis variances of the spectrum ((cycles/unit)²).
    ///
    /// # Errors
    /// A NaN, infinite or negative variance.
    pub fn from_diagonal(variances: [f64; N]) -> Result<Self, CovError> {
        let mut c = Self::zeros();
        for (i, v) in variances.iter().enumerate() {
            let name = Self::axes()[i].name();
            crate::spec::Arg::new("Cov::from_diagonal", name, *v).non_negative()?;
            c.set(i, i, *v);
        }
        Ok(c)
    }

    /// Σ of a Gaussian light field with primal standard deviation `stds[i]` along axis `i`
    /// (metres, tangent units or seconds): `Σ_ii = 1 / (4π² s_i²)`.
    ///
    /// `f64::INFINITY` means constant along that axis (`Σ_ii = 0`).
    ///
    /// # Errors
    /// A NaN, zero or negative std (a zero std is a Dirac: use [`Cov::dirac`]).
    pub fn gaussian(stds: [f64; N]) -> Result<Self, CovError> {
        let mut c = Self::zeros();
        for (i, s) in stds.iter().enumerate() {
            let out_of_range = |expected: &str| CovError::OutOfRange {
                operator: "Cov::gaussian".into(),
                parameter: format!("std.{}", Self::axes()[i].name()),
                value: *s,
                expected: expected.into(),
            };
            if s.is_nan() || *s <= 0.0 {
                return Err(out_of_range("must be > 0 (f64::INFINITY for a constant axis)"));
            }
            let v = if s.is_infinite() {
                0.0
            } else {
                1.0 / (FOUR_PI_SQ * s * s)
            };
            if !v.is_finite() {
                return Err(out_of_range("too small: 1/(4π² s²) overflows f64"));
            }
            c.set(i, i, v);
        }
        Ok(c)
    }

    /// Σ of a Gaussian light field with full primal covariance `c` (units² of the axes):
    /// `Σ = C⁻¹ / 4π²`.
    ///
    /// # Errors
    /// Non-finite entries, an asymmetric matrix, or a `c` that is not positive definite.
    pub fn from_primal_covariance(c: &SMatrix<f64, N, N>) -> Result<Self, CovError> {
        crate::spectrum::symmetric("Cov::from_primal_covariance", "c", N, |i, j| c[(i, j)])?;
        let chol = nalgebra::Cholesky::new(*c).ok_or_else(|| {
            let mut a = [[0.0; MAX]; MAX];
            for (i, row) in a.iter_mut().enumerate().take(N) {
                for (j, v) in row.iter_mut().enumerate().take(N) {
                    *v = c[(i, j)];
                }
            }
            CovError::NotPsd {
                min_eigenvalue: sym_eigen(N, &a).0[0],
                tolerance: 0.0,
            }
        })?;
        let inv = chol.inverse() / FOUR_PI_SQ;
        let mut out = Self::zeros();
        for i in 0..N {
            for j in i..N {
                out.set(i, j, 0.5 * (inv[(i, j)] + inv[(j, i)]));
            }
        }
        out.check_finite("Cov::from_primal_covariance")?;
        Ok(out)
    }

    /// A Dirac-like (point or pinhole) source: unbounded frequency content in position,
    /// none in direction (a point emits the same radiance in every nearby direction).
    ///
    /// An exact Dirac has infinite Σ, which no finite arithmetic carries. This source is a
    /// Gaussian of primal std `relative_size × scene_scale` on the spatial axes (`x`, and
    /// `y` in 3D), constant along `u`, `v` and `t`. The bound is relative to the scene so it
    /// stays far above every other frequency of the scene whatever its units:
    /// [`DIRAC_RELATIVE_SIZE`] = 1e-6 is the recommended `relative_size` (a point one
    /// millionth of the scene). Anything computed from it that depends on the bound (e.g.
    /// Σ_xx at the sensor of an in-focus point) scales as `1 / relative_size²`; quantities
    /// that do not, converge as `relative_size → 0`.
    ///
    /// # Errors
    /// Non-finite or non-positive `scene_scale` (m) or `relative_size`.
    pub fn dirac(scene_scale: f64, relative_size: f64) -> Result<Self, CovError> {
        crate::arg!("Cov::dirac", scene_scale).positive()?;
        crate::arg!("Cov::dirac", relative_size).positive()?;
        let s = scene_scale * relative_size;
        let v = 1.0 / (FOUR_PI_SQ * s * s);
        let mut c = Self::zeros();
        for axis in [Axis::X, Axis::Y] {
            if let Ok(i) = Self::index(axis) {
                c.set(i, i, v);
            }
        }
        c.check_finite("Cov::dirac")?;
        Ok(c)
    }

    /// Builds Σ from a dense matrix, checking that it is finite, symmetric (to
    /// `1e-12 × max|entry|`, then averaged to exact symmetry) and PSD (see [`PSD_RTOL`]).
    ///
    /// # Errors
    /// [`CovError::NonFinite`] (an entry, named `m[row·N + col]`), [`CovError::NotSymmetric`],
    /// [`CovError::NotPsd`].
    pub fn from_matrix(m: &SMatrix<f64, N, N>) -> Result<Self, CovError> {
        let m = crate::spectrum::symmetric("Cov::from_matrix", "m", N, |i, j| m[(i, j)])?;
        let mut c = Self::zeros();
        for i in 0..N {
            for j in i..N {
                c.set(i, j, m[i][j]);
            }
        }
        let report = c.validity();
        if !report.psd {
            return Err(CovError::NotPsd {
                min_eigenvalue: report.min_eigenvalue,
                tolerance: -report.tolerance,
            });
        }
        Ok(c)
    }

    /// The dense matrix (nalgebra), exactly symmetric.
    pub fn to_matrix(&self) -> SMatrix<f64, N, N> {
        SMatrix::from_fn(|i, j| self.get(i, j))
    }

    /// Copies the matrix into the fixed array the small kernels use.
    pub(crate) fn to_small(self) -> Small {
        let mut a = [[0.0; MAX]; MAX];
        for (i, row) in a.iter_mut().enumerate().take(N) {
            for (j, v) in row.iter_mut().enumerate().take(N) {
                *v = self.get(i, j);
            }
        }
        a
    }

    /// Checks every entry is finite.
    ///
    /// # Errors
    /// [`CovError::Overflow`] naming `operator` and the first non-finite entry.
    #[inline]
    pub fn check_finite(&self, operator: &str) -> Result<(), CovError> {
        for i in 0..N {
            for j in i..N {
                let v = self.get(i, j);
                if !v.is_finite() {
                    return Err(CovError::overflow(operator, (i, j, v)));
                }
            }
        }
        Ok(())
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        self.packed().iter().all(|v| v.is_finite())
    }

    /// Largest absolute entry (the max norm); 0 for Σ = 0.
    pub fn max_abs(&self) -> f64 {
        self.packed().iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    /// Frobenius norm, computed with scaling so entries up to 1e300 do not overflow.
    pub fn norm(&self) -> f64 {
        let s = self.max_abs();
        if s == 0.0 || !s.is_finite() {
            return s;
        }
        let mut acc = 0.0;
        for i in 0..N {
            for j in 0..N {
                let v = self.get(i, j) / s;
                acc += v * v;
            }
        }
        s * acc.sqrt()
    }

    /// Eigenvalues, ascending (Jacobi; robust for entries from 1e-300 to 1e300).
    pub fn eigenvalues(&self) -> [f64; N] {
        // Decomposed at unit scale (the largest entry in [1, 2)), so that entries near
        // f64's limits do not overflow inside the iteration; eigenvalues scale with Σ. The
        // scale is a power of two: scaling is exact, the same bits as unscaled.
        let mut a = self.to_small();
        let largest = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        // 1 (exact) where Σ is 0 or not finite, or the power of two underflows.
        let p2 = 2f64.powi(largest.log2().floor() as i32);
        let scale = if largest > 0.0 && largest.is_finite() && p2 > 0.0 {
            p2
        } else {
            1.0
        };
        a.iter_mut().flatten().for_each(|v| *v /= scale);
        let (vals, _) = sym_eigen(N, &a);
        std::array::from_fn(|i| vals[i] * scale)
    }

    /// Numerical health of Σ: finiteness, positive semi-definiteness, condition number.
    pub fn validity(&self) -> Validity {
        let finite = self.is_finite();
        if !finite {
            return Validity {
                finite,
                psd: false,
                min_eigenvalue: f64::NAN,
                max_eigenvalue: f64::NAN,
                tolerance: f64::NAN,
                condition: f64::NAN,
            };
        }
        let ev = self.eigenvalues();
        let min = ev[0];
        let max = ev[N - 1];
        let norm2 = min.abs().max(max.abs());
        let tolerance = PSD_RTOL * norm2;
        let condition = if max == 0.0 {
            1.0
        } else if min <= 0.0 {
            f64::INFINITY
        } else {
            max / min
        };
        Validity {
            finite,
            psd: min >= -tolerance,
            min_eigenvalue: min,
            max_eigenvalue: max,
            tolerance,
            condition,
        }
    }
}

impl<const N: usize> Default for Cov<N> {
    fn default() -> Self {
        Self::zeros()
    }
}

/// The numerical health of a covariance (see [`Cov::validity`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Validity {
    /// Every entry is finite.
    pub finite: bool,
    /// Smallest eigenvalue `≥ −tolerance`.
    pub psd: bool,
    /// Smallest eigenvalue ((cycles/unit)²; mixed units when axes differ).
    pub min_eigenvalue: f64,
    /// Largest eigenvalue.
    pub max_eigenvalue: f64,
    /// `PSD_RTOL × ‖Σ‖₂`: how negative the smallest eigenvalue may be from rounding.
    pub tolerance: f64,
    /// `λ_max / λ_min`: 1 for Σ = 0, infinite for a singular Σ ≠ 0.
    pub condition: f64,
}

impl Validity {
    /// Finite and PSD (Σ is always exactly symmetric by construction).
    pub fn is_valid(&self) -> bool {
        self.finite && self.psd
    }
}

impl fmt::Display for Validity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "finite: {}, symmetric: true, PSD: {} (λmin {:.3e}, tolerance {:.1e}), λmax {:.3e}, condition {:.3e}",
            self.finite, self.psd, self.min_eigenvalue, self.tolerance, self.max_eigenvalue, self.condition
        )
    }
}

impl<const N: usize> From<Cov<N>> for SMatrix<f64, N, N> {
    fn from(c: Cov<N>) -> Self {
        c.to_matrix()
    }
}

impl<const N: usize> TryFrom<SMatrix<f64, N, N>> for Cov<N> {
    type Error = CovError;
    fn try_from(m: SMatrix<f64, N, N>) -> Result<Self, CovError> {
        Cov::from_matrix(&m)
    }
}

impl<const N: usize> fmt::Debug for Cov<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Cov<{N}>[")?;
        for i in 0..N {
            if i > 0 {
                write!(f, "; ")?;
            }
            for j in 0..N {
                if j > 0 {
                    write!(f, ", ")?;
                }
                write!(f, "{:e}", self.get(i, j))?;
            }
        }
        write!(f, "]")
    }
}

/// A table with axis names: one row per axis.
impl<const N: usize> fmt::Display for Cov<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "   ")?;
        for a in Self::axes() {
            write!(f, " {:>11}", a.name())?;
        }
        for (i, a) in Self::axes().iter().enumerate() {
            write!(f, "\n {} ", a.name())?;
            for j in 0..N {
                write!(f, " {:>11.4e}", self.get(i, j))?;
            }
        }
        Ok(())
    }
}

impl<const N: usize> approx::AbsDiffEq for Cov<N> {
    type Epsilon = f64;
    fn default_epsilon() -> f64 {
        f64::EPSILON
    }
    fn abs_diff_eq(&self, other: &Self, epsilon: f64) -> bool {
        self.packed()
            .iter()
            .zip(other.packed())
            .all(|(a, b)| a.abs_diff_eq(b, epsilon))
    }
}

impl<const N: usize> approx::RelativeEq for Cov<N> {
    fn default_max_relative() -> f64 {
        f64::EPSILON
    }
    fn relative_eq(&self, other: &Self, epsilon: f64, max_relative: f64) -> bool {
        self.packed()
            .iter()
            .zip(other.packed())
            .all(|(a, b)| a.relative_eq(b, epsilon, max_relative))
    }
}

impl<const N: usize> serde::Serialize for Cov<N> {
    /// Serialises as `N` rows of `N` numbers.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<Vec<f64>> = (0..N).map(|i| (0..N).map(|j| self.get(i, j)).collect()).collect();
        rows.serialize(s)
    }
}

impl<'de, const N: usize> serde::Deserialize<'de> for Cov<N> {
    /// Reads `N` rows of `N` numbers and validates them with [`Cov::from_matrix`].
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let rows: Vec<Vec<f64>> = Vec::deserialize(d)?;
        if rows.len() != N || rows.iter().any(|r| r.len() != N) {
            return Err(D::Error::custom(format!("expected {N} rows of {N} numbers")));
        }
        let m = SMatrix::<f64, N, N>::from_fn(|i, j| rows[i][j]);
        Cov::from_matrix(&m).map_err(D::Error::custom)
    }
}
