//! Refraction against the ground truth (flatland) and a ray-traced Jacobian of vector
//! Snell's law (3D, both axes).

use cov_brdf::Lobe;
use cov_core::{Cov, CovError, Operator};
use cov_refraction::{Refract, RoughRefract};
use cov_validate::{Field, Grid, Primal, compare};
use nalgebra::{DMatrix, SMatrix, Vector3};

type V3 = Vector3<f64>;

#[test]
fn refraction_matches_ground_truth_2d() {
    let stds = [0.1, 0.2];
    for (n1, n2, ci) in [(1.0, 1.5, 0.9), (1.0, 1.33, 0.3), (1.5, 1.0, 0.95)] {
        let r = Refract::new(n1, n2, ci).unwrap();
        let mut p = Cov::<2>::gaussian(stds).unwrap();
        Operator::apply(&r, &mut p).unwrap();
        let f = Field::gaussian(&stds)
            .then(Primal::scale(2, 0, ci))
            .then(Primal::scale(2, 0, 1.0 / r.cos_t()))
            .then(Primal::scale(2, 1, 1.0 / r.angular_scale()));
        let c = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
        assert!(c.rel_error < 1e-3, "{n1}->{n2} cos {ci}: {:e}", c.rel_error);
    }
}

/// Traced map (x, y, u, v) incident → transmitted, through the plane z = 0.
fn trace(eta: f64, th_i: f64, th_t: f64, z: &[f64; 4]) -> [f64; 4] {
    let (si, ci) = th_i.sin_cos();
    let (st, ct) = th_t.sin_cos();
    let (d, ex, ey) = (
        V3::new(si, 0.0, -ci),
        V3::new(ci, 0.0, si),
        V3::new(0.0, 1.0, 0.0),
    );
    let (dt, ext) = (V3::new(st, 0.0, -ct), V3::new(ct, 0.0, st));
    let o = ex * z[0] + ey * z[1];
    let w = (d + ex * z[2] + ey * z[3]).normalize();
    let h = o - w * (o.z / w.z);
    let n = V3::new(0.0, 0.0, 1.0);
    let cos_i = -w.dot(&n);
    let k = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
    let t = w * eta + n * (eta * cos_i - k.sqrt());
    let s = -h.dot(&dt) / t.dot(&dt);
    let p = h + t * s;
    [
        p.dot(&ext),
        p.dot(&ey),
        t.dot(&ext) / t.dot(&dt),
        t.dot(&ey) / t.dot(&dt),
    ]
}

#[test]
fn refraction_matches_vector_snell_3d() {
    for (n1, n2, ci) in [(1.0, 1.5, 0.7), (1.5, 1.0, 0.9), (1.0, 2.4, 0.2)] {
        let r = Refract::new(n1, n2, ci).unwrap();
        let (th_i, th_t) = (f64::acos(ci), f64::acos(r.cos_t()));
        let h = 1e-6;
        let mut j = DMatrix::zeros(4, 4);
        for k in 0..4 {
            let (mut zp, mut zm) = ([0.0; 4], [0.0; 4]);
            zp[k] = h;
            zm[k] = -h;
            let (a, b) = (trace(n1 / n2, th_i, th_t, &zp), trace(n1 / n2, th_i, th_t, &zm));
            for i in 0..4 {
                j[(i, k)] = (a[i] - b[i]) / (2.0 * h);
            }
        }
        let a = j.try_inverse().unwrap();
        let m = SMatrix::<f64, 4, 4>::from_fn(|i, k| if i == k { 2.0 + i as f64 } else { 0.3 });
        let mut got = Cov::<4>::from_matrix(&m).unwrap();
        Operator::apply(&r, &mut got).unwrap();
        let expected = a.transpose() * DMatrix::from_fn(4, 4, |i, k| m[(i, k)]) * &a;
        let got = DMatrix::from_fn(4, 4, |i, k| got.get(i, k));
        let err = (&got - &expected).norm() / expected.norm();
        assert!(err < 1e-6, "{n1}->{n2} cos {ci}: {err:e}\n{got}\n{expected}");
    }
}

#[test]
fn total_internal_reflection_is_a_typed_error() {
    // Critical angle glass → air: sin θc = 1/1.5, cos θc = √(1 − 1/2.25) ≈ 0.745.
    let err = Refract::new(1.5, 1.0, 0.5).unwrap_err();
    assert!(matches!(err, CovError::NoTransport { .. }), "{err}");
    // Just above the critical angle: finite, PSD, huge angular scale.
    let cc = (1.0f64 - 1.0 / 2.25).sqrt();
    let r = Refract::new(1.5, 1.0, cc * (1.0 + 1e-9)).unwrap();
    assert!(r.angular_scale().is_finite() && r.angular_scale() > 1e3);
    let mut c = Cov::<4>::gaussian([0.1, 0.1, 0.2, 0.2]).unwrap();
    Operator::apply(&r, &mut c).unwrap();
    assert!(c.validity().is_valid());
    // Normal incidence: no scaling in x and u beyond the indices.
    let r = Refract::new(1.0, 1.5, 1.0).unwrap();
    assert_eq!(r.cos_t(), 1.0);
}

#[test]
fn rough_refraction_and_bad_parameters() {
    let mut c = Cov::<2>::gaussian([0.1, 0.2]).unwrap();
    Operator::apply(
        &RoughRefract::new(1.0, 1.5, 0.8, Lobe::beckmann(0.2).unwrap()).unwrap(),
        &mut c,
    )
    .unwrap();
    assert!(c.validity().is_valid());
    assert!(Refract::new(0.0, 1.0, 0.5).is_err());
    assert!(Refract::new(1.0, f64::NAN, 0.5).is_err());
    assert!(Refract::new(1.0, 1.5, 0.0).is_err());
    assert!(RoughRefract::new(1.0, 1.5, 0.5, Lobe::Phong { exponent: -2.0 }).is_err());
}
