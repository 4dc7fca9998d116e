//! The path tracer: direct lighting from area lights (light and BRDF sampling combined by
//! multiple importance sampling) and one indirect bounce (with light sampling at the
//! second vertex), over pixel × lens × time.
//!
//! The estimator is unbiased for the transport it includes: paths of one and two bounces
//! (camera → x₁ → light, camera → x₁ → x₂ → light) and lights seen directly.

use crate::sampler::Sampler;
use glam::DVec3;

use crate::geometry::Hit;
use crate::world::{CameraRay, World};

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

/// Light sampling at a surface hit of material `mat`; with `mis`, weighted against BRDF
/// sampling.
fn direct<S: Sampler + ?Sized>(
    world: &World,
    hit: &Hit,
    mat: &crate::material::Material,
    wo: DVec3,
    time: f64,
    rng: &mut S,
    mis: bool,
) -> DVec3 {
    let n_lights = world.lights.len();
    let pick = (rng.next() * n_lights as f64) as usize;
    let light = &world.lights[pick.min(n_lights - 1)];
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
        .occluded(o, ls.wi, time, 0.0, ls.dist * (1.0 - 1e-6))
    {
        return DVec3::ZERO;
    }
    let pl = ls.pdf / n_lights as f64;
    let w = if mis {
        let pb = mat.pdf(hit.n, wo, ls.wi);
        pl * pl / (pl * pl + pb * pb)
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

/// The light the surface at `hit` reflects towards the camera.
fn reflected<S: Sampler + ?Sized>(
    world: &World,
    ray: &CameraRay,
    hit: &Hit,
    mat: &crate::material::Material,
    rng: &mut S,
) -> DVec3 {
    let hit = *hit;
    let wo = -ray.dir;
    let mut l = direct(world, &hit, mat, wo, ray.time, rng, true);
    // One indirect bounce, by BRDF sampling.
    let Some(wi) = mat.sample(hit.n, wo, rng.next(), rng.next()) else {
        return l;
    };
    let pb = mat.pdf(hit.n, wo, wi);
    let cos = hit.n.dot(wi);
    if pb <= 0.0 || cos <= 0.0 || wi.dot(hit.ng) <= 0.0 {
        return l;
    }
    let throughput = mat.eval(hit.n, wo, wi) * (cos / pb);
    let o = spawn(&hit, wi);
    let Some(h2) = world.geometry.intersect(o, wi, ray.time, 0.0, f64::INFINITY) else {
        return l;
    };
    match h2.light {
        Some(li) => {
            // A light found by BRDF sampling: the other half of the MIS pair.
            let le = emitted(world, &h2);
            if le != DVec3::ZERO {
                let light = &world.lights[li as usize];
                let pl = light.pdf(hit.p, wi, h2.t) / world.lights.len() as f64;
                l += throughput * le * (pb * pb / (pb * pb + pl * pl));
            }
        }
        None => {
            let mat2 = world.material_at(&h2, footprint(world, hit.t + h2.t));
            l += throughput * direct(world, &h2, &mat2, -wi, ray.time, rng, false);
        }
    }
    l
}
