//! Queries: what a renderer reads off Σ (docs/physics.md section 4).

use crate::Spectrum;
use crate::spectrum::resolve;
use std::fmt;

use nalgebra::DMatrix;

use crate::linalg::{MAX, Small, sym_eigen};
use crate::{Axis, Cov, CovError, FOUR_PI_SQ};

/// Default Nyquist factor `k` (dimensionless): a spectrum of std `σ` along an axis is
/// taken to extend to `±k·σ`, so samples must be spaced at most `1 / (2·k·σ)` apart.
/// `k = 2` keeps about 95% of a Gaussian spectrum's energy inside the band.
pub const NYQUIST_K: f64 = 2.0;

/// A covariance restricted to a subset of axes: the result of [`Cov::marginal`] or
/// [`Cov::integrated`], and the input of the image-space queries.
#[derive(Clone, PartialEq)]
pub struct CovBlock {
    axes: Vec<Axis>,
    m: Small,
}

impl<const N: usize> Cov<N> {
    /// Spectrum bandwidth along `axis`: `√Σ_aa` (cycles per unit).
    ///
    /// # Errors
    /// [`CovError::MissingAxis`].
    pub fn bandwidth(&self, axis: Axis) -> Result<f64, CovError> {
        let i = Self::index(axis)?;
        Ok(self.get(i, i).max(0.0).sqrt())
    }

    /// Bandwidths along every axis of the layout, in order.
    pub fn bandwidths(&self) -> [f64; N] {
        std::array::from_fn(|i| self.get(i, i).max(0.0).sqrt())
    }

    /// The sub-block on `axes` (in the given order): the spectrum's marginal, i.e. the
    /// primal light field sliced through the ray (other coordinates held at 0).
    ///
    /// # Errors
    /// Missing or repeated axis, or an empty list.
    pub fn marginal(&self, axes: &[Axis]) -> Result<CovBlock, CovError> {
        let (idx, k) = resolve(N, "marginal", axes)?;
        let mut m = [[0.0; MAX]; MAX];
        for (a, &i) in idx[..k].iter().enumerate() {
            for (b, &j) in idx[..k].iter().enumerate() {
                m[a][b] = self.get(i, j);
            }
        }
        Ok(CovBlock {
            axes: axes.to_vec(),
            m,
        })
    }

    /// The covariance of the primal integrated over every axis not in `keep` (rule 4:
    /// the spectrum sliced at zero there): `Σ_kk − Σ_kr Σ_rr⁺ Σ_rk`. This is what a sensor
    /// sees after aperture, shutter and angular integration.
    ///
    /// # Errors
    /// Missing or repeated axis, or an empty list.
    pub fn integrated(&self, keep: &[Axis]) -> Result<CovBlock, CovError> {
        resolve(N, "integrated", keep)?;
        let dropped: Vec<Axis> = Self::axes()
            .iter()
            .copied()
            .filter(|a| !keep.contains(a))
            .collect();
        let mut c = *self;
        if !dropped.is_empty() {
            c.integrate(&dropped)?;
        }
        c.marginal(keep)
    }

    /// The whole matrix as a block over all axes.
    pub fn block(&self) -> CovBlock {
        CovBlock {
            axes: Self::axes().to_vec(),
            m: self.to_small(),
        }
    }
}

/// The primal reconstruction filter that matches a spectrum (see
/// [`CovBlock::reconstruction_filter`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Filter {
    /// Axes of the filter, in order.
    pub axes: Vec<Axis>,
    /// Primal covariance of the Gaussian filter (units² of the axes).
    pub covariance: DMatrix<f64>,
    /// Standard deviations along the principal axes, ascending (units of the axes).
    pub extents: Vec<f64>,
    /// Principal directions: column `i` goes with `extents[i]`.
    pub directions: DMatrix<f64>,
    /// Whether the extent was clamped by `max_extent` along some direction (Σ singular or
    /// nearly so there: the signal is smooth beyond what the filter may cover).
    pub clamped: bool,
}

impl CovBlock {
    /// Axes of the block, in order.
    pub fn axes(&self) -> &[Axis] {
        &self.axes
    }

    /// Size of the block.
    pub fn len(&self) -> usize {
        self.axes.len()
    }

    /// Whether the block has no axes (never true for blocks built by cov-core).
    pub fn is_empty(&self) -> bool {
        self.axes.is_empty()
    }

    /// Entry `(i, j)`; indices must be `< len()`.
    #[inline]
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(i < self.len() && j < self.len(), "index out of range");
        self.m[i][j]
    }

    /// Dense copy.
    pub fn to_dmatrix(&self) -> DMatrix<f64> {
        let n = self.len();
        DMatrix::from_fn(n, n, |i, j| self.m[i][j])
    }

    /// `√Σ_ii` for each axis (cycles per unit).
    pub fn bandwidths(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.m[i][i].max(0.0).sqrt()).collect()
    }

    /// Eigenvalues, ascending.
    pub fn eigenvalues(&self) -> Vec<f64> {
        let (vals, _) = sym_eigen(self.len(), &self.m);
        vals[..self.len()].to_vec()
    }

    /// The spectrum's volume `√det Σ` (product of the units of the axes, in cycles).
    /// Zero when Σ is singular (negative rounding noise counts as zero).
    pub fn spectrum_volume(&self) -> f64 {
        let vals = self.eigenvalues();
        if vals.iter().any(|v| *v <= 0.0) {
            return 0.0;
        }
        vals.iter().map(|v| v.sqrt()).product()
    }

    /// Sampling density over the block's axes: samples per unit volume of the primal
    /// domain (e.g. per m² of image plane × per tangent² of lens × per s of shutter), by
    /// Nyquist with factor `k` (see [`NYQUIST_K`]): `(2k)ⁿ √det Σ`.
    ///
    /// # Errors
    /// Non-finite or non-positive `k`.
    pub fn sampling_density(&self, k: f64) -> Result<f64, CovError> {
        crate::arg!("sampling_density", k).positive()?;
        Ok((2.0 * k).powi(self.len() as i32) * self.spectrum_volume())
    }

    /// The Gaussian reconstruction filter whose spectrum matches Σ: primal covariance
    /// `(4π² Σ)⁻¹`, regularised where Σ is singular.
    ///
    /// `max_extent[i]` (units of axis `i`, > 0) is the largest filter std allowed along axis
    /// `i` (e.g. a few pixels, or the scene size). Σ is rescaled by `D = diag(max_extent)`
    /// to the dimensionless `Σ̃ = D Σ D`; eigenvalues of `Σ̃` are floored at `1/(4π²)`
    /// (a filter std of 1 in those units, i.e. `max_extent`), and the filter is
    /// `D (4π² Σ̃_reg)⁻¹ D`. A zero spectrum gives the widest allowed filter.
    ///
    /// # Errors
    /// Wrong number of extents, non-finite or non-positive extents.
    pub fn reconstruction_filter(&self, max_extent: &[f64]) -> Result<Filter, CovError> {
        let n = self.len();
        if max_extent.len() != n {
            return Err(CovError::Shape {
                what: "reconstruction_filter: max_extent".into(),
                expected: format!("{n} values (one per axis)"),
                got: format!("{} values", max_extent.len()),
            });
        }
        for k in 0..n {
            crate::arg!("reconstruction_filter", max_extent[k]).positive()?;
        }
        let mut st = [[0.0; MAX]; MAX];
        for i in 0..n {
            for j in 0..n {
                st[i][j] = self.m[i][j] * max_extent[i] * max_extent[j];
            }
        }
        let (vals, vecs) = sym_eigen(n, &st);
        let floor = 1.0 / FOUR_PI_SQ;
        let mut clamped = false;
        let mut f = DMatrix::zeros(n, n);
        for k in 0..n {
            let lam = if vals[k] < floor {
                clamped = true;
                floor
            } else {
                vals[k]
            };
            let w = 1.0 / (FOUR_PI_SQ * lam);
            for i in 0..n {
                for j in 0..n {
                    f[(i, j)] += vecs[i][k] * vecs[j][k] * w * max_extent[i] * max_extent[j];
                }
            }
        }
        let f = (&f + f.transpose()) * 0.5;
        let mut fs = [[0.0; MAX]; MAX];
        for i in 0..n {
            for j in 0..n {
                fs[i][j] = f[(i, j)];
            }
        }
        let (fv, fvec) = sym_eigen(n, &fs);
        Ok(Filter {
            axes: self.axes.clone(),
            covariance: f,
            extents: fv[..n].iter().map(|v| v.max(0.0).sqrt()).collect(),
            directions: DMatrix::from_fn(n, n, |i, j| fvec[i][j]),
            clamped,
        })
    }
}

impl fmt::Debug for CovBlock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "CovBlock{:?}{:?}", self.axes, self.to_dmatrix().as_slice())
    }
}
