//! Motion against the ground truth in flatland with time (x, u, t), and its laws.

use std::sync::Arc;

use cov_core::{Axis, Chain, Cov, Operator};
use cov_motion::{CameraMotion, Moving, Shutter, ShutterShape};
use cov_occlusion::Window;
use cov_validate::{Field, Grid, Primal, compare};

const STDS: [f64; 3] = [0.2, 0.3, 0.5];

fn moving_window(v: f64, s: f64) -> Moving {
    Moving::new(
        [v, 0.0],
        [0.0, 0.0],
        Chain::new().with(Window::isotropic(s).unwrap()),
    )
    .unwrap()
}

#[test]
fn moving_windows_match_ground_truth_at_several_speeds() {
    for v in [0.0, 0.3, -1.0, 4.0] {
        let s = 0.05;
        let mut p = Cov::<3>::gaussian(STDS).unwrap();
        Operator::apply(&moving_window(v, s), &mut p).unwrap();
        // docs/physics.md: l'(x,u,t) = l(x,u,t)·w(x − v·t).
        let f = Field::gaussian(&STDS).then(Primal::Window(Arc::new(move |z: &[f64]| {
            let xo = z[0] - v * z[2];
            (-0.5 * xo * xo / (s * s)).exp()
        })));
        let r = compare(&f, &p, &Grid::auto(&p, 48, &[1.0; 3])).unwrap();
        assert!(r.rel_error < 1e-3, "v={v}: {:e}", r.rel_error);
    }
}

#[test]
fn angular_motion_and_camera_motion_match_ground_truth() {
    // A camera translating at 1.5 m/s and turning at 0.8 rad/s.
    let w = 0.8;
    let mut p = Cov::<3>::gaussian(STDS).unwrap();
    Operator::apply(&CameraMotion::new([1.5, 0.0], [w, 0.0]).unwrap(), &mut p).unwrap();
    // Camera frame: l_c(x, u, t) = l(x + 1.5 t, u + ω t, t).
    let mut m = Primal::identity(3);
    m[2] = 1.5;
    m[3 + 2] = w;
    let f = Field::gaussian(&STDS).then(Primal::Map(m));
    let r = compare(&f, &p, &Grid::auto(&p, 48, &[1.0; 3])).unwrap();
    assert!(r.rel_error < 1e-3, "camera motion: {:e}", r.rel_error);
}

#[test]
fn box_shutter_is_a_moment_matched_window() {
    // The Gaussian shutter is exact; the box is measured (its |sinc| spectrum has no
    // finite second moment, so the error grows with the grid).
    let mut p = Cov::<3>::gaussian(STDS).unwrap();
    Operator::apply(&Shutter::new(0.1, ShutterShape::Gaussian).unwrap(), &mut p).unwrap();
    let f = Field::gaussian(&STDS).then(Primal::gaussian_window(2, 0.1));
    let r = compare(&f, &p, &Grid::auto(&p, 48, &[1.0; 3])).unwrap();
    assert!(r.rel_error < 1e-3, "gaussian shutter: {:e}", r.rel_error);
    let mut b = Cov::<3>::gaussian(STDS).unwrap();
    Operator::apply(&Shutter::new(0.2, ShutterShape::Box).unwrap(), &mut b).unwrap();
    let fb = Field::gaussian(&STDS).then(Primal::Window(Arc::new(|z: &[f64]| {
        if z[2].abs() <= 0.1 { 1.0 } else { 0.0 }
    })));
    for n in [32, 64] {
        let r = compare(&fb, &b, &Grid::auto(&b, n, &[1.0; 3])).unwrap();
        println!(
            "box shutter 0.2 s, grid {n}: Σtt predicted {:.3e}, measured {:.3e}, rel error {:.3}",
            r.predicted[(2, 2)],
            r.measured[(2, 2)],
            r.rel_error
        );
        assert!(r.rel_error.is_finite());
    }
}

#[test]
fn doubling_velocity_doubles_the_xt_shear() {
    let start = Cov::<3>::gaussian(STDS).unwrap();
    let shear = |v: f64| {
        let mut c = start;
        Operator::apply(&moving_window(v, 0.05), &mut c).unwrap();
        c.at(Axis::X, Axis::T).unwrap()
    };
    let (a, b) = (shear(0.7), shear(1.4));
    assert!(a != 0.0);
    assert!((b - 2.0 * a).abs() <= 1e-12 * b.abs(), "{a} {b}");
}

#[test]
fn motion_needs_time_and_rejects_bad_input() {
    let mut c = Cov::<4>::gaussian([0.1, 0.1, 0.1, 0.1]).unwrap();
    assert!(
        Operator::apply(&moving_window(1.0, 0.1), &mut c).is_err(),
        "no t in layout 4"
    );
    assert!(
        Shutter::new(0.0, ShutterShape::Box).is_err(),
        "zero-length shutter"
    );
    assert!(Shutter::new(f64::NAN, ShutterShape::Gaussian).is_err());
    assert!(Moving::new([f64::INFINITY, 0.0], [0.0, 0.0], Chain::new()).is_err());
    assert_eq!(Operator::requires(&moving_window(1.0, 0.1)).smallest_layout(), 3);
    let m2 = Moving::new([1.0, 2.0], [0.0, 0.0], Chain::new()).unwrap();
    assert_eq!(Operator::requires(&m2).smallest_layout(), 5);
}
