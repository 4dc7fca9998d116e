//! The covariance pass: for each pixel, a few covariance paths that follow the path
//! tracer's paths (camera → x₁ → light, camera → x₁ → x₂ → light, …; up to the scene's
//! `max_depth` surface vertices), each vertex's direct light turned into an operator
//! chain of the library (light source, travel, blocker edge, reflection at each vertex back to the
//! camera, motion, lens, shutter), evaluated, and reduced to the sensor's per-pixel
//! decisions (cov-sensor). Every vertex's chain is weighted by the radiance it carries to
//! the camera, ignoring visibility, so a shadowed region keeps the frequency content of
//! the light, blockers and surface around it.
//!
//! What a vertex's chain sees, in light order:
//!
//! 1. the emitter as a Gaussian window of the light's size ([`crate::world::Light::window_std`]),
//!    constant in angle and time, seen from the vertex through `Unproject(cos_l)`;
//! 2. travel to the vertex, with a `BlockerEdge` where the path's shadow ray or auxiliary
//!    ones to other points of the light are blocked (at the blocker's depth, the distance
//!    from the path to the edge that the blocked and clear rays bound, docs/physics.md
//!    section 3, "Where a shadow's edge is");
//! 3. the reflection at the vertex (cov-brdf's `Reflect::with_turn`: the shape's curvature,
//!    the material's lobe, and the turn from the plane of incidence to the plane of the
//!    outgoing ray; then the change of handedness and the texture), inside `Moving` when
//!    the shape moves;
//! 4. for a later vertex (`depth` 2 or more; the renderer's default is [`DEFAULT_DEPTH`],
//!    one), travel back along the path to the vertex before, with a `BlockerEdge` where
//!    probes from the first vertex at its lobe's angular width see an outline beside the segment, and the
//!    reflection there, as in 3 (glossy inter-reflection: a glossy floor mirroring what
//!    stands on it, the outline blurred by the floor's lobe);
//! 5. travel to the camera, with a `Moving` `BlockerEdge` where auxiliary camera rays
//!    around the pixel see a silhouette (a nearer surface or the background) in front of
//!    or behind the hit, a crease or another material, its window weighed by the step's
//!    contrast (docs/physics.md section 3): defocus and motion blur of edges;
//! 6. the camera: its motion, the shutter window, the thin lens (or pinhole), and the
//!    sensor's sampling rates (`Sensor::rates`).
//!
//! The pass holds Σ in covariance form: chains are short (at most about 20 operators), where
//! both forms agree to rounding.

use cov_brdf::Reflect;
use cov_core::{AnyCov, Chain, CovError, Form};
use cov_curvature::Curvature;
use cov_defocus::{Pinhole, ThinLens};
use cov_motion::{CameraMotion, Moving, Shutter, ShutterShape};
use cov_occlusion::{BlockerEdge, Texture};
use cov_projection::{RotateFrame, Unproject};
use cov_sensor::{PixelRates, Sensor, SensorParams};
use cov_travel::Travel;
use glam::{DVec2, DVec3};
use rand::Rng;

use crate::geometry::Hit;
use crate::trace::{luminance, spawn};
use crate::world::World;

/// Auxiliary shadow rays per covariance path (to find blockers near the path).
pub const SHADOW_PROBES: usize = 4;
/// Auxiliary camera rays per covariance path (to find silhouettes near the pixel).
pub const EDGE_PROBES: usize = 4;

/// A unit vector orthogonal to `d`, in the plane of `d` and `n` when they are not parallel:
/// the frame `x` of a ray in its plane of incidence.
pub fn frame_x(d: DVec3, n: DVec3) -> DVec3 {
    let p = n - d * n.dot(d);
    if p.length() > 1e-9 {
        p.normalize()
    } else {
        crate::material::basis(d).0
    }
}

/// The frame rotation about `d` that turns the frame x `from` into `to` (positive from x
/// towards `y = d × x`).
pub fn turn(d: DVec3, from: DVec3, to: DVec3) -> f64 {
    let y = d.cross(from);
    to.dot(y).atan2(to.dot(from))
}

/// Pushes `ops`, which act on an object moving at `velocity`, onto `chain`: inside
/// `Moving` (in the frame `(x, d × x)` of the ray `d`) when the pass traces time and the
/// object moves, as they are otherwise.
fn push_on(
    chain: &mut Chain,
    motion: bool,
    velocity: DVec3,
    (d, x): (DVec3, DVec3),
    ops: Chain,
) -> Result<(), CovError> {
    if motion && velocity != DVec3::ZERO {
        chain.push(Moving::new(in_frame(velocity, d, x), [0.0, 0.0], ops)?);
    } else {
        chain.push(ops);
    }
    Ok(())
}

/// The tangential velocity `v` seen in the frame `(x, d × x)` of a ray `d`.
fn in_frame(v: DVec3, d: DVec3, x: DVec3) -> [f64; 2] {
    [v.dot(x), v.dot(d.cross(x))]
}

/// The per-pixel prediction of the covariance pass.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelCov {
    /// Image-space Σ in (cycles/px)²: `xx, xy, yy` with `x` along the image's columns and
    /// `y` down its rows, as the film's pixels (weighted mean over the pixel's paths).
    pub sigma: [f64; 3],
    /// Samples per pixel over pixel × lens × time (weighted mean).
    pub spp: f64,
    /// Sum of the paths' weights (0: no path carried light).
    pub weight: f64,
}

/// Everything the pass needs once per image.
#[derive(Debug)]
pub struct CovCamera {
    sensor: Sensor,
    end: Chain,
    layout: usize,
}

impl CovCamera {
    /// The camera end of every chain, and the sensor.
    ///
    /// # Errors
    /// Camera parameters the operators reject (never for a scene that loaded).
    pub fn new(world: &World) -> Result<CovCamera, CovError> {
        let cam = &world.camera;
        let d_s = cam.sensor_distance();
        let time = world.has_motion;
        let mut end = Chain::new();
        if time && let Some((a, b)) = cam.shutter {
            end.push(Shutter::new(b - a, ShutterShape::Box)?);
        }
        let aperture = (cam.lens_radius > 0.0).then_some(cam.lens_radius / 2.0);
        match aperture {
            Some(ap) => end.push(ThinLens::new(cam.focal_length, ap, cam.focus_distance)?),
            None => end.push(Pinhole::new(d_s)?),
        }
        let sensor = Sensor::new(SensorParams {
            width: cam.width,
            fov_x: cam.fov_x,
            distance: d_s,
            aperture,
            shutter: if time {
                cam.shutter.map(|(a, b)| (b - a) / 12f64.sqrt())
            } else {
                None
            },
            ..SensorParams::default()
        })?;
        Ok(CovCamera {
            sensor,
            end,
            layout: if time { 5 } else { 4 },
        })
    }

    /// The layout the pass traces in (4, or 5 with motion).
    pub fn layout(&self) -> usize {
        self.layout
    }

    /// The sensor.
    pub fn sensor(&self) -> &Sensor {
        &self.sensor
    }
}

/// The source Σ of a light window of std `s` (m), constant in angle and time.
fn source(layout: usize, s: f64) -> Result<AnyCov, CovError> {
    let inf = f64::INFINITY;
    if layout == 5 {
        AnyCov::gaussian(&[s, s, inf, inf, inf])
    } else {
        AnyCov::gaussian(&[s, s, inf, inf])
    }
}

/// The rectangle of pixels a covariance path predicts for: `x0, y0, x1, y1` (pixel
/// coordinates, `x1 > x0`, `y1 > y0`).
pub type Block = [f64; 4];

/// The spectrum of the texture at `hit` in the frame `(x_out, d_out × x_out)` of the
/// outgoing ray `d_out`: `Texture::from_moments`'s spectrum (`Texture::moments_spectrum`)
/// of the texture's statistics band-limited at `band`, at lookups over `region` (m on the
/// surface; crate::texture), enveloped in the surface's `(u, v)` frame and then carried
/// to the tangent plane and to the ray (the inverse projection `x_surface = x_ray / cos_o`
/// along the plane of incidence, docs/physics.md section 3). `None` without a texture or
/// where the surface's coordinates are degenerate.
fn texture_window(
    world: &World,
    hit: &Hit,
    d_out: DVec3,
    x_out: DVec3,
    (band, region): (f64, f64),
) -> Result<Option<Texture>, CovError> {
    let Some((tex, per_m)) = world.texture_at(hit) else {
        return Ok(None);
    };
    let cos_o = hit.n.dot(d_out).clamp(1e-6, 1.0);
    let e1 = (x_out - hit.n * x_out.dot(hit.n)).normalize_or_zero();
    let e2 = d_out.cross(x_out);
    // Tangent coordinates from (u, v): s = M·(u, v).
    let [du, dv] = hit.dpduv;
    let (m00, m01, m10, m11) = (e1.dot(du), e1.dot(dv), e2.dot(du), e2.dot(dv));
    let det = m00 * m11 - m01 * m10;
    // Relative to the map's own scale: below it (u, v) does not determine the position.
    let scale = m00 * m00 + m01 * m01 + m10 * m10 + m11 * m11;
    if det.abs() <= 1e-12 * scale || !det.is_finite() {
        return Ok(None);
    }
    // J = ∂(u, v)/∂(x, y) of the ray = M⁻¹ · diag(1/cos_o, 1).
    let j = [[m11 / det / cos_o, -m01 / det], [-m10 / det / cos_o, m00 / det]];
    // Jᵀ G J.
    let to_ray = |g: [f64; 3]| -> [f64; 3] {
        let g = [[g[0], g[1]], [g[1], g[2]]];
        let jgj = |a: usize, b: usize| -> f64 {
            let mut acc = 0.0;
            for (r, gr) in g.iter().enumerate() {
                for (c, grc) in gr.iter().enumerate() {
                    acc += j[r][a] * grc * j[c][b];
                }
            }
            acc
        };
        [jgj(0, 0), jgj(0, 1), jgj(1, 1)]
    };
    // The block predicts for all its pixels the sharpest detail found in it: the envelope
    // of the lookups' spectra taken in the surface's own (u, v) frame, which does not turn
    // from pixel to pixel as the ray's frame does near normal incidence (taken in the ray's
    // frame, it made textures look smoother in a band of columns where that frame turns
    // fast). Per axis the largest; the correlation is the lookups' mean correlation
    // coefficient (1 for stripes everywhere the same way, 0 for a checker's two edges),
    // scaled to the envelope, so the envelope stays positive semi-definite.
    let (mut e, mut cross, mut norm) = ([0.0f64; 3], 0.0, 0.0);
    // The moments are the pyramid's averages (finite, `mean_sq ≥ 0`, gradients PSD by
    // construction): their spectra are made unchecked, and the envelope is checked once,
    // below.
    // The region: the block's footprint, a square of side `region · cos_o` across the ray
    // (`region` is its length on the surface along the plane of incidence, as
    // `footprints` gives it, so the product is twice the block's side there) turned as the
    // image's columns are, carried to (u, v) by J, the surface's own map; a square in
    // (u, v) scaled by the map's mean stretch covered other areas of the surface where
    // the map stretches `u` and `v` differently (a sphere, a long quad), and the whole
    // stretched length across the plane of incidence too.
    let side = region * cos_o;
    let right = world.camera.right - d_out * world.camera.right.dot(d_out);
    let (cx, cy) = match right.try_normalize() {
        Some(r) => (r.dot(x_out), r.dot(e2)),
        None => (1.0, 0.0),
    };
    let uv_of = |x: f64, y: f64| DVec2::new(j[0][0] * x + j[0][1] * y, j[1][0] * x + j[1][1] * y);
    let edges = [uv_of(side * cx, side * cy), uv_of(-side * cy, side * cx)];
    for m in tex.moments(hit.uv, band * per_m, edges) {
        let [xx, xy, yy] = Texture::moments_spectrum(m.mean, m.mean_sq, m.grad);
        e[0] = e[0].max(xx);
        e[2] = e[2].max(yy);
        cross += xy;
        norm += (xx * yy).max(0.0).sqrt();
    }
    let rho = if norm > 0.0 {
        (cross / norm).clamp(-1.0, 1.0)
    } else {
        0.0
    };
    e[1] = rho * (e[0] * e[2]).sqrt();
    let w = to_ray(e);
    // Jᵀ E J of a rank-one envelope (stripes) can round `xy` past `√(xx·yy)`: onto the bound.
    let bound = (w[0] * w[2]).max(0.0).sqrt();
    Ok(Some(Texture::new(w[0], w[1].clamp(-bound, bound), w[2])?))
}

/// Surface vertices a covariance path follows at most: those of the deepest path tracer
/// a scene can ask for ([`crate::scene::MAX_PATH_DEPTH`]). A render's covariance paths
/// follow at most its scene's own depth ([`World::max_depth`]): a deeper vertex would
/// predict light the image does not have.
pub const MAX_DEPTH: u32 = crate::scene::MAX_PATH_DEPTH;

/// Surface vertices a covariance path follows unless told otherwise: 1 (camera → x₁ →
/// light). Measured, not chosen: following the second vertex as well made `cov` worse on
/// the glossy scene, the one it was built for (relMSE at 4 spp 1.07e-2 → 3.37e-2 over three
/// seeds and their maps; the Σ-only filters of `cov-filter` 11–42% worse at every budget),
/// and did not pay on the other bundled scenes (docs/render-bench.md, "Following the second
/// vertex"). Depth 2 stays available.
pub const DEFAULT_DEPTH: u32 = 1;

/// The footprints on a surface seen at distance `dist` along the path from the camera, at
/// the cosine `cos_o` to the ray that leaves it, for a block of side `side` (px): half a
/// pixel, the finest detail the pixel grid can show (its Nyquist rate), where textures
/// are band-limited (stretched by the inverse projection's geometric mean over the two
/// axes); and twice the block's side along the stretched axis, a square that holds the
/// whole block wherever in it the path lands, over which the prediction is used and the
/// texture's statistics are averaged.
fn footprints(world: &World, dist: f64, cos_o: f64, side: f64) -> (f64, f64) {
    let cam = &world.camera;
    let cos_o = cos_o.abs().clamp(1e-6, 1.0);
    let pitch = 2.0 * cam.tan_x * dist / cam.width as f64;
    (0.5 * pitch / cos_o.sqrt(), 2.0 * side * pitch / cos_o)
}

/// Traces one covariance path through the pixel point `(px, py)` of `block` at time
/// uniform `ut`, through at most `depth` surface vertices (1 to [`MAX_DEPTH`]); returns,
/// for every vertex, the sensor's rates of the direct light it reflects along the path,
/// with that light's weight (its luminance times the path's throughput to the camera).
/// Empty when the path sees nothing. Textures are read over the block's footprint, and
/// edges are looked for around the path and at the block's corners.
///
/// Each vertex's chain runs in light order: the emitter, travel past the nearest blocker,
/// the reflection there; then, back along the path, travel to the vertex before, its
/// reflection towards the vertex before it, and so on to the first hit; then the camera
/// side (silhouettes, the camera), shared by every vertex. The next vertex is drawn from
/// the material's lobe as the path tracer draws it. A light found that way ends the path:
/// its reflection is the direct light of the vertex before, already counted.
pub fn trace_path<R: Rng>(
    world: &World,
    cc: &CovCamera,
    (px, py): (f64, f64),
    block: Block,
    ut: f64,
    depth: u32,
    rng: &mut R,
) -> Result<Vec<(PixelRates, f64)>, CovError> {
    let cam = &world.camera;
    let ray = cam.ray(px, py, (0.5, 0.5), ut);
    let time = ray.time;
    let mut out = Vec::new();
    let Some(hit) = world
        .geometry
        .intersect(ray.origin, ray.dir, time, 0.0, f64::INFINITY)
    else {
        return Ok(out);
    };
    let motion = cc.layout == 5;
    let d_out = -ray.dir; // from the hit towards the camera
    let x_out = frame_x(d_out, hit.n);
    let side = (block[2] - block[0]).max(block[3] - block[1]).max(1.0);
    let footprint = footprints(world, hit.t, hit.n.dot(d_out), side);
    // 5–6. The camera side, the end of every vertex's chain.
    let tail = camera_side(world, cc, (&hit, d_out), ((px, py), block), ut, footprint.0)?;
    let mut emit = |start: &AnyCov, chain: &Chain, weight: f64| -> Result<(), CovError> {
        let rates = cc.sensor.rates(&chain.eval_any(Form::Covariance, start)?)?;
        if weight.is_finite() && weight >= 0.0 {
            out.push((rates, weight));
        }
        Ok(())
    };
    if let Some(li) = hit.light {
        // A light seen directly: its window, seen at the angle of the camera ray.
        let light = &world.lights[li as usize];
        let weight = luminance(light.radiance()).max(0.0) * if hit.front { 1.0 } else { 0.0 };
        let chain = Chain::new()
            .with(Unproject::new(hit.ng.dot(d_out).abs().clamp(1e-6, 1.0))?)
            .with(tail);
        emit(&source(cc.layout, light.window_std())?, &chain, weight)?;
        return Ok(out);
    }
    let (mut v, mut d_o, mut x_o, mut fp, mut dist) = (hit, d_out, x_out, footprint, hit.t);
    let mut tail = tail;
    let mut throughput = DVec3::ONE;
    for k in 0..depth.clamp(1, MAX_DEPTH) {
        let mat = world.material_at(&v, fp.0);
        match lit(world, cc, (&v, &mat), (d_o, x_o), (fp, time), rng)? {
            Some((start, mut chain, w)) => {
                chain.push(tail.clone());
                emit(&start, &chain, luminance(throughput * w.0) * w.1)?;
            }
            None if k == 0 => {
                // The light sample does not reach this side: what the camera sees here is
                // indirect light, taken as constant (Σ = 0) where it leaves the surface.
                // The camera side (silhouettes, defocus, motion) still counts, with weight 0.
                let mut chain = Chain::new();
                if let Some(t) = texture_window(world, &v, d_o, x_o, fp)? {
                    push_on(&mut chain, motion, v.velocity, (d_o, x_o), Chain::new().with(t))?;
                }
                chain.push(tail.clone());
                emit(&AnyCov::zeros(cc.layout)?, &chain, 0.0)?;
            }
            None => {}
        }
        if k + 1 >= depth {
            break;
        }
        // The next vertex, drawn from the lobe as the path tracer draws it.
        let Some(wi) = mat.sample(v.n, d_o, rng.random(), rng.random()) else {
            break;
        };
        let (pdf, cos_i) = (mat.pdf(v.n, d_o, wi), v.n.dot(wi));
        if !(pdf > 0.0 && cos_i > 0.0 && wi.dot(v.ng) > 0.0) {
            break;
        }
        let Some(next) = world
            .geometry
            .intersect(spawn(&v, wi), wi, time, 0.0, f64::INFINITY)
        else {
            break;
        };
        if next.light.is_some() {
            break;
        }
        throughput *= mat.eval(v.n, d_o, wi) * (cos_i / pdf);
        // The light that leaves `next` towards `v`: travel, into the plane of incidence at
        // `v`, reflected there towards the vertex before, then what followed `v`.
        let d_in = -wi;
        let (x_in, x_next) = (frame_x(d_in, v.n), frame_x(d_in, next.n));
        let mut t = Chain::new();
        let edge = segment_edge(world, (&v, &mat), wi, &next, time, fp.0);
        travel_past(&mut t, next.t, edge, motion, (d_in, x_next))?;
        t.push(RotateFrame::new(turn(d_in, x_next, x_in))?);
        let here = at_surface(world, &v, &mat, (d_in, x_in, cos_i), (d_o, x_o), fp)?;
        push_on(&mut t, motion, v.velocity, (d_o, x_o), here)?;
        t.push(tail);
        tail = t;
        dist += next.t;
        fp = footprints(world, dist, next.n.dot(d_in), side);
        (v, d_o, x_o) = (next, d_in, x_next);
    }
    Ok(out)
}

/// The change of handedness at a reflection, `l'(x, y, u, v) = l(x, −y, u, −v)`. The pass
/// frames every ray right-handed, `(x, d × x)` with `x` in the plane of incidence.
/// cov-brdf's `Reflect` takes the incident frame with `y = n × t` (`t` the tangent of `x`),
/// which is `−(d × x)` for light arriving at the surface, and gives the reflected ray's
/// frame right-handed. Flipping `y` before it, with the turn's sign reversed (its `y` is
/// reversed), is the same as flipping `y` after it with the turn measured in the pass's own
/// frame: the flip commutes with the projections, the isotropic curvature, the mirror
/// symmetry and the pass's isotropic lobes, and reverses a rotation. A mirror shows the
/// image of what it reflects, not a rotated copy (test `a_mirror_shows_what_it_reflects`).
#[derive(Debug)]
struct Handedness;

impl cov_core::Operator for Handedness {
    fn apply(&self, cov: &mut dyn cov_core::Spectrum) -> Result<(), CovError> {
        cov.scale(cov_core::Axis::Y, -1.0)?;
        cov.scale(cov_core::Axis::V, -1.0)
    }

    fn requires(&self) -> cov_core::AxisSet {
        cov_core::AxisSet::SPACE
    }
}

/// The reflection at the vertex `v` of light arriving along `d_in` (frame `x_in`, cosine
/// `cos_i` to the normal) towards `d_out` (frame `x_out`), in the frame of `d_out`:
/// cov-brdf's `Reflect::with_turn` (the shape's curvature, the material's lobe, the turn
/// from the plane of incidence to the plane of the outgoing ray) and the change of
/// [`Handedness`], then the texture, which
/// multiplies the reflected light where it leaves the surface (it commutes with the lobe:
/// a window in position, a convolution in angle).
fn at_surface(
    world: &World,
    v: &Hit,
    mat: &crate::material::Material,
    (d_in, x_in, cos_i): (DVec3, DVec3, f64),
    (d_out, x_out): (DVec3, DVec3),
    footprint: (f64, f64),
) -> Result<Chain, CovError> {
    let t_in = (x_in - v.n * x_in.dot(v.n)).normalize_or_zero();
    let t_out = (x_out - v.n * x_out.dot(v.n)).normalize_or_zero();
    let y_in = d_in.cross(x_in);
    let bounce = Reflect::with_turn(
        cos_i.clamp(1e-6, 1.0),
        v.n.dot(d_out).clamp(1e-6, 1.0),
        Curvature::anisotropic(v.curvature.k1, v.curvature.k2, v.curvature.angle(t_in, y_in))?,
        mat.lobe(),
        t_out.dot(y_in).atan2(t_out.dot(t_in)),
    )?;
    let mut ops = Chain::new().with(bounce).with(Handedness);
    if let Some(t) = texture_window(world, v, d_out, x_out, footprint)? {
        ops.push(t);
    }
    Ok(ops)
}

/// The direct light that the vertex `v` of material `mat` reflects along `d_out` (frame
/// `x_out`), for one light sample: the source Σ, the chain from the emitter to the light
/// leaving `v` (1. the emitter window, foreshortened towards `v`; 2. travel, with the
/// nearest blocker near the path; 3. the reflection, in the shape's frame when it moves),
/// and the weight `(f·L, cos·n_lights/pdf)`, ignoring visibility. `None` when the sample
/// does not reach this side.
#[allow(clippy::type_complexity)]
fn lit<R: Rng>(
    world: &World,
    cc: &CovCamera,
    (v, mat): (&Hit, &crate::material::Material),
    (d_out, x_out): (DVec3, DVec3),
    (footprint, time): ((f64, f64), f64),
    rng: &mut R,
) -> Result<Option<(AnyCov, Chain, (DVec3, f64))>, CovError> {
    let n_l = world.lights.len();
    let pick = ((rng.random::<f64>() * n_l as f64) as usize).min(n_l - 1);
    let light = &world.lights[pick];
    let Some(ls) = light.sample(v.p, rng.random(), rng.random()) else {
        return Ok(None);
    };
    let (cos_i, f) = (v.n.dot(ls.wi), mat.eval(v.n, d_out, ls.wi));
    if !(cos_i > 0.0 && f != DVec3::ZERO) {
        return Ok(None);
    }
    let d_in = -ls.wi; // from the light towards the vertex
    let start = source(cc.layout, light.window_std())?;
    let cos_l = ls.n.dot(ls.wi).abs().clamp(1e-6, 1.0);
    let (x_l, x_in) = (frame_x(d_in, ls.n), frame_x(d_in, v.n));
    let mut chain = Chain::new()
        .with(Unproject::new(cos_l)?)
        .with(RotateFrame::new(turn(d_in, x_l, x_in))?);
    match nearest_blocker(world, v, light, ls.y, time, rng) {
        Some((s_b, r_b)) => {
            chain.push(Travel::new(s_b)?);
            chain.push(BlockerEdge::new(r_b)?);
            chain.push(Travel::new((ls.dist - s_b).max(0.0))?);
        }
        None => chain.push(Travel::new(ls.dist)?),
    }
    let here = at_surface(world, v, mat, (d_in, x_in, cos_i), (d_out, x_out), footprint)?;
    push_on(&mut chain, cc.layout == 5, v.velocity, (d_out, x_out), here)?;
    Ok(Some((
        start,
        chain,
        (f * ls.radiance, cos_i * n_l as f64 / ls.pdf),
    )))
}

/// The camera side of a path whose first hit is `hit`, in the frame of the hit's outgoing
/// ray `d_out` (towards the camera): 5. travel to the camera, past the nearest silhouette; 6. the camera (its motion,
/// the shutter, the lens, the sensor's end of the chain).
fn camera_side(
    world: &World,
    cc: &CovCamera,
    (hit, d_out): (&Hit, DVec3),
    ((px, py), block): ((f64, f64), Block),
    ut: f64,
    footprint: f64,
) -> Result<Chain, CovError> {
    let cam = &world.camera;
    let motion = cc.layout == 5;
    let x_out = frame_x(d_out, hit.n);
    let x_cam = frame_x(d_out, cam.right);
    let mut chain = Chain::new();
    let edge = nearest_silhouette(world, hit, (px, py), block, ut, footprint);
    travel_past(&mut chain, hit.t, edge, motion, (d_out, x_out))?;
    chain.push(RotateFrame::new(turn(d_out, x_out, x_cam))?);
    if motion && (cam.velocity != DVec3::ZERO || cam.angular_velocity != DVec3::ZERO) {
        // A turning camera turns the direction of every ray it sees at `ω × d`.
        chain.push(CameraMotion::new(
            in_frame(cam.velocity, d_out, x_cam),
            in_frame(cam.angular_velocity.cross(d_out), d_out, x_cam),
        )?);
    }
    chain.push(cc.end.clone());
    Ok(chain)
}

/// Travel of `len` towards the probes' origin (the camera, or the vertex before), past
/// `edge` where one was found: travel to it, its `BlockerEdge` (inside `Moving` when the
/// nearer surface moves, in the frame `(x, d × x)` of the ray `d`), travel on.
fn travel_past(
    chain: &mut Chain,
    len: f64,
    edge: Option<Silhouette>,
    motion: bool,
    (d, x): (DVec3, DVec3),
) -> Result<(), CovError> {
    match edge {
        Some(e) => {
            chain.push(Travel::new((len - e.depth).max(0.0))?);
            let window = Chain::new().with(BlockerEdge::new(e.radius)?);
            push_on(chain, motion, e.velocity, (d, x), window)?;
            chain.push(Travel::new(e.depth.min(len))?);
        }
        None => chain.push(Travel::new(len)?),
    }
    Ok(())
}

/// The nearest blocker edge near the path from the light point `y` to the hit, found by
/// the path's own shadow ray and auxiliary ones to other points of the light. Returns
/// (distance from the light along the path, distance from the path to the edge at that
/// depth), or `None` when no ray is blocked.
///
/// - The path's ray is clear: the edge lies between the path and the blocked rays'
///   blockers; the nearest blocker hit's distance from the path's line bounds it.
/// - The path's ray is blocked at depth `s`: the edge lies between the path and the clear
///   rays; the nearest clear ray's distance from the path at that depth bounds it (the
///   rays meet at the hit, so it is `(len − s) · |ω_k − ω_0|`). When every ray is blocked
///   (an umbra), the widest of those distances: the sharpest edge the probes allow.
///
/// A point of the light below the surface's own horizon (on the other side of the
/// geometric normal from the path's light) is skipped: the ray would meet the surface
/// itself, which is the cosine's fall over the terminator (the lobe and the curvature),
/// not a blocker's edge. Without this, convex shapes read a blocker at the hit near their
/// terminator, and isolated pixels predicted hundreds of cycles per pixel.
fn nearest_blocker<R: Rng>(
    world: &World,
    hit: &Hit,
    light: &crate::world::Light,
    y: DVec3,
    time: f64,
    rng: &mut R,
) -> Option<(f64, f64)> {
    let seg = hit.p - y;
    let len = seg.length();
    if len <= 0.0 {
        return None;
    }
    let dir = seg / len;
    let w0 = -dir;
    let lit_side = w0.dot(hit.ng);
    // Nearest blocker hit off a clear path; the blocked path's depth (the path's own ray
    // is traced first, so it is known before any probe); for a blocked path, the nearest
    // clear probe's distance from it at that depth and the widest blocked probe's.
    let mut off_path: Option<(f64, f64)> = None;
    let mut own: Option<f64> = None;
    let (mut nearest_clear, mut widest_blocked) = (f64::INFINITY, 0.0f64);
    for k in 0..=SHADOW_PROBES {
        let target = if k == 0 {
            y
        } else {
            match light.sample(hit.p, rng.random(), rng.random()) {
                Some(s) => s.y,
                None => continue,
            }
        };
        let d = target - hit.p;
        let dist = d.length();
        if dist <= 0.0 {
            continue;
        }
        let wi = d / dist;
        if k > 0 && wi.dot(hit.ng) * lit_side <= 0.0 {
            continue;
        }
        let o = spawn(hit, wi);
        let blocker = world.geometry.intersect(o, wi, time, 0.0, dist * (1.0 - 1e-6));
        if k == 0 {
            own = blocker.map(|b| (b.p - y).dot(dir).clamp(0.0, len));
            continue;
        }
        // How far this probe passes from the path at the blocked path's depth (the rays
        // meet at the hit).
        let apart = own.map(|s| (len - s) * (wi - w0).length());
        match blocker {
            Some(b) => {
                let rel = b.p - y;
                let along = rel.dot(dir).clamp(0.0, len);
                let r = (rel - dir * rel.dot(dir)).length();
                if off_path.is_none_or(|(_, br)| r < br) {
                    off_path = Some((along, r));
                }
                if let Some(a) = apart {
                    widest_blocked = widest_blocked.max(a);
                }
            }
            None => {
                if let Some(a) = apart {
                    nearest_clear = nearest_clear.min(a);
                }
            }
        }
    }
    let floor = 1e-6 * len;
    match own {
        None => off_path.map(|(s, r)| (s, r.max(floor))),
        Some(s) => {
            let r = if nearest_clear.is_finite() {
                nearest_clear
            } else {
                widest_blocked
            };
            Some((s, r.max(floor)))
        }
    }
}

/// Depth difference that makes a silhouette, relative to the hit's depth: between what a
/// probe ray hits and where it meets the hit's tangent plane.
pub const DEPTH_JUMP: f64 = 0.05;
/// Cosine of the normal turn that makes a crease (25°).
pub const CREASE_COS: f64 = 0.906;

/// A silhouette near a pixel's path.
struct Silhouette {
    /// Distance from the probes' origin (the camera, or the vertex a segment leaves) to
    /// the edge's surface (m).
    depth: f64,
    /// Distance from the path to the edge at that depth (m), divided by the square root of
    /// the edge's contrast ([`contrast`]): the `BlockerEdge` whose window is the contrast
    /// times the full-contrast edge's.
    radius: f64,
    /// Velocity of the nearer surface.
    velocity: DVec3,
}

/// The luminance a hit sends back along `-d` (towards the camera) from direct light,
/// ignoring visibility: one deterministic sample at the middle of each light, unshadowed
/// (shadows are the blockers' business); an emitter's own radiance; 0 for nothing. A
/// proxy for the radiance on either side of an edge, no ray traced.
fn direct_proxy(world: &World, hit: Option<&Hit>, d: DVec3, footprint: f64) -> f64 {
    let Some(h) = hit else { return 0.0 };
    if let Some(li) = h.light {
        return if h.front {
            luminance(world.lights[li as usize].radiance()).max(0.0)
        } else {
            0.0
        };
    }
    let mat = world.material_at(h, footprint);
    let wo = -d;
    let mut sum = 0.0;
    for light in &world.lights {
        if let Some(ls) = light.sample(h.p, 0.5, 0.5) {
            let cos_i = h.n.dot(ls.wi);
            if cos_i > 0.0 && ls.pdf > 0.0 {
                sum += luminance(mat.eval(h.n, wo, ls.wi) * ls.radiance) * cos_i / ls.pdf;
            }
        }
    }
    if sum.is_finite() { sum.max(0.0) } else { 0.0 }
}

/// The contrast of a step between radiances `a` and `b` (both ≥ 0), `|a − b| / max(a, b)`:
/// the step's share of the amplitude spectrum relative to a full-contrast edge (one side
/// dark), the model of cov-occlusion's `Texture::from_moments` applied to a step
/// (docs/physics.md section 3, "edges of partial contrast"). A field `b + (a − b)·s(x)` with `s` a unit
/// step has the amplitude `|a − b|` on the step's spectrum against `min(a, b)` on the
/// Dirac at zero, so the edge's window is weighed by `|a − b| / (min + |a − b|)`. Both
/// sides dark (light that only arrives indirectly): 1, the full-contrast edge, as before.
fn contrast(a: f64, b: f64) -> f64 {
    let hi = a.max(b);
    if hi > 0.0 {
        ((a - b).abs() / hi).min(1.0)
    } else {
        1.0
    }
}

/// Whether two hits see the same surface: the same material (or two materials with the
/// same parameters and texture), or both the same emitter.
fn same_surface(world: &World, a: &Hit, b: &Hit) -> bool {
    if a.light.is_some() || b.light.is_some() {
        return a.light == b.light;
    }
    let (i, j) = (a.material as usize, b.material as usize);
    i == j
        || (world.materials.get(i) == world.materials.get(j)
            && world.material_textures.get(i) == world.material_textures.get(j))
}

/// An edge found by a probe, kept in `best` if it is the first found or narrower than the
/// one there (the sharpest edge's window wins): at `depth` from the probes' origin, its
/// nearer surface moving at `velocity`, its full-contrast window of radius `full` weighed
/// by the [`contrast`] of the step between the radiances `here` and `there` (none when
/// both sides are alike).
fn keep_narrowest(
    best: &mut Option<Silhouette>,
    (here, there): (f64, f64),
    (depth, velocity): (f64, DVec3),
    full: f64,
) {
    let c = contrast(here, there);
    if c <= 0.0 {
        return;
    }
    let radius = full / c.sqrt();
    if best.as_ref().is_none_or(|b| radius < b.radius) {
        *best = Some(Silhouette {
            depth,
            radius,
            velocity,
        });
    }
}

/// What a probe from `origin` along `dir`, which met `h`, says about the surface of
/// `hit` (met at distance `hit.t` from the same origin) beside it: `None` where that
/// surface continues (the probe meets a surface within [`DEPTH_JUMP`] of `hit.t` of where
/// it would meet `hit`'s tangent plane, turned by less than a crease, of the same
/// material: a surface that continues smoothly is no silhouette however oblique, though at
/// grazing angles its depth changes by more than `DEPTH_JUMP` within half a pixel); else
/// an edge: the nearer surface's distance from `origin`, and its velocity.
fn edge_beside(
    world: &World,
    hit: &Hit,
    (origin, dir): (DVec3, DVec3),
    h: Option<&Hit>,
) -> Option<(f64, DVec3)> {
    let along = hit.n.dot(dir);
    let on_plane = if along.abs() > 1e-12 {
        (hit.n.dot(hit.p - origin) / along).max(0.0)
    } else {
        f64::INFINITY
    };
    match h {
        Some(h2)
            if (h2.t - on_plane).abs() <= DEPTH_JUMP * hit.t
                && h2.n.dot(hit.n) >= CREASE_COS
                && same_surface(world, hit, h2) =>
        {
            None
        }
        Some(h2) => Some((
            h2.t.min(hit.t),
            if h2.t < hit.t { h2.velocity } else { hit.velocity },
        )),
        None => Some((hit.t, hit.velocity)),
    }
}

/// An edge around the pixel: auxiliary pinhole rays half a pixel away from the path, and
/// at the centres of the block's corner pixels, that see something else: a surface at a
/// clearly different depth (more than [`DEPTH_JUMP`] of the hit's depth away from where
/// the probe meets the hit's tangent plane) or nothing (a
/// silhouette), a surface turned by more than `acos(`[`CREASE_COS`]`)` (a crease, where
/// shading changes abruptly), another material (a step in reflectance), or an emitter
/// where the path sees none (the edge of a light) or the reverse. The edge lies at the
/// nearer surface's depth, half a pixel's footprint from the path there: a block that holds
/// an edge predicts it for all its pixels. Each edge's window is weighed by its
/// [`contrast`], from the two sides' [`direct_proxy`]; the strongest window wins.
///
/// The probes above are taken at the path's own instant. Where motion is traced, two more
/// rays through the path's own image point, a third and two thirds of the shutter later
/// (modulo the shutter), look for an object that crosses the pixel while the shutter is
/// open: a ball that rolls through a pixel of felt for part of the exposure draws its
/// swept band's edges there, which a path that sees the felt at its instant would miss.
/// With the path's own time they sample the shutter at three equally spaced instants, so
/// an object that covers the pixel for more than a third of the exposure is always found;
/// one that covers it for less adds less contrast to the time-integrated pixel. The edge
/// found is the same space-time edge as one found at the path's instant, and takes the
/// nearer surface's velocity (`Moving`): only its extent across the motion stays sharp.
fn nearest_silhouette(
    world: &World,
    hit: &Hit,
    (px, py): (f64, f64),
    block: Block,
    ut: f64,
    footprint: f64,
) -> Option<Silhouette> {
    let cam = &world.camera;
    let mut best: Option<Silhouette> = None;
    let mut here: Option<f64> = None;
    let around = [(0.5, 0.0), (-0.5, 0.0), (0.0, 0.5), (0.0, -0.5)];
    let [x0, y0, x1, y1] = block;
    let corners = [
        (x0 + 0.5, y0 + 0.5),
        (x1 - 0.5, y0 + 0.5),
        (x0 + 0.5, y1 - 0.5),
        (x1 - 0.5, y1 - 0.5),
    ];
    let big = x1 - x0 > 1.0 || y1 - y0 > 1.0;
    // With motion traced, the path's own image point at the other two thirds of the
    // shutter: with the path's own time they sample it at three equally spaced instants
    // (see above).
    let thirds = world.has_motion && cam.shutter.is_some();
    let probes = around
        .iter()
        .take(EDGE_PROBES)
        .map(|&(dx, dy)| (px + dx, py + dy, ut))
        .chain(corners.into_iter().filter(|_| big).map(|(x, y)| (x, y, ut)))
        .chain(
            [1.0 / 3.0, 2.0 / 3.0]
                .into_iter()
                .filter(|_| thirds)
                .map(|d| (px, py, (ut + d).fract())),
        );
    for (qx, qy, uq) in probes {
        let r = cam.ray(qx, qy, (0.5, 0.5), uq);
        let h = world
            .geometry
            .intersect(r.origin, r.dir, r.time, 0.0, f64::INFINITY);
        let Some((depth, vel)) = edge_beside(world, hit, (r.origin, r.dir), h.as_ref()) else {
            continue;
        };
        // The path's own side, once, seen along the first probe that finds an edge (half a
        // pixel from the path's own ray).
        let l_here = *here.get_or_insert_with(|| direct_proxy(world, Some(hit), r.dir, footprint));
        // Half a pixel's footprint at that depth, its window weighed by the contrast.
        keep_narrowest(
            &mut best,
            (l_here, direct_proxy(world, h.as_ref(), r.dir, footprint)),
            (depth, vel),
            (cam.tan_x * depth / cam.width as f64).max(1e-9),
        );
    }
    best
}

/// An edge near the segment from the vertex `v` to the next vertex `next` (along `wi`):
/// an outline in what a glossy `v` reflects (the floor mirroring a torus against the
/// wall). Four probes from `v` at the lobe's angular std from the segment (`tan θ` the
/// square root of the lobe's smaller primal variance), tested against `next` as the
/// camera's probes are tested against the first hit ([`nearest_silhouette`]): another
/// depth than `next`'s tangent plane, a crease, another material ([`edge_beside`]). The edge lies at the
/// nearer surface's distance from `v`, `tan θ` times that distance from the segment, its
/// window weighed by the step's [`contrast`]. A diffuse `v` (infinite variance) has none:
/// its reflection removes every angular detail, so no edge beyond it reaches the image.
fn segment_edge(
    world: &World,
    (v, mat): (&Hit, &crate::material::Material),
    wi: DVec3,
    next: &Hit,
    time: f64,
    footprint: f64,
) -> Option<Silhouette> {
    let (vu, vv) = mat.lobe().variances();
    let tan = vu.min(vv).sqrt();
    if !(tan.is_finite() && tan > 0.0) {
        return None;
    }
    let (a, b) = wi.any_orthonormal_pair();
    let origin = spawn(v, wi);
    let mut best: Option<Silhouette> = None;
    let mut here: Option<f64> = None;
    for off in [a, -a, b, -b] {
        let dir = (wi + off * tan).normalize();
        if dir.dot(v.ng) <= 0.0 {
            continue;
        }
        let h = world.geometry.intersect(origin, dir, time, 0.0, f64::INFINITY);
        let Some((depth, vel)) = edge_beside(world, next, (origin, dir), h.as_ref()) else {
            continue;
        };
        let l_here = *here.get_or_insert_with(|| direct_proxy(world, Some(next), wi, footprint));
        keep_narrowest(
            &mut best,
            (l_here, direct_proxy(world, h.as_ref(), dir, footprint)),
            (depth, vel),
            (tan * depth).max(1e-9),
        );
    }
    best
}

/// Largest number of covariance paths per block of the covariance grid.
pub const MAX_COV_PATHS: u32 = 256;
/// Sides of the covariance grid's blocks [`covariance_maps`] accepts (px; they divide a
/// tile).
pub const STRIDES: [u32; 5] = [1, 2, 4, 8, 16];

/// The covariance maps of an image: per pixel, the predicted image-space Σ and samples
/// per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct CovMaps {
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Per pixel.
    pub pixels: Vec<PixelCov>,
    /// Covariance paths traced per block of the grid.
    pub paths_per_block: u32,
    /// Side of the grid's blocks (px; 1: a prediction per pixel).
    pub stride: u32,
    /// Layout the paths were traced in.
    pub layout: usize,
}

/// The image of per-tile results, each tile's values row by row, in tile order.
fn assemble<T: Clone>(
    w: u32,
    h: u32,
    tiles: &[(u32, u32, u32, u32)],
    results: Vec<Vec<T>>,
    fill: T,
) -> Vec<T> {
    let mut out = vec![fill; w as usize * h as usize];
    for (&(x0, y0, x1, y1), tile) in tiles.iter().zip(results) {
        let coords = (y0..y1).flat_map(|y| (x0..x1).map(move |x| (y * w + x) as usize));
        for (i, v) in coords.zip(tile) {
            out[i] = v;
        }
    }
    out
}

/// The generator of the covariance pass's tile `index`: seeded by the scene seed, one
/// stream per tile, so maps do not depend on the thread count.
fn tile_rng(seed: u64, index: usize) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed ^ (1 << 56));
    rng.set_stream(index as u64);
    rng
}

/// Traces `paths` covariance paths (1 to [`MAX_COV_PATHS`]) per block of `stride × stride`
/// pixels, jittered over the block and the shutter, each through [`DEFAULT_DEPTH`]
/// surface vertex ([`trace_path`]; [`covariance_rows`] takes the depth); every pixel of a
/// block gets the block's radiance-weighted prediction over its paths' vertices. A
/// coarser grid costs `stride²` times less; a block that holds an edge predicts for all
/// its pixels the detail that its paths saw, so edges widen to the block, which narrows
/// filters and raises densities near them (conservative).
///
/// # Errors
/// `paths` or `stride` out of range ([`STRIDES`]); an operator that rejects what the scene
/// gives it, with the pixel it happened at.
pub fn covariance_maps(
    world: &World,
    paths: u32,
    stride: u32,
    seed: u64,
    progress: crate::film::Progress<'_>,
) -> Result<CovMaps, crate::RenderError> {
    let rows = 0..world.camera.height;
    covariance_rows(world, paths, stride, DEFAULT_DEPTH, seed, rows, progress)
}

/// `Err` (the setting `name`) unless `depth` is 1 to the scene's [`World::max_depth`]: a
/// covariance path follows the path tracer's vertices, and no more.
///
/// # Errors
/// `depth` out of that range.
pub fn check_depth(world: &World, depth: u32, name: &'static str) -> Result<(), crate::RenderError> {
    let most = world.max_depth.min(MAX_DEPTH);
    if (1..=most).contains(&depth) {
        return Ok(());
    }
    Err(crate::RenderError::setting(
        name,
        format!(
            "1 to the scene's max_depth, {most} (2 where the scene file gives none; a covariance path follows the path tracer's vertices)"
        ),
        depth,
    ))
}

/// [`covariance_maps`] of the tiles whose first row lies in `rows` (a part of a render,
/// the `parts` module); the other pixels keep [`PixelCov::default`]. Each tile draws from
/// its own generator, seeded by its index in the whole image, so a tile's values are the
/// same whichever rows are traced. Paths follow at most `depth` surface vertices (1 to
/// the scene's [`World::max_depth`]; 1 traces camera → hit → light only).
///
/// # Errors
/// As [`covariance_maps`], and `depth` out of range.
pub fn covariance_rows(
    world: &World,
    paths: u32,
    stride: u32,
    depth: u32,
    seed: u64,
    rows: std::ops::Range<u32>,
    progress: crate::film::Progress<'_>,
) -> Result<CovMaps, crate::RenderError> {
    use rayon::prelude::*;
    if !STRIDES.contains(&stride) {
        return Err(crate::RenderError::setting(
            "the covariance grid's stride",
            format!("one of {STRIDES:?}"),
            stride,
        ));
    }
    if !(1..=MAX_COV_PATHS).contains(&paths) {
        return Err(crate::RenderError::setting(
            "covariance paths per block",
            format!("1 to {MAX_COV_PATHS}"),
            paths,
        ));
    }
    check_depth(world, depth, "the covariance paths' depth")?;
    let cc = CovCamera::new(world).map_err(|e| crate::RenderError::Camera(e.to_string()))?;
    let (w, h) = (world.camera.width, world.camera.height);
    let tl: Vec<(usize, (u32, u32, u32, u32))> = crate::film::tiles(w, h)
        .into_iter()
        .enumerate()
        .filter(|(_, t)| rows.contains(&t.1))
        .collect();
    let results: Result<Vec<Vec<PixelCov>>, crate::RenderError> = tl
        .par_iter()
        .map(|&(index, (x0, y0, x1, y1))| {
            let mut rng = tile_rng(seed, index);
            let mut out = vec![PixelCov::default(); ((x1 - x0) * (y1 - y0)) as usize];
            for by in (y0..y1).step_by(stride as usize) {
                for bx in (x0..x1).step_by(stride as usize) {
                    let (sx, sy) = ((x1 - bx).min(stride), (y1 - by).min(stride));
                    let acc = block_cov(world, &cc, (bx, by), (sx, sy), (paths, depth), &mut rng)?;
                    for y in by..by + sy {
                        for x in bx..bx + sx {
                            out[((y - y0) * (x1 - x0) + (x - x0)) as usize] = acc;
                        }
                    }
                }
            }
            if let Some(p) = progress {
                p();
            }
            Ok(out)
        })
        .collect();
    Ok(CovMaps {
        width: w,
        height: h,
        pixels: assemble(
            w,
            h,
            &tl.iter().map(|t| t.1).collect::<Vec<_>>(),
            results?,
            PixelCov::default(),
        ),
        paths_per_block: paths,
        stride,
        layout: cc.layout(),
    })
}

/// The radiance-weighted mean prediction of `paths` paths through the block of `size`
/// pixels at `at`.
fn block_cov<R: Rng>(
    world: &World,
    cc: &CovCamera,
    (x, y): (u32, u32),
    (sx, sy): (u32, u32),
    (paths, depth): (u32, u32),
    rng: &mut R,
) -> Result<PixelCov, crate::RenderError> {
    let mut acc = PixelCov::default();
    let (mut plain, mut n_plain, mut plain_spp) = ([0.0; 3], 0.0, 0.0);
    for _ in 0..paths {
        let (jx, jy, ut) = (
            rng.random::<f64>() * f64::from(sx),
            rng.random::<f64>() * f64::from(sy),
            rng.random::<f64>(),
        );
        let (px, py) = (f64::from(x) + jx, f64::from(y) + jy);
        let block = [f64::from(x), f64::from(y), f64::from(x + sx), f64::from(y + sy)];
        let r = trace_path(world, cc, (px, py), block, ut, depth, rng).map_err(|e| {
            crate::RenderError::Covariance {
                x: px.floor() as u32,
                y: py.floor() as u32,
                message: e.to_string(),
            }
        })?;
        for (d, wgt) in r {
            // The chain ends in the camera's frame, `y` up (the ray frame's `d × x` with `x`
            // the camera's right); the image's rows, the film's splats and the maps run
            // down, so `xy` changes sign.
            let s = [d.image_cov_px[0][0], -d.image_cov_px[0][1], d.image_cov_px[1][1]];
            if !(s.iter().all(|v| v.is_finite()) && d.samples_per_pixel.is_finite()) {
                continue;
            }
            for k in 0..3 {
                acc.sigma[k] += wgt * s[k];
                plain[k] += s[k];
            }
            acc.spp += wgt * d.samples_per_pixel;
            acc.weight += wgt;
            plain_spp += d.samples_per_pixel;
            n_plain += 1.0;
        }
    }
    if acc.weight > 0.0 {
        for k in 0..3 {
            acc.sigma[k] /= acc.weight;
        }
        acc.spp /= acc.weight;
    } else if n_plain > 0.0 {
        // No path carried light: the geometry's content, unweighted.
        acc.sigma = plain.map(|v| v / n_plain);
        acc.spp = plain_spp / n_plain;
    }
    Ok(acc)
}

#[cfg(test)]
mod tests {
    use glam::DQuat;

    use super::*;

    /// A floor of `floor` (a material's RON) at y = 0, a ball of radius 0.5 standing at
    /// 3 m, a wall at 6 m, lit from above.
    fn floor_and_ball(floor: &str) -> World {
        let text = format!(
            r#"Scene(
            camera: (position: (0.0, 1.0, 2.0), look_at: (0.0, 0.0, 0.0), fov: 40.0, width: 16, height: 16),
            materials: {{ "floor": {floor}, "ball": Diffuse(albedo: (0.8, 0.2, 0.2)), "wall": Diffuse(albedo: (0.5, 0.5, 0.5)) }},
            lights: [Sphere(center: (0.0, 4.0, -2.0), radius: 0.5, radiance: (5.0, 5.0, 5.0))],
            shapes: [
                Quad(corner: (-20.0, 0.0, 4.0), edge_u: (40.0, 0.0, 0.0), edge_v: (0.0, 0.0, -10.0), material: "floor"),
                Quad(corner: (-20.0, 0.0, -6.0), edge_u: (40.0, 0.0, 0.0), edge_v: (0.0, 20.0, 0.0), material: "wall"),
                Sphere(center: (0.0, 0.5, -3.0), radius: 0.5, material: "ball"),
            ],
        )"#
        );
        World::from_text(&text, "<test>", std::path::Path::new(".")).unwrap()
    }

    /// From the floor's point under the camera's gaze, the segment to the wall along
    /// `wi`, turned `angle` radians sideways from the ball's centre.
    fn segment(world: &World, angle: f64) -> (Hit, DVec3, Hit) {
        let v = world
            .geometry
            .intersect(DVec3::new(0.0, 1.0, 0.0), DVec3::NEG_Y, 0.0, 0.0, 10.0)
            .unwrap();
        let to_ball = (DVec3::new(0.0, 0.5, -3.0) - v.p).normalize();
        let wi = DQuat::from_rotation_y(angle) * to_ball;
        let next = world
            .geometry
            .intersect(spawn(&v, wi), wi, 0.0, 0.0, f64::INFINITY)
            .unwrap();
        (v, wi, next)
    }

    /// A glossy floor mirrors the ball's outline against the wall: a segment that passes
    /// the ball within the lobe's width (Phong 100: `tan θ` = 0.1) finds the outline at the
    /// ball's distance, its window the lobe's width there weighed by the contrast; one
    /// far from the ball finds none, and a diffuse floor, whose reflection keeps no
    /// angular detail, never looks.
    #[test]
    fn a_glossy_floor_reflects_the_outline_beside_its_path() {
        let glossy = floor_and_ball("Phong(albedo: (0.8, 0.8, 0.8), exponent: 100.0)");
        let mat = |w: &World, v: &Hit| w.material_at(v, 1e-3);
        // The ball subtends 0.165 rad from the floor's point; 0.2 rad sideways passes it
        // by 0.035 rad, inside the lobe's 0.1.
        let (v, wi, next) = segment(&glossy, 0.2);
        assert!(next.t > 5.0, "the segment reaches the wall: {}", next.t);
        let e = segment_edge(&glossy, (&v, &mat(&glossy, &v)), wi, &next, 0.0, 1e-3)
            .expect("the ball's outline beside the segment");
        assert!(
            (2.4..3.1).contains(&e.depth),
            "at the ball's distance: {}",
            e.depth
        );
        // The lobe's width at the ball over the square root of the contrast (at most 1; the
        // ball and the wall are both lit, well above a contrast of 1%).
        let full = 0.1 * e.depth;
        assert!(
            e.radius >= full * (1.0 - 1e-9) && e.radius <= 10.0 * full,
            "the lobe's width at the ball is {full} m, the edge's radius {}",
            e.radius
        );
        // Far from the ball: the wall alone, one surface.
        let (v, wi, next) = segment(&glossy, 0.7);
        assert!(segment_edge(&glossy, (&v, &mat(&glossy, &v)), wi, &next, 0.0, 1e-3).is_none());
        // A diffuse floor: no probe.
        let dull = floor_and_ball("Diffuse(albedo: (0.8, 0.8, 0.8))");
        let (v, wi, next) = segment(&dull, 0.2);
        assert!(segment_edge(&dull, (&v, &mat(&dull, &v)), wi, &next, 0.0, 1e-3).is_none());
    }
}
