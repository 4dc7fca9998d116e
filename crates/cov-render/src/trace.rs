//! The path tracer: direct lighting from area lights (light and BRDF sampling combined by
//! multiple importance sampling) at every surface vertex of a path, up to the scene's
//! `max_depth` (default 2: one indirect bounce), over pixel × lens × time. At the last
//! vertex, light sampling alone where the material is diffuse, and both strategies
//! combined where it is glossy (the function `reflected` says why).
//!
//! The estimator is unbiased for the transport it includes: paths of 1 to `max_depth`
//! surface vertices (camera → x₁ → light, camera → x₁ → x₂ → light, …) and lights seen
//! directly.

use crate::sampler::Sampler;
use glam::DVec3;

use crate::geometry::Hit;
use crate::material::Material;
use crate::world::{CameraRay, World};

/// The revision of the estimator: what an image of a given scene, size, sample count and
/// seed converges to and how its samples are drawn. A cached reference image is keyed by
/// it (`covtrace render-bench`), so a change to the tracer that moves any pixel must raise
/// it, or references rendered by an older build would be measured against as if current.
/// 2: light and BRDF sampling combined at a glossy second vertex; 3: sphere textures
/// unmirrored; 4: the key took the scene's files too (no change to images); 5: a shadow
/// ray skips the light it was aimed at (a sphere light's outline lost up to 0.6%).
pub const ESTIMATOR_REVISION: u32 = 5;

/// Offset of a spawned ray from its surface, relative to the scene's scale of the point.
const SPAWN_EPS: f64 = 1e-7;

/// A ray origin just off the surface at `hit`, on the side of `dir`.
pub fn spawn(hit: &Hit, dir: DVec3) -> DVec3 {
    let eps = SPAWN_EPS * (1.0 + hit.p.abs().max_element());
    let side = if dir.dot(hit.ng) >= 0.0 { 1.0 } else { -1.0 };
    hit.p + hit.ng * (eps * side)
}

pub use crate::material::luminance;

/// The radiance a light leaves towards `-dir` at `hit` (one-sided emitters).
fn emitted(world: &World, hit: &Hit) -> DVec3 {
    match hit.light {
        Some(l) if hit.front => world.lights[l as usize].radiance(),
        _ => DVec3::ZERO,
    }
}

/// The fraction of a pixel's footprint over which textures are filtered: the pixel's own
/// samples already average over its area, so a texture lookup blurs only a little more
/// (pbrt-v4 scales its ray differentials by `max(1/8, 1/√spp)`; 1/8 is that bound).
pub const TEXTURE_FOOTPRINT: f64 = 0.125;

/// The footprint (m) over which the tracer filters a texture seen at distance `dist` along
/// the path from the camera: [`TEXTURE_FOOTPRINT`] of a pixel's width at that distance.
fn footprint(world: &World, dist: f64) -> f64 {
    let cam = &world.camera;
    TEXTURE_FOOTPRINT * 2.0 * cam.tan_x * dist / cam.width as f64
}

/// The weight of a sample drawn with density `a` against the other strategy's density `b`
/// for the same direction: the power heuristic with exponent 2, `a²/(a² + b²)`.
fn power_heuristic(a: f64, b: f64) -> f64 {
    a * a / (a * a + b * b)
}

/// Light sampling at a surface hit of material `mat`; with `mis`, weighted against BRDF
/// sampling ([`power_heuristic`]).
fn direct<S: Sampler + ?Sized>(
    world: &World,
    hit: &Hit,
    mat: &Material,
    wo: DVec3,
    time: f64,
    rng: &mut S,
    mis: bool,
) -> DVec3 {
    let n_lights = world.lights.len();
    let pick = (rng.next() * n_lights as f64) as usize;
    let pick = pick.min(n_lights - 1);
    let light = &world.lights[pick];
    let Some(ls) = light.sample(hit.p, rng.next(), rng.next()) else {
        return DVec3::ZERO;
    };
    let f = mat.eval(hit.n, wo, ls.wi);
    let cos = hit.n.dot(ls.wi);
    if f == DVec3::ZERO || cos <= 0.0 || ls.wi.dot(hit.ng) <= 0.0 {
        return DVec3::ZERO;
    }
    let o = spawn(hit, ls.wi);
    if world
        .geometry
        .occluded(o, ls.wi, time, 0.0, ls.dist * (1.0 - 1e-6), Some(pick as u32))
    {
        return DVec3::ZERO;
    }
    let pl = ls.pdf / n_lights as f64;
    let w = if mis {
        power_heuristic(pl, mat.pdf(hit.n, wo, ls.wi))
    } else {
        1.0
    };
    f * ls.radiance * (cos * w / pl)
}

/// The radiance arriving along a camera ray (one sample of the estimator).
pub fn radiance<S: Sampler + ?Sized>(world: &World, ray: &CameraRay, rng: &mut S) -> DVec3 {
    let s = radiance_parts(world, ray, rng);
    s.emitted + s.reflected
}

/// What one camera ray gives the film: its radiance in two parts, and what it hit first.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RaySample {
    /// The emission of a light the ray sees directly.
    pub emitted: DVec3,
    /// The light reflected towards the camera by the surface the ray sees.
    pub reflected: DVec3,
    /// What the ray hits first ([`Features`]).
    pub features: Features,
}

/// A camera ray's first hit, as a denoiser's guides use it (averaged over a pixel's
/// samples like the image, so defocus and motion blur them the same way). The tracer has
/// no perfectly specular material, so the first hit is the first non-specular one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Features {
    /// The material's reflectance; a light's colour scaled to a largest channel of 1;
    /// 0 where the ray escapes.
    pub albedo: DVec3,
    /// The shading normal (world space, unit, towards the camera); 0 where the ray
    /// escapes.
    pub normal: DVec3,
    /// Distance along the ray (m); 0 where the ray escapes.
    pub depth: f64,
}

/// [`radiance`] in two parts, with the first hit's features: the emission of a light the
/// ray sees directly, and the light reflected by the surface it sees. A film reconstructs
/// only the second with a filter: an emitter's own edge is as sharp as the pixel grid, and
/// its radiance is far above what it borders.
pub fn radiance_parts<S: Sampler + ?Sized>(world: &World, ray: &CameraRay, rng: &mut S) -> RaySample {
    let Some(hit) = world
        .geometry
        .intersect(ray.origin, ray.dir, ray.time, 0.0, f64::INFINITY)
    else {
        return RaySample::default();
    };
    let mut features = Features {
        albedo: DVec3::ZERO,
        normal: hit.n,
        depth: hit.t,
    };
    if let Some(l) = hit.light {
        let le = world.lights[l as usize].radiance();
        features.albedo = le / le.max_element().max(1e-300);
        return RaySample {
            emitted: emitted(world, &hit),
            features,
            ..RaySample::default()
        };
    }
    let mat = world.material_at(&hit, footprint(world, hit.t));
    features.albedo = mat.albedo();
    RaySample {
        reflected: reflected(world, ray, &hit, &mat, rng),
        features,
        ..RaySample::default()
    }
}

/// The light the surface at `hit` reflects towards the camera: direct light at each of
/// the path's surface vertices, up to the scene's depth ([`World::max_depth`]).
///
/// At every vertex but the last, light sampling is weighed against the BRDF sample that
/// continues the path (multiple importance sampling). At the last vertex a lobe narrower
/// than the lights (a glossy ball reflecting a lamp onto the floor) makes light sampling
/// alone fire rare bright samples, the lobe's peak over the light sample's density: there
/// a BRDF sample joins it, the two weighed as at the others. A diffuse last vertex, whose
/// BRDF sample seldom finds a light while its ray costs as much as the light's, takes
/// light sampling alone, unbiased on its own. From the third vertex on, a path continues
/// with the probability of its throughput's largest channel (at most 1) and is divided by
/// it (Russian roulette, unbiased); the first two vertices are always taken.
fn reflected<S: Sampler + ?Sized>(
    world: &World,
    ray: &CameraRay,
    hit: &Hit,
    mat: &Material,
    rng: &mut S,
) -> DVec3 {
    let depth = world.max_depth.max(1);
    let (mut l, mut beta) = (DVec3::ZERO, DVec3::ONE);
    let (mut v, mut mat, mut wo, mut dist) = (*hit, *mat, -ray.dir, hit.t);
    for k in 1..=depth {
        let last = k == depth;
        let both = !last || !matches!(mat, Material::Diffuse { .. });
        // This vertex's light, summed before the throughput multiplies it.
        let mut here = direct(world, &v, &mat, wo, ray.time, rng, both);
        let next = if both {
            bounce(world, &v, &mat, wo, ray.time, rng)
        } else {
            None
        };
        // A light found by BRDF sampling: the other half of the MIS pair.
        if let Some(b) = &next
            && (last || b.hit.light.is_some())
        {
            here += b.emission(world, &v);
        }
        l += beta * here;
        let Some(b) = next.filter(|b| !last && b.hit.light.is_none()) else {
            break;
        };
        beta *= b.throughput;
        if k + 1 >= ROULETTE_FROM {
            let q = beta.max_element().min(1.0);
            if q.is_nan() || rng.next() >= q {
                break;
            }
            beta /= q;
        }
        dist += b.hit.t;
        mat = world.material_at(&b.hit, footprint(world, dist));
        (v, wo) = (b.hit, -b.wi);
    }
    l
}

/// The first vertex at which a path may end by Russian roulette ([`reflected`]): the
/// third, so that paths of the default depth (2) take no roulette number and keep their
/// sampler dimensions.
const ROULETTE_FROM: u32 = 3;

/// A direction drawn from a material's lobe and what the ray along it hits.
struct Bounce {
    /// The direction (away from the surface).
    wi: DVec3,
    /// Its density (solid angle) under the lobe.
    pdf: f64,
    /// `f cos / pdf`.
    throughput: DVec3,
    /// What the ray hits.
    hit: Hit,
}

impl Bounce {
    /// The emission this bounce found, seen from `from`, weighted against light sampling
    /// at `from` ([`power_heuristic`], as in [`direct`]); 0 unless the ray hit a light's
    /// front.
    fn emission(&self, world: &World, from: &Hit) -> DVec3 {
        let (Some(li), le) = (self.hit.light, emitted(world, &self.hit)) else {
            return DVec3::ZERO;
        };
        if le == DVec3::ZERO {
            return DVec3::ZERO;
        }
        let light = &world.lights[li as usize];
        let pl = light.pdf(from.p, self.wi, self.hit.t) / world.lights.len() as f64;
        self.throughput * le * power_heuristic(self.pdf, pl)
    }
}

/// A BRDF sample at `hit` and the ray it spawns; `None` when the sample falls below the
/// surface or the ray escapes.
fn bounce<S: Sampler + ?Sized>(
    world: &World,
    hit: &Hit,
    mat: &Material,
    wo: DVec3,
    time: f64,
    rng: &mut S,
) -> Option<Bounce> {
    let wi = mat.sample(hit.n, wo, rng.next(), rng.next())?;
    let pdf = mat.pdf(hit.n, wo, wi);
    let cos = hit.n.dot(wi);
    if pdf <= 0.0 || cos <= 0.0 || wi.dot(hit.ng) <= 0.0 {
        return None;
    }
    let throughput = mat.eval(hit.n, wo, wi) * (cos / pdf);
    let next = world
        .geometry
        .intersect(spawn(hit, wi), wi, time, 0.0, f64::INFINITY)?;
    Some(Bounce {
        wi,
        pdf,
        throughput,
        hit: next,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use std::path::Path;

    /// Uniform numbers from a seeded generator, as a [`Sampler`].
    struct Uniform(rand_chacha::ChaCha8Rng);

    impl Sampler for Uniform {
        fn next(&mut self) -> f64 {
            self.0.random()
        }
    }

    /// A floor of `material` (RON) under a 1 m lamp, its point at the origin seen from
    /// `(−1, 1, 0)` (45°, the lamp around the mirror direction): the world, the hit, its
    /// material and the direction towards the viewer.
    fn floor_under_lamp(material: &str) -> (World, Hit, Material, DVec3) {
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 3.0, 3.0), look_at: (0.0, 0.0, 0.0), fov: 30.0, width: 4, height: 4),
            materials: {{ "floor": {material} }},
            lights: [Rect(corner: (0.5, 1.0, -0.5), edge_u: (1.0, 0.0, 0.0), edge_v: (0.0, 0.0, 1.0), radiance: (2.0, 2.0, 2.0))],
            shapes: [Quad(corner: (-2.0, 0.0, -2.0), edge_u: (4.0, 0.0, 0.0), edge_v: (0.0, 0.0, 4.0), material: "floor")],
        )"#
        );
        let world = World::from_text(&text, "<test>", Path::new(".")).unwrap();
        let from = DVec3::new(-1.0, 1.0, 0.0);
        let hit = world
            .geometry
            .intersect(from, -from.normalize(), 0.0, 0.0, f64::INFINITY)
            .unwrap();
        let mat = world.material_at(&hit, 0.0);
        (world, hit, mat, from.normalize())
    }

    /// Mean and variance of `n` draws of `f`.
    fn moments(n: u32, mut f: impl FnMut() -> f64) -> (f64, f64) {
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let v = f();
            s += v;
            s2 += v * v;
        }
        let m = s / f64::from(n);
        (m, (s2 / f64::from(n) - m * m).max(0.0))
    }

    /// The light a path's last vertex `hit` reflects along `wo`: [`reflected`] in a world
    /// of depth 1, where the first vertex is the last.
    fn last_vertex(world: &mut World, hit: &Hit, mat: &Material, wo: DVec3, rng: &mut Uniform) -> DVec3 {
        world.max_depth = 1;
        let ray = CameraRay {
            origin: hit.p + wo,
            dir: -wo,
            time: 0.0,
        };
        reflected(world, &ray, hit, mat, rng)
    }

    /// A Phong-300 floor at 45° to a 1 m lamp that fills its lobe (a glossy ball's
    /// reflection of a lamp, as the felt sees it in the snooker scene): the last
    /// vertex's estimate agrees with light sampling alone (the estimator before the two
    /// were combined) and with BRDF sampling alone, within 4σ, and its variance is a
    /// fraction of light sampling's.
    #[test]
    fn a_glossy_last_vertex_combines_light_and_brdf_sampling() {
        let (mut world, hit, mat, wo) = floor_under_lamp("Phong(albedo: (0.8, 0.8, 0.8), exponent: 300.0)");
        let mut rng = Uniform(rand_chacha::ChaCha8Rng::seed_from_u64(7));
        let n = 40_000;
        let combined = moments(n, || last_vertex(&mut world, &hit, &mat, wo, &mut rng).y);
        let light = moments(n, || direct(&world, &hit, &mat, wo, 0.0, &mut rng, false).y);
        let brdf = moments(n, || {
            bounce(&world, &hit, &mat, wo, 0.0, &mut rng)
                .filter(|b| b.hit.light.is_some())
                .map_or(0.0, |b| (b.throughput * emitted(&world, &b.hit)).y)
        });
        let se = |a: (f64, f64), b: (f64, f64)| ((a.1 + b.1) / f64::from(n)).sqrt();
        for (name, other) in [("light sampling", light), ("BRDF sampling", brdf)] {
            assert!(
                (combined.0 - other.0).abs() <= 4.0 * se(combined, other),
                "combined {combined:?}, {name} {other:?}"
            );
        }
        assert!(combined.0 > 0.5, "the lamp fills the lobe: {combined:?}");
        assert!(
            combined.1 * 20.0 < light.1,
            "variance: combined {}, light sampling {}",
            combined.1,
            light.1
        );
    }

    /// A diffuse last vertex takes light sampling alone: the same numbers as `direct`
    /// without its MIS weight, drawn from the same generator.
    #[test]
    fn a_diffuse_last_vertex_samples_the_light_alone() {
        let (mut world, hit, mat, wo) = floor_under_lamp("Diffuse(albedo: (0.5, 0.5, 0.5))");
        let (mut a, mut b) = (
            Uniform(rand_chacha::ChaCha8Rng::seed_from_u64(3)),
            Uniform(rand_chacha::ChaCha8Rng::seed_from_u64(3)),
        );
        for _ in 0..64 {
            let got = last_vertex(&mut world, &hit, &mat, wo, &mut a);
            assert_eq!(got, direct(&world, &hit, &mat, wo, 0.0, &mut b, false));
        }
    }
}
