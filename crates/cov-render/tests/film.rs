//! The film and the methods of `render-bench`: reconstruction keeps constants, filters
//! lower the error of a noisy image, and every method runs on every scene (the two-pass
//! unbiasedness check is in tests/render.rs, beside the closed form it uses).

use std::path::Path;

use cov_render::adaptive::Guide;
use cov_render::film::{Film, Filter, Gaussian};
use cov_render::metrics::measure;
use cov_render::{Method, RenderSettings, Renderer, World, covariance_maps};

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

/// A renderer of `world` with `method` at `spp`, seed 1, sharing `guide` when given.
fn renderer<'w>(world: &'w World, method: Method, spp: f64, guide: Option<&Guide>) -> Renderer<'w> {
    let settings = RenderSettings {
        method,
        spp,
        ..RenderSettings::default()
    };
    let r = Renderer::new(world, settings).unwrap();
    match guide {
        Some(g) => r.with_guide(g.clone()).unwrap(),
        None => r,
    }
}

/// Every method runs on every bundled scene, spends its budget, and gives a finite,
/// non-negative image; a covariance method without a guide traces the pass itself.
#[test]
fn every_method_runs_on_every_scene() {
    for name in ["cornell.ron", "pool.ron", "glossy.ron"] {
        let world = scene(name, 24, 16);
        let maps = covariance_maps(&world, 1, 4, 1, None).unwrap();
        assert_eq!(maps.stride, 4);
        let guide = Guide::new(&maps, 0.0);
        let reference = cov_render::render(&world, 16, 99);
        for m in Method::ALL {
            let r = renderer(&world, m, 6.0, Some(&guide)).render(None).unwrap();
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
            assert_eq!(r.passes, 1);
            let e = measure(&r.image, &reference).unwrap();
            assert!(e.rmse.is_finite() && e.relmse.is_finite(), "{name} {m:?}");
            assert!(r.timing.total() > 0.0);
            // Without a guide the renderer traces the same pass (same seed, same grid):
            // the same image.
            let mut own = renderer(&world, m, 6.0, None);
            let again = own.render(None).unwrap();
            assert_eq!(again.image, r.image, "{name} {m:?}");
            assert_eq!(own.maps().is_some(), m.uses_covariance(), "{name} {m:?}");
        }
    }
}

/// A guide of another size is refused with both sizes; settings out of range name the
/// setting.
#[test]
fn guides_and_settings_are_checked() {
    let world = scene("cornell.ron", 24, 16);
    let small = scene("cornell.ron", 8, 8);
    let guide = Guide::new(&covariance_maps(&small, 1, 4, 1, None).unwrap(), 0.0);
    let e = Renderer::new(&world, RenderSettings::default())
        .unwrap()
        .with_guide(guide)
        .unwrap_err()
        .to_string();
    assert!(e.contains("8x8 against 24x16"), "{e}");
    for (s, name) in [
        (
            RenderSettings {
                spp: 0.5,
                ..RenderSettings::default()
            },
            "spp",
        ),
        (
            RenderSettings {
                spp: f64::NAN,
                ..RenderSettings::default()
            },
            "spp",
        ),
        (
            RenderSettings {
                time: Some(-1.0),
                ..RenderSettings::default()
            },
            "time",
        ),
        (
            RenderSettings {
                time: Some(f64::INFINITY),
                ..RenderSettings::default()
            },
            "time",
        ),
        (
            RenderSettings {
                cov_paths: 0,
                ..RenderSettings::default()
            },
            "cov_paths",
        ),
        (
            RenderSettings {
                cov_stride: 3,
                ..RenderSettings::default()
            },
            "cov_stride",
        ),
    ] {
        let e = Renderer::new(&world, s).unwrap_err().to_string();
        assert!(e.starts_with(name) && !e.contains('\n'), "{e}");
    }
}

/// A time-limited render adds passes that continue each pixel's sequence: the samples of
/// `p` passes of `n` spp are the samples of one pass of `p·n` spp (the same box image up
/// to the order of the additions).
#[test]
fn progressive_passes_continue_the_same_sequences() {
    let world = scene("pool.ron", 16, 16);
    let settings = RenderSettings {
        method: Method::Uniform,
        spp: 2.0,
        time: Some(0.5),
        ..RenderSettings::default()
    };
    // In a thread pool of its own: in rayon's global pool its work would queue behind
    // the other tests of this binary that render at the same time, and the wall clock
    // it is checked against would count their work.
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let r = pool.install(|| Renderer::new(&world, settings).unwrap().render(None).unwrap());
    assert!(r.passes >= 2, "{} passes in 0.5 s", r.passes);
    assert_eq!(r.samples, u64::from(r.passes) * 2 * 256);
    assert!(r.timing.total() <= 0.5 * 1.5, "{:?}", r.timing);
    let once = renderer(&world, Method::Uniform, f64::from(2 * r.passes), None)
        .render(None)
        .unwrap();
    for (a, b) in r.image.pixels.iter().zip(&once.image.pixels) {
        assert!(
            (*a - *b).abs().max_element() <= 1e-9 * (1.0 + b.abs().max_element()),
            "{a} vs {b}"
        );
    }
    // Every method keeps passing within its time, and covariance ones trace once.
    for m in Method::ALL {
        let settings = RenderSettings {
            method: m,
            spp: 1.0,
            time: Some(0.3),
            ..RenderSettings::default()
        };
        let r = Renderer::new(&world, settings).unwrap().render(None).unwrap();
        assert!(r.passes >= 2, "{m:?}: {} passes", r.passes);
        assert!(r.image.pixels.iter().all(|p| p.is_finite()), "{m:?}");
    }
}

/// On a scene of smooth light, filtering removes most of the noise: the covariance filter
/// at 4 spp is closer to a 256-spp reference than the box filter at 4 spp.
#[test]
fn the_covariance_filter_lowers_the_error_of_a_noisy_image() {
    let world = scene("cornell.ron", 64, 48);
    let reference = cov_render::render(&world, 256, 77);
    let uni = renderer(&world, Method::Uniform, 4.0, None).render(None).unwrap();
    let cov = renderer(&world, Method::CovFilter, 4.0, None)
        .render(None)
        .unwrap();
    let (eu, ec) = (
        measure(&uni.image, &reference).unwrap(),
        measure(&cov.image, &reference).unwrap(),
    );
    assert!(
        ec.relmse < 0.5 * eu.relmse,
        "cov-filter {} vs uniform {}",
        ec.relmse,
        eu.relmse
    );
}

/// `lum_top` holds the luminance of each pixel's last dyadic block of sample indices
/// (`n/2 .. n` at a power of two `n`), whichever passes the samples came in.
#[test]
fn lum_top_is_the_last_dyadic_block() {
    let world = common::plane_under_sphere_light(60.0, 8, 6);
    let n = 8 * 6;
    let render = |passes: &[u32]| {
        let mut f = Film::new(8, 6);
        for &c in passes {
            f.render(&world, &vec![c; n], 3, f64::INFINITY, None);
        }
        f
    };
    let (four, eight) = (render(&[4]), render(&[8]));
    // Two passes crossing the blocks 2..4 and 4..8, and three that end inside a block.
    let (split, ragged) = (render(&[2, 6]), render(&[1, 2, 5]));
    for i in 0..n {
        let top = eight.lum[i][0] - four.lum[i][0];
        let tol = 1e-12 * eight.lum[i][0].abs().max(1e-300);
        assert!((eight.lum_top[i] - top).abs() <= tol, "pixel {i}");
        assert!((split.lum_top[i] - top).abs() <= tol, "pixel {i}, passes 2 + 6");
        assert!(
            (ragged.lum_top[i] - top).abs() <= tol,
            "pixel {i}, passes 1 + 2 + 5"
        );
        assert_eq!(split.count[i], 8);
    }
    // Below two samples the block is the samples themselves.
    let one = render(&[1]);
    assert_eq!(one.lum_top, one.lum.iter().map(|l| l[0]).collect::<Vec<_>>());
}

/// `variance_of_mean` sees the convergence of a pixel's scrambled net: on a directly lit
/// plane (a smooth integrand) it is well below the Monte Carlo estimate `s²/n` and still
/// not below the actual error of the pixel means; on independent noise (no net) it is
/// the Monte Carlo estimate.
#[test]
fn variance_of_mean_sees_the_nets_convergence() {
    let (w, h) = (48u32, 36u32);
    let n = (w * h) as usize;
    let world = common::plane_under_sphere_light(60.0, w, h);
    let mut film = Film::new(w, h);
    film.render(&world, &vec![16; n], 5, f64::INFINITY, None);
    let mut reference = Film::new(w, h);
    reference.render(&world, &vec![1024; n], 6, f64::INFINITY, None);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let var = film.variance();
    let mc = mean(&var.iter().map(|v| v / 16.0).collect::<Vec<_>>());
    let est = mean(&film.variance_of_mean());
    let actual = mean(
        &(0..n)
            .map(|i| (film.lum[i][0] / 16.0 - reference.lum[i][0] / 1024.0).powi(2))
            .collect::<Vec<_>>(),
    );
    // Measured: s²/n 8.6e-8, the pixel means' actual squared error 3.6e-8 (the net
    // converges faster than Monte Carlo), this estimate 4.4e-8.
    assert!(actual < 0.5 * mc, "actual {actual:.3e}, Monte Carlo's {mc:.3e}");
    assert!(est < 0.6 * mc, "estimate {est:.3e}, Monte Carlo's {mc:.3e}");
    assert!(est > actual, "estimate {est:.3e}, actual {actual:.3e}");
    // Independent Gaussian noise: the halves are independent, the split agrees with
    // s²/n in expectation, and the pooled ratio (at most 1) is near 1.
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut noise = Film::new(w, h);
    for i in 0..n {
        let mut top = 0.0;
        for k in 0..16 {
            let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
            let y = 1.0 + 0.1 * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos();
            noise.lum[i][0] += y;
            noise.lum[i][1] += y * y;
            if k >= 8 {
                top += y;
            }
        }
        noise.count[i] = 16;
        noise.lum_top[i] = top;
    }
    let mc = mean(&noise.variance().iter().map(|v| v / 16.0).collect::<Vec<_>>());
    let est = mean(&noise.variance_of_mean());
    assert!(
        est > 0.8 * mc && est <= mc,
        "estimate {est:.3e}, Monte Carlo's {mc:.3e}"
    );
}
