//! Dense evaluation of the four rules in a generic real type: `f64` for the "plain"
//! implementation, [`twofloat::TwoFloat`] (double-double, ~32 significant digits) for the
//! reference. The formulas are the textbook ones of docs/physics.md section 2, written once.

use std::ops::{Add, Div, Mul, Neg, Sub};

use twofloat::TwoFloat;

/// The arithmetic the reference needs.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + PartialOrd
{
    /// From f64 (exact).
    fn of(v: f64) -> Self;
    /// To f64 (rounded).
    fn to(self) -> f64;
    /// Absolute value.
    fn abs_val(self) -> Self {
        if self < Self::of(0.0) { -self } else { self }
    }
    /// Division to the type's full precision (twofloat's own `/` is only about as
    /// accurate as f64: measured 7e-17 relative on `a²/(4a)`).
    fn div_full(self, other: Self) -> Self {
        self / other
    }
}

impl Real for f64 {
    fn of(v: f64) -> Self {
        v
    }
    fn to(self) -> f64 {
        self
    }
}

impl Real for TwoFloat {
    fn of(v: f64) -> Self {
        TwoFloat::from(v)
    }
    fn to(self) -> f64 {
        f64::from(self)
    }
    /// Long division: three quotient digits, each remainder formed with twofloat's exact
    /// products and sums.
    fn div_full(self, other: Self) -> Self {
        let b = f64::from(other);
        let q1 = TwoFloat::from(f64::from(self) / b);
        let r1 = self - q1 * other;
        let q2 = TwoFloat::from(f64::from(r1) / b);
        let r2 = r1 - q2 * other;
        let q3 = TwoFloat::from(f64::from(r2) / b);
        q1 + q2 + q3
    }
}

/// A dense `n × n` matrix.
#[derive(Clone, Debug, PartialEq)]
pub struct Dense<R> {
    /// Size.
    pub n: usize,
    /// Row-major entries.
    pub a: Vec<R>,
}

impl<R: Real> Dense<R> {
    /// From f64 rows.
    pub fn from_f64(n: usize, v: &[f64]) -> Self {
        Dense {
            n,
            a: v.iter().map(|x| R::of(*x)).collect(),
        }
    }

    /// Entry.
    pub fn at(&self, i: usize, j: usize) -> R {
        self.a[i * self.n + j]
    }

    fn set(&mut self, i: usize, j: usize, v: R) {
        self.a[i * self.n + j] = v;
    }

    /// The entries as f64, row-major.
    pub fn to_f64(&self) -> Vec<f64> {
        self.a.iter().map(|x| x.to()).collect()
    }

    /// Rule 1: `Aᵀ Σ A` with `A` given row-major in f64.
    pub fn congruence(&mut self, a: &[f64]) {
        let n = self.n;
        let am: Vec<R> = a.iter().map(|x| R::of(*x)).collect();
        let mut b = vec![R::of(0.0); n * n];
        for i in 0..n {
            for j in 0..n {
                let mut s = R::of(0.0);
                for k in 0..n {
                    s = s + self.at(i, k) * am[k * n + j];
                }
                b[i * n + j] = s;
            }
        }
        for i in 0..n {
            for j in 0..n {
                let mut s = R::of(0.0);
                for k in 0..n {
                    s = s + am[k * n + i] * b[k * n + j];
                }
                self.set(i, j, s);
            }
        }
    }

    /// Rule 2: `Σ_ii += w`.
    pub fn window(&mut self, i: usize, w: f64) {
        let v = self.at(i, i) + R::of(w);
        self.set(i, i, v);
    }

    /// Rule 3 on one axis `p` with lobe spectrum `s` (`s = 0`: diffuse, i.e. rule 4):
    /// `Σ − Σ e_p e_pᵀ Σ / (s + Σ_pp)`, with row and column `p` as `Σ_ip s/(s + Σ_pp)`
    /// (the same number); a zero denominator (no content, diffuse lobe)
    /// leaves the other axes and clears `p`.
    pub fn lobe(&mut self, p: usize, s: f64) {
        let n = self.n;
        let m = R::of(s) + self.at(p, p);
        if m.abs_val() == R::of(0.0) {
            for k in 0..n {
                self.set(k, p, R::of(0.0));
                self.set(p, k, R::of(0.0));
            }
            return;
        }
        let col: Vec<R> = (0..n).map(|k| self.at(k, p)).collect();
        let t = R::of(s).div_full(m);
        for i in 0..n {
            for j in 0..n {
                // Row and column p by the identity Σ_ip − Σ_ip Σ_pp/m = Σ_ip s/m, which
                // keeps them to relative precision when Σ_pp ≫ s (the difference would
                // lose them even in double-double at 1e300); elsewhere col_i · (col_j/m):
                // no intermediate of size Σ², which overflows at 1e300.
                let v = if i == p || j == p {
                    col[if i == p { j } else { i }] * t
                } else {
                    self.at(i, j) - col[i] * col[j].div_full(m)
                };
                self.set(i, j, v);
            }
        }
    }

    /// Rule 3 on two axes `p, q` with a correlated lobe spectrum `S` (row-major 2×2):
    /// `Σ − Σ Pᵀ (S + PΣPᵀ)⁻¹ P Σ` with the 2×2 inverse by its adjugate. A singular
    /// `S + PΣPᵀ` is not handled (callers keep `S` positive definite).
    pub fn lobe2(&mut self, p: usize, q: usize, s: [f64; 4]) {
        let n = self.n;
        let m00 = R::of(s[0]) + self.at(p, p);
        let m01 = R::of(s[1]) + self.at(p, q);
        let m11 = R::of(s[3]) + self.at(q, q);
        let det = m00 * m11 - m01 * m01;
        let (i00, i01, i11) = (m11.div_full(det), (-m01).div_full(det), m00.div_full(det));
        let cp: Vec<R> = (0..n).map(|k| self.at(k, p)).collect();
        let cq: Vec<R> = (0..n).map(|k| self.at(k, q)).collect();
        for i in 0..n {
            for j in 0..n {
                let corr = cp[i] * (i00 * cp[j] + i01 * cq[j]) + cq[i] * (i01 * cp[j] + i11 * cq[j]);
                let v = self.at(i, j) - corr;
                self.set(i, j, v);
            }
        }
    }
}
