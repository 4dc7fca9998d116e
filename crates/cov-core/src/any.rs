//! Σ whose layout is known at run time: [`AnyCov`] (a result), [`AnyFactor`] and
//! [`AnySpectrum`] (Σ held in either form, what a chain evaluates and what a snapshot
//! saves). These are the only places that dispatch on the layout; the const-generic
//! [`Cov<N>`] and [`CovFactor<N>`] keep the fast kernels.

use std::fmt;

use crate::{Axis, Cov, CovBlock, CovError, CovFactor, Form, Spectrum, Validity, layout_axes};

/// Applies `$body` to the inner value of an `AnyCov`/`AnyFactor` whatever its layout.
macro_rules! each {
    ($ty:ident, $value:expr, $c:ident => $body:expr) => {
        match $value {
            $ty::Two($c) => $body,
            $ty::Three($c) => $body,
            $ty::Four($c) => $body,
            $ty::Five($c) => $body,
        }
    };
}

/// Builds an `AnyCov`/`AnyFactor` from a generic `$ty<N>` by its layout.
macro_rules! wrap {
    ($any:ident, $v:expr) => {{
        let v = $v;
        if let Some(c) = v.cast::<2>() {
            $any::Two(c)
        } else if let Some(c) = v.cast::<3>() {
            $any::Three(c)
        } else if let Some(c) = v.cast::<4>() {
            $any::Four(c)
        } else {
            // N is 2..=5 (a compile-time assertion in `Cov`): this is N = 5.
            $any::Five(v.cast::<5>().unwrap_or_default())
        }
    }};
}

/// Σ of a layout chosen at run time (a RON path's, say): one of the four [`Cov<N>`].
///
/// ```
/// use cov_core::{AnyCov, Axis, Cov, CovError};
///
/// let c = AnyCov::from(Cov::<4>::gaussian([0.1, 0.1, f64::INFINITY, f64::INFINITY])?);
/// assert_eq!(c.dim(), 4);
/// assert_eq!(c.axes()[2], Axis::U);
/// assert!(c.to::<4>().is_some() && c.to::<2>().is_none());
/// let back = AnyCov::from_rows(&c.rows())?;
/// assert_eq!(back, c);
/// # Ok::<(), CovError>(())
/// ```
#[derive(Clone, Copy, PartialEq)]
pub enum AnyCov {
    /// `x, u`.
    Two(Cov<2>),
    /// `x, u, t`.
    Three(Cov<3>),
    /// `x, y, u, v`.
    Four(Cov<4>),
    /// `x, y, u, v, t`.
    Five(Cov<5>),
}

impl<const N: usize> From<Cov<N>> for AnyCov {
    #[inline]
    fn from(c: Cov<N>) -> Self {
        wrap!(AnyCov, c)
    }
}

impl<const N: usize> From<&Cov<N>> for AnyCov {
    #[inline]
    fn from(c: &Cov<N>) -> Self {
        AnyCov::from(*c)
    }
}

impl AnyCov {
    /// Σ = 0 in layout `n`.
    ///
    /// # Errors
    /// [`CovError::Shape`] unless `n` is 2, 3, 4 or 5.
    pub fn zeros(n: usize) -> Result<AnyCov, CovError> {
        Ok(match n {
            2 => AnyCov::Two(Cov::zeros()),
            3 => AnyCov::Three(Cov::zeros()),
            4 => AnyCov::Four(Cov::zeros()),
            5 => AnyCov::Five(Cov::zeros()),
            _ => return Err(bad_layout("AnyCov", n)),
        })
    }

    /// Σ from `n` rows of `n` numbers (validated as [`Cov::from_matrix`]).
    ///
    /// # Errors
    /// A size other than 2..=5 square, or a matrix that is not a covariance.
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<AnyCov, CovError> {
        let n = rows.len();
        if !(2..=5).contains(&n) || rows.iter().any(|r| r.len() != n) {
            return Err(CovError::Shape {
                what: "Σ".into(),
                expected: "N rows of N numbers, N in 2..=5".into(),
                got: format!(
                    "{n} rows of lengths {:?}",
                    rows.iter().map(Vec::len).collect::<Vec<_>>()
                ),
            });
        }
        fn build<const N: usize>(rows: &[Vec<f64>]) -> Result<AnyCov, CovError> {
            Cov::<N>::from_matrix(&nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| rows[i][j]))
                .map(AnyCov::from)
        }
        match n {
            2 => build::<2>(rows),
            3 => build::<3>(rows),
            4 => build::<4>(rows),
            _ => build::<5>(rows),
        }
    }

    /// A Gaussian light field in layout `n` with primal std `stds[i]` along axis `i`
    /// (`inf`: constant), as [`Cov::gaussian`].
    ///
    /// # Errors
    /// `stds.len() != n`, a layout other than 2..=5, or an invalid std.
    pub fn gaussian(stds: &[f64]) -> Result<AnyCov, CovError> {
        fn build<const N: usize>(stds: &[f64]) -> Result<AnyCov, CovError> {
            let mut a = [0.0; N];
            a.copy_from_slice(stds);
            Cov::<N>::gaussian(a).map(AnyCov::from)
        }
        match stds.len() {
            2 => build::<2>(stds),
            3 => build::<3>(stds),
            4 => build::<4>(stds),
            5 => build::<5>(stds),
            n => Err(bad_layout("AnyCov::gaussian", n)),
        }
    }

    /// A Dirac-like source in layout `n` ([`Cov::dirac`]).
    ///
    /// # Errors
    /// As [`Cov::dirac`]; a layout other than 2..=5.
    pub fn dirac(n: usize, scene_scale: f64, relative_size: f64) -> Result<AnyCov, CovError> {
        Ok(match n {
            2 => AnyCov::Two(Cov::dirac(scene_scale, relative_size)?),
            3 => AnyCov::Three(Cov::dirac(scene_scale, relative_size)?),
            4 => AnyCov::Four(Cov::dirac(scene_scale, relative_size)?),
            5 => AnyCov::Five(Cov::dirac(scene_scale, relative_size)?),
            _ => return Err(bad_layout("AnyCov::dirac", n)),
        })
    }

    /// The layout size N.
    pub fn dim(&self) -> usize {
        each!(AnyCov, self, c => c.dim())
    }

    /// The axes of the layout, in order.
    pub fn axes(&self) -> &'static [Axis] {
        layout_axes(self.dim()).unwrap_or(&[])
    }

    /// The typed Σ when the layout is `N`.
    pub fn to<const N: usize>(&self) -> Option<Cov<N>> {
        each!(AnyCov, self, c => c.cast::<N>())
    }

    /// Entry `Σ_ij` by index (`i, j < dim`; panics otherwise, as [`Cov::get`]).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        each!(AnyCov, self, c => c.get(i, j))
    }

    /// Sets `Σ_ij = Σ_ji = value` by index (as [`Cov::set`]: no PSD check).
    pub fn set(&mut self, i: usize, j: usize, value: f64) {
        each!(AnyCov, self, c => c.set(i, j, value))
    }

    /// Entry `Σ_ab` by axis.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`].
    pub fn at(&self, a: Axis, b: Axis) -> Result<f64, CovError> {
        each!(AnyCov, self, c => c.at(a, b))
    }

    /// The rows of Σ.
    pub fn rows(&self) -> Vec<Vec<f64>> {
        let n = self.dim();
        (0..n).map(|i| (0..n).map(|j| self.get(i, j)).collect()).collect()
    }

    /// √Σ_ii per axis (cycles per unit).
    pub fn bandwidths(&self) -> Vec<f64> {
        each!(AnyCov, self, c => c.bandwidths().to_vec())
    }

    /// Whether every entry is finite.
    pub fn is_finite(&self) -> bool {
        each!(AnyCov, self, c => c.is_finite())
    }

    /// Largest absolute entry.
    pub fn max_abs(&self) -> f64 {
        each!(AnyCov, self, c => c.max_abs())
    }

    /// Eigenvalues, ascending.
    pub fn eigenvalues(&self) -> Vec<f64> {
        each!(AnyCov, self, c => c.eigenvalues().to_vec())
    }

    /// Symmetry and PSD report ([`Cov::validity`]).
    pub fn validity(&self) -> Validity {
        each!(AnyCov, self, c => c.validity())
    }

    /// The whole matrix as a [`CovBlock`].
    pub fn block(&self) -> CovBlock {
        each!(AnyCov, self, c => c.block())
    }

    /// The marginal block on `axes` ([`Cov::marginal`]).
    ///
    /// # Errors
    /// As [`Cov::marginal`].
    pub fn marginal(&self, axes: &[Axis]) -> Result<CovBlock, CovError> {
        each!(AnyCov, self, c => c.marginal(axes))
    }

    /// The block on `keep` after integrating every other axis ([`Cov::integrated`]).
    ///
    /// # Errors
    /// As [`Cov::integrated`].
    pub fn integrated(&self, keep: &[Axis]) -> Result<CovBlock, CovError> {
        each!(AnyCov, self, c => c.integrated(keep))
    }

    /// This Σ as a [`Spectrum`] in covariance form.
    pub fn as_spectrum_mut(&mut self) -> &mut dyn Spectrum {
        each!(AnyCov, self, c => c as &mut dyn Spectrum)
    }
}

impl fmt::Debug for AnyCov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        each!(AnyCov, self, c => fmt::Debug::fmt(c, f))
    }
}

impl fmt::Display for AnyCov {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        each!(AnyCov, self, c => fmt::Display::fmt(c, f))
    }
}

impl serde::Serialize for AnyCov {
    /// As its rows (like [`Cov`]).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        each!(AnyCov, self, c => c.serialize(s))
    }
}

impl<'de> serde::Deserialize<'de> for AnyCov {
    /// From rows, validated.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let rows = Vec::<Vec<f64>>::deserialize(d)?;
        AnyCov::from_rows(&rows).map_err(serde::de::Error::custom)
    }
}

impl approx::AbsDiffEq for AnyCov {
    type Epsilon = f64;
    fn default_epsilon() -> f64 {
        f64::EPSILON
    }
    fn abs_diff_eq(&self, other: &Self, epsilon: f64) -> bool {
        self.dim() == other.dim()
            && (0..self.dim())
                .all(|i| (0..self.dim()).all(|j| self.get(i, j).abs_diff_eq(&other.get(i, j), epsilon)))
    }
}

impl approx::RelativeEq for AnyCov {
    fn default_max_relative() -> f64 {
        f64::EPSILON
    }
    fn relative_eq(&self, other: &Self, epsilon: f64, max_relative: f64) -> bool {
        self.dim() == other.dim()
            && (0..self.dim()).all(|i| {
                (0..self.dim()).all(|j| {
                    self.get(i, j)
                        .relative_eq(&other.get(i, j), epsilon, max_relative)
                })
            })
    }
}

/// A square-root factor of a layout chosen at run time: one of the four [`CovFactor<N>`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnyFactor {
    /// `x, u`.
    Two(CovFactor<2>),
    /// `x, u, t`.
    Three(CovFactor<3>),
    /// `x, y, u, v`.
    Four(CovFactor<4>),
    /// `x, y, u, v, t`.
    Five(CovFactor<5>),
}

impl<const N: usize> From<CovFactor<N>> for AnyFactor {
    #[inline]
    fn from(f: CovFactor<N>) -> Self {
        wrap!(AnyFactor, f)
    }
}

/// Σ held in either form, in a layout chosen at run time: what [`crate::Chain`]
/// evaluates a path in, and what [`Spectrum::snapshot`] saves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnySpectrum {
    /// Covariance form.
    Covariance(AnyCov),
    /// Square-root form.
    SquareRoot(AnyFactor),
}

impl<const N: usize> From<Cov<N>> for AnySpectrum {
    fn from(c: Cov<N>) -> Self {
        AnySpectrum::Covariance(AnyCov::from(c))
    }
}

impl<const N: usize> From<CovFactor<N>> for AnySpectrum {
    fn from(f: CovFactor<N>) -> Self {
        AnySpectrum::SquareRoot(AnyFactor::from(f))
    }
}

impl AnySpectrum {
    /// `c` held in `form`.
    pub fn new(form: Form, c: &AnyCov) -> AnySpectrum {
        match form {
            Form::Covariance => AnySpectrum::Covariance(*c),
            Form::SquareRoot => {
                AnySpectrum::SquareRoot(each!(AnyCov, c, c => AnyFactor::from(CovFactor::from_cov(c))))
            }
        }
    }

    /// Σ now.
    ///
    /// # Errors
    /// An overflow of Σ (square-root form).
    pub fn cov(&self) -> Result<AnyCov, CovError> {
        match self {
            AnySpectrum::Covariance(c) => Ok(*c),
            AnySpectrum::SquareRoot(f) => each!(AnyFactor, f, f => f.to_cov().map(AnyCov::from)),
        }
    }

    /// Σ as a typed covariance when the layout is `N` (`None` otherwise, or on overflow).
    pub fn to_cov<const N: usize>(&self) -> Option<Cov<N>> {
        match self {
            AnySpectrum::Covariance(c) => c.to::<N>(),
            AnySpectrum::SquareRoot(f) => each!(AnyFactor, f, f => f.cast::<N>())?.to_cov().ok(),
        }
    }

    /// Σ as a typed factor when the layout is `N`.
    pub fn to_factor<const N: usize>(&self) -> Option<CovFactor<N>> {
        match self {
            AnySpectrum::Covariance(c) => c.to::<N>().map(|c| CovFactor::from_cov(&c)),
            AnySpectrum::SquareRoot(f) => each!(AnyFactor, f, f => f.cast::<N>()),
        }
    }

    /// The held Σ as the [`Spectrum`] operators act on.
    pub fn as_spectrum_mut(&mut self) -> &mut dyn Spectrum {
        match self {
            AnySpectrum::Covariance(c) => c.as_spectrum_mut(),
            AnySpectrum::SquareRoot(f) => each!(AnyFactor, f, f => f as &mut dyn Spectrum),
        }
    }
}

fn bad_layout(what: &str, n: usize) -> CovError {
    CovError::Shape {
        what: what.into(),
        expected: "layout 2 (x,u), 3 (x,u,t), 4 (x,y,u,v) or 5 (x,y,u,v,t)".into(),
        got: format!("{n}"),
    }
}
