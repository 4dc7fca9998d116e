//! Primal light fields as composed functions of `z`.

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

/// A scalar function of the perturbation `z` (length `N`), shared between threads.
pub type PrimalFn = Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;

/// One primal operation `l → l'` (docs/physics.md section 3 is written in these terms).
#[derive(Clone)]
pub enum Primal {
    /// Change of coordinates `l'(z) = l(A z)`, `A` row-major `N × N`.
    Map(Vec<f64>),
    /// Product with a window: `l'(z) = l(z)·w(z)`.
    Window(PrimalFn),
    /// Convolution along one axis with a lobe: `l'(z) = ∫ l(z − s·e_axis) ρ(s) ds`, by
    /// the trapezoidal rule on `nodes` points over `[−half_width, half_width]`.
    Convolve {
        /// Axis index in the layout.
        axis: usize,
        /// The lobe `ρ(s)` (need not be normalised).
        lobe: Arc<dyn Fn(f64) -> f64 + Send + Sync>,
        /// Half-width of the quadrature interval (units of the axis).
        half_width: f64,
        /// Number of quadrature nodes.
        nodes: usize,
    },
}

impl fmt::Debug for Primal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Primal::Map(a) => write!(f, "Map({a:?})"),
            Primal::Window(_) => write!(f, "Window"),
            Primal::Convolve {
                axis,
                half_width,
                nodes,
                ..
            } => {
                write!(f, "Convolve(axis {axis}, ±{half_width}, {nodes} nodes)")
            }
        }
    }
}

impl Primal {
    /// Identity matrix of size `n`, row-major.
    pub fn identity(n: usize) -> Vec<f64> {
        (0..n * n)
            .map(|k| if k / n == k % n { 1.0 } else { 0.0 })
            .collect()
    }

    /// `l'(z) = l(z')` with `z'_target = z_target + s·z_source`.
    pub fn shear(n: usize, target: usize, source: usize, s: f64) -> Primal {
        let mut a = Self::identity(n);
        a[target * n + source] += s;
        Primal::Map(a)
    }

    /// `l'(z) = l(z')` with `z'_axis = c·z_axis`.
    pub fn scale(n: usize, axis: usize, c: f64) -> Primal {
        let mut a = Self::identity(n);
        a[axis * n + axis] = c;
        Primal::Map(a)
    }

    /// Travel by `d` (docs/physics.md: `l'(x,u) = l(x − d·u, u)`, and `(y, v)` likewise in 3D).
    pub fn travel(n: usize, d: f64) -> Primal {
        let mut a = Self::identity(n);
        let (x, u) = (0, if n >= 4 { 2 } else { 1 });
        a[x * n + u] = -d;
        if n >= 4 {
            a[n + 3] = -d;
        }
        Primal::Map(a)
    }

    /// A Gaussian window of std `std` along `axis`: `w = exp(−z²/2s²)`.
    pub fn gaussian_window(axis: usize, std: f64) -> Primal {
        Primal::Window(Arc::new(move |z: &[f64]| {
            (-0.5 * z[axis] * z[axis] / (std * std)).exp()
        }))
    }

    /// A Gaussian lobe of variance `var` along `axis` (quadrature over ±8 std).
    pub fn gaussian_lobe(axis: usize, var: f64, nodes: usize) -> Primal {
        let sd = var.sqrt();
        Primal::Convolve {
            axis,
            lobe: Arc::new(move |s: f64| (-0.5 * s * s / var).exp()),
            half_width: 8.0 * sd,
            nodes,
        }
    }

    /// The reflection composite in flatland `(x, u)`, from its primal definition:
    /// projection onto the surface by `cos_in`, incident directions turned back toward the
    /// light (`u → −u`), curvature `k` (`u += k x`), `u` turned back, a Gaussian lobe of
    /// angular variance `lobe_var` (`nodes` quadrature nodes), inverse curvature, and the
    /// unprojection by `cos_out`. What `cov_brdf::Reflect` must reproduce.
    pub fn reflection_2d(cos_in: f64, cos_out: f64, k: f64, lobe_var: f64, nodes: usize) -> Vec<Primal> {
        vec![
            Primal::scale(2, 0, cos_in),
            Primal::scale(2, 1, -1.0),
            Primal::shear(2, 1, 0, k),
            Primal::scale(2, 1, -1.0),
            Primal::gaussian_lobe(1, lobe_var, nodes),
            Primal::shear(2, 1, 0, -k),
            Primal::scale(2, 0, 1.0 / cos_out),
        ]
    }
}

/// A primal light field: a starting field and the operations applied to it in order.
#[derive(Clone)]
pub struct Field {
    n: usize,
    start: PrimalFn,
    ops: Vec<Primal>,
}

impl fmt::Debug for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Field(N={}, {:?})", self.n, self.ops)
    }
}

impl Field {
    /// A Gaussian starting field with primal std per axis (`f64::INFINITY`: constant along
    /// that axis). Its spectrum covariance is `1/(4π² s²)` per axis.
    pub fn gaussian(stds: &[f64]) -> Field {
        let inv: Vec<f64> = stds
            .iter()
            .map(|s| if s.is_infinite() { 0.0 } else { 1.0 / (s * s) })
            .collect();
        Field {
            n: stds.len(),
            start: Arc::new(move |z: &[f64]| {
                let q: f64 = z.iter().zip(&inv).map(|(x, i)| x * x * i).sum();
                (-0.5 * q).exp()
            }),
            ops: Vec::new(),
        }
    }

    /// A starting field given as any function of `z` (length `n`).
    pub fn from_fn(n: usize, f: impl Fn(&[f64]) -> f64 + Send + Sync + 'static) -> Field {
        Field {
            n,
            start: Arc::new(f),
            ops: Vec::new(),
        }
    }

    /// Appends an operation.
    pub fn then(mut self, op: Primal) -> Field {
        self.ops.push(op);
        self
    }

    /// Appends operations in order (e.g. [`Primal::reflection_2d`]).
    pub fn then_all(mut self, ops: impl IntoIterator<Item = Primal>) -> Field {
        self.ops.extend(ops);
        self
    }

    /// Layout size.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Evaluates the field at `z`.
    pub fn eval(&self, z: &[f64]) -> f64 {
        self.eval_upto(self.ops.len(), z)
    }

    fn eval_upto(&self, k: usize, z: &[f64]) -> f64 {
        if k == 0 {
            return (self.start)(z);
        }
        let n = self.n;
        match &self.ops[k - 1] {
            Primal::Map(a) => {
                let mut w = [0.0; 5];
                for i in 0..n {
                    w[i] = (0..n).map(|j| a[i * n + j] * z[j]).sum();
                }
                self.eval_upto(k - 1, &w[..n])
            }
            Primal::Window(w) => {
                let v = w(z);
                if v == 0.0 {
                    0.0
                } else {
                    v * self.eval_upto(k - 1, z)
                }
            }
            Primal::Convolve {
                axis,
                lobe,
                half_width,
                nodes,
            } => {
                let m = (*nodes).max(2);
                let h = 2.0 * half_width / (m - 1) as f64;
                let mut w = [0.0; 5];
                w[..n].copy_from_slice(z);
                let mut acc = 0.0;
                for q in 0..m {
                    let s = -half_width + q as f64 * h;
                    let weight = if q == 0 || q == m - 1 { 0.5 } else { 1.0 };
                    w[*axis] = z[*axis] - s;
                    acc += weight * lobe(s) * self.eval_upto(k - 1, &w[..n]);
                }
                acc * h
            }
        }
    }
}

/// Spectrum variance `1/(4π² s²)` of a Gaussian of primal std `s`.
pub(crate) fn spectrum_var(std: f64) -> f64 {
    1.0 / (4.0 * PI * PI * std * std)
}
