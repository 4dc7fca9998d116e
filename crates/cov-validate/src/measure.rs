//! Sampling, FFT and moments.

use std::time::Instant;

use cov_core::Cov;
use nalgebra::DMatrix;
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use crate::field::{Field, spectrum_var};

/// Errors of the validator.
#[derive(Debug, Clone, PartialEq)]
pub enum ValidateError {
    /// Grid and field disagree on the layout, or a parameter is unusable.
    Config(String),
}

impl std::fmt::Display for ValidateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ValidateError::Config(s) => write!(f, "validator configuration: {s}"),
        }
    }
}

impl std::error::Error for ValidateError {}

/// The sampling grid: `size` samples per axis at `spacing[i]`, centred on the ray, under a
/// Gaussian window of std `window_std[i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Samples per axis (the FFT size; a power of two is fastest).
    pub size: usize,
    /// Sample spacing per axis (units of the axis).
    pub spacing: Vec<f64>,
    /// Std of the Gaussian window per axis (units of the axis).
    pub window_std: Vec<f64>,
}

/// The spectrum variance the window adds on an axis, as a fraction of the predicted one
/// (dimensionless): large enough to keep the primal extent within the grid, small enough
/// that the subtraction costs little accuracy.
pub const WINDOW_FRACTION: f64 = 0.25;

impl Grid {
    /// Chooses a grid of `size` samples per axis for a field whose spectrum is expected
    /// near `predicted`.
    ///
    /// Per axis: the window adds [`WINDOW_FRACTION`]` × Σ_ii` (or, where `Σ_ii = 0`, has std
    /// `fallback_std[i]`); the spacing then balances the primal coverage
    /// (`±c` window stds) and the spectral coverage (`±c` total spectrum stds, below
    /// Nyquist), giving `c = √(size / (4 s_w σ_tot))`: about 6.7 std for 64 samples.
    pub fn auto<const N: usize>(predicted: &Cov<N>, size: usize, fallback_std: &[f64]) -> Grid {
        let diagonal: Vec<f64> = (0..N).map(|i| predicted.get(i, i)).collect();
        Self::from_diagonal(&diagonal, size, fallback_std)
    }

    /// [`Grid::auto`] from the predicted spectrum variance per axis, for fields of any
    /// dimension (e.g. a 1-D image integrated by quadrature).
    pub fn from_diagonal(diagonal: &[f64], size: usize, fallback_std: &[f64]) -> Grid {
        let n = diagonal.len();
        let mut spacing = Vec::with_capacity(n);
        let mut window_std = Vec::with_capacity(n);
        for (i, d) in diagonal.iter().enumerate() {
            let p = d.max(0.0);
            let sw = if p > 0.0 {
                1.0 / (2.0 * std::f64::consts::PI * (WINDOW_FRACTION * p).sqrt())
            } else {
                fallback_std.get(i).copied().unwrap_or(1.0)
            };
            let sigma_tot = (p + spectrum_var(sw)).sqrt();
            let c = (size as f64 / (4.0 * sw * sigma_tot)).sqrt();
            spacing.push(1.0 / (2.0 * c * sigma_tot));
            window_std.push(sw);
        }
        Grid {
            size,
            spacing,
            window_std,
        }
    }
}

/// Measures Σ of `field` on `grid` (docs/physics.md section 5): samples `l·W`, FFTs it, takes
/// the normalised second moments of `|l̂|` and subtracts the window's covariance.
///
/// # Errors
/// A grid whose dimension differs from the field's, or fewer than 4 samples per axis.
pub fn measure(field: &Field, grid: &Grid) -> Result<DMatrix<f64>, ValidateError> {
    let n = field.dim();
    if grid.spacing.len() != n || grid.window_std.len() != n {
        return Err(ValidateError::Config(format!(
            "grid has {} axes, field has {n}",
            grid.spacing.len()
        )));
    }
    if grid.size < 4 {
        return Err(ValidateError::Config("at least 4 samples per axis".into()));
    }
    let m = grid.size;
    let total = m.pow(n as u32);
    let mut data = vec![Complex::new(0.0, 0.0); total];
    let mut z = [0.0; 5];
    for (flat, d) in data.iter_mut().enumerate() {
        let mut rem = flat;
        let mut w = 0.0;
        for a in (0..n).rev() {
            let k = rem % m;
            rem /= m;
            z[a] = (k as f64 - (m / 2) as f64) * grid.spacing[a];
            w += z[a] * z[a] / (grid.window_std[a] * grid.window_std[a]);
        }
        let win = (-0.5 * w).exp();
        if win > 1e-300 {
            *d = Complex::new(field.eval(&z[..n]) * win, 0.0);
        }
    }
    fft_nd(&mut data, n, m);
    // Moments of |l̂| over frequencies f_a = k_a / (m h_a), k_a in [−m/2, m/2).
    let mut mom = DMatrix::<f64>::zeros(n, n);
    let mut mass = 0.0;
    let mut f = [0.0; 5];
    for (flat, d) in data.iter().enumerate() {
        let amp = d.norm();
        if amp == 0.0 {
            continue;
        }
        let mut rem = flat;
        for a in (0..n).rev() {
            let k = rem % m;
            rem /= m;
            let ks = if k < m / 2 { k as f64 } else { k as f64 - m as f64 };
            f[a] = ks / (m as f64 * grid.spacing[a]);
        }
        mass += amp;
        for i in 0..n {
            for j in i..n {
                mom[(i, j)] += amp * f[i] * f[j];
            }
        }
    }
    if mass == 0.0 {
        return Ok(DMatrix::zeros(n, n));
    }
    for i in 0..n {
        for j in i..n {
            let v = mom[(i, j)] / mass;
            mom[(i, j)] = v;
            mom[(j, i)] = v;
        }
        mom[(i, i)] -= spectrum_var(grid.window_std[i]);
    }
    Ok(mom)
}

fn fft_nd(data: &mut [Complex<f64>], n: usize, m: usize) {
    let mut planner = FftPlanner::<f64>::new();
    let fft = planner.plan_fft_forward(m);
    let mut line = vec![Complex::new(0.0, 0.0); m];
    let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    for axis in 0..n {
        let stride = m.pow((n - 1 - axis) as u32);
        let total = data.len();
        for base in 0..total {
            // `base` is the start of a line when its coordinate along `axis` is 0.
            if !(base / stride).is_multiple_of(m) {
                continue;
            }
            for k in 0..m {
                line[k] = data[base + k * stride];
            }
            fft.process_with_scratch(&mut line, &mut scratch);
            for k in 0..m {
                data[base + k * stride] = line[k];
            }
        }
    }
}

/// Predicted against measured Σ for one case.
#[derive(Clone, Debug)]
pub struct Comparison {
    /// The closed-form prediction.
    pub predicted: DMatrix<f64>,
    /// The brute-force measurement.
    pub measured: DMatrix<f64>,
    /// `‖measured − predicted‖_F / ‖predicted‖_F`.
    pub rel_error: f64,
    /// The same after scaling each axis by the measurement's bandwidth there (window
    /// included), so that axes in different units weigh alike.
    pub rel_error_scaled: f64,
    /// Seconds spent measuring (sampling, FFT, moments).
    pub measure_seconds: f64,
    /// Grid used.
    pub grid: Grid,
}

/// Measures `field` on `grid` and compares with `predicted`.
///
/// # Errors
/// As [`measure`].
pub fn compare<const N: usize>(
    field: &Field,
    predicted: &Cov<N>,
    grid: &Grid,
) -> Result<Comparison, ValidateError> {
    if field.dim() != N {
        return Err(ValidateError::Config(format!(
            "field has N = {}, prediction {N}",
            field.dim()
        )));
    }
    let t0 = Instant::now();
    let measured = measure(field, grid)?;
    let measure_seconds = t0.elapsed().as_secs_f64();
    let p = DMatrix::from_fn(N, N, |i, j| predicted.get(i, j));
    let diff = &measured - &p;
    let pn = p.norm();
    let rel_error = if pn > 0.0 { diff.norm() / pn } else { diff.norm() };
    let scale: Vec<f64> = (0..N)
        .map(|i| 1.0 / (p[(i, i)].max(0.0) + spectrum_var(grid.window_std[i])).sqrt())
        .collect();
    let sd = DMatrix::from_fn(N, N, |i, j| diff[(i, j)] * scale[i] * scale[j]);
    let sp = DMatrix::from_fn(N, N, |i, j| p[(i, j)] * scale[i] * scale[j]);
    let rel_error_scaled = if sp.norm() > 0.0 {
        sd.norm() / sp.norm()
    } else {
        sd.norm()
    };
    Ok(Comparison {
        predicted: p,
        measured,
        rel_error,
        rel_error_scaled,
        measure_seconds,
        grid: grid.clone(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Primal;
    use cov_core::{Axis, Spectrum};

    #[test]
    fn gaussian_fields_measure_their_closed_form() {
        let start = Cov::<2>::gaussian([0.2, 0.05]).unwrap();
        let field = Field::gaussian(&[0.2, 0.05]);
        let r = compare(&field, &start, &Grid::auto(&start, 64, &[1.0, 1.0])).unwrap();
        assert!(r.rel_error < 1e-4, "{r:?}");
        // After a travel (correlated spectrum).
        let mut p = start;
        p.shear(Axis::X, Axis::U, -3.0).unwrap();
        let f2 = field.then(Primal::travel(2, 3.0));
        let r = compare(&f2, &p, &Grid::auto(&p, 64, &[1.0, 1.0])).unwrap();
        assert!(r.rel_error < 1e-4, "{r:?}");
    }

    #[test]
    fn wrong_sign_is_detected() {
        // The validator must be able to fail: travel with the wrong sign.
        let start = Cov::<2>::gaussian([0.2, 0.05]).unwrap();
        let mut p = start;
        p.shear(Axis::X, Axis::U, 3.0).unwrap();
        let f = Field::gaussian(&[0.2, 0.05]).then(Primal::travel(2, 3.0));
        let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0, 1.0])).unwrap();
        assert!(r.rel_error > 0.1, "{r:?}");
    }

    #[test]
    fn three_and_four_dimensions() {
        let p3 = Cov::<3>::gaussian([0.2, 0.05, 0.01]).unwrap();
        let r = compare(
            &Field::gaussian(&[0.2, 0.05, 0.01]),
            &p3,
            &Grid::auto(&p3, 48, &[1.0; 3]),
        )
        .unwrap();
        assert!(r.rel_error < 1e-3, "{r:?}");
        let p4 = Cov::<4>::gaussian([0.2, 0.1, 0.05, 0.07]).unwrap();
        let r = compare(
            &Field::gaussian(&[0.2, 0.1, 0.05, 0.07]),
            &p4,
            &Grid::auto(&p4, 24, &[1.0; 4]),
        )
        .unwrap();
        assert!(r.rel_error < 1e-3, "{r:?}");
    }
}
