//! Curvature against the ground truth (primal map from the tensor built here from the
//! principal curvatures) and against its dense form.

use cov_core::Spectrum;
use cov_core::{Cov, Operator};
use cov_curvature::{Curvature, CurvatureTensor};
use cov_validate::{Field, Grid, Primal, compare};
use nalgebra::SMatrix;
use proptest::prelude::*;

#[test]
fn isotropic_curvature_2d_matches_ground_truth() {
    for k in [-3.0, 0.5, 4.0] {
        let stds = [0.1, 0.3];
        let mut p = Cov::<2>::gaussian(stds).unwrap();
        Operator::apply(&Curvature::isotropic(k).unwrap(), &mut p).unwrap();
        // docs/physics.md: l'(x,u) = l(x, u + k·x).
        let f = Field::gaussian(&stds).then(Primal::shear(2, 1, 0, k));
        let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
        assert!(r.rel_error < 1e-3, "k={k}: {:e}", r.rel_error);
    }
}

#[test]
fn anisotropic_curvature_4d_matches_ground_truth() {
    let (kx, ky, a) = (3.0f64, -1.0f64, 0.5f64);
    // K = R diag(kx, ky) Rᵀ, R's columns the principal directions.
    let (s, c) = a.sin_cos();
    let kxx = c * c * kx + s * s * ky;
    let kxy = c * s * (kx - ky);
    let kyy = s * s * kx + c * c * ky;
    let stds = [0.1, 0.15, 0.3, 0.25];
    let mut p = Cov::<4>::gaussian(stds).unwrap();
    Operator::apply(&Curvature::anisotropic(kx, ky, a).unwrap(), &mut p).unwrap();
    let mut m = Primal::identity(4);
    m[2 * 4] = kxx;
    m[2 * 4 + 1] = kxy;
    m[3 * 4] = kxy;
    m[3 * 4 + 1] = kyy;
    let f = Field::gaussian(&stds).then(Primal::Map(m));
    let r = compare(&f, &p, &Grid::auto(&p, 32, &[1.0; 4])).unwrap();
    assert!(r.rel_error < 1e-3, "anisotropic: {:e}", r.rel_error);
}

#[test]
fn flatland_rejects_anisotropy() {
    let mut c = Cov::<2>::gaussian([0.1, 0.1]).unwrap();
    let an = Curvature::anisotropic(1.0, 2.0, 0.0).unwrap();
    assert!(Operator::apply(&an, &mut c).is_err());
    assert_eq!(Operator::requires(&an).smallest_layout(), 4);
    assert!(Curvature::isotropic(f64::NAN).is_err());
    assert!(CurvatureTensor::new(1.0, f64::INFINITY, 0.0).is_err());
}

proptest! {
    /// Principal form = tensor form = dense congruence, and curvature then its inverse
    /// is the identity.
    #[test]
    fn principal_tensor_dense_agree(kx in -1e3f64..1e3, ky in -1e3f64..1e3, a in -4.0f64..4.0, e in -0.5f64..0.5) {
        let m = SMatrix::<f64, 4, 4>::from_fn(|i, j| if i == j { 1.0 + i as f64 } else { e / (1.0 + (i * j) as f64) });
        let start = Cov::<4>::from_matrix(&(m * m.transpose())).unwrap();
        let cv = Curvature::anisotropic(kx, ky, a).unwrap();
        let (kxx, kxy, kyy) = cv.tensor();
        let mut p = start;
        Operator::apply(&cv, &mut p).unwrap();
        let mut t = start;
        Operator::apply(&CurvatureTensor::new(kxx, kxy, kyy).unwrap(), &mut t).unwrap();
        let mut dense = SMatrix::<f64, 4, 4>::identity();
        dense[(2, 0)] = kxx;
        dense[(2, 1)] = kxy;
        dense[(3, 0)] = kxy;
        dense[(3, 1)] = kyy;
        let mut d = start;
        d.congruence(dense.transpose().as_slice()).unwrap();
        let scale = d.norm();
        prop_assert!((p.to_matrix() - d.to_matrix()).norm() <= 1e-11 * scale);
        prop_assert!((t.to_matrix() - d.to_matrix()).norm() <= 1e-12 * scale);
        prop_assert!(p.validity().is_valid());
        let mut back = p;
        Operator::apply(&cv.inverse(), &mut back).unwrap();
        prop_assert!((back.to_matrix() - start.to_matrix()).norm() <= 1e-10 * scale);
    }
}
