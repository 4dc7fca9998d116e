//! Media operators against the brute-force ground truth, their limits, and the
//! comparison of the two Gaussian fits of the Henyey–Greenstein lobe.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::Arc;

use cov_core::{Cov, Operator};
use cov_media::{Absorption, Fit, Phase, Scatter, Segment};
use cov_validate::{Field, Grid, Primal, compare};

const STDS: [f64; 2] = [0.1, 0.2];

/// Transmittance by quadrature of σ_t along the ray (docs/physics.md: a primal product).
fn transmittance(length: f64, sigma: impl Fn(f64) -> f64 + Send + Sync + 'static) -> Primal {
    Primal::Window(Arc::new(move |z: &[f64]| {
        let n = 200;
        let h = length / n as f64;
        let tau: f64 = (0..n)
            .map(|k| sigma(z[0] + (k as f64 + 0.5) * h * z[1]) * h)
            .sum();
        (-tau).exp()
    }))
}

#[test]
fn absorption_matches_ground_truth_and_ignores_constant_and_gradient() {
    for (l, hxx, grad) in [(1.0, 2.0, 0.0), (2.0, 0.5, 3.0), (0.3, 40.0, -5.0)] {
        let mut p = Cov::<2>::gaussian(STDS).unwrap();
        Operator::apply(&Absorption::new(l, [hxx, 0.0, 0.0]).unwrap(), &mut p).unwrap();
        let f = Field::gaussian(&STDS).then(transmittance(l, move |x| 0.7 + grad * x + 0.5 * hxx * x * x));
        let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
        assert!(r.rel_error < 1e-3, "L={l} H={hxx} g={grad}: {:e}", r.rel_error);
    }
}

#[test]
fn segment_is_absorption_then_travel() {
    let (l, hxx) = (1.5, 3.0);
    let mut p = Cov::<2>::gaussian(STDS).unwrap();
    Operator::apply(&Segment::new(l, [hxx, 0.0, 0.0]).unwrap(), &mut p).unwrap();
    let f = Field::gaussian(&STDS)
        .then(transmittance(l, move |x| 0.5 * hxx * x * x))
        .then(Primal::travel(2, l));
    let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
    assert!(r.rel_error < 1e-3, "segment: {:e}", r.rel_error);
}

#[test]
fn absorption_in_3d_with_anisotropic_hessian() {
    let (l, h) = (1.0, [2.0, 0.7, 1.0]);
    let stds = [0.15, 0.2, 0.3, 0.25];
    let mut p = Cov::<4>::gaussian(stds).unwrap();
    Operator::apply(&Absorption::new(l, h).unwrap(), &mut p).unwrap();
    let f = Field::gaussian(&stds).then(Primal::Window(Arc::new(move |z: &[f64]| {
        let n = 64;
        let dh = l / n as f64;
        let tau: f64 = (0..n)
            .map(|k| {
                let s = (k as f64 + 0.5) * dh;
                let (x, y) = (z[0] + s * z[2], z[1] + s * z[3]);
                0.5 * (h[0] * x * x + 2.0 * h[1] * x * y + h[2] * y * y) * dh
            })
            .sum();
        (-tau).exp()
    })));
    let r = compare(&f, &p, &Grid::auto(&p, 24, &[1.0; 4])).unwrap();
    assert!(r.rel_error < 1e-3, "3D absorption: {:e}", r.rel_error);
}

#[test]
fn absorption_limits() {
    let start = Cov::<4>::gaussian([0.1, 0.1, 0.2, 0.2]).unwrap();
    let run = |h: [f64; 3], l: f64| {
        let mut c = start;
        Operator::apply(&Absorption::new(l, h).unwrap(), &mut c).unwrap();
        c
    };
    assert_eq!(run([0.0; 3], 5.0), start, "homogeneous medium: unchanged");
    assert_eq!(run([1.0, 0.0, 1.0], 0.0), start, "zero length: unchanged");
    let big = run([1e12, 0.0, 1e12], 10.0);
    assert!(
        big.validity().is_valid() && big.get(0, 0) > 1e11,
        "very dense variation: a narrow window"
    );
    // Extinction at a maximum on the ray: no window (PSD part of H is 0).
    assert_eq!(run([-2.0, 0.0, -1.0], 1.0), start);
    // Saddle: only the positive direction acts.
    let saddle = Absorption::new(1.0, [1.0, 0.0, -1.0]).unwrap();
    assert_eq!(saddle.hessian(), [1.0, 0.0, 0.0]);
    assert!(Absorption::new(-1.0, [0.0; 3]).is_err());
    assert!(Absorption::new(1.0, [f64::NAN, 0.0, 0.0]).is_err());
}

/// The in-plane slice of the HG lobe around the scattering direction, brute-force.
fn hg_field(theta: f64, g: f64) -> Field {
    let phase = Phase::henyey_greenstein(g).unwrap();
    Field::gaussian(&STDS)
        .then(Primal::scale(2, 0, theta.cos().abs()))
        .then(Primal::Convolve {
            axis: 1,
            lobe: Arc::new(move |w| phase.eval(theta + w)),
            half_width: FRAC_PI_2,
            nodes: 601,
        })
}

#[test]
fn hg_fits_compared_over_g() {
    let mut wins = [0usize; 2];
    let mut sum = [0.0f64; 2];
    for theta in [0.0, 0.5] {
        for g in [0.2, 0.5, 0.7, 0.9] {
            let f = hg_field(theta, g);
            let mut errs = [0.0; 2];
            for (k, fit) in [Fit::Curvature, Fit::Moment].into_iter().enumerate() {
                let mut p = Cov::<2>::gaussian(STDS).unwrap();
                Operator::apply(
                    &Scatter::new(theta, Phase::henyey_greenstein(g).unwrap(), fit, 0.0).unwrap(),
                    &mut p,
                )
                .unwrap();
                let r = compare(&f, &p, &Grid::auto(&p, 64, &[1.0; 2])).unwrap();
                errs[k] = r.rel_error_scaled;
                sum[k] += r.rel_error_scaled;
            }
            println!(
                "HG θ={theta} g={g}: curvature fit error {:.4}, moment fit error {:.4}",
                errs[0], errs[1]
            );
            wins[usize::from(errs[1] < errs[0])] += 1;
        }
    }
    println!(
        "curvature wins {} times, moment {} (mean errors {:.4} / {:.4})",
        wins[0],
        wins[1],
        sum[0] / 8.0,
        sum[1] / 8.0
    );
    // The default (moment) is the one the measurement supports on average; the curvature
    // fit stays the better one at a sharp forward peak.
    assert!(
        sum[1] < sum[0],
        "moment fit should be the more accurate on average"
    );
    assert_eq!(Fit::default(), Fit::Moment);
}

#[test]
fn hg_limits_and_tabulated() {
    // g = 0: isotropic, no angular content left (either fit).
    for fit in [Fit::Curvature, Fit::Moment] {
        let mut c = Cov::<2>::gaussian(STDS).unwrap();
        Operator::apply(
            &Scatter::new(0.4, Phase::henyey_greenstein(0.0).unwrap(), fit, 0.0).unwrap(),
            &mut c,
        )
        .unwrap();
        assert_eq!(c.get(1, 1), 0.0, "{fit:?}");
    }
    // g → ±1: a near-delta lobe, finite and PSD.
    for g in [0.999_999, -0.999_999] {
        let theta = if g > 0.0 { 0.0 } else { PI };
        let mut c = Cov::<2>::gaussian(STDS).unwrap();
        let s = Scatter::new(theta, Phase::henyey_greenstein(g).unwrap(), Fit::Curvature, 0.0).unwrap();
        assert!(s.variances()[0] < 1e-10, "{g}: {:?}", s.variances());
        Operator::apply(&s, &mut c).unwrap();
        assert!(c.validity().is_valid());
    }
    assert!(Phase::henyey_greenstein(1.0).is_err());
    assert!(Phase::henyey_greenstein(f64::NAN).is_err());
    assert!(Scatter::new(4.0, Phase::henyey_greenstein(0.5).unwrap(), Fit::Curvature, 0.0).is_err());
    // A table of the HG function gives the same curvature fit to 1%.
    let g = 0.6;
    let angles: Vec<f64> = (0..=3600).map(|k| k as f64 * PI / 3600.0).collect();
    let hg = Phase::henyey_greenstein(g).unwrap();
    let values: Vec<f64> = angles.iter().map(|a| hg.eval(*a)).collect();
    let tab = Phase::Tabulated { angles, values }.validated().unwrap();
    for theta in [0.3, 1.0] {
        let a = Scatter::new(theta, hg.clone(), Fit::Curvature, 0.0)
            .unwrap()
            .variances();
        let b = Scatter::new(theta, tab.clone(), Fit::Curvature, 0.0)
            .unwrap()
            .variances();
        for k in 0..2 {
            let same = (a[k].is_infinite() && b[k].is_infinite()) || (a[k] - b[k]).abs() <= 1e-2 * a[k];
            assert!(same, "θ={theta}: {a:?} vs {b:?}");
        }
    }
    assert!(
        Phase::Tabulated {
            angles: vec![0.0, 1.0],
            values: vec![1.0, 1.0]
        }
        .validated()
        .is_err()
    );
    assert!(
        Phase::Tabulated {
            angles: vec![0.0, 1.0, 0.5],
            values: vec![1.0, 1.0, 1.0]
        }
        .validated()
        .is_err()
    );
}
