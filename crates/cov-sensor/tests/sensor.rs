//! Sensor decisions: units, formulas, the 4D/5D agreement, and the sensor operator.

use std::f64::consts::PI;

use cov_core::{Axis, Cov, Operator};
use cov_sensor::{Integrate, Sensor, SensorParams};

fn sensor(aperture: Option<f64>, shutter: Option<f64>) -> Sensor {
    Sensor::new(SensorParams {
        width: 800,
        fov_x: 0.6,
        distance: 0.05,
        filter: 0.5,
        aperture,
        shutter,
        ..SensorParams::default()
    })
    .unwrap()
}

#[test]
fn image_space_units_and_filter() {
    let s = sensor(None, None);
    let pitch = s.pitch();
    assert!((pitch - 2.0 * 0.05 * 0.3f64.tan() / 800.0).abs() < 1e-18);
    let c = Cov::<2>::from_diagonal([4e6, 10.0]).unwrap();
    let d = s.decisions(c).unwrap();
    // Pixel filter window then integration over u (no x–u correlation): Σ_xx + w.
    let w = 1.0 / (4.0 * PI * PI * (0.5 * pitch).powi(2));
    let expected = (4e6 + w) * pitch * pitch;
    assert!((d.image_cov_px[0][0] - expected).abs() < 1e-12 * expected);
    // Filter std = 1/(2π √Σ_px) of the content, before the pixel window (not clamped).
    let content = 4e6 * pitch * pitch;
    assert!((d.filter_std_px[0] - 1.0 / (2.0 * PI * content.sqrt())).abs() < 1e-12);
    assert!(!d.filter_clamped);
    // Density over the image axis only: (2k) √Σ_px, k = 2; one pixel of extent.
    assert!((d.density - 4.0 * expected.sqrt()).abs() < 1e-12);
    assert_eq!(d.samples_per_pixel, d.density);
}

#[test]
fn static_scene_in_5d_matches_4d() {
    let m4 = nalgebra::SMatrix::<f64, 4, 4>::from_fn(|i, j| {
        if i == j {
            [4e6, 2e6, 30.0, 20.0][i]
        } else if i + j == 2 {
            1e3
        } else {
            0.0
        }
    });
    let c4 = Cov::<4>::from_matrix(&m4).unwrap();
    let m5 = nalgebra::SMatrix::<f64, 5, 5>::from_fn(|i, j| if i < 4 && j < 4 { m4[(i, j)] } else { 0.0 });
    let c5 = Cov::<5>::from_matrix(&m5).unwrap();
    for s in [sensor(None, None), sensor(Some(0.004), None)] {
        let (a, b) = (s.decisions(c4).unwrap(), s.decisions(c5).unwrap());
        assert_eq!(a.image_cov_px, b.image_cov_px);
        assert_eq!(a.density, b.density);
    }
    let mut o4 = c4;
    let mut o5 = c5;
    Operator::apply(&sensor(None, None), &mut o4).unwrap();
    Operator::apply(&sensor(None, None), &mut o5).unwrap();
    for i in 0..4 {
        for j in 0..4 {
            assert_eq!(o4.get(i, j), o5.get(i, j));
        }
    }
}

#[test]
fn lens_and_time_enter_the_sampled_domain() {
    let m = nalgebra::SMatrix::<f64, 3, 3>::from_fn(|i, j| if i == j { [4e6, 40.0, 900.0][i] } else { 0.0 });
    let c = Cov::<3>::from_matrix(&m).unwrap();
    let d = sensor(Some(0.004), Some(0.01)).decisions(c).unwrap();
    assert_eq!(d.sampled_axes, ["x_px", "lens_x", "t"]);
    assert!(d.samples_per_pixel > 0.0 && d.samples_per_pixel.is_finite());
    // More shutter content (a faster moving edge) means more samples.
    let m2 = nalgebra::SMatrix::<f64, 3, 3>::from_fn(|i, j| if i == j { [4e6, 40.0, 9e4][i] } else { 0.0 });
    let d2 = sensor(Some(0.004), Some(0.01))
        .decisions(Cov::<3>::from_matrix(&m2).unwrap())
        .unwrap();
    assert!(d2.samples_per_pixel > d.samples_per_pixel);
    // A shutter needs t.
    assert!(sensor(None, Some(0.01)).decisions(Cov::<2>::zeros()).is_err());
}

#[test]
fn zero_spectrum_gives_the_widest_filter_and_no_nan() {
    let d = sensor(None, None).decisions(Cov::<4>::zeros()).unwrap();
    // A flat image: the widest filter on both axes, however narrow the pixel filter.
    assert_eq!(d.filter_std_px, [8.0, 8.0]);
    assert!(d.filter_clamped);
    assert!(d.density.is_finite());
    // The pixel filter's window alone sets the density: (2k)² / (4π² f²) per px².
    let w = 1.0 / (4.0 * PI * PI * 0.25);
    assert!((d.density - 16.0 * w).abs() < 1e-12 * d.density);
}

#[test]
fn bad_parameters_and_integrate() {
    let base = SensorParams::default();
    assert!(Sensor::new(SensorParams { width: 0, ..base }).is_err());
    assert!(Sensor::new(SensorParams { fov_x: 4.0, ..base }).is_err());
    assert!(
        Sensor::new(SensorParams {
            filter: f64::NAN,
            ..base
        })
        .is_err()
    );
    assert!(
        Sensor::new(SensorParams {
            aperture: Some(-1.0),
            ..base
        })
        .is_err()
    );
    assert!(Integrate::new(vec![]).is_err());
    let mut c = Cov::<3>::gaussian([0.1, 0.2, 0.3]).unwrap();
    Operator::apply(&Integrate::new(vec![Axis::T]).unwrap(), &mut c).unwrap();
    assert_eq!(c.get(2, 2), 0.0);
}

/// The Nyquist factor's default, written out in the parameter table, is core's `NYQUIST_K`.
#[test]
fn the_nyquist_default_is_cores() {
    assert_eq!(cov_sensor::SensorParams::NYQUIST.default, Some("2.0"));
    assert_eq!(cov_core::NYQUIST_K, 2.0);
    assert_eq!(SensorParams::default().nyquist, cov_core::NYQUIST_K);
}
