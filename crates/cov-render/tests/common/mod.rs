//! Shared by the renderer's tests.

use std::path::Path;

use cov_render::World;

/// A diffuse plane (ρ = 0.5) seen straight down from 1 m above, under a sphere light
/// (L = 1, R = 0.5 m) whose centre is D = 2 m above the plane's point below the camera:
/// `width × height` pixels over a field of view of `fov` degrees.
pub fn plane_under_sphere_light(fov: f64, width: u32, height: u32) -> World {
    let text = format!(
        r#"Scene(
        camera: (position: (0.0, 1.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov: {fov:?}, width: {width}, height: {height}),
        materials: {{ "grey": Diffuse(albedo: (0.5, 0.5, 0.5)) }},
        lights: [Sphere(center: (0.0, 2.0, 0.0), radius: 0.5, radiance: (1.0, 1.0, 1.0))],
        shapes: [Quad(corner: (-50.0, 0.0, -50.0), edge_u: (100.0, 0.0, 0.0), edge_v: (0.0, 0.0, 100.0), material: "grey")],
    )"#
    );
    World::from_text(&text, "<test>", Path::new(".")).unwrap()
}
