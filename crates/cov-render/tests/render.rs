//! The renderer: determinism, energy against a closed form, the covariance maps' invariants.

use std::path::{Path, PathBuf};

use cov_render::film::Film;
use cov_render::{World, covariance_maps, render};

mod common;

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes")
}

fn load(name: &str, w: u32, h: u32) -> World {
    World::load(&scenes().join(name))
        .unwrap_or_else(|e| panic!("{e}"))
        .with_resolution(w, h)
}

/// The spectrum variance (cycles/px)² that the sensor's pixel filter adds on each image
/// axis, `1/(4π² f²)` for a filter of std `f` px: what every pixel's Σ has beside the
/// image's content.
fn own_window() -> f64 {
    let f = cov_sensor::SensorParams::default().filter;
    1.0 / (4.0 * std::f64::consts::PI.powi(2) * f * f)
}

/// A pixel of a covariance map: finite, its Σ PSD, its predicted samples non-negative.
fn finite_and_psd(p: &cov_render::covpass::PixelCov, what: &str) {
    let [a, b, c] = p.sigma;
    assert!(
        a.is_finite() && b.is_finite() && c.is_finite() && p.spp.is_finite(),
        "{what}: {p:?}"
    );
    assert!(
        a >= 0.0 && c >= 0.0 && a * c - b * b >= -1e-9 * (a * c).max(1e-300),
        "{what}: not PSD {p:?}"
    );
    assert!(p.spp >= 0.0, "{what}: {p:?}");
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool")
}

#[test]
fn every_bundled_scene_renders_the_same_on_one_and_two_threads() {
    for name in ["cornell.ron", "pool.ron", "glossy.ron"] {
        let world = load(name, 24, 18);
        let a = pool(1).install(|| render(&world, 4, 7));
        let b = pool(2).install(|| render(&world, 4, 7));
        assert_eq!(a, b, "{name}: image differs with the thread count");
        assert!(
            a.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0),
            "{name}"
        );
        assert!(
            a.pixels.iter().any(|p| p.max_element() > 0.0),
            "{name}: black image"
        );
        let ma = pool(1)
            .install(|| covariance_maps(&world, 2, 1, 7, None))
            .unwrap();
        let mb = pool(2)
            .install(|| covariance_maps(&world, 2, 1, 7, None))
            .unwrap();
        assert_eq!(ma, mb, "{name}: covariance maps differ with the thread count");
        // A different seed gives a different image (the seed is used).
        assert_ne!(a, pool(2).install(|| render(&world, 4, 8)), "{name}");
    }
}

/// The scenes kept as known limits (examples/limits) load, their covariance maps are
/// finite and PSD, and they render finite and not black.
#[test]
fn every_limit_scene_renders() {
    let dir = scenes().join("../limits");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("examples/limits") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "ron") {
            continue;
        }
        let world = World::load(&path)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_resolution(16, 12);
        let maps = covariance_maps(&world, 1, 4, 7, None).unwrap_or_else(|e| panic!("{e}"));
        for p in &maps.pixels {
            finite_and_psd(p, &path.display().to_string());
        }
        let img = render(&world, 2, 7);
        assert!(
            img.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0),
            "{}",
            path.display()
        );
        assert!(
            img.pixels.iter().any(|p| p.max_element() > 0.0),
            "{}: black",
            path.display()
        );
        n += 1;
    }
    assert!(n >= 2, "examples/limits holds {n} scenes");
}

/// A diffuse plane of albedo ρ under a sphere light of radiance L and radius R whose
/// centre is D above the point seen: the irradiance is `π L (R/D)²`, so the radiance
/// leaving the plane is `ρ L (R/D)²`. The estimator (MIS direct light plus a bounce that
/// only finds the light) must match it within its Monte Carlo error.
#[test]
fn a_diffuse_plane_under_a_sphere_light_matches_the_closed_form() {
    let world = common::plane_under_sphere_light(0.5, 1, 1);
    let n = 20_000u32;
    let mut film = Film::new(1, 1);
    film.render(&world, &[n], 3, f64::INFINITY, None);
    let (img, var) = (film.box_image(), film.variance());
    let exact = 0.5 * (0.5f64 / 2.0).powi(2);
    let got = img.pixels[0].y;
    let stderr = (var[0] / n as f64).sqrt();
    assert!(stderr > 0.0 && stderr < 0.02 * exact, "stderr {stderr}");
    assert!(
        (got - exact).abs() <= 4.0 * stderr,
        "got {got}, closed form {exact}, 4σ = {}",
        4.0 * stderr
    );
}

/// Inside a diffuse sphere of radius `R` and albedo ρ, lit by a sphere light of radius `r`
/// and radiance `L` at its centre, every point of the wall takes `E₀ = π L s` from the
/// light directly (`s = (r/R)²`, the light's share of the projected solid angle) and sees
/// the rest of the wall, of one radiosity by symmetry, over `1 − s` of it: each bounce
/// multiplies the irradiance by `ρ (1 − s)`. A path of `d` surface vertices
/// (`max_depth: d`) therefore sees `ρ L s Σ_{k<d} (ρ (1 − s))ᵏ`. The tracer must match it
/// at depths 1, 2 (the default: no `max_depth` written), 5 and 32 (Russian roulette from
/// the third vertex) within 4σ, each depth's sum at least 8σ from its neighbours' (so the
/// depth is the one asked for).
#[test]
fn a_furnace_of_any_depth_matches_its_closed_form() {
    let (albedo, radiance, r) = (0.5f64, 100.0f64, 0.1f64);
    let s = r * r;
    let exact =
        |d: u32| albedo * radiance * s * (0..d).map(|k| (albedo * (1.0 - s)).powi(k as i32)).sum::<f64>();
    for depth in [None, Some(1u32), Some(5), Some(32)] {
        let field = depth.map_or(String::new(), |d| format!("max_depth: {d},"));
        let text = format!(
            r#"Scene(
            {field}
            camera: (position: (0.0, 0.0, 0.5), look_at: (0.0, 0.0, 1.0), fov: 10.0, width: 1, height: 1),
            materials: {{ "wall": Diffuse(albedo: ({albedo:?}, {albedo:?}, {albedo:?})) }},
            lights: [Sphere(center: (0.0, 0.0, 0.0), radius: {r:?}, radiance: ({radiance:?}, {radiance:?}, {radiance:?}))],
            shapes: [Sphere(center: (0.0, 0.0, 0.0), radius: 1.0, material: "wall")],
        )"#
        );
        let world = World::from_text(&text, "<furnace>", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
        let d = depth.unwrap_or(2);
        assert_eq!(world.max_depth, d);
        let n = 60_000u32;
        let mut film = Film::new(1, 1);
        film.render(&world, &[n], 9, f64::INFINITY, None);
        let got = film.box_image().pixels[0].y;
        let stderr = (film.variance()[0] / f64::from(n)).sqrt();
        assert!(
            stderr > 0.0 && (got - exact(d)).abs() <= 4.0 * stderr,
            "depth {d}: got {got}, closed form {} ± {stderr}",
            exact(d)
        );
        for other in [d - 1, d + 1].into_iter().filter(|&o| o >= 1 && o != d) {
            assert!(
                (exact(other) - exact(d)).abs() >= 8.0 * stderr || d >= 32,
                "depth {d}: the test cannot tell it from depth {other} (σ {stderr})"
            );
        }
    }
}

/// A scene of depth 4 (`max_depth: 4`, the glossy scene): its covariance paths follow up
/// to four vertices, with finite, PSD maps that differ from one vertex's (the later
/// vertices are seen); a fifth vertex, which its images do not have, is refused with the
/// scene's depth named.
#[test]
fn covariance_paths_follow_a_deeper_scene_and_no_further() {
    let text = std::fs::read_to_string(scenes().join("glossy.ron")).expect("glossy.ron");
    let text = text.replacen("Scene(", "Scene(\n    max_depth: 4,", 1);
    let world = World::from_text(&text, "glossy-4.ron", &scenes())
        .unwrap_or_else(|e| panic!("{e}"))
        .with_resolution(32, 24);
    assert_eq!(world.max_depth, 4);
    let one = cov_render::covpass::covariance_rows(&world, 2, 4, 1, 3, 0..24, None).expect("depth 1");
    let four = cov_render::covpass::covariance_rows(&world, 2, 4, 4, 3, 0..24, None).expect("depth 4");
    for p in &four.pixels {
        finite_and_psd(p, "depth 4");
    }
    assert_ne!(one, four, "the later vertices change the maps");
    let e = cov_render::covpass::covariance_rows(&world, 2, 4, 5, 3, 0..24, None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("must be 1 to the scene's max_depth, 4"), "{e}");
}

/// A camera moving at `v` along its right while turning at `ω = v/d` about its up axis
/// tracks the point at distance `d` ahead (docs/physics.md, motion): the tracer's ray
/// through the image's centre meets the tracked sphere's front at the shutter's two ends
/// (within the turn's third-order term), where moving alone it sweeps `v t` across; and the
/// covariance pass keeps the sphere's outline as sharp as a still camera does and predicts
/// little time content, where moving alone (or turning the wrong way) the outline is
/// blurred and the swept bands need many samples in time.
#[test]
fn a_camera_that_turns_to_track_a_point_keeps_it_still() {
    let (v, d, close) = (1.0f64, 5.0f64, 0.5f64);
    let world = |velocity: f64, turn: f64| -> World {
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 0.0, 0.0), look_at: (0.0, 0.0, -5.0), fov: 40.0, width: 32, height: 24,
                shutter: (open: 0.0, close: {close:?}), velocity: ({velocity:?}, 0.0, 0.0), angular_velocity: (0.0, {turn:?}, 0.0)),
            materials: {{ "grey": Diffuse(albedo: (0.5, 0.5, 0.5)), "dark": Diffuse(albedo: (0.05, 0.05, 0.05)) }},
            lights: [Rect(corner: (-2.0, 4.0, -7.0), edge_u: (4.0, 0.0, 0.0), edge_v: (0.0, 0.0, 4.0), radiance: (5.0, 5.0, 5.0))],
            shapes: [
                Sphere(center: (0.0, 0.0, -{d:?}), radius: 0.8, material: "grey"),
                Quad(corner: (-40.0, -30.0, -30.0), edge_u: (80.0, 0.0, 0.0), edge_v: (0.0, 60.0, 0.0), material: "dark"),
            ],
        )"#
        );
        World::from_text(&text, "<tracking>", Path::new(".")).unwrap_or_else(|e| panic!("{e}"))
    };
    let (still, tracking, moving) = (world(0.0, 0.0), world(v, v / d), world(v, 0.0));
    // How far the ray through the image's centre passes from the tracked point.
    let miss = |w: &World, ut: f64| {
        let ray = w.camera.ray(16.0, 12.0, (0.5, 0.5), ut);
        (glam::DVec3::new(0.0, 0.0, -d) - ray.origin)
            .cross(ray.dir)
            .length()
    };
    let turn = v / d * close;
    let third = d * (turn.tan() - turn).abs();
    for ut in [0.0, 0.5, 1.0] {
        assert!(
            miss(&tracking, ut) <= third + 1e-12,
            "tracking, at {ut}: {}",
            miss(&tracking, ut)
        );
    }
    assert!(
        (miss(&moving, 1.0) - v * close).abs() < 1e-9,
        "{}",
        miss(&moving, 1.0)
    );
    // The pass, along the sphere's row: the sharpest outline (the largest `Σxx`) and the
    // time content (predicted samples per pixel over pixel × lens × time, above the row's
    // least, summed in units of it: a swept band needs many).
    let row = |w: &World| -> (f64, f64) {
        let maps = covariance_maps(w, 4, 1, 5, None).expect("maps");
        let px: Vec<_> = (0..32).map(|x| maps.pixels[12 * 32 + x]).collect();
        let least = px.iter().map(|p| p.spp).fold(f64::INFINITY, f64::min);
        let sharpest = px.iter().map(|p| p.sigma[0]).fold(0.0, f64::max);
        (sharpest, px.iter().map(|p| p.spp / least - 1.0).sum())
    };
    let (still, tracking, moving, wrong) =
        (row(&still), row(&tracking), row(&moving), row(&world(v, -v / d)));
    assert!(
        tracking.0 >= 0.8 * still.0 && moving.0 < 0.7 * still.0,
        "outline: still {still:?}, tracking {tracking:?}, moving {moving:?}"
    );
    assert!(
        tracking.1 < 0.25 * moving.1 && moving.1 < wrong.1,
        "time content: still {still:?}, tracking {tracking:?}, moving {moving:?}, turning the wrong way {wrong:?}"
    );
}

/// A sphere spinning about `y` at `w` carries its surface with it: the point that faces
/// `+z` at time 0 faces `+x` a quarter turn later, with the same texture coordinates and
/// derivatives turned with it. Rolling without slipping (`spin = up × v / r`), the point
/// touching the floor is still and the top moves at twice the ball's velocity (what the
/// covariance pass's motion reads).
#[test]
fn a_spinning_sphere_carries_its_surface() {
    let text = |spin: &str, velocity: &str| {
        format!(
            r#"Scene(
            camera: (position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), fov: 30.0, width: 8, height: 8, shutter: (open: 0.0, close: 1.0)),
            materials: {{ "grey": Diffuse(albedo: (0.5, 0.5, 0.5)) }},
            lights: [Rect(corner: (-1.0, 4.0, -1.0), edge_u: (2.0, 0.0, 0.0), edge_v: (0.0, 0.0, 2.0), radiance: (5.0, 5.0, 5.0))],
            shapes: [Sphere(center: (0.0, 0.0, 0.0), radius: 0.5, material: "grey", velocity: {velocity}, spin: {spin})],
        )"#
        )
    };
    let w = 2.0f64;
    let world = World::from_text(
        &text(&format!("(0.0, {w:?}, 0.0)"), "(0.0, 0.0, 0.0)"),
        "<spin>",
        Path::new("."),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let quarter = std::f64::consts::FRAC_PI_2 / w;
    // What a ray from `o` along `d` at time `t` meets.
    let meet =
        |w: &World, o: glam::DVec3, d: glam::DVec3, t: f64| w.geometry.intersect(o, d, t, 0.0, f64::INFINITY);
    let from_z = meet(&world, glam::DVec3::new(0.0, 0.0, 3.0), -glam::DVec3::Z, 0.0).expect("front at 0");
    let from_x = meet(&world, glam::DVec3::new(3.0, 0.0, 0.0), -glam::DVec3::X, quarter)
        .expect("side a quarter turn later");
    assert!(
        (from_z.uv - from_x.uv).length() < 1e-12,
        "{:?} against {:?}",
        from_z.uv,
        from_x.uv
    );
    // ∂p/∂u turned by a quarter about y: (a, b, c) → (c, b, −a).
    let [du0, _] = from_z.dpduv;
    let [du1, _] = from_x.dpduv;
    assert!(
        (du1 - glam::DVec3::new(du0.z, du0.y, -du0.x)).length() < 1e-9 * du0.length(),
        "{du0} {du1}"
    );
    // Without spin the side shows other coordinates.
    let still = World::from_text(
        &text("(0.0, 0.0, 0.0)", "(0.0, 0.0, 0.0)"),
        "<still>",
        Path::new("."),
    )
    .unwrap();
    let side = meet(&still, glam::DVec3::new(3.0, 0.0, 0.0), -glam::DVec3::X, quarter).unwrap();
    assert!((side.uv - from_z.uv).length() > 0.2, "{:?}", side.uv);
    // Rolling along +x at 1 m/s on a floor facing +y: spin (0, 0, −v/r).
    let rolling = World::from_text(
        &text("(0.0, 0.0, -2.0)", "(1.0, 0.0, 0.0)"),
        "<rolling>",
        Path::new("."),
    )
    .unwrap();
    let at = |o: glam::DVec3, d: glam::DVec3| meet(&rolling, o, d, 0.0).expect("the ball").velocity;
    let bottom = at(glam::DVec3::new(0.0, -3.0, 0.0), glam::DVec3::Y);
    let top = at(glam::DVec3::new(0.0, 3.0, 0.0), -glam::DVec3::Y);
    assert!(bottom.length() < 1e-12, "the contact point moves at {bottom}");
    assert!(
        (top - glam::DVec3::new(2.0, 0.0, 0.0)).length() < 1e-12,
        "the top moves at {top}"
    );
    // Bounded where it is written.
    let e = World::from_text(
        &text("(0.0, 1e6, 0.0)", "(0.0, 0.0, 0.0)"),
        "s.ron",
        Path::new("."),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("s.ron:5:118: spin must be at most 6283.185307179586 rad/s"),
        "{e}"
    );
}

/// A camera sliding past a lamp it sees directly (a new user's scene, 2026-12-02): the
/// lamp's emission, swept across the image by the motion, stays in its pixels (the film
/// never filters it), so the guarded allocation must not give those pixels fewer samples
/// for the filter their reflected light may take. It gave them the pilot's count, and
/// `cov` erred 1.4 to 2.6 times more than uniform sampling at 4 to 64 spp; it must err
/// less than uniform sampling at 8 spp against a 256-spp reference.
#[test]
fn a_lamp_swept_across_the_image_keeps_its_samples() {
    let text = r#"Scene(
    camera: (
        position: (-4.0, 1.0, 0.0),
        look_at: (0.0, 3.0, 0.0),
        fov: 50.0,
        width: 64,
        height: 48,
        shutter: (open: 0.0, close: 0.05), velocity: (0.0, 0.0, 40.0),
    ),
    textures: {
        "checks": Checker(checks: (12, 12), a: (0.9, 0.9, 0.9), b: (0.1, 0.1, 0.1)),
        "wallchecks": Checker(checks: (16, 8), a: (0.8, 0.7, 0.6), b: (0.1, 0.15, 0.3)),
        "ballchecks": Checker(checks: (8, 4), a: (0.9, 0.2, 0.1), b: (0.9, 0.9, 0.9)),
    },
    materials: {
        "floor": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "checks"),
        "wall": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "wallchecks"),
        "ball": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "ballchecks"),
    },
    lights: [
        Rect(corner: (-1.0, 3.0, -1.0), edge_u: (2.0, 0.0, 0.0), edge_v: (0.0, 0.0, 2.0), radiance: (8.0, 8.0, 8.0)),
    ],
    shapes: [
        Quad(corner: (-6.0, 0.0, -3.0), edge_u: (12.0, 0.0, 0.0), edge_v: (0.0, 0.0, 8.0), material: "floor"),
        Quad(corner: (-6.0, 0.0, -3.0), edge_u: (12.0, 0.0, 0.0), edge_v: (0.0, 4.0, 0.0), material: "wall"),
        Quad(corner: (3.0, 0.0, -6.0), edge_u: (0.0, 0.0, 12.0), edge_v: (0.0, 4.0, 0.0), material: "wall"),
        Sphere(center: (0.0, 1.0, 0.0), radius: 0.4, material: "ball"),
    ],
)
"#;
    let world = World::from_text(text, "<lamp>", Path::new(".")).unwrap_or_else(|e| panic!("{e}"));
    let image = |method: cov_render::Method, spp: f64, seed: u64| {
        let settings = cov_render::RenderSettings {
            method,
            spp,
            seed,
            ..cov_render::RenderSettings::default()
        };
        cov_render::Renderer::new(&world, settings)
            .and_then(|mut r| r.render(None))
            .expect("render")
            .image
    };
    let reference = image(cov_render::Method::Uniform, 256.0, 99);
    let err = |m| {
        cov_render::metrics::measure(&image(m, 8.0, 1), &reference)
            .expect("same size")
            .relmse
    };
    let (uniform, cov) = (err(cov_render::Method::Uniform), err(cov_render::Method::Cov));
    assert!(cov < uniform, "cov {cov}, uniform {uniform}");
}

/// Adaptive counts and a second pass that continues each pixel's sequence keep the box
/// estimate unbiased: a diffuse plane under a sphere light (closed form `ρ L (R/D)²`, as above) estimated from 3 001 then 9 000 more samples matches within 4σ.
#[test]
fn a_two_pass_estimate_matches_the_closed_form() {
    let world = common::plane_under_sphere_light(0.5, 1, 1);
    let mut film = Film::new(1, 1);
    film.render(&world, &[3001], 5, f64::INFINITY, None);
    film.render(&world, &[9000], 5, f64::INFINITY, None);
    assert_eq!(film.count[0], 12001);
    let got = film.box_image().pixels[0].y;
    let exact = 0.5 * (0.5f64 / 2.0).powi(2);
    let stderr = (film.variance()[0] / 12001.0).sqrt();
    assert!(
        stderr > 0.0 && (got - exact).abs() <= 4.0 * stderr,
        "got {got}, closed form {exact} ± {stderr}"
    );
}

#[test]
fn covariance_maps_are_finite_psd_and_see_the_scene() {
    for name in ["cornell.ron", "pool.ron", "glossy.ron"] {
        let world = load(name, 32, 24);
        let maps = covariance_maps(&world, 4, 1, 1, None).unwrap();
        assert_eq!(maps.pixels.len(), 32 * 24);
        for p in &maps.pixels {
            finite_and_psd(p, name);
        }
        // The prediction varies over the image: some pixels need more samples than others.
        let (lo, hi) = maps
            .pixels
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), p| (l.min(p.spp), h.max(p.spp)));
        assert!(hi > 2.0 * lo, "{name}: flat prediction {lo}..{hi}");
    }
    // Motion and defocus enter the layout only where the scene has them.
    assert_eq!(
        covariance_maps(&load("cornell.ron", 8, 6), 1, 1, 1, None)
            .unwrap()
            .layout,
        5
    );
    assert_eq!(
        covariance_maps(&load("glossy.ron", 8, 6), 1, 1, 1, None)
            .unwrap()
            .layout,
        4
    );
}

/// The covariance pass weights each path by the radiance it carries (ignoring visibility
/// towards the light). Where nothing blocks the light and no light arrives after a bounce,
/// a diffuse plane under a sphere light, the weights must estimate the closed-form radiance
/// `ρ L (R/D)²` within their Monte Carlo error: the maps average Σ with the image's own
/// radiance, not a biased stand-in.
#[test]
fn the_covariance_pass_weights_estimate_the_radiance() {
    use cov_render::covpass::{CovCamera, MAX_DEPTH, trace_path};
    use rand::{Rng, SeedableRng};
    let world = common::plane_under_sphere_light(0.5, 1, 1);
    let exact = 0.5 * (0.5f64 / 2.0).powi(2);
    let cc = CovCamera::new(&world).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let m = 100_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..m {
        let (px, py, ut) = (rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>());
        let block = [0.0, 0.0, 1.0, 1.0];
        let vertices = trace_path(&world, &cc, (px, py), block, ut, MAX_DEPTH, &mut rng).unwrap();
        assert!(!vertices.is_empty(), "the plane is seen");
        let mut w = 0.0;
        for (rates, wv) in vertices {
            assert!(rates.samples_per_pixel.is_finite() && rates.image_cov_px[0][0] >= 0.0);
            w += wv;
        }
        sum += w;
        sum2 += w * w;
    }
    let mean = sum / f64::from(m);
    let se = ((sum2 / f64::from(m) - mean * mean) / f64::from(m)).sqrt();
    assert!(se > 0.0 && se < 0.005 * exact, "stderr {se}");
    assert!(
        (mean - exact).abs() <= 4.0 * se,
        "weights {mean} ± {se}, closed form {exact}"
    );
}

/// A step in albedo enters the pass as an edge weighted by its contrast (the amplitude
/// convention, docs/physics.md section 3): two quads meeting under the camera, of albedos
/// 0.5 and `other`. The pixels beside the boundary predict more detail for a strong step
/// (0.05 against 0.5) than for a faint one (0.45), in the ratio of their contrasts, and
/// none where the two materials are the same; pixels far from it see no edge.
#[test]
fn a_material_edge_weighs_by_its_contrast() {
    let sigma_xx = |other: f64| -> (f64, f64) {
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov: 10.0, width: 8, height: 8),
            materials: {{ "a": Diffuse(albedo: (0.5, 0.5, 0.5)), "b": Diffuse(albedo: ({other:?}, {other:?}, {other:?})) }},
            lights: [Sphere(center: (0.0, 2.0, 0.0), radius: 0.5, radiance: (1.0, 1.0, 1.0))],
            shapes: [
                Quad(corner: (-5.0, 0.0, -5.0), edge_u: (5.0, 0.0, 0.0), edge_v: (0.0, 0.0, 10.0), material: "a"),
                Quad(corner: (0.0, 0.0, -5.0), edge_u: (5.0, 0.0, 0.0), edge_v: (0.0, 0.0, 10.0), material: "b"),
            ],
        )"#
        );
        let world = World::from_text(&text, "<test>", std::path::Path::new(".")).unwrap();
        let maps = covariance_maps(&world, 4, 1, 1, None).unwrap();
        // Less the pixel filter's own window, which every pixel has.
        let own = own_window();
        let at = |x: usize| maps.pixels[4 * 8 + x].sigma[0] - own;
        (at(3).max(at(4)), at(0))
    };
    let (strong, far_strong) = sigma_xx(0.05);
    let (faint, far_faint) = sigma_xx(0.45);
    let (same, _) = sigma_xx(0.5);
    // The window of the edge scales with the contrast, |0.5 − b| / 0.5: 0.9 against 0.1.
    assert!(
        (strong / faint / 9.0 - 1.0).abs() < 1e-3,
        "strong {strong}, faint {faint}"
    );
    assert!(same.abs() < 1e-9 * strong, "faint {faint}, none {same}");
    assert!(
        far_strong.abs().max(far_faint.abs()) < 1e-9 * strong,
        "{far_strong} {far_faint}"
    );
}

/// A mirror floor shows the striped wall it reflects: with two vertices per path the
/// floor's pixels predict the stripes' bandwidth and orientation, as the wall seen
/// directly at the same distance in the mirror's unfolded geometry (the wall continued
/// below the floor, lit by the light's mirror image); with one vertex they see only the
/// floor. The residue (within 4%) is the Monte Carlo of 64 paths per pixel. Without the
/// change of handedness at the reflection, `Σ_xy` came out with the wrong sign and the
/// edge columns 7–8% low.
#[test]
fn a_mirror_shows_what_it_reflects() {
    let scene = |mirror: bool| -> World {
        let (floor, lower, light_y) = if mirror {
            (
                r#"Quad(corner: (-5.0, 0.0, -6.0), edge_u: (10.0, 0.0, 0.0), edge_v: (0.0, 0.0, 6.0), material: "mirror"),"#,
                "",
                4.0,
            )
        } else {
            (
                "",
                r#"Quad(corner: (-5.0, -3.0, -6.0), edge_u: (0.0, 3.0, 0.0), edge_v: (10.0, 0.0, 0.0), material: "wall"),"#,
                -4.0,
            )
        };
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 3.0, 0.0), look_at: (0.0, 0.0, -4.0), fov: 40.0, width: 16, height: 16),
            textures: {{ "stripes": Stripes(count: 5, duty: 0.5, a: (0.8, 0.8, 0.8), b: (0.1, 0.1, 0.1)) }},
            materials: {{
                "wall": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "stripes"),
                "mirror": Phong(albedo: (0.9, 0.9, 0.9), exponent: 1000000.0),
            }},
            lights: [Sphere(center: (0.0, {light_y:?}, -2.0), radius: 0.5, radiance: (5.0, 5.0, 5.0))],
            shapes: [
                Quad(corner: (-5.0, 0.0, -6.0), edge_u: (0.0, 3.0, 0.0), edge_v: (10.0, 0.0, 0.0), material: "wall"),
                {floor}
                {lower}
            ],
        )"#
        );
        World::from_text(&text, "<test>", std::path::Path::new(".")).unwrap()
    };
    let maps = |w: &World, depth: u32| {
        cov_render::covpass::covariance_rows(w, 64, 1, depth, 1, 0..16, None).unwrap()
    };
    let (m2, m1, u) = (
        maps(&scene(true), 2),
        maps(&scene(true), 1),
        maps(&scene(false), 2),
    );
    // Less the pixel filter's own window, which every pixel has.
    let own = own_window();
    // Rows 5 to 9 see the floor, away from where it meets the wall (rows 3 and 4), and the
    // reflected rays reach the wall below its top.
    for y in 5..10 {
        for x in 5..11 {
            let at = |m: &cov_render::CovMaps| m.pixels[y * 16 + x].sigma[0] - own;
            let (mirror, direct, floor_only) = (at(&m2), at(&u), at(&m1));
            assert!(direct > 0.0, "({x}, {y}): the wall's stripes {direct}");
            assert!(
                (mirror / direct - 1.0).abs() < 0.05,
                "({x}, {y}): in the mirror {mirror}, seen directly {direct}"
            );
            // The image of the stripes, not a turned copy: the correlation of x and y (the
            // stripes converge in perspective) keeps its sign and size.
            let xy = |m: &cov_render::CovMaps| m.pixels[y * 16 + x].sigma[1];
            assert!(
                (xy(&m2) / xy(&u) - 1.0).abs() < 0.25,
                "({x}, {y}): Σ_xy in the mirror {}, seen directly {}",
                xy(&m2),
                xy(&u)
            );
            assert!(
                floor_only.abs() < 1e-3 * direct,
                "({x}, {y}): one vertex {floor_only}"
            );
        }
    }
}

/// A plane seen at a grazing angle is no silhouette of itself: half a pixel away its depth
/// changes by more than the silhouette threshold (7% here), but it continues the hit's
/// tangent plane. Lit from below, both sides are dark, where an edge would count at full
/// contrast: the floor's pixels must predict the pixel filter's own window and nothing
/// more.
#[test]
fn a_plane_at_a_grazing_angle_is_no_silhouette() {
    let text = r#"Scene(
        camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 1.0, -1.0), fov: 40.0, width: 16, height: 16),
        materials: { "floor": Diffuse(albedo: (0.5, 0.5, 0.5)) },
        lights: [Sphere(center: (0.0, -2.0, -3.0), radius: 0.5, radiance: (5.0, 5.0, 5.0))],
        shapes: [Quad(corner: (-50.0, 0.0, -50.0), edge_u: (100.0, 0.0, 0.0), edge_v: (0.0, 0.0, 50.0), material: "floor")],
    )"#;
    let world = World::from_text(text, "<test>", std::path::Path::new(".")).unwrap();
    let maps = cov_render::covpass::covariance_rows(&world, 4, 1, 1, 1, 0..16, None).unwrap();
    let own = own_window();
    // Rows 12 to 15 see the floor 3 to 6 m away, at 10° to 19° from grazing.
    for y in 12..16 {
        for x in 4..12 {
            let s = maps.pixels[y * 16 + x].sigma;
            assert!(
                (s[0] - own).abs() < 1e-9 * own && (s[2] - own).abs() < 1e-9 * own,
                "({x}, {y}): {s:?} against the pixel filter's {own}"
            );
        }
    }
}

/// A texture's spectrum does not depend on how the ray's frame is turned. Vertical stripes
/// on a wall seen head-on, from a little above its middle: across a row the ray's frame
/// (`x` in the plane of incidence) turns by about 120° (vertical in the middle column,
/// about 60° from it at the sides), while the stripes' detail stays horizontal. Every pixel must predict horizontal detail and no
/// vertical detail (Σ_yy below 1% of Σ_xx: perspective tilts the stripes by up to about 2°
/// at the sides; Σ_xx still varies with where a pixel falls on the stripes). Taken in
/// the ray's frame with its correlation dropped, the texture's spectrum was spread over
/// both axes where that frame is turned: Σ_yy rose to Σ_xx's size and Σ_xx about halved.
#[test]
fn a_texture_does_not_turn_with_the_rays_frame() {
    let text = r#"Scene(
        camera: (position: (0.0, 0.3, 2.0), look_at: (0.0, 0.0, 0.0), fov: 30.0, width: 32, height: 16),
        textures: { "stripes": Stripes(count: 60, duty: 0.5, a: (0.3, 0.3, 0.3), b: (0.9, 0.9, 0.9)) },
        materials: { "wall": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "stripes") },
        lights: [Rect(corner: (-20.0, -20.0, 30.0), edge_u: (40.0, 0.0, 0.0), edge_v: (0.0, 40.0, 0.0), radiance: (1.0, 1.0, 1.0))],
        shapes: [Quad(corner: (-6.0, -3.0, 0.0), edge_u: (0.0, 6.0, 0.0), edge_v: (12.0, 0.0, 0.0), material: "wall")],
    )"#;
    let world = World::from_text(text, "<test>", std::path::Path::new(".")).unwrap();
    let maps = cov_render::covpass::covariance_rows(&world, 4, 1, 1, 1, 0..16, None).unwrap();
    let own = own_window();
    let xx: Vec<f64> = (0..32 * 16).map(|i| maps.pixels[i].sigma[0] - own).collect();
    let lo = xx.iter().fold(f64::INFINITY, |a, &v| a.min(v));
    assert!(
        lo > 0.0,
        "every pixel sees the stripes: smallest Σ_xx above the filter's {lo}"
    );
    for (i, p) in maps.pixels.iter().enumerate() {
        let yy = p.sigma[2] - own;
        assert!(
            yy.abs() < 1e-2 * xx[i],
            "pixel {i}: Σ_yy {yy} beside Σ_xx {}",
            xx[i]
        );
    }
}

/// The image-space bandwidth (cycles/px, the pixel filter's own window removed) that the
/// covariance pass predicts at each pixel of `text`'s scene, with `paths` paths per pixel.
fn bandwidths(text: &str, paths: u32) -> Vec<f64> {
    let world = World::from_text(text, "<test>", std::path::Path::new(".")).unwrap();
    let maps = covariance_maps(&world, paths, 1, 1, None).unwrap();
    let own = own_window();
    maps.pixels
        .iter()
        .map(|p| (p.sigma[0] + p.sigma[2] - 2.0 * own).max(0.0).sqrt())
        .collect()
}

/// A sphere lit from the side by a large light: the points of the light below a point's
/// own horizon near the terminator are the cosine's fall, not a blocker's edge. When the
/// shadow probes took the sphere itself for a blocker at the hit, the band around the
/// terminator predicted 0.1 to 17 cycles/px; the image there is smooth.
#[test]
fn a_sphere_does_not_shadow_itself_at_its_terminator() {
    let sphere = r#"Scene(
        camera: (position: (0.0, 0.0, 5.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 20.0, width: 24, height: 24),
        materials: { "a": Diffuse(albedo: (0.5, 0.5, 0.5)) },
        lights: [Sphere(center: (6.0, 0.0, 0.0), radius: 2.0, radiance: (1.0, 1.0, 1.0))],
        shapes: [Sphere(center: (0.0, 0.0, 0.0), radius: 1.0, material: "a")],
    )"#;
    let b = bandwidths(sphere, 16);
    // The sphere fills the frame but its corners; the terminator runs down the middle.
    let band = (4..20).flat_map(|y| (6..18).map(move |x| (x, y)));
    let worst = band.map(|(x, y)| b[y * 24 + x]).fold(0.0, f64::max);
    assert!(worst < 0.05, "{worst} cycles/px at the terminator");
}

/// Under a square blocker lit by a small sphere light: where the path's own shadow ray is
/// blocked, the edge is between it and the clear probes (or beyond every probe, in the
/// umbra), not on the path. When the blocked path put the edge on itself, the floor under
/// the blocker predicted 0.5 to 14 cycles/px (the image there is flat); now it falls from
/// the penumbra inwards and stays within what an image can show.
#[test]
fn an_umbra_is_no_sharper_than_the_edge_around_it() {
    let umbra = r#"Scene(
        camera: (position: (0.0, 0.6, 3.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 30.0, width: 24, height: 24),
        materials: { "a": Diffuse(albedo: (0.5, 0.5, 0.5)) },
        lights: [Sphere(center: (0.0, 4.0, 0.0), radius: 0.5, radiance: (1.0, 1.0, 1.0))],
        shapes: [
            Quad(corner: (-10.0, 0.0, -10.0), edge_u: (20.0, 0.0, 0.0), edge_v: (0.0, 0.0, 20.0), material: "a"),
            Quad(corner: (-1.0, 1.0, -1.0), edge_u: (2.0, 0.0, 0.0), edge_v: (0.0, 0.0, 2.0), material: "a"),
        ],
    )"#;
    let b = bandwidths(umbra, 16);
    // Row 5 is the blocker's front edge, rows 6 to 8 its unlit underside, rows 9 to 20 the
    // floor under it; the lit floor beyond predicts nothing.
    let median = |y: usize| {
        let mut r: Vec<f64> = b[y * 24..y * 24 + 24].to_vec();
        r.sort_by(f64::total_cmp);
        r[12]
    };
    let worst = b[9 * 24..21 * 24].iter().copied().fold(0.0, f64::max);
    assert!(
        worst < cov_render::validate::NYQUIST_CAP,
        "{worst} cycles/px under the blocker"
    );
    assert!(median(10) > 0.1, "the penumbra's edge is seen: {}", median(10));
    assert!(
        median(18) < 0.5 * median(10),
        "{} then {}",
        median(10),
        median(18)
    );
}

/// A smooth-shaded cylinder (an OBJ with radial vertex normals) filling the frame, its
/// axis at 45° across the image, a Phong highlight along it: the covariance pass's Σ at
/// the highlight is oriented as the rendered image is, its larger spectral spread across
/// the streak (the mesh's principal curvatures and their direction, and the turn of the
/// surface frame between the planes of incidence), in the image's rows. Turned the other
/// way, both turn. With the maps' `y` running up (before 2026-11-27) the signs disagreed;
/// with the mesh read flat or isotropic, `Σ_xy` is 0.3% of the content's trace or less,
/// against 44% here.
#[test]
fn a_cylinder_highlight_is_oriented_as_the_image_is() {
    let dir = std::env::temp_dir().join(format!("covtrace-cylinder-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A cylinder of radius 1.5 m and length 8 m along (cos tilt, sin tilt, 0), its front at
    // z = 1.5 and its outlines out of the frame.
    let cylinder = |tilt: f64| -> String {
        let (seg, r, half) = (96, 1.5, 4.0);
        let axis = glam::DVec3::new(tilt.cos(), tilt.sin(), 0.0);
        let (u, w) = (glam::DVec3::new(-tilt.sin(), tilt.cos(), 0.0), glam::DVec3::Z);
        let mut obj = String::new();
        for end in [-half, half] {
            for i in 0..seg {
                let a = 2.0 * std::f64::consts::PI * i as f64 / seg as f64;
                let n = u * a.cos() + w * a.sin();
                let p = axis * end + n * r;
                obj += &format!("v {} {} {}\nvn {} {} {}\n", p.x, p.y, p.z, n.x, n.y, n.z);
            }
        }
        for i in 0..seg {
            let (a, b) = (i + 1, (i + 1) % seg + 1);
            let (c, d) = (a + seg, b + seg);
            obj += &format!("f {a}//{a} {b}//{b} {d}//{d}\nf {a}//{a} {d}//{d} {c}//{c}\n");
        }
        obj
    };
    let xy_sign = |tilt: f64| -> (f64, f64) {
        let (ax, ay) = (tilt.cos(), tilt.sin());
        std::fs::write(dir.join("cyl.obj"), cylinder(tilt)).unwrap();
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 0.0, 6.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 12.0, width: 32, height: 32),
            materials: {{ "c": Phong(albedo: (0.8, 0.8, 0.8), exponent: 300.0) }},
            lights: [Sphere(center: ({lx}, {ly}, 6.0), radius: 0.05, radiance: (400.0, 400.0, 400.0))],
            shapes: [Mesh(obj: "cyl.obj", material: "c")],
        )"#,
            lx = 0.8 * ax,
            ly = 0.8 * ay,
        );
        let world = World::from_text(&text, "<test>", &dir).unwrap_or_else(|e| panic!("{e}"));
        let img = render(&world, 64, 1);
        let maps = covariance_maps(&world, 16, 1, 1, None).unwrap();
        let lum: Vec<f64> = img.pixels.iter().map(|p| p.y).collect();
        let peak = lum.iter().copied().fold(0.0, f64::max);
        // The image's structure tensor and the mean Σ_xy over the pixels of the highlight
        // (above 30% of its peak), away from the frame's border.
        let (mut j_xy, mut s_xy, mut s_tr, mut n) = (0.0, 0.0, 0.0, 0.0);
        for y in 2..30 {
            for x in 2..30 {
                let k = y * 32 + x;
                if lum[k] < 0.3 * peak {
                    continue;
                }
                let gx = lum[k + 1] - lum[k - 1];
                let gy = lum[k + 32] - lum[k - 32];
                j_xy += gx * gy;
                let s = maps.pixels[k].sigma;
                s_xy += s[1];
                s_tr += s[0] + s[2];
                n += 1.0;
            }
        }
        assert!(n >= 20.0, "{n} pixels in the highlight");
        let own = own_window();
        (j_xy.signum(), s_xy / (s_tr - 2.0 * own * n))
    };
    for tilt in [0.25 * std::f64::consts::PI, -0.25 * std::f64::consts::PI] {
        let (image, sigma) = xy_sign(tilt);
        // The image's gradients run across the streak, and so does Σ's larger spread.
        assert!(
            image * sigma > 0.0 && sigma.abs() > 0.1,
            "tilt {tilt}: image {image}, Σ_xy/tr {sigma}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A small sphere moving diagonally across the frame during the shutter: the
/// reconstruction filter at its streak is elongated along the streak, in the image's rows
/// (its `xy` of the sign opposite to the image's gradients'). Before 2026-11-27 the maps
/// kept the camera's `y` (up), and every filter was mirrored: across the streak.
#[test]
fn a_diagonal_streak_is_filtered_along_itself() {
    for (vx, vy) in [(1.0, 1.0), (1.0, -1.0)] {
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 0.0, 6.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 12.0, width: 32, height: 32, shutter: (open: 0.0, close: 0.2)),
            materials: {{ "c": Diffuse(albedo: (0.8, 0.8, 0.8)), "bg": Diffuse(albedo: (0.1, 0.1, 0.1)) }},
            lights: [Sphere(center: (0.0, 0.0, 8.0), radius: 0.5, radiance: (40.0, 40.0, 40.0))],
            shapes: [Sphere(center: (0.0, 0.0, 0.0), radius: 0.12, material: "c", velocity: ({vx}, {vy}, 0.0)),
                     Quad(corner: (-5.0, -5.0, -1.0), edge_u: (10.0, 0.0, 0.0), edge_v: (0.0, 10.0, 0.0), material: "bg")],
        )"#
        );
        let world = World::from_text(&text, "<test>", std::path::Path::new(".")).unwrap();
        let img = render(&world, 64, 1);
        let maps = covariance_maps(&world, 16, 1, 1, None).unwrap();
        let lum: Vec<f64> = img.pixels.iter().map(|p| p.y).collect();
        let peak = lum.iter().copied().fold(0.0, f64::max);
        let (mut j, mut f, mut n) = (0.0, [0.0; 3], 0.0);
        for y in 2..30 {
            for x in 2..30 {
                let k = y * 32 + x;
                j += (lum[k + 1] - lum[k - 1]) * (lum[k + 32] - lum[k - 32]);
                if lum[k] > 0.2 * peak {
                    let c = cov_render::adaptive::filter_cov(&maps.pixels[k]);
                    (0..3).for_each(|i| f[i] += c[i]);
                    n += 1.0;
                }
            }
        }
        assert!(n >= 20.0, "{n} pixels in the streak");
        let corr = f[1] / (f[0] * f[2]).sqrt();
        assert!(
            j * corr < 0.0 && corr.abs() > 0.2,
            "velocity ({vx}, {vy}): image {j}, filter's correlation {corr}"
        );
    }
}

/// Diagonal stripes (a texture) on a plane facing the camera: Σ's spread runs across the
/// stripes as the image's gradients do, in the image's rows. Before 2026-11-27 the maps'
/// `y` ran up and `Σ_xy` came out with the sign opposite to the image's.
#[test]
fn diagonal_stripes_are_oriented_as_the_image_is() {
    let own = own_window();
    for (ux, uy) in [(1.0, 1.0), (1.0, -1.0)] {
        let (vx, vy) = (-uy, ux);
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 0.0, 6.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 12.0, width: 32, height: 32),
            textures: {{ "stripes": Stripes(count: 12, duty: 0.5, a: (0.3, 0.3, 0.3), b: (0.9, 0.9, 0.9)) }},
            materials: {{ "wall": Diffuse(albedo: (1.0, 1.0, 1.0), texture: "stripes") }},
            lights: [Sphere(center: (0.0, 0.0, 8.0), radius: 1.0, radiance: (10.0, 10.0, 10.0))],
            shapes: [Quad(corner: ({cx}, {cy}, 0.0), edge_u: ({ex}, {ey}, 0.0), edge_v: ({fx}, {fy}, 0.0), material: "wall")],
        )"#,
            cx = -1.5 * (ux + vx),
            cy = -1.5 * (uy + vy),
            ex = 3.0 * ux,
            ey = 3.0 * uy,
            fx = 3.0 * vx,
            fy = 3.0 * vy
        );
        let world = World::from_text(&text, "<test>", std::path::Path::new(".")).unwrap();
        let img = render(&world, 16, 1);
        let maps = covariance_maps(&world, 8, 1, 1, None).unwrap();
        let lum: Vec<f64> = img.pixels.iter().map(|p| p.y).collect();
        let (mut j, mut xx, mut xy) = (0.0, 0.0, 0.0);
        for y in 4..28 {
            for x in 4..28 {
                let k = y * 32 + x;
                j += (lum[k + 1] - lum[k - 1]) * (lum[k + 32] - lum[k - 32]);
                xx += maps.pixels[k].sigma[0] - own;
                xy += maps.pixels[k].sigma[1];
            }
        }
        // Stripes at 45°: the content's spread is along one diagonal, `xy ≈ ±xx`.
        assert!(
            j * xy > 0.0 && (xy / xx).abs() > 0.5,
            "stripes along ({ux}, {uy}): image {j}, Σ_xy/Σ_xx {}",
            xy / xx
        );
    }
}

/// A ball that rolls across a pixel while the shutter is open draws the edges of its
/// swept band there, across its motion, even where the pixel's covariance path sees the
/// background at its own instant. Here the ball sweeps twice its diameter along the rows,
/// so the pixels of its middle row near the sweep's centre are covered for about half of
/// the exposure, and most of their paths miss it. Each of them must predict the band's
/// edge: detail across the motion (`Σ_yy`), where the background alone (lit from above,
/// the ball's shadow far below these rows) has none. Before 2026-11-28 the pass probed
/// for edges at the path's instant only, and these pixels read as bare background.
#[test]
fn a_ball_crossing_a_pixel_during_the_shutter_is_seen() {
    let text = r#"Scene(
        camera: (position: (0.0, 0.0, 6.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 1.0, 0.0), fov: 12.0, width: 32, height: 32, shutter: (open: 0.0, close: 0.2)),
        materials: { "c": Diffuse(albedo: (0.8, 0.8, 0.8)), "bg": Diffuse(albedo: (0.1, 0.1, 0.1)) },
        lights: [Sphere(center: (0.0, 8.0, 6.0), radius: 0.5, radiance: (40.0, 40.0, 40.0))],
        shapes: [Sphere(center: (-0.24, 0.0, 0.0), radius: 0.12, material: "c", velocity: (2.4, 0.0, 0.0)),
                 Quad(corner: (-5.0, -5.0, -1.0), edge_u: (10.0, 0.0, 0.0), edge_v: (0.0, 10.0, 0.0), material: "bg")],
    )"#;
    let world = World::from_text(text, "<test>", std::path::Path::new(".")).unwrap();
    let own = own_window();
    let across = |maps: &cov_render::CovMaps, x: usize, y: usize| maps.pixels[y * 32 + x].sigma[2] - own;
    for seed in 1..4 {
        let maps = cov_render::covpass::covariance_rows(&world, 1, 1, 1, seed, 0..32, None).unwrap();
        // The background far from the band: rows 2 to 5.
        let bare = (2..6)
            .flat_map(|y| (4..28).map(move |x| (x, y)))
            .map(|(x, y)| across(&maps, x, y))
            .fold(0.0, f64::max);
        for y in 15..17 {
            for x in 13..19 {
                let a = across(&maps, x, y);
                assert!(
                    a > 0.1 * own && a > 100.0 * bare,
                    "seed {seed}, pixel ({x}, {y}): Σ_yy beyond the pixel filter's {a}, the background's {bare}, the filter's own {own}"
                );
            }
        }
    }
}
