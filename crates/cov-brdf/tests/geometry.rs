//! The reflection composite against ray tracing: the Jacobian of the traced ray map
//! (incident ray frame → reflected ray frame), by central differences, gives the exact
//! linear map `z_out = J z_in`, so `Σ_out = J⁻ᵀ... ` i.e. `Σ_out = Aᵀ Σ A` with `A = J⁻¹`.

use cov_brdf::{Lobe, Reflect};
use cov_core::{Cov, Operator};
use cov_curvature::Curvature;
use nalgebra::{DMatrix, SMatrix, Vector3};

type V3 = Vector3<f64>;

/// Surface z = −½ (a X² + 2b XY + c Y²): convex (seen from +z) for K = [[a,b],[b,c]] > 0.
struct Quadric {
    a: f64,
    b: f64,
    c: f64,
}

impl Quadric {
    fn f(&self, p: &V3) -> f64 {
        p.z + 0.5 * (self.a * p.x * p.x + 2.0 * self.b * p.x * p.y + self.c * p.y * p.y)
    }
    fn normal(&self, p: &V3) -> V3 {
        V3::new(self.a * p.x + self.b * p.y, self.b * p.x + self.c * p.y, 1.0).normalize()
    }
    fn hit(&self, o: &V3, d: &V3) -> V3 {
        // Newton on s for f(o + s d) = 0, starting from the tangent plane.
        let mut s = -o.z / d.z;
        for _ in 0..50 {
            let p = o + d * s;
            let g = V3::new(self.a * p.x + self.b * p.y, self.b * p.x + self.c * p.y, 1.0);
            let step = self.f(&p) / g.dot(d);
            s -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        o + d * s
    }
}

struct Frame {
    d: V3,
    ex: V3,
    ey: V3,
}

/// Traced map (x, y, u, v) in the incident frame → the same in the reflected frame.
fn trace(q: &Quadric, fin: &Frame, fout: &Frame, z: &[f64; 4]) -> [f64; 4] {
    // The ray crosses the incident frame's reference plane (through the hit point, ⊥ d) at (x, y).
    let o = fin.ex * z[0] + fin.ey * z[1];
    let dir = (fin.d + fin.ex * z[2] + fin.ey * z[3]).normalize();
    let h = q.hit(&o, &dir);
    let n = q.normal(&h);
    let r = dir - n * (2.0 * dir.dot(&n));
    let s = -h.dot(&fout.d) / r.dot(&fout.d);
    let p = h + r * s;
    [
        p.dot(&fout.ex),
        p.dot(&fout.ey),
        r.dot(&fout.ex) / r.dot(&fout.d),
        r.dot(&fout.ey) / r.dot(&fout.d),
    ]
}

fn jacobian(q: &Quadric, fin: &Frame, fout: &Frame) -> DMatrix<f64> {
    let h = 1e-6;
    let mut j = DMatrix::zeros(4, 4);
    for k in 0..4 {
        let mut zp = [0.0; 4];
        let mut zm = [0.0; 4];
        zp[k] = h;
        zm[k] = -h;
        let (a, b) = (trace(q, fin, fout, &zp), trace(q, fin, fout, &zm));
        for i in 0..4 {
            j[(i, k)] = (a[i] - b[i]) / (2.0 * h);
        }
    }
    j
}

fn frames(theta: f64) -> (Frame, Frame) {
    let (s, c) = theta.sin_cos();
    let fin = Frame {
        d: V3::new(s, 0.0, -c),
        ex: V3::new(c, 0.0, s),
        ey: V3::new(0.0, 1.0, 0.0),
    };
    let fout = Frame {
        d: V3::new(s, 0.0, c),
        ex: V3::new(c, 0.0, -s),
        ey: V3::new(0.0, 1.0, 0.0),
    };
    (fin, fout)
}

fn check(q: &Quadric, theta: f64, curvature: Curvature) {
    let (fin, fout) = frames(theta);
    let j = jacobian(q, &fin, &fout);
    let a = j.clone().try_inverse().unwrap();
    let m = SMatrix::<f64, 4, 4>::from_fn(|i, k| {
        let base = [
            [4.0, 1.0, 0.5, 0.2],
            [1.0, 3.0, 0.1, 0.3],
            [0.5, 0.1, 2.0, 0.4],
            [0.2, 0.3, 0.4, 1.5],
        ];
        base[i][k]
    });
    let start = Cov::<4>::from_matrix(&m).unwrap();
    let expected = a.transpose() * DMatrix::from_fn(4, 4, |i, k| m[(i, k)]) * &a;
    let mut got = start;
    let cos = theta.cos();
    Operator::apply(
        &Reflect::new(cos, cos, curvature, Lobe::Mirror).unwrap(),
        &mut got,
    )
    .unwrap();
    let got = DMatrix::from_fn(4, 4, |i, k| got.get(i, k));
    let err = (&got - &expected).norm() / expected.norm();
    assert!(
        err < 1e-6,
        "θ={theta}, K=({},{},{}): rel error {err:e}\ngot {got}\nexpected {expected}",
        q.a,
        q.b,
        q.c
    );
}

#[test]
fn flat_mirror_keeps_sigma() {
    check(
        &Quadric {
            a: 0.0,
            b: 0.0,
            c: 0.0,
        },
        0.0,
        Curvature::isotropic(0.0).unwrap(),
    );
    check(
        &Quadric {
            a: 0.0,
            b: 0.0,
            c: 0.0,
        },
        0.7,
        Curvature::isotropic(0.0).unwrap(),
    );
}

#[test]
fn convex_and_concave_spheres_at_normal_incidence() {
    for k in [0.5, 2.0, -1.0] {
        check(
            &Quadric { a: k, b: 0.0, c: k },
            0.0,
            Curvature::isotropic(k).unwrap(),
        );
    }
}

#[test]
fn anisotropic_curvature_at_normal_incidence() {
    // Principal curvatures 2 and −0.5 along a direction at 0.4 rad from x.
    let cv = Curvature::anisotropic(2.0, -0.5, 0.4).unwrap();
    let (a, b, c) = cv.tensor();
    check(&Quadric { a, b, c }, 0.0, cv);
}

/// Oblique incidence in the plane of incidence with curvature only along y (across the
/// plane), where the surface-frame curvature is the surface's own.
#[test]
fn oblique_incidence_with_curvature_across_the_plane() {
    let cv = Curvature::anisotropic(0.0, 1.5, 0.0).unwrap();
    check(
        &Quadric {
            a: 0.0,
            b: 0.0,
            c: 1.5,
        },
        0.5,
        cv,
    );
}

/// Oblique incidence with a full anisotropic tensor (in-plane, across and mixed terms).
#[test]
fn oblique_incidence_anisotropic() {
    for theta in [0.3, 0.9, 1.3] {
        let cv = Curvature::anisotropic(1.2, -0.7, 0.6).unwrap();
        let (a, b, c) = cv.tensor();
        check(&Quadric { a, b, c }, theta, cv);
    }
}

#[test]
fn convex_mirror_diverges() {
    // Parallel rays (u = 0) at x > 0 leave with u > 0 on a convex mirror.
    let q = Quadric {
        a: 1.0,
        b: 0.0,
        c: 1.0,
    };
    let (fin, fout) = frames(0.0);
    let out = trace(&q, &fin, &fout, &[0.01, 0.0, 0.0, 0.0]);
    assert!(out[2] > 0.0);
    assert!((out[2] - 0.02).abs() < 1e-5, "2x/R: {}", out[2]);
}
