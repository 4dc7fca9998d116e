//! Travel against the brute-force ground truth and against its dense form.

use cov_core::{Cov, Operator, Spectrum};
use cov_travel::Travel;
use cov_validate::{Field, Grid, Primal, compare};
use nalgebra::SMatrix;
use proptest::prelude::*;

#[test]
fn travel_matches_ground_truth_2d_3d_4d() {
    for d in [-0.7, 0.3, 2.0] {
        let stds = [0.05, 0.2];
        let mut p = Cov::<2>::gaussian(stds).unwrap();
        Operator::apply(&Travel::new(d).unwrap(), &mut p).unwrap();
        let f = Field::gaussian(&stds).then(Primal::travel(2, d));
        let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
        assert!(r.rel_error < 1e-3, "2D d={d}: {:e}", r.rel_error);

        let stds3 = [0.05, 0.2, 0.01];
        let mut p = Cov::<3>::gaussian(stds3).unwrap();
        Operator::apply(&Travel::new(d).unwrap(), &mut p).unwrap();
        let f = Field::gaussian(&stds3).then(Primal::travel(3, d));
        let r = compare(&f, &p, &Grid::auto(&p, 40, &[1.0; 3])).unwrap();
        assert!(r.rel_error < 1e-3, "3D d={d}: {:e}", r.rel_error);
    }
    let stds4 = [0.05, 0.08, 0.2, 0.1];
    let mut p = Cov::<4>::gaussian(stds4).unwrap();
    Operator::apply(&Travel::new(0.5).unwrap(), &mut p).unwrap();
    let f = Field::gaussian(&stds4).then(Primal::travel(4, 0.5));
    let r = compare(&f, &p, &Grid::auto(&p, 32, &[1.0; 4])).unwrap();
    assert!(r.rel_error < 1e-3, "4D: {:e}", r.rel_error);
}

#[test]
fn bad_parameters_are_rejected() {
    assert!(Travel::new(f64::NAN).is_err());
    assert!(Travel::new(f64::INFINITY).is_err());
}

proptest! {
    #[test]
    fn sparse_equals_dense(d in -1e3f64..1e3, a in -1.0f64..1.0, b in -1.0f64..1.0, c in 0.1f64..2.0) {
        let m = SMatrix::<f64, 5, 5>::from_fn(|i, j| if i == j { c + i as f64 } else { a * b / (1.0 + (i + j) as f64) });
        let start = Cov::<5>::from_matrix(&(m * m.transpose())).unwrap();
        let mut s = start;
        Operator::apply(&Travel::new(d).unwrap(), &mut s).unwrap();
        let mut dense = SMatrix::<f64, 5, 5>::identity();
        dense[(0, 2)] = -d;
        dense[(1, 3)] = -d;
        let mut r = start;
        r.congruence(dense.transpose().as_slice()).unwrap();
        prop_assert!((s.to_matrix() - r.to_matrix()).norm() <= 1e-12 * r.norm());
    }
}
