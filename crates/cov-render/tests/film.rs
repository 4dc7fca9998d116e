//! The film and the methods of `render-bench`: reconstruction keeps constants, filters
//! lower the error of a noisy image, and every method runs on every scene (the two-pass
//! unbiasedness check is in tests/render.rs, beside the closed form it uses).

use std::path::Path;

use cov_render::World;
use cov_render::film::{Film, Filter, Gaussian};

mod common;

#[test]
fn filters_agree_with_the_box_on_a_flat_image() {
    // 16×12 pixels over 2°: every pixel sees (almost) the same radiance.
    let world = common::plane_under_sphere_light(2.0, 16, 12);
    let counts = vec![64u32; 16 * 12];
    let mut a = Film::new(16, 12);
    a.render(&world, &counts, 1, f64::INFINITY, None);
    let mut b = Film::new(16, 12);
    b.render(&world, &counts, 1, f64::INFINITY, None);
    let (ia, ib) = (
        a.image(&Filter::Box),
        b.image(&Filter::Fixed(Gaussian::isotropic(1.0))),
    );
    for (k, (p, q)) in ia.pixels.iter().zip(&ib.pixels).enumerate() {
        assert!((p.y - q.y).abs() < 0.05 * p.y, "pixel {k}: box {p}, gauss {q}");
    }
}

/// Reconstruction is a normalised average: a film whose pixels all hold the same mean
/// gives that mean back exactly, whatever the counts and the per-pixel filters.
#[test]
fn reconstruction_keeps_a_constant_under_any_filters() {
    use glam::DVec3;
    let (w, h) = (23u32, 17u32);
    let mut film = Film::new(w, h);
    let c = DVec3::new(0.3, 1.7, 42.0);
    let mut filters = Vec::new();
    for i in 0..(w * h) as usize {
        let n = 1 + (i * 7919 % 13) as u32;
        film.count[i] = n;
        film.reflected[i] = c * f64::from(n);
        let a = 0.05 + (i % 11) as f64;
        filters.push(Gaussian::from_cov([
            a,
            0.3 * a * ((i % 3) as f64 - 1.0),
            1.0 + (i % 5) as f64,
        ]));
    }
    for f in [
        Filter::Box,
        Filter::Fixed(Gaussian::isotropic(2.0)),
        Filter::PerPixel(filters),
    ] {
        for p in film.image(&f).pixels {
            assert!(
                (p - c).abs().max_element() <= 1e-12 * c.max_element(),
                "{f:?}: {p}"
            );
        }
    }
}

fn scene(name: &str, w: u32, h: u32) -> World {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/scenes")
        .join(name);
    World::load(&p)
        .unwrap_or_else(|e| panic!("{e}"))
        .with_resolution(w, h)
}

/// Every method runs on every bundled scene, spends its budget, and gives a finite,
/// non-negative image; the covariance methods need the covariance pass.
#[test]
fn every_method_runs_on_every_scene() {
    use cov_render::bench::{Guide, Method, error, run};
    use cov_render::render::covariance_maps_strided;
    for name in ["cornell.ron", "pool.ron", "glossy.ron"] {
        let world = scene(name, 24, 16);
        let maps = covariance_maps_strided(&world, 1, 4, 1, None).unwrap();
        assert_eq!(maps.stride, 4);
        let guide = Guide::new(&maps, 0.0);
        let reference = cov_render::render(&world, 16, 99);
        for m in Method::ALL {
            let r = run(&world, m, 6.0, Some(&guide), 1, None).unwrap();
            assert!(
                r.image
                    .pixels
                    .iter()
                    .all(|p| p.is_finite() && p.min_element() >= 0.0),
                "{name} {m:?}"
            );
            // Rounding moves at most one sample per pixel.
            assert!(
                (r.samples as f64 - 6.0 * 24.0 * 16.0).abs() <= 24.0 * 16.0,
                "{name} {m:?}: {} samples",
                r.samples
            );
            let e = error(&r.image, &reference).unwrap();
            assert!(e.rmse.is_finite() && e.relmse.is_finite(), "{name} {m:?}");
            assert!(r.timing.total() > 0.0);
            if m.uses_covariance() {
                assert!(
                    run(&world, m, 6.0, None, 1, None).is_err(),
                    "{m:?} without a guide"
                );
            }
        }
    }
}

/// On a scene of smooth light, filtering removes most of the noise: the covariance filter
/// at 4 spp is closer to a 256-spp reference than the box filter at 4 spp.
#[test]
fn the_covariance_filter_lowers_the_error_of_a_noisy_image() {
    use cov_render::bench::{Guide, Method, error, run};
    use cov_render::render::covariance_maps_strided;
    let world = scene("cornell.ron", 64, 48);
    let reference = cov_render::render(&world, 256, 77);
    let guide = Guide::new(&covariance_maps_strided(&world, 1, 4, 1, None).unwrap(), 0.0);
    let uni = run(&world, Method::Uniform, 4.0, None, 1, None).unwrap();
    let cov = run(&world, Method::CovFilter, 4.0, Some(&guide), 1, None).unwrap();
    let (eu, ec) = (
        error(&uni.image, &reference).unwrap(),
        error(&cov.image, &reference).unwrap(),
    );
    assert!(
        ec.relmse < 0.5 * eu.relmse,
        "cov-filter {} vs uniform {}",
        ec.relmse,
        eu.relmse
    );
}
