//! The feature images (AOVs) a denoiser takes, and the denoiser itself when this build
//! has it.

use std::path::Path;

use cov_render::denoise::Denoise;
use cov_render::film::Film;
use cov_render::{Method, RenderSettings, Renderer, World};

mod common;

/// A diffuse plane (albedo 0.5) seen straight down from 1 m: every sample's first hit has
/// albedo 0.5, normal +y and a distance of 1 m over the cosine of its angle off the axis
/// (within 0.25° here).
#[test]
fn features_of_a_plane_seen_from_above_are_its_closed_form() {
    let world = common::plane_under_sphere_light(0.5, 2, 2);
    let mut film = Film::new(2, 2);
    film.render(&world, &[16; 4], 1, f64::INFINITY, None);
    let aovs = film.aovs();
    for i in 0..4 {
        assert!(
            (aovs.albedo.pixels[i] - glam::DVec3::splat(0.5))
                .abs()
                .max_element()
                < 1e-12
        );
        assert!((aovs.normal.pixels[i] - glam::DVec3::Y).abs().max_element() < 1e-12);
        let d = aovs.depth[i];
        assert!((1.0..1.0 + 1e-4).contains(&d), "depth {d}");
    }
}

/// A textured plane seen straight down, filling the view: a 2×2 checker over 8×8 pixels.
/// Pixels inside a square see only its colour, so their albedo is that colour exactly
/// (the material's albedo 1 times the texture).
#[test]
fn the_albedo_of_a_textured_plane_is_its_texture() {
    let h = 0.25f64.to_radians().tan();
    let text = format!(
        r#"Scene(
        camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov: 0.5, width: 8, height: 8),
        textures: {{ "c": Checker(checks: (2, 2), a: (0.8, 0.2, 0.1), b: (0.1, 0.3, 0.9), size: 512) }},
        materials: {{ "t": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "c") }},
        lights: [Sphere(center: (0.0, 2.0, 0.0), radius: 0.5, radiance: (1.0, 1.0, 1.0))],
        shapes: [Quad(corner: ({m:?}, 0.0, {m:?}), edge_u: ({w:?}, 0.0, 0.0), edge_v: (0.0, 0.0, {w:?}), material: "t")],
    )"#,
        m = -h,
        w = 2.0 * h
    );
    let world = World::from_text(&text, "<test>", Path::new(".")).unwrap();
    let mut film = Film::new(8, 8);
    film.render(&world, &[16; 64], 1, f64::INFINITY, None);
    let aovs = film.aovs();
    let (a, b) = (glam::DVec3::new(0.8, 0.2, 0.1), glam::DVec3::new(0.1, 0.3, 0.9));
    for (x, y, want) in [(1, 1, a), (6, 1, b), (1, 6, b), (6, 6, a), (2, 5, b), (5, 2, b)] {
        let got = aovs.albedo.pixels[y * 8 + x];
        assert!(
            (got - want).abs().max_element() < 1e-5,
            "pixel ({x}, {y}): {got} against {want}"
        );
    }
}

/// The multi-layer EXR holds the three layers with the film's values.
#[test]
fn the_feature_file_reads_back() {
    let world = common::plane_under_sphere_light(30.0, 4, 3);
    let mut film = Film::new(4, 3);
    film.render(&world, &[4; 12], 1, f64::INFINITY, None);
    let aovs = film.aovs();
    let path = std::env::temp_dir().join(format!("covtrace-aov-{}.exr", std::process::id()));
    cov_render::output::write_aovs(&aovs, &path).unwrap();
    let img = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let names: Vec<String> = img
        .layer_data
        .iter()
        .map(|l| {
            l.attributes
                .layer_name
                .as_ref()
                .map(|n| n.to_string())
                .unwrap_or_default()
        })
        .collect();
    assert_eq!(names, ["albedo", "normal", "depth"]);
    let depth = &img.layer_data[2].channel_data.list[0].sample_data;
    for i in 0..12 {
        let v = depth.value_by_flat_index(i).to_f32();
        assert!(
            (f64::from(v) - aovs.depth[i]).abs() < 1e-6,
            "{v} vs {}",
            aovs.depth[i]
        );
    }
}

fn cornell(w: u32, h: u32) -> World {
    World::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes/cornell.ron"))
        .unwrap()
        .with_resolution(w, h)
}

/// Renders `world` with `method` at `spp`, followed by `denoise`.
#[cfg(feature = "oidn")]
fn render_with(world: &World, method: Method, spp: f64, denoise: Denoise) -> cov_render::Rendered {
    let s = RenderSettings {
        method,
        spp,
        denoise,
        ..RenderSettings::default()
    };
    Renderer::new(world, s).unwrap().render(None).unwrap()
}

/// Without the feature, asking for the denoiser is a clear error, never a crash.
#[cfg(not(feature = "oidn"))]
#[test]
fn without_oidn_the_denoiser_says_how_to_get_it() {
    let world = cornell(16, 12);
    let s = RenderSettings {
        method: Method::Uniform,
        spp: 2.0,
        denoise: Denoise::Oidn,
        ..RenderSettings::default()
    };
    let e = Renderer::new(&world, s)
        .unwrap()
        .render(None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("--features oidn") && !e.contains('\n'), "{e}");
}

/// With OIDN: a 4-spp uniform render denoised, with and without guides, is much closer
/// to a 256-spp reference than the noisy image.
#[cfg(feature = "oidn")]
#[test]
fn oidn_lowers_the_error_of_a_noisy_render() {
    use cov_render::metrics::measure;
    let world = cornell(64, 48);
    let reference = cov_render::render(&world, 256, 77);
    let run = |d: Denoise| {
        let r = render_with(&world, Method::Uniform, 4.0, d);
        assert!(
            r.image
                .pixels
                .iter()
                .all(|p| p.is_finite() && p.min_element() >= 0.0)
        );
        measure(&r.image, &reference).unwrap().relmse
    };
    let (noisy, guided, color) = (run(Denoise::None), run(Denoise::Oidn), run(Denoise::OidnColor));
    assert!(
        guided < 0.5 * noisy && color < 0.5 * noisy,
        "noisy {noisy}, guided {guided}, colour {color}"
    );
}

/// With OIDN, covariance tracing gives the denoiser its box image: the guarded allocation
/// decides where samples go, the denoiser reconstructs them. The render equals OIDN run
/// on the box image of the same samples, and its samples are those of `cov` alone.
#[cfg(feature = "oidn")]
#[test]
fn the_denoiser_receives_the_box_image_of_the_guarded_samples() {
    let world = cornell(64, 48);
    let run = |d: Denoise| render_with(&world, Method::Cov, 8.0, d);
    let (plain, denoised) = (run(Denoise::None), run(Denoise::Oidn));
    assert_eq!(plain.film, denoised.film);
    let aovs = plain.film.aovs();
    let want = cov_render::denoise::oidn(&plain.film.box_image(), Some(&aovs)).unwrap();
    assert_eq!(denoised.image.digest(), want.digest());
    assert_ne!(denoised.image.digest(), plain.image.digest());
}

/// Below 3 spp covariance tracing followed by the denoiser has no pilot to allocate
/// from, so nothing reads Σ: the pass is not traced or timed, and the render is uniform
/// sampling's with the denoiser, bit for bit.
#[cfg(feature = "oidn")]
#[test]
fn a_denoised_render_without_a_pilot_traces_no_pass() {
    let world = cornell(64, 48);
    for spp in [1.0, 2.0] {
        let s = RenderSettings {
            method: Method::Cov,
            spp,
            denoise: Denoise::Oidn,
            ..RenderSettings::default()
        };
        let mut r = Renderer::new(&world, s).unwrap();
        let cov = r.render(None).unwrap();
        assert!(r.maps().is_none() && cov.timing.covariance == 0.0, "{spp} spp");
        let uniform = render_with(&world, Method::Uniform, spp, Denoise::Oidn);
        assert_eq!(cov.image.digest(), uniform.image.digest(), "{spp} spp");
    }
    // From 3 spp the pilot allocates from Σ.
    let s = RenderSettings {
        method: Method::Cov,
        spp: 3.0,
        denoise: Denoise::Oidn,
        ..RenderSettings::default()
    };
    let mut r = Renderer::new(&world, s).unwrap();
    r.render(None).unwrap();
    assert!(r.maps().is_some());
}
