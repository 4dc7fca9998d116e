//! The film and the methods of `render-bench`: reconstruction keeps constants, adaptive
//! counts stay unbiased against a closed form, and every method runs on every scene.

use std::path::Path;

use cov_render::World;
use cov_render::film::{Film, Filter, Gaussian};

/// A 16×12 image of a diffuse plane under a large sphere light, seen straight down: every
/// pixel sees (almost) the same radiance.
fn flat() -> World {
    let text = r#"Scene(
        camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov: 2.0, width: 16, height: 12),
        materials: { "grey": Diffuse(albedo: (0.5, 0.5, 0.5)) },
        lights: [Sphere(center: (0.0, 2.0, 0.0), radius: 0.5, radiance: (1.0, 1.0, 1.0))],
        shapes: [Quad(corner: (-50.0, 0.0, -50.0), edge_u: (100.0, 0.0, 0.0), edge_v: (0.0, 0.0, 100.0), material: "grey")],
    )"#;
    World::from_text(text, "<test>", Path::new(".")).unwrap()
}

#[test]
fn filters_agree_with_the_box_on_a_flat_image() {
    let world = flat();
    let counts = vec![64u32; 16 * 12];
    let mut a = Film::new(16, 12);
    a.render(&world, &counts, 1, f64::INFINITY, None);
    let mut b = Film::new(16, 12);
    b.render(&world, &counts, 1, f64::INFINITY, None);
    let (ia, ib) = (a.image(&Filter::Box), b.image(&Filter::Fixed(Gaussian::isotropic(1.0))));
    for (k, (p, q)) in ia.pixels.iter().zip(&ib.pixels).enumerate() {
        assert!((p.y - q.y).abs() < 0.05 * p.y, "pixel {k}: box {p}, gauss {q}");
    }
}
