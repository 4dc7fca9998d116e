//! Projection, mirror and frame rotation against the ground truth and geometry.

use cov_core::Spectrum;
use cov_core::{Cov, Operator};
use cov_projection::{Mirror, Project, RotateFrame, Unproject};
use cov_validate::{Field, Grid, Primal, compare};
use glam::DVec3;

#[test]
fn projection_chain_matches_ground_truth_2d() {
    let stds = [0.1, 0.2];
    let mut p = Cov::<2>::gaussian(stds).unwrap();
    p.shear(cov_core::Axis::X, cov_core::Axis::U, -0.5).unwrap();
    let base = Field::gaussian(&stds).then(Primal::travel(2, 0.5));
    for op in 0..3 {
        let mut q = p;
        let f = match op {
            0 => {
                Operator::apply(&Project::new(0.3).unwrap(), &mut q).unwrap();
                base.clone().then(Primal::scale(2, 0, 0.3))
            }
            1 => {
                Operator::apply(&Unproject::new(0.6).unwrap(), &mut q).unwrap();
                base.clone().then(Primal::scale(2, 0, 1.0 / 0.6))
            }
            _ => {
                Operator::apply(&Mirror, &mut q).unwrap();
                base.clone().then(Primal::scale(2, 1, -1.0))
            }
        };
        let r = compare(&f, &q, &Grid::auto(&q, 64, &[1.0; 2])).unwrap();
        assert!(r.rel_error < 1e-3, "op {op}: {:e}", r.rel_error);
    }
}

#[test]
fn frame_rotation_matches_ground_truth_4d() {
    let a = 0.7f64;
    let stds = [0.1, 0.3, 0.2, 0.15];
    let mut p = Cov::<4>::gaussian(stds).unwrap();
    Operator::apply(&RotateFrame::new(a).unwrap(), &mut p).unwrap();
    // The new frame's x axis is the old one turned by +a toward y: z_old = R(a) z_new.
    let (s, c) = a.sin_cos();
    let m = vec![c, -s, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, 0.0, c, -s, 0.0, 0.0, s, c];
    let f = Field::gaussian(&stds).then(Primal::Map(m));
    let r = compare(&f, &p, &Grid::auto(&p, 32, &[1.0; 4])).unwrap();
    assert!(r.rel_error < 1e-3, "rotation: {:e}", r.rel_error);
}

#[test]
fn from_vectors_finds_the_plane_of_incidence() {
    let dir = DVec3::new(0.0, 0.0, -1.0);
    let fx = DVec3::X;
    // Normal tilted toward y: the plane of incidence is the y-z plane, so x turns by ±π/2.
    let t = 0.4f64;
    let n = DVec3::new(0.0, t.sin(), t.cos());
    let p = Project::from_vectors(dir, fx, n).unwrap();
    assert!((p.cos() - t.cos()).abs() < 1e-15);
    assert!((p.angle().abs() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    // Tilted toward x: no rotation needed.
    let p = Project::from_vectors(dir, fx, DVec3::new(t.sin(), 0.0, t.cos())).unwrap();
    assert!(p.angle().abs() < 1e-12);
    // Normal incidence: angle 0, never NaN.
    let p = Project::from_vectors(dir, fx, DVec3::Z).unwrap();
    assert_eq!(p.angle(), 0.0);
    assert!(
        Project::from_vectors(dir, fx, DVec3::X).is_err(),
        "grazing: cos = 0"
    );
    assert!(
        Project::from_vectors(dir, DVec3::Z, DVec3::Z).is_err(),
        "frame not orthogonal"
    );
    assert!(Project::from_vectors(DVec3::new(f64::NAN, 0.0, 1.0), fx, DVec3::Z).is_err());
}

#[test]
fn grazing_and_bad_parameters() {
    let mut c = Cov::<4>::gaussian([0.1, 0.1, 0.2, 0.2]).unwrap();
    Operator::apply(&Project::new(1e-12).unwrap(), &mut c).unwrap();
    Operator::apply(&Unproject::new(1e-12).unwrap(), &mut c).unwrap();
    assert!(c.validity().is_valid());
    assert!(Project::new(0.0).is_err());
    assert!(Project::new(1.5).is_err());
    assert!(Project::new(f64::NAN).is_err());
    assert!(Unproject::new(-0.5).is_err());
    assert!(RotateFrame::new(f64::INFINITY).is_err());
    let mut flat = Cov::<2>::gaussian([0.1, 0.1]).unwrap();
    assert!(Operator::apply(&Project::with_angle(0.5, 0.3).unwrap(), &mut flat).is_err());
}

/// Head-on incidence with normalised vectors: `dir · normal` can round to just above 1
/// (for about one normalised vector in five, `v · v > 1`), which is still `|cos θ| = 1`.
#[test]
fn head_on_incidence_is_cos_one() {
    for k in 0..200 {
        let a = 0.37 * f64::from(k);
        let dir = DVec3::new(a.sin() * 0.7, a.cos(), 0.3 + 0.01 * f64::from(k)).normalize();
        let fx = dir.any_orthonormal_vector();
        for normal in [dir, -dir] {
            let p = Project::from_vectors(dir, fx, normal)
                .unwrap_or_else(|e| panic!("{dir:?} ({}): {e}", dir.dot(dir)));
            assert!((p.cos() - 1.0).abs() <= 1e-15, "{}", p.cos());
            assert_eq!(p.angle(), 0.0);
        }
    }
}
