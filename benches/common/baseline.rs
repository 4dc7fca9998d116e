//! The baseline every library kernel and chain is measured against: the textbook in-place
//! update of the packed numbers of Σ for each operator, with constant indices and no
//! checks, as plain scalar code gets (the public C++ library of this method is code of
//! this kind; our measurement of it runs at this speed). Each function is the same
//! formula as the library operator of the same name (`same_as_library` in
//! `benches/chain.rs` checks it to rounding before anything is timed).
//!
//! Layouts: N = 2 is (x, u); N = 4 is (x, y, u, v); N = 5 is (x, y, u, v, t).

use std::f64::consts::PI;

/// Σ packed as the upper triangle, row by row (the same 15 slots as `Cov<N>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Packed<const N: usize> {
    /// The packed entries.
    pub p: [f64; 15],
}

#[inline(always)]
const fn ix<const N: usize>(i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    i * N - i * (i + 1) / 2 + j
}

impl<const N: usize> Packed<N> {
    #[inline(always)]
    fn g(&self, i: usize, j: usize) -> f64 {
        self.p[ix::<N>(i, j)]
    }
    #[inline(always)]
    fn s(&mut self, i: usize, j: usize, v: f64) {
        self.p[ix::<N>(i, j)] = v;
    }

    /// `z_j += s z_i` seen from the spectrum: column `j` gains `s ×` column `i`.
    #[inline(always)]
    fn shear(&mut self, i: usize, j: usize, s: f64) {
        let (sii, sij, sjj) = (self.g(i, i), self.g(i, j), self.g(j, j));
        for k in 0..N {
            if k != j {
                let v = self.g(k, j) + s * self.g(k, i);
                self.s(k, j, v);
            }
        }
        self.s(j, j, sjj + s * (2.0 * sij + s * sii));
    }

    #[inline(always)]
    fn scale(&mut self, i: usize, c: f64) {
        for k in 0..N {
            let v = self.g(k, i) * if k == i { c * c } else { c };
            self.s(k, i, v);
        }
    }

    #[inline(always)]
    fn rotate(&mut self, i: usize, j: usize, c: f64, s: f64) {
        let (sii, sij, sjj) = (self.g(i, i), self.g(i, j), self.g(j, j));
        for k in 0..N {
            if k != i && k != j {
                let (ki, kj) = (self.g(k, i), self.g(k, j));
                self.s(k, i, c * ki + s * kj);
                self.s(k, j, c * kj - s * ki);
            }
        }
        let cs = c * s;
        self.s(i, i, c * c * sii + 2.0 * cs * sij + s * s * sjj);
        self.s(j, j, s * s * sii - 2.0 * cs * sij + c * c * sjj);
        self.s(i, j, cs * (sjj - sii) + (c * c - s * s) * sij);
    }

    /// Σ − Σ e_p e_pᵀ Σ / (s + Σ_pp), in the product form `Σ_pp s/m`, `Σ_op s/m`.
    #[inline(always)]
    fn lobe(&mut self, p: usize, s: f64) {
        let spp = self.g(p, p);
        let m = s + spp;
        let (inv, t) = if m > 0.0 { (1.0 / m, s / m) } else { (0.0, 0.0) };
        let mut col = [0.0; N];
        for (k, c) in col.iter_mut().enumerate() {
            *c = self.g(k, p);
        }
        for a in 0..N {
            if a == p {
                continue;
            }
            let ga = col[a] * inv;
            for b in a..N {
                if b != p {
                    let v = self.g(a, b) - ga * col[b];
                    self.s(a, b, v);
                }
            }
            self.s(a, p, col[a] * t);
        }
        self.s(p, p, spp * t);
    }

    const X: usize = 0;
    const Y: usize = 1;
    const U: usize = if N >= 4 { 2 } else { 1 };
    const V: usize = 3;

    /// Travel by `d`.
    #[inline(always)]
    pub fn travel(&mut self, d: f64) {
        self.shear(Self::X, Self::U, -d);
        if N >= 4 {
            self.shear(Self::Y, Self::V, -d);
        }
    }

    /// Isotropic curvature `k`.
    #[inline(always)]
    pub fn curvature(&mut self, k: f64) {
        self.shear(Self::U, Self::X, k);
        if N >= 4 {
            self.shear(Self::V, Self::Y, k);
        }
    }

    /// Rotation of the tangent frame by (cos, sin) (N ≥ 4).
    #[inline(always)]
    pub fn rotate_frame(&mut self, c: f64, s: f64) {
        if N >= 4 {
            self.rotate(Self::X, Self::Y, c, s);
            self.rotate(Self::U, Self::V, c, s);
        }
    }

    /// Mirror symmetry of the direction axes.
    #[inline(always)]
    pub fn mirror(&mut self) {
        self.scale(Self::U, -1.0);
        if N >= 4 {
            self.scale(Self::V, -1.0);
        }
    }

    /// Phong lobe of exponent `e` (spectrum variance `e/(4π²)` on u and v).
    #[inline(always)]
    pub fn phong(&mut self, e: f64) {
        let s = 1.0 / (4.0 * PI * PI * (1.0 / e));
        self.lobe(Self::U, s);
        if N >= 4 {
            self.lobe(Self::V, s);
        }
    }

    /// Projection onto a surface: turn the frame into the plane of incidence, then
    /// foreshorten x by `cos`.
    #[inline(always)]
    pub fn project(&mut self, cos: f64, angle: f64) {
        if N >= 4 && angle != 0.0 {
            let (s, c) = angle.sin_cos();
            self.rotate_frame(c, s);
        }
        self.scale(Self::X, cos);
    }

    /// Inverse projection.
    #[inline(always)]
    pub fn unproject(&mut self, cos: f64, angle: f64) {
        self.scale(Self::X, 1.0 / cos);
        if N >= 4 && angle != 0.0 {
            let (s, c) = angle.sin_cos();
            self.rotate_frame(c, s);
        }
    }

    /// A Gaussian window of std `std` on the spatial axes.
    #[inline(always)]
    pub fn window(&mut self, std: f64) {
        let w = 1.0 / (4.0 * PI * PI * std * std);
        let v = self.g(Self::X, Self::X) + w;
        self.s(Self::X, Self::X, v);
        if N >= 4 {
            let v = self.g(Self::Y, Self::Y) + w;
            self.s(Self::Y, Self::Y, v);
        }
    }
}

/// (cos, angle) of a projection from the ray direction, its frame x axis and the
/// surface normal, as the C++ library computes them (an `atan2`, then `sin_cos` of the
/// angle). The library's `Project::from_vectors` takes the turn's cosine and sine from the
/// components instead, without either call (docs/speed.md).
#[inline(always)]
pub fn projection_angles(dir: [f64; 3], fx: [f64; 3], n: [f64; 3]) -> (f64, f64) {
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let dn = dot(dir, n);
    let fy = [
        dir[1] * fx[2] - dir[2] * fx[1],
        dir[2] * fx[0] - dir[0] * fx[2],
        dir[0] * fx[1] - dir[1] * fx[0],
    ];
    let p = [n[0] - dn * dir[0], n[1] - dn * dir[1], n[2] - dn * dir[2]];
    let angle = if dot(p, p).sqrt() <= 1e-12 {
        0.0
    } else {
        dot(p, fy).atan2(dot(p, fx))
    };
    (dn.abs(), angle)
}

/// One ray's parameters for the bounce chain.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Distance to the surface.
    pub d1: f64,
    /// Ray direction, its frame x axis, the surface normal.
    pub dir: [f64; 3],
    /// Frame x axis (orthogonal to `dir`).
    pub fx: [f64; 3],
    /// Surface normal.
    pub n: [f64; 3],
    /// Surface curvature.
    pub k: f64,
    /// Phong exponent.
    pub e: f64,
    /// Cosine and frame angle of the outgoing ray.
    pub cos_out: f64,
    /// Frame angle of the outgoing ray.
    pub angle_out: f64,
    /// Turn of the frame towards the next event.
    pub turn: f64,
    /// Distance to the next event.
    pub d2: f64,
    /// Std of the window there.
    pub std: f64,
}

/// The 10-operator bounce chain on one ray: travel, projection from vectors, curvature,
/// mirror, lobe, curvature back, unprojection, rotation, travel, window.
#[inline(always)]
pub fn bounce<const N: usize>(p: &mut Packed<N>, r: &Ray) {
    p.travel(r.d1);
    let (cos, angle) = projection_angles(r.dir, r.fx, r.n);
    p.project(cos, if N >= 4 { angle } else { 0.0 });
    p.curvature(r.k);
    p.mirror();
    p.phong(r.e);
    p.curvature(-r.k);
    p.unproject(r.cos_out, if N >= 4 { r.angle_out } else { 0.0 });
    if N >= 4 {
        let (s, c) = r.turn.sin_cos();
        p.rotate_frame(c, s);
    }
    p.travel(r.d2);
    p.window(r.std);
}

/// The bounce chain with coefficients computed once (fixed parameters): what a
/// closed-form evaluation of one fixed path does per state.
#[derive(Clone, Copy, Debug)]
pub struct Fixed {
    d1: f64,
    cos: f64,
    ca: (f64, f64),
    k: f64,
    s_lobe: f64,
    inv_cos_out: f64,
    cb: (f64, f64),
    ct: (f64, f64),
    d2: f64,
    w: f64,
}

impl Fixed {
    /// The coefficients of ray `r`'s chain.
    pub fn new(r: &Ray) -> Fixed {
        let (cos, angle) = projection_angles(r.dir, r.fx, r.n);
        let sc = |a: f64| {
            let (s, c) = a.sin_cos();
            (c, s)
        };
        Fixed {
            d1: r.d1,
            cos,
            ca: sc(angle),
            k: r.k,
            s_lobe: 1.0 / (4.0 * PI * PI * (1.0 / r.e)),
            inv_cos_out: 1.0 / r.cos_out,
            cb: sc(r.angle_out),
            ct: sc(r.turn),
            d2: r.d2,
            w: 1.0 / (4.0 * PI * PI * r.std * r.std),
        }
    }

    /// Runs the chain on `p`.
    #[inline(always)]
    pub fn run<const N: usize>(&self, p: &mut Packed<N>) {
        type P<const M: usize> = Packed<M>;
        p.travel(self.d1);
        if N >= 4 {
            p.rotate_frame(self.ca.0, self.ca.1);
        }
        p.scale(P::<N>::X, self.cos);
        p.curvature(self.k);
        p.mirror();
        p.lobe(P::<N>::U, self.s_lobe);
        if N >= 4 {
            p.lobe(P::<N>::V, self.s_lobe);
        }
        p.curvature(-self.k);
        p.scale(P::<N>::X, self.inv_cos_out);
        if N >= 4 {
            p.rotate_frame(self.cb.0, self.cb.1);
            p.rotate_frame(self.ct.0, self.ct.1);
        }
        p.travel(self.d2);
        let v = p.g(0, 0) + self.w;
        p.s(0, 0, v);
        if N >= 4 {
            let v = p.g(1, 1) + self.w;
            p.s(1, 1, v);
        }
    }
}
