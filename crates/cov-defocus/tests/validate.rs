//! The lens against the ground truth in flatland with time, focus laws, and the pinhole
//! limit.

use cov_core::Spectrum;
use cov_core::{Axis, Cov, DIRAC_RELATIVE_SIZE, Operator};
use cov_defocus::{Pinhole, ThinLens};
use cov_validate::{Field, Grid, Primal, compare, measure};

/// Source: a Gaussian spot of std `s` (constant in angle), `d_o` in front of the lens.
fn lens_case(s: f64, d_o: f64, lens: &ThinLens) -> (Cov<3>, Field) {
    let stds = [s, f64::INFINITY, 0.5];
    let mut p = Cov::<3>::gaussian(stds).unwrap();
    p.shear(Axis::X, Axis::U, -d_o).unwrap();
    Operator::apply(lens, &mut p).unwrap();
    // docs/physics.md: aperture window on x, lens l(x, u + x/f), travel d_s.
    let (f, a, d_s) = (0.05, lens.aperture(), lens.sensor_distance());
    let field = Field::gaussian(&stds)
        .then(Primal::travel(3, d_o))
        .then(Primal::gaussian_window(0, a))
        .then(Primal::shear(3, 1, 0, 1.0 / f))
        .then(Primal::travel(3, d_s));
    (p, field)
}

#[test]
fn lens_matches_ground_truth_in_front_at_and_behind_focus() {
    let lens = ThinLens::new(0.05, 0.004, 1.0).unwrap();
    for d_o in [0.6, 1.0, 2.5] {
        let (p, f) = lens_case(0.003, d_o, &lens);
        let r = compare(&f, &p, &Grid::auto(&p, 48, &[1.0; 3])).unwrap();
        assert!(r.rel_error < 1e-3, "d_o={d_o}: {:e}", r.rel_error);
    }
}

#[test]
fn integrated_image_matches_ground_truth_after_aperture_and_shutter() {
    // Image-space Σ: the sensor integrates over the lens (u) and the exposure (t); the
    // brute force integrates the primal field by quadrature and measures a 1D spectrum.
    let lens = ThinLens::new(0.05, 0.004, 1.0).unwrap();
    let (mut p, f) = lens_case(0.003, 0.6, &lens);
    let shutter_std = 0.05;
    p.add_variance(
        Axis::T,
        1.0 / (4.0 * std::f64::consts::PI.powi(2) * shutter_std * shutter_std),
    )
    .unwrap();
    let f = f.then(Primal::gaussian_window(2, shutter_std));
    let mut predicted = p;
    predicted.integrate(&[Axis::U, Axis::T]).unwrap();
    let d_s = lens.sensor_distance();
    let (u_half, t_half) = (8.0 * lens.aperture() / d_s + 0.5, 8.0 * shutter_std);
    let image = Field::from_fn(1, move |z: &[f64]| {
        let (nu, nt) = (161, 81);
        let (hu, ht) = (2.0 * u_half / (nu - 1) as f64, 2.0 * t_half / (nt - 1) as f64);
        let mut acc = 0.0;
        for i in 0..nu {
            for j in 0..nt {
                let (u, t) = (-u_half + i as f64 * hu, -t_half + j as f64 * ht);
                acc += f.eval(&[z[0], u, t]);
            }
        }
        acc * hu * ht
    });
    let sigma = predicted.get(0, 0);
    let m = measure(&image, &Grid::from_diagonal(&[sigma], 128, &[1.0])).unwrap();
    let err = (m[(0, 0)] - sigma).abs() / sigma;
    assert!(
        err < 1e-3,
        "image Σxx predicted {sigma:e}, measured {:e}: {err:e}",
        m[(0, 0)]
    );
}

#[test]
fn an_in_focus_point_has_no_defocus_term() {
    // A Dirac-like point at the focus distance: its image is the point magnified by
    // d_s/d_o, whatever the aperture; out of focus the aperture adds blur.
    let d_f = 2.0;
    let image_var = |aperture: f64, d_o: f64| {
        let lens = ThinLens::new(0.05, aperture, d_f).unwrap();
        let mut c = Cov::<2>::dirac(1.0, DIRAC_RELATIVE_SIZE).unwrap();
        c.shear(Axis::X, Axis::U, -d_o).unwrap();
        Operator::apply(&lens, &mut c).unwrap();
        c.integrate(&[Axis::U]).unwrap();
        (c.get(0, 0), lens.sensor_distance())
    };
    let point = Cov::<2>::dirac(1.0, DIRAC_RELATIVE_SIZE).unwrap().get(0, 0);
    for a in [0.001, 0.005, 0.02] {
        let (v, d_s) = image_var(a, d_f);
        let magnified = point * (d_f / d_s).powi(2);
        assert!(
            (v - magnified).abs() <= 1e-6 * magnified,
            "a={a}: {v:e} vs {magnified:e}"
        );
        let (out, _) = image_var(a, 1.0);
        assert!(out < 1e-3 * magnified, "out of focus blurs: {out:e}");
    }
}

#[test]
fn pinhole_is_the_zero_aperture_limit() {
    let d_s = 0.05;
    let mut start = Cov::<3>::gaussian([0.2, 0.1, 0.5]).unwrap();
    start.shear(Axis::X, Axis::U, -1.0).unwrap();
    let mut ph = start;
    Operator::apply(&Pinhole::new(d_s).unwrap(), &mut ph).unwrap();
    assert!(ph.validity().is_valid());
    assert_eq!(ph.get(1, 1), 0.0, "nothing left in angle");
    assert!((ph.get(0, 0) - start.get(1, 1) / (d_s * d_s)).abs() <= 1e-12 * ph.get(0, 0));
    // A lens focused at infinity (f = d_s) with an ever smaller aperture converges to it.
    let mut last = f64::INFINITY;
    for a in [1e-3, 1e-4, 1e-5] {
        let lens = ThinLens::new(d_s, a, 1e12).unwrap();
        let mut c = start;
        Operator::apply(&lens, &mut c).unwrap();
        c.integrate(&[Axis::U]).unwrap();
        let err = (c.get(0, 0) - ph.get(0, 0)).abs() / ph.get(0, 0);
        assert!(err < last, "converges: {err:e}");
        last = err;
    }
    assert!(last < 1e-3, "{last:e}");
    assert!(Pinhole::new(0.0).is_err());
    assert!(
        ThinLens::new(0.05, 0.01, 0.04).is_err(),
        "focus inside the focal length"
    );
}
