//! The scene as the renderer uses it: camera, lights, materials and geometry, built from a
//! [`SceneFile`] with every cross-reference checked.

use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;
use std::path::Path;

use glam::{DVec2, DVec3};

use crate::geometry::{Geometry, Hit, MAX_COORD, Prim, Shape};
use crate::material::{Material, basis};
use crate::scene::{
    At, CameraDesc, LightDesc, MAX_SCENE_BYTES, MAX_SHARED_BOX, MAX_TRIANGLES, MaterialDesc, Rgb, SceneError,
    SceneFile, ShapeDesc, TextureDesc, V3,
};
use crate::texture::TextureMap;

fn v(a: V3) -> DVec3 {
    DVec3::from_array(a.0)
}

/// A thin-lens (or pinhole) camera with a shutter, a velocity and a rotation rate.
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    /// Lens centre at time 0.
    pub position: DVec3,
    /// Image right (unit).
    pub right: DVec3,
    /// Image up (unit).
    pub up: DVec3,
    /// Viewing direction (unit).
    pub forward: DVec3,
    /// `tan(fov_x/2)`.
    pub tan_x: f64,
    /// `tan(fov_y/2)`.
    pub tan_y: f64,
    /// Horizontal field of view (rad).
    pub fov_x: f64,
    /// Width (px).
    pub width: u32,
    /// Height (px).
    pub height: u32,
    /// Lens radius (m); 0: pinhole.
    pub lens_radius: f64,
    /// Distance in focus (m).
    pub focus_distance: f64,
    /// Focal length (m).
    pub focal_length: f64,
    /// Shutter interval (s), if time is sampled.
    pub shutter: Option<(f64, f64)>,
    /// Time added to every ray's (s): an animation's frame ([`World::at_frame`]) moves
    /// the shutter, or a still image's instant, by this much.
    pub time_offset: f64,
    /// Frames per second of an animation.
    pub frame_rate: f64,
    /// Velocity (m/s).
    pub velocity: DVec3,
    /// Rotation rate about the lens centre (rad/s, axis times rate): at time `t` the
    /// camera's frame (forward, right, up) is turned by `ω t` ([`Camera::frame_at`]).
    pub angular_velocity: DVec3,
}

/// A ray leaving the camera.
#[derive(Clone, Copy, Debug)]
pub struct CameraRay {
    /// Origin (on the lens).
    pub origin: DVec3,
    /// Direction (unit).
    pub dir: DVec3,
    /// Time (s).
    pub time: f64,
}

impl Camera {
    /// The largest |coordinate| of the camera's position over the times `t0..t1` (∞ where
    /// its motion overflows).
    pub fn reach(&self, t0: f64, t1: f64) -> f64 {
        let m = [t0, t1]
            .map(|t| (self.position + self.velocity * t).abs().max_element())
            .into_iter()
            .fold(0.0, f64::max);
        if m.is_nan() { f64::INFINITY } else { m }
    }

    /// The ray through the image point `(px, py)` (pixels, from the top-left corner), the
    /// lens point `lens` (uniforms in `[0,1)²`, mapped to the disk) and the time uniform
    /// `ut`.
    pub fn ray(&self, px: f64, py: f64, lens: (f64, f64), ut: f64) -> CameraRay {
        let time = self.time_offset + self.shutter.map_or(0.0, |(a, b)| a + (b - a) * ut);
        let (forward, right, up) = self.frame_at(time);
        let nx = (2.0 * px / self.width as f64 - 1.0) * self.tan_x;
        let ny = (1.0 - 2.0 * py / self.height as f64) * self.tan_y;
        let pin = (forward + right * nx + up * ny).normalize();
        let centre = self.position + self.velocity * time;
        if self.lens_radius <= 0.0 {
            return CameraRay {
                origin: centre,
                dir: pin,
                time,
            };
        }
        let focus = centre + pin * (self.focus_distance / pin.dot(forward));
        let (dx, dy) = concentric_disk(lens.0, lens.1);
        let origin = centre + (right * dx + up * dy) * self.lens_radius;
        CameraRay {
            origin,
            dir: (focus - origin).normalize(),
            time,
        }
    }

    /// The camera's forward, right and up directions at time `time` (s): turned by
    /// `angular_velocity · time` about the lens centre; those of time 0 when it does not
    /// turn.
    pub fn frame_at(&self, time: f64) -> (DVec3, DVec3, DVec3) {
        if self.angular_velocity == DVec3::ZERO {
            return (self.forward, self.right, self.up);
        }
        let q = glam::DQuat::from_scaled_axis(self.angular_velocity * time);
        (q * self.forward, q * self.right, q * self.up)
    }

    /// Lens to sensor (m): the thin-lens image distance, or the focal length for a pinhole.
    pub fn sensor_distance(&self) -> f64 {
        if self.lens_radius > 0.0 {
            self.focal_length * self.focus_distance / (self.focus_distance - self.focal_length)
        } else {
            self.focal_length
        }
    }
}

/// Shirley's concentric map of the unit square onto the unit disk.
pub fn concentric_disk(u: f64, v: f64) -> (f64, f64) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, PI / 4.0 * (b / a))
    } else {
        (b, PI / 2.0 - PI / 4.0 * (a / b))
    };
    (r * phi.cos(), r * phi.sin())
}

/// An area light.
#[derive(Clone, Copy, Debug)]
pub enum Light {
    /// A one-sided parallelogram.
    Rect {
        /// Corner.
        corner: DVec3,
        /// First edge.
        eu: DVec3,
        /// Second edge.
        ev: DVec3,
        /// Unit normal (`eu × ev`).
        n: DVec3,
        /// Area (m²).
        area: f64,
        /// Radiance.
        radiance: DVec3,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius.
        radius: f64,
        /// Radiance.
        radiance: DVec3,
    },
}

/// A point sampled on a light, seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The point.
    pub y: DVec3,
    /// The light's normal there.
    pub n: DVec3,
    /// Unit direction from the shading point to `y`.
    pub wi: DVec3,
    /// Distance to `y`.
    pub dist: f64,
    /// Density of `wi` in solid angle (for this light).
    pub pdf: f64,
    /// Radiance leaving `y` towards the shading point.
    pub radiance: DVec3,
}

impl Light {
    /// Radiance.
    pub fn radiance(&self) -> DVec3 {
        match *self {
            Light::Rect { radiance, .. } | Light::Sphere { radiance, .. } => radiance,
        }
    }

    /// The std of the emitter seen as a Gaussian window (m): a box of side `a` has std
    /// `a/√12`; a disk of radius `r`, `r/2`.
    pub fn window_std(&self) -> f64 {
        match *self {
            Light::Rect { area, .. } => area.sqrt() / 12f64.sqrt(),
            Light::Sphere { radius, .. } => radius / 2.0,
        }
    }

    /// Samples a point on the light as seen from `x` (uniforms `u1, u2`).
    pub fn sample(&self, x: DVec3, u1: f64, u2: f64) -> Option<LightSample> {
        match *self {
            Light::Rect {
                corner,
                eu,
                ev,
                n,
                area,
                radiance,
            } => {
                let y = corner + eu * u1 + ev * u2;
                let d = y - x;
                let dist = d.length();
                if dist <= 0.0 {
                    return None;
                }
                let wi = d / dist;
                let cos_l = -wi.dot(n);
                if cos_l <= 0.0 {
                    return None;
                }
                Some(LightSample {
                    y,
                    n,
                    wi,
                    dist,
                    pdf: dist * dist / (cos_l * area),
                    radiance,
                })
            }
            Light::Sphere {
                center,
                radius,
                radiance,
            } => {
                let dc = center - x;
                let dist_c = dc.length();
                if dist_c <= radius * (1.0 + 1e-9) {
                    return None;
                }
                let w = dc / dist_c;
                let sin2 = (radius / dist_c).powi(2);
                let cos_max = (1.0 - sin2).max(0.0).sqrt();
                let cos_t = 1.0 - u1 * (1.0 - cos_max);
                let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
                let phi = 2.0 * PI * u2;
                let (t, b) = basis(w);
                let wi = (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + w * cos_t).normalize();
                // The nearer intersection of the cone direction with the sphere.
                let bq = -wi.dot(dc);
                let c = dist_c * dist_c - radius * radius;
                let disc = (bq * bq - c).max(0.0);
                let dist = -bq - disc.sqrt();
                let y = x + wi * dist;
                Some(LightSample {
                    y,
                    n: (y - center).normalize(),
                    wi,
                    dist,
                    pdf: 1.0 / (2.0 * PI * (1.0 - cos_max)),
                    radiance,
                })
            }
        }
    }

    /// Density in solid angle with which [`Light::sample`] picks `wi` from `x`, given that
    /// the ray hits the light at distance `dist`.
    pub fn pdf(&self, x: DVec3, wi: DVec3, dist: f64) -> f64 {
        match *self {
            Light::Rect { n, area, .. } => {
                let cos_l = -wi.dot(n);
                if cos_l <= 0.0 {
                    return 0.0;
                }
                dist * dist / (cos_l * area)
            }
            Light::Sphere { center, radius, .. } => {
                let dist_c = (center - x).length();
                if dist_c <= radius {
                    return 0.0;
                }
                let cos_max = (1.0 - (radius / dist_c).powi(2)).max(0.0).sqrt();
                1.0 / (2.0 * PI * (1.0 - cos_max))
            }
        }
    }
}

/// Everything the renderer needs.
#[derive(Debug)]
pub struct World {
    /// The file it came from.
    pub file: String,
    /// A hash (FNV-1a, 64 bits) of the scene's text and of every file it reads (textures,
    /// OBJ meshes): what tells renders of different scenes apart (the `parts` module).
    pub fingerprint: u64,
    /// The animation frame the camera and the objects are at ([`World::at_frame`]).
    pub frame: u32,
    /// The camera.
    pub camera: Camera,
    /// Materials, by index.
    pub materials: Vec<Material>,
    /// Material names, by index.
    pub material_names: Vec<String>,
    /// Per material, the index of its texture in [`World::textures`].
    pub material_textures: Vec<Option<u32>>,
    /// Textures, by index.
    pub textures: Vec<TextureMap>,
    /// Lights, by index.
    pub lights: Vec<Light>,
    /// Primitives under a BVH.
    pub geometry: Geometry,
    /// The files the scene reads besides itself (image textures, OBJ meshes), as
    /// resolved from its folder.
    pub inputs: Vec<std::path::PathBuf>,
    /// The path tracer's depth: surface vertices at which a path takes direct light (the
    /// scene's `max_depth`, 1 to [`crate::scene::MAX_PATH_DEPTH`]).
    pub max_depth: u32,
    /// Whether anything moves during an open shutter (the covariance is then traced with
    /// a time axis, layout 5; else layout 4).
    pub has_motion: bool,
    /// What the scene asks for that is read otherwise than its file may suggest, one line
    /// each, positioned as errors are (`file:line:col: message`), for the user (an OBJ
    /// whose `usemtl` lines name several materials, which a mesh does not read). The
    /// scene loads and renders; `covtrace` prints them as warnings.
    pub warnings: Vec<String>,
}

impl World {
    /// The same scene at another resolution (the vertical field of view follows the new
    /// aspect ratio; sides are clamped to 1..=[`crate::scene::MAX_RESOLUTION`]).
    pub fn with_resolution(mut self, width: u32, height: u32) -> World {
        let (w, h) = (
            width.clamp(1, crate::scene::MAX_RESOLUTION),
            height.clamp(1, crate::scene::MAX_RESOLUTION),
        );
        self.camera.width = w;
        self.camera.height = h;
        self.camera.tan_y = self.camera.tan_x * h as f64 / w as f64;
        self
    }

    /// The same scene at frame `frame` of an animation: the shutter (or a still's instant)
    /// moves by `frame / frame_rate` seconds, so that the camera and the objects are where
    /// their velocities take them by then. Frames count from the scene as written (frame
    /// 0); up to [`MAX_FRAME`].
    ///
    /// # Errors
    /// A frame above [`MAX_FRAME`], or one that moves a shape or the camera beyond
    /// [`MAX_COORD`] ([`World::frame_problem`]).
    pub fn at_frame(mut self, frame: u32) -> Result<World, crate::RenderError> {
        if let Some(expected) = self.frame_problem(frame) {
            return Err(crate::RenderError::setting("frame", expected, frame));
        }
        let (offset, t0, t1) = self.frame_times(frame);
        self.camera.time_offset = offset;
        self.geometry = self.geometry.retimed(t0, t1);
        self.frame = frame;
        Ok(self)
    }

    /// Frame `frame`'s time offset (`frame / frame_rate`) and its shutter (or a still's
    /// instant), moved by it.
    fn frame_times(&self, frame: u32) -> (f64, f64, f64) {
        let c = &self.camera;
        let offset = f64::from(frame) / c.frame_rate;
        let (t0, t1) = c.shutter.unwrap_or((0.0, 0.0));
        (offset, t0 + offset, t1 + offset)
    }

    /// What frame `frame` would have to be instead, `None` when it can be rendered: at most
    /// [`MAX_FRAME`], and a frame at which every shape and the camera stay within
    /// [`MAX_COORD`]. Motion is linear in time, so the first and the last frame of a range
    /// bound every frame between them.
    pub fn frame_problem(&self, frame: u32) -> Option<String> {
        if frame > MAX_FRAME {
            return Some(format!("0 to {MAX_FRAME}"));
        }
        let (_, t0, t1) = self.frame_times(frame);
        let reach = self.geometry.reach(t0, t1).max(self.camera.reach(t0, t1));
        (reach > MAX_COORD).then(|| {
            // Rounded, a distance just past the bound would read as the bound itself.
            let shown = cov_core::approx(reach);
            let shown = match shown.parse::<f64>() {
                Ok(v) if v <= MAX_COORD => format!("{reach:e}"),
                _ => shown,
            };
            format!(
                "a frame at which every shape and the camera stay within ±{MAX_COORD:e} m (at frame {frame}, one of them reaches {shown} m)"
            )
        })
    }

    /// The material at a surface hit, its albedo multiplied by its texture's colour there,
    /// averaged over a footprint of `footprint` metres on the surface.
    pub fn material_at(&self, hit: &Hit, footprint: f64) -> Material {
        let mat = self.materials[hit.material as usize];
        match self.texture_at(hit) {
            Some((tex, per_m)) => mat.with_albedo(mat.albedo() * tex.rgb(hit.uv, footprint * per_m)),
            None => mat,
        }
    }

    /// The texture of the hit's material, with the surface's texture coordinates per metre
    /// (for footprints); `None` without a texture or where the coordinates are degenerate.
    pub fn texture_at(&self, hit: &Hit) -> Option<(&TextureMap, f64)> {
        let t = (*self.material_textures.get(hit.material as usize)?)?;
        let area = hit.dpduv[0].cross(hit.dpduv[1]).length();
        // Below this the (u, v) map is singular (a sphere's pole, a degenerate triangle):
        // the texture's base level is used, without a footprint.
        let per_m = if area > 1e-300 { 1.0 / area.sqrt() } else { 0.0 };
        Some((&self.textures[t as usize], per_m))
    }

    /// Reads and builds a scene file.
    ///
    /// # Errors
    /// An unreadable or oversized file, or any error of [`World::from_text`].
    pub fn load(path: &Path) -> Result<World, SceneError> {
        let file = cov_core::one_line(&path.display().to_string());
        let err = |message: String| SceneError {
            file: file.clone(),
            at: None,
            message,
        };
        let bytes = read_bounded(path, MAX_SCENE_BYTES, "scene").map_err(err)?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let (line, col) = cov_core::utf8_error_at(e.as_bytes()).map_or((1, 1), |(l, c, _)| (l, c));
            SceneError {
                file: file.clone(),
                at: Some((line, col)),
                message: "the file is not UTF-8 text".into(),
            }
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Self::from_text(&text, &file, dir).map_err(|e| {
            // A mesh given where a scene belongs: say so rather than what RON expected.
            let obj = path.extension().is_some_and(|x| x.eq_ignore_ascii_case("obj"));
            if obj {
                err("an OBJ mesh, not a scene: a scene (`Scene(...)` in RON) places it with a `Mesh(obj: \"…\", material: …)` shape".into())
            } else {
                e
            }
        })
    }

    /// Builds a scene from text; `file` names it in errors and `dir` is where OBJ paths
    /// are resolved.
    ///
    /// # Errors
    /// Malformed or out-of-range input, an unknown material, an unreadable OBJ: one
    /// positioned line.
    pub fn from_text(text: &str, file: &str, dir: &Path) -> Result<World, SceneError> {
        let desc = SceneFile::parse(text, file)?;
        let at = |ordinal: u32, message: String| SceneError {
            file: file.to_string(),
            at: SceneFile::locate(text, ordinal),
            message,
        };
        let camera = camera(&desc.camera).map_err(|(o, m)| at(o, m))?;
        let (textures, texture_names) = textures(&desc, dir).map_err(|(o, m)| at(o, m))?;
        let (materials, material_names, material_textures) =
            materials(&desc, &Names(&texture_names, "texture")).map_err(|(o, m)| at(o, m))?;
        let mut prims = Vec::new();
        let (t0, t1) = camera.shutter.unwrap_or((0.0, 0.0));
        let mut boxes = SharedBoxes::default();
        let lights = lights(&desc, &mut prims, &mut boxes).map_err(|(o, m)| at(o, m))?;
        let names = Names(&material_names, "material");
        let mut warnings = Vec::new();
        let any_velocity = shapes(
            &desc,
            &names,
            dir,
            &mut prims,
            (t0, t1),
            &mut boxes,
            &mut warnings,
        )
        .map_err(|(o, m)| at(o, m))?
            || camera.velocity != DVec3::ZERO
            || camera.angular_velocity != DVec3::ZERO;
        large_enough(&desc).map_err(|(o, m)| at(o, m))?;
        let warnings = warnings.into_iter().map(|(o, m)| at(o, m).to_string()).collect();
        let inputs = input_files(&desc, dir);
        Ok(World {
            file: file.to_string(),
            fingerprint: fingerprint(text, &inputs),
            inputs,
            frame: 0,
            max_depth: desc.max_depth.map_or(crate::scene::DEFAULT_PATH_DEPTH, |d| d.0),
            has_motion: camera.shutter.is_some() && any_velocity,
            camera,
            materials,
            material_names,
            material_textures,
            textures,
            lights,
            geometry: Geometry::new(prims, t0, t1),
            warnings,
        })
    }
}

/// A check's failure: the number of the [`At`] value it concerns, and the message.
type Failure = (u32, String);

/// The camera of a description.
fn camera(c: &CameraDesc) -> Result<Camera, Failure> {
    // A point of the camera's, `field`, within the scene's extent.
    let point = |p: &At<V3>, field: &str| -> Result<DVec3, Failure> {
        let x = v(p.value);
        if x.is_finite() && x.abs().max_element() <= MAX_COORD {
            return Ok(x);
        }
        Err((
            p.ordinal,
            format!(
                "`{field}` must lie within ±{MAX_COORD:e} m of the origin, as every point of the scene does, got ({}, {}, {})",
                cov_core::num(x.x),
                cov_core::num(x.y),
                cov_core::num(x.z)
            ),
        ))
    };
    let position = point(&c.position, "position")?;
    let aim = point(&c.look_at, "look_at")?;
    let look = aim - position;
    if look.length() <= 0.0 {
        return Err((c.look_at.ordinal, "the camera looks at its own position".into()));
    }
    let forward = look.normalize();
    let up0 = c.up.as_ref().map_or(DVec3::Y, |u| v(u.value));
    if let Some(u) = c.up.as_ref().filter(|_| up0 == DVec3::ZERO) {
        return Err((u.ordinal, "`up` is the zero vector: it gives no direction".into()));
    }
    let right = forward.cross(up0);
    if right.length() <= 1e-12 {
        return Err(match c.up.as_ref() {
            Some(u) => (u.ordinal, "`up` is parallel to the viewing direction".into()),
            None => (
                c.look_at.ordinal,
                "the camera looks straight up or down, along the default `up` (0, 1, 0): give the camera an `up` across the view, e.g. up: (0.0, 0.0, -1.0)".into(),
            ),
        });
    }
    let right = right.normalize();
    let up = right.cross(forward);
    let fov_x = c.fov.value.0.to_radians();
    if fov_x >= PI || c.fov.value.0 < crate::scene::MIN_FOV {
        return Err((
            c.fov.ordinal,
            format!(
                "fov must be {:e} to below 180 degrees, got {}",
                crate::scene::MIN_FOV,
                cov_core::num(c.fov.value.0)
            ),
        ));
    }
    let (width, height) = (c.width.0, c.height.0);
    let tan_x = (fov_x / 2.0).tan();
    let tan_y = tan_x * height as f64 / width as f64;
    let (lo, hi) = crate::scene::LENS_RANGE;
    let in_lens_range = |what: &str, v: f64, at: u32| {
        if (lo..=hi).contains(&v) {
            Ok(())
        } else {
            Err((
                at,
                format!("{what} must be {lo:e} to {hi:e} m, got {}", cov_core::num(v)),
            ))
        }
    };
    let (lens_radius, focus_distance, focal_length) = match &c.lens {
        Some(l) => {
            let f = l.focal_length.as_ref().map_or(0.05, |f| f.value.0);
            if let Some(fl) = &l.focal_length {
                in_lens_range("focal_length", f, fl.ordinal)?;
            }
            let r = l.aperture.value.0;
            if r != 0.0 {
                in_lens_range("aperture (0 for a pinhole)", r, l.aperture.ordinal)?;
            }
            let d = l.focus_distance.value.0;
            if d > MAX_COORD {
                return Err((
                    l.focus_distance.ordinal,
                    format!(
                        "focus_distance must be at most {MAX_COORD:e} m (the scene's extent), got {}",
                        cov_core::num(d)
                    ),
                ));
            }
            if d <= f {
                return Err((
                    l.focus_distance.ordinal,
                    format!(
                        "focus_distance {} must exceed the focal length {} (a real image)",
                        cov_core::num(d),
                        cov_core::num(f)
                    ),
                ));
            }
            (r, d, f)
        }
        None => (0.0, 1.0, 0.05),
    };
    let (slo, shi) = crate::scene::SHUTTER_RANGE;
    let shutter = match &c.shutter {
        // Equal ends are a shutter open for no time, not one that closes first.
        Some(s) if s.close.value.0 >= s.open.0 && !(slo..=shi).contains(&(s.close.value.0 - s.open.0)) => {
            return Err((
                s.close.ordinal,
                format!(
                    "the shutter must stay open {slo:e} to {shi:e} s (close − open), got {}",
                    cov_core::num(s.close.value.0 - s.open.0)
                ),
            ));
        }
        Some(s) if s.close.value.0 > s.open.0 => Some((s.open.0, s.close.value.0)),
        Some(s) => {
            return Err((
                s.close.ordinal,
                format!(
                    "the shutter closes ({}) before it opens ({})",
                    cov_core::num(s.close.value.0),
                    cov_core::num(s.open.0)
                ),
            ));
        }
        None => None,
    };
    let camera = Camera {
        position,
        right,
        up,
        forward,
        tan_x,
        tan_y,
        fov_x,
        width,
        height,
        lens_radius,
        focus_distance,
        focal_length,
        shutter,
        time_offset: 0.0,
        frame_rate: c.frame_rate.map_or(DEFAULT_FRAME_RATE, |r| r.0),
        velocity: c.velocity.as_ref().map_or(DVec3::ZERO, |u| v(u.value)),
        angular_velocity: c.angular_velocity.as_ref().map_or(DVec3::ZERO, |u| v(u.value)),
    };
    if let Some(w) = &c.angular_velocity {
        rotation_rate(w, "angular_velocity")?;
    }
    let (t0, t1) = camera.shutter.unwrap_or((0.0, 0.0));
    let reach = camera.reach(t0, t1);
    if reach > MAX_COORD {
        return Err((
            c.velocity.as_ref().map_or(c.look_at.ordinal, |u| u.ordinal),
            format!(
                "the camera reaches {} m from the origin (over the shutter, if it moves): the renderer holds ±{MAX_COORD:e} m",
                cov_core::num(reach)
            ),
        ));
    }
    Ok(camera)
}

/// A rotation rate `w` (rad/s, axis times rate) of the field `field`, or `Err` at it when
/// it is longer than [`crate::scene::MAX_ANGULAR_VELOCITY`].
fn rotation_rate(w: &At<V3>, field: &str) -> Result<DVec3, Failure> {
    let rate = v(w.value).length();
    if rate.is_finite() && rate <= crate::scene::MAX_ANGULAR_VELOCITY {
        return Ok(v(w.value));
    }
    // A vector whose length overflows is shown by its largest entry.
    let got = if rate.is_finite() {
        cov_core::num(rate)
    } else {
        format!("more than {}", cov_core::num(v(w.value).abs().max_element()))
    };
    Err((
        w.ordinal,
        format!(
            "{field} must be at most {} rad/s (a thousand turns a second) in length, got {got}",
            cov_core::num(crate::scene::MAX_ANGULAR_VELOCITY),
        ),
    ))
}

/// The colour `field` of the texture `name`: a reflectance, at most 1 per channel (`Err`
/// at the colour).
fn reflectance(c: &At<Rgb>, name: &At<String>, field: &str) -> Result<DVec3, Failure> {
    let v = DVec3::from_array(c.value.0);
    if v.max_element() > 1.0 {
        return Err((
            c.ordinal,
            format!(
                "texture `{}`: colour `{field}` above 1 reflects more than it receives",
                crate::echo(&name.value)
            ),
        ));
    }
    Ok(v)
}

/// Largest side of a generated texture, by default (texels).
pub const DEFAULT_TEXTURE_SIZE: u32 = 1024;
/// Most texels over all the textures of a scene (used or not): two textures of the
/// largest side ([`crate::texture::MAX_TEXTURE_SIDE`]), about 1.4 GB with their pyramids.
/// Each texture alone is bounded by its side; without this, a few kilobytes of scene
/// asked for tens of gigabytes.
pub const MAX_SCENE_TEXELS: usize = 2 * 4096 * 4096;
/// Narrowest lobe a material may have, as an angular std (rad): GGX `alpha` at least
/// this, Phong `exponent` at most its inverse square (1e12). f64 resolves a direction near
/// the normal to about √ε ≈ 1.5e-8 rad (the cosine of a smaller angle rounds to 1), and the
/// BRDF's half-vector is recomputed from the two directions, so a lobe within a few times
/// that evaluates to nothing where it should peak: a new user's GGX floor of `alpha`
/// 1e-10, or Phong of exponent 1e20, lost its lights' reflections without a word. 1e-6
/// leaves a margin of about 70.
pub const MIN_LOBE_WIDTH: f64 = 1e-6;
/// Largest Phong exponent: a lobe of angular std [`MIN_LOBE_WIDTH`] (`1/√e`), 1e12.
pub const MAX_PHONG_EXPONENT: f64 = 1.0 / (MIN_LOBE_WIDTH * MIN_LOBE_WIDTH);
/// Largest OBJ file read (bytes): about 70 bytes a triangle for [`MAX_TRIANGLES`].
pub const MAX_OBJ_BYTES: u64 = 350 << 20;

/// `Err` at `at` if the scene's textures up to `name` hold more than
/// [`MAX_SCENE_TEXELS`] (`texels`); `made`: counted once the texture was made (an
/// image, whose size its file tells), not before.
fn too_many_texels(texels: usize, name: &At<String>, at: u32, made: bool) -> Result<(), Failure> {
    if texels <= MAX_SCENE_TEXELS {
        return Ok(());
    }
    Err((
        at,
        format!(
            "texture `{}` {} the scene's textures to {texels} texels; a scene holds at most {MAX_SCENE_TEXELS} (two of 4096², about 1.4 GB with their pyramids)",
            crate::echo(&name.value),
            if made { "brings" } else { "would bring" }
        ),
    ))
}

/// The bytes of `path`, a `what` file (scene, OBJ), if at most `limit`: a file's length is
/// checked first, and the read stops one byte past `limit` whatever the length says (a
/// device or a pipe reports none).
///
/// # Errors
/// An unreadable file, or one longer than `limit`, in one line.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, String> {
    use std::io::Read;
    crate::error::within_length(path, limit, what)?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(limit + 1).read_to_end(&mut bytes))
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!(
            "the file is more than {limit} bytes; {what} files are read up to that"
        ));
    }
    Ok(bytes)
}

/// The textures, and their names, in the order of the file's map.
fn textures(desc: &SceneFile, dir: &Path) -> Result<(Vec<TextureMap>, Vec<String>), Failure> {
    let mut maps = Vec::new();
    let mut names = Vec::new();
    // The procedural textures' texels are known before any is made: too many, and none is.
    let mut texels = 0usize;
    for (name, t) in &desc.textures {
        let (side, at) = match &t.value {
            TextureDesc::Image { .. } => (0, t.ordinal),
            TextureDesc::Checker { size, .. }
            | TextureDesc::Stripes { size, .. }
            | TextureDesc::Noise { size, .. } => match size {
                Some(s) => (s.value.min(crate::texture::MAX_TEXTURE_SIDE), s.ordinal),
                None => (DEFAULT_TEXTURE_SIZE, t.ordinal),
            },
        };
        texels += side as usize * side as usize;
        too_many_texels(texels, name, at, false)?;
    }
    // Then each image's, on top, as it is decoded.
    for (name, t) in &desc.textures {
        let rep = |r: &Option<At<crate::scene::Repeat>>| {
            r.as_ref()
                .map_or(DVec2::ONE, |r| DVec2::new(r.value.0, r.value.1))
        };
        let size = |s: &Option<At<u32>>| s.as_ref().map_or(DEFAULT_TEXTURE_SIZE, |s| s.value);
        let says = |e: &dyn std::fmt::Display| format!("texture `{}`: {e}", crate::echo(&name.value));
        // A procedural texture: the map, and where each parameter it may refuse is written
        // (`None`: left at its default, said at the texture's name).
        let (made, own, sz, repeat) = match &t.value {
            TextureDesc::Image { file, repeat } => {
                let map = TextureMap::load(&dir.join(&file.value), rep(repeat))
                    .map_err(|e| (file.ordinal, says(&e)))?;
                let (w, h) = map.size();
                texels += w * h;
                too_many_texels(texels, name, file.ordinal, true)?;
                maps.push(map);
                names.push(name.value.clone());
                continue;
            }
            TextureDesc::Checker {
                checks,
                a,
                b,
                size: sz,
                repeat,
            } => (
                TextureMap::checker(
                    checks.value,
                    reflectance(a, name, "a")?,
                    reflectance(b, name, "b")?,
                    size(sz),
                    rep(repeat),
                ),
                [("checks", Some(checks.ordinal)), ("", None)],
                sz,
                repeat,
            ),
            TextureDesc::Stripes {
                count,
                duty,
                a,
                b,
                size: sz,
                repeat,
            } => (
                TextureMap::stripes(
                    count.value,
                    duty.as_ref().map_or(0.5, |d| d.value.0),
                    reflectance(a, name, "a")?,
                    reflectance(b, name, "b")?,
                    size(sz),
                    rep(repeat),
                ),
                [
                    ("count", Some(count.ordinal)),
                    ("duty", duty.as_ref().map(|d| d.ordinal)),
                ],
                sz,
                repeat,
            ),
            TextureDesc::Noise {
                cells,
                a,
                b,
                seed,
                size: sz,
                repeat,
            } => (
                TextureMap::noise(
                    cells.value,
                    seed.unwrap_or(0),
                    reflectance(a, name, "a")?,
                    reflectance(b, name, "b")?,
                    size(sz),
                    rep(repeat),
                ),
                [("cells", Some(cells.ordinal)), ("", None)],
                sz,
                repeat,
            ),
        };
        let map = made.map_err(|e| {
            let written = [
                ("size", sz.as_ref().map(|s| s.ordinal)),
                ("repeat", repeat.as_ref().map(|r| r.ordinal)),
            ];
            let place = own
                .iter()
                .chain(&written)
                .find(|(n, _)| *n == e.name)
                .and_then(|(_, p)| *p);
            (place.unwrap_or(t.ordinal), says(&e))
        })?;
        maps.push(map);
        names.push(name.value.clone());
    }
    Ok((maps, names))
}

/// Materials, their names, and their textures' indices.
type Materials = (Vec<Material>, Vec<String>, Vec<Option<u32>>);

/// The materials, their names and their textures, in the order of the file's map.
fn materials(desc: &SceneFile, textures: &Names<'_>) -> Result<Materials, Failure> {
    let mut materials = Vec::new();
    let mut names = Vec::new();
    let mut texs = Vec::new();
    for (name, m) in &desc.materials {
        let (mat, texture) = match m {
            MaterialDesc::Diffuse { albedo, texture } => (
                Material::Diffuse {
                    albedo: DVec3::from_array(albedo.value.0),
                },
                texture,
            ),
            MaterialDesc::Phong {
                albedo,
                exponent,
                texture,
            } => (
                Material::Phong {
                    albedo: DVec3::from_array(albedo.value.0),
                    exponent: exponent.value.0,
                },
                texture,
            ),
            MaterialDesc::Ggx {
                albedo,
                alpha,
                texture,
            } => (
                Material::Ggx {
                    albedo: DVec3::from_array(albedo.value.0),
                    alpha: alpha.value.0,
                },
                texture,
            ),
        };
        let at = match m {
            MaterialDesc::Diffuse { albedo, .. }
            | MaterialDesc::Phong { albedo, .. }
            | MaterialDesc::Ggx { albedo, .. } => albedo.ordinal,
        };
        let albedo = mat.albedo();
        if albedo.max_element() > 1.0 {
            return Err((
                at,
                format!(
                    "material `{}`: an albedo above 1 reflects more than it receives",
                    crate::echo(&name.value)
                ),
            ));
        }
        // A lobe narrower than f64 resolves, at the parameter that makes it so.
        let narrow = match m {
            MaterialDesc::Ggx { alpha, .. } if alpha.value.0 < MIN_LOBE_WIDTH => Some((
                alpha.ordinal,
                format!(
                    "`alpha` = {} is below {MIN_LOBE_WIDTH:e}",
                    cov_core::num(alpha.value.0)
                ),
            )),
            MaterialDesc::Phong { exponent, .. } if exponent.value.0 > MAX_PHONG_EXPONENT => Some((
                exponent.ordinal,
                format!(
                    "`exponent` = {} is above {MAX_PHONG_EXPONENT:e}",
                    cov_core::num(exponent.value.0)
                ),
            )),
            _ => None,
        };
        if let Some((ordinal, what)) = narrow {
            return Err((
                ordinal,
                format!(
                    "material `{}`: {what}, a lobe narrower than f64 resolves directions (its reflections would vanish)",
                    crate::echo(&name.value)
                ),
            ));
        }
        texs.push(texture.as_ref().map(|t| textures.index(t)).transpose()?);
        materials.push(mat);
        names.push(name.value.clone());
    }
    Ok((materials, names, texs))
}

/// The names of a scene's materials or textures, for looking up the ones referred to.
struct Names<'a>(&'a [String], &'static str);

impl Names<'_> {
    /// The index of the entry `name` refers to.
    fn index(&self, name: &At<String>) -> Result<u32, Failure> {
        self.0
            .iter()
            .position(|n| *n == name.value)
            .map(|i| i as u32)
            .ok_or_else(|| {
                let known = if self.0.is_empty() {
                    "none".to_string()
                } else {
                    self.0
                        .iter()
                        .map(|n| crate::echo(n))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                (
                    name.ordinal,
                    format!(
                        "unknown {} `{}`; the scene defines: {known}",
                        self.1,
                        crate::echo(&name.value)
                    ),
                )
            })
    }
}

/// The lights; emitters are also geometry (the camera sees them), added to `prims`, their
/// boxes counted in `boxes`.
fn lights(desc: &SceneFile, prims: &mut Vec<Prim>, boxes: &mut SharedBoxes) -> Result<Vec<Light>, Failure> {
    let mut lights = Vec::new();
    for l in &desc.lights.value {
        let index = lights.len() as u32;
        let from = prims.len();
        let place = match l {
            LightDesc::Rect { corner, .. } => corner.ordinal,
            LightDesc::Sphere { center, .. } => center.ordinal,
        };
        match l {
            LightDesc::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
            } => {
                let (c0, eu, ev) = (v(corner.value), v(edge_u.value), v(*edge_v));
                let cr = eu.cross(ev);
                if cr.length() <= 0.0 {
                    return Err((edge_u.ordinal, no_area("a Rect light's")));
                }
                lights.push(Light::Rect {
                    corner: c0,
                    eu,
                    ev,
                    n: cr.normalize(),
                    area: cr.length(),
                    radiance: DVec3::from_array(radiance.0),
                });
                for tri in quad_triangles(c0, eu, ev) {
                    prims.push(Prim {
                        shape: Shape::triangle(tri, None, None),
                        velocity: DVec3::ZERO,
                        material: u32::MAX,
                        light: Some(index),
                    });
                }
            }
            LightDesc::Sphere {
                center,
                radius,
                radiance,
            } => {
                let radius = radius.value;
                lights.push(Light::Sphere {
                    center: v(center.value),
                    radius: radius.0,
                    radiance: DVec3::from_array(radiance.0),
                });
                prims.push(Prim {
                    shape: Shape::Sphere {
                        center: v(center.value),
                        radius: radius.0,
                        spin: DVec3::ZERO,
                    },
                    velocity: DVec3::ZERO,
                    material: u32::MAX,
                    light: Some(index),
                });
            }
        }
        // Lights do not move: their reach is the same at every instant.
        within_reach(prims, from, 0.0, 0.0, place, "light")?;
        boxes.add(prims, from, (0.0, 0.0), (place, true))?;
    }
    if lights.is_empty() {
        return Err((
            desc.lights.ordinal,
            "the scene has no light (`lights: []`)".into(),
        ));
    }
    Ok(lights)
}

/// `Err` at the size if a sphere's radius or a quad's or rect light's edge is below
/// [`crate::geometry::min_size`] where it is placed (checked after the parallel edges and
/// the reach of every shape, which are reported first).
fn large_enough(desc: &SceneFile) -> Result<(), Failure> {
    let v = |a: V3| DVec3::from_array(a.0);
    // Each size with where it is placed and where it is written.
    let mut sizes: Vec<(&str, f64, DVec3, u32)> = Vec::new();
    // A parallelogram's two edges, at its first edge's position; the largest component
    // where the length underflows (an edge of 1e-300 m).
    let sphere = |center: &V3, radius: &At<crate::scene::Positive>| {
        ("sphere's radius", radius.value.0, v(*center), radius.ordinal)
    };
    let edges = |what, corner: V3, eu: &At<V3>, ev: V3| {
        [v(eu.value), v(ev)].map(|e| (what, e.length().max(e.abs().max_element()), v(corner), eu.ordinal))
    };
    for l in &desc.lights.value {
        match l {
            LightDesc::Rect {
                corner,
                edge_u,
                edge_v,
                ..
            } => sizes.extend(edges("Rect light's edge", corner.value, edge_u, *edge_v)),
            LightDesc::Sphere { center, radius, .. } => sizes.push(sphere(&center.value, radius)),
        }
    }
    for s in &desc.shapes.value {
        match s {
            ShapeDesc::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => sizes.extend(edges("Quad's edge", corner.value, edge_u, *edge_v)),
            ShapeDesc::Sphere { center, radius, .. } => sizes.push(sphere(&center.value, radius)),
            ShapeDesc::Mesh { .. } => {}
        }
    }
    for (what, size, at, ordinal) in sizes {
        let least = crate::geometry::min_size(at);
        if size < least {
            return Err((
                ordinal,
                format!(
                    "this {what} is {} m; {}: smaller, rays leaving it skip it and its arithmetic loses its digits",
                    cov_core::num(size),
                    at_least(least)
                ),
            ));
        }
    }
    Ok(())
}

/// The words of a size check that failed: the least size `least` (m,
/// [`crate::geometry::min_size`]) and how it is made.
fn at_least(least: f64) -> String {
    format!(
        "at least {} m here ({:e} of 1 m + its distance along an axis from the origin)",
        cov_core::approx(least),
        crate::geometry::MIN_SIZE
    )
}

/// What is said of a parallelogram (`whose`: "a Quad's", "a Rect light's") whose edges
/// span no area.
fn no_area(whose: &str) -> String {
    format!("{whose} `edge_u` and `edge_v` span no area (one is zero, or they are parallel)")
}

/// `Err` at `ordinal` if a primitive of `prims[from..]` (a `what`: sphere, quad, mesh,
/// light) reaches past [`MAX_COORD`] over the shutter `t0..t1`.
fn within_reach(
    prims: &[Prim],
    from: usize,
    t0: f64,
    t1: f64,
    ordinal: u32,
    what: &str,
) -> Result<(), Failure> {
    let reach = crate::geometry::reach(&prims[from..], t0, t1);
    if reach <= MAX_COORD {
        return Ok(());
    }
    Err((ordinal, beyond_reach(what, reach)))
}

/// What [`within_reach`] says of a `what` that reaches `reach` m from the origin.
fn beyond_reach(what: &str, reach: f64) -> String {
    format!(
        "this {what} reaches {} m from the origin (over the shutter, if it moves): the renderer's single-precision BVH holds ±{MAX_COORD:e} m",
        cov_core::approx(reach)
    )
}

/// How many primitives hold each bounding box so far ([`MAX_SHARED_BOX`]).
#[derive(Default)]
struct SharedBoxes(HashMap<[u32; 6], u32>);

impl SharedBoxes {
    /// Counts the boxes of `prims[from..]`, the primitives of one shape or light, over the
    /// shutter; `Err` at `ordinal` when one is held by more than [`MAX_SHARED_BOX`]. With
    /// `per_shape`, a box the shape's own primitives share counts once (a quad's two
    /// triangles; the user counts the copies of the quad, and the BVH builds 512 equal
    /// boxes in milliseconds); a mesh's triangles count each, as the file may repeat one.
    fn add(
        &mut self,
        prims: &[Prim],
        from: usize,
        (t0, t1): (f64, f64),
        (ordinal, per_shape): (u32, bool),
    ) -> Result<(), Failure> {
        let mut keys: Vec<[u32; 6]> = prims[from..].iter().map(|p| p.box_key(t0, t1)).collect();
        if per_shape {
            keys.sort_unstable();
            keys.dedup();
        }
        for key in keys {
            let n = self.0.entry(key).or_insert(0);
            *n += 1;
            if *n > MAX_SHARED_BOX {
                return Err((
                    ordinal,
                    format!(
                        "more than {MAX_SHARED_BOX} shapes, lights or mesh triangles lie exactly on one another here (copies of one shape in one place): only one of them can be seen; remove the copies"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The shapes, added to `prims`; whether any of them moves. Each must stay within
/// [`MAX_COORD`] over the shutter `(t0, t1)`, and no box may be shared by more than
/// [`MAX_SHARED_BOX`] primitives (`boxes`, the lights' counted).
fn shapes(
    desc: &SceneFile,
    names: &Names<'_>,
    dir: &Path,
    prims: &mut Vec<Prim>,
    (t0, t1): (f64, f64),
    boxes: &mut SharedBoxes,
    warnings: &mut Vec<Failure>,
) -> Result<bool, Failure> {
    let mut triangles = 0usize;
    let mut any_velocity = false;
    // What the meshes may take: checked as they are placed, so that a scene of many
    // placements that the process cannot hold is refused, not aborted half way.
    let memory = crate::memory::available_memory();
    // Each OBJ file is read once, however many meshes place it.
    let mut read: HashMap<std::path::PathBuf, Obj> = HashMap::new();
    if desc.shapes.value.is_empty() {
        warnings.push((
            desc.shapes.ordinal,
            "`shapes` is empty: the camera sees the lights alone, and their light falls on nothing".into(),
        ));
    }
    for s in &desc.shapes.value {
        let from = prims.len();
        let (material, velocity) = match s {
            ShapeDesc::Sphere {
                material, velocity, ..
            }
            | ShapeDesc::Quad {
                material, velocity, ..
            }
            | ShapeDesc::Mesh {
                material, velocity, ..
            } => (names.index(material)?, velocity.map_or(DVec3::ZERO, v)),
        };
        any_velocity |= velocity != DVec3::ZERO;
        let mut push = |shape| {
            prims.push(Prim {
                shape,
                velocity,
                material,
                light: None,
            })
        };
        match s {
            ShapeDesc::Sphere {
                center, radius, spin, ..
            } => {
                let spin = match spin {
                    Some(w) => rotation_rate(w, "spin")?,
                    None => DVec3::ZERO,
                };
                push(Shape::Sphere {
                    center: v(center.value),
                    radius: radius.value.0,
                    spin,
                })
            }
            ShapeDesc::Quad {
                corner,
                edge_u,
                edge_v,
                ..
            } => {
                let (eu, ev) = (v(edge_u.value), v(*edge_v));
                if eu.cross(ev).length() <= 0.0 {
                    return Err((edge_u.ordinal, no_area("a Quad's")));
                }
                for (tri, uv) in quad_triangles(v(corner.value), eu, ev).into_iter().zip(QUAD_UV) {
                    push(Shape::triangle(tri, None, Some(uv)));
                }
            }
            ShapeDesc::Mesh {
                obj,
                translate,
                scale,
                rotate,
                material,
                ..
            } => {
                let in_obj = |e: String| (obj.ordinal, format!("OBJ `{}`: {e}", crate::echo(&obj.value)));
                let Obj {
                    triangles: tris,
                    usemtl,
                } = match read.entry(dir.join(&obj.value)) {
                    Entry::Occupied(e) => e.into_mut(),
                    Entry::Vacant(e) => {
                        let tris = load_obj(e.key(), MAX_TRIANGLES - triangles).map_err(in_obj)?;
                        e.insert(tris)
                    }
                };
                if usemtl.len() > 1 {
                    let listed: Vec<String> = usemtl
                        .iter()
                        .take(4)
                        .map(|n| format!("`{}`", crate::echo(n)))
                        .collect();
                    let more = if usemtl.len() > 4 { ", …" } else { "" };
                    warnings.push((
                        obj.ordinal,
                        format!(
                            "OBJ `{}` names {} materials with `usemtl` ({}{more}); a mesh has one material, so all of it is `{}` (one OBJ file per material, one `Mesh` each, gives each its own)",
                            crate::echo(&obj.value),
                            usemtl.len(),
                            listed.join(", "),
                            crate::echo(&material.value)
                        ),
                    ));
                }
                if tris.len() > MAX_TRIANGLES - triangles {
                    return Err(in_obj(too_many_triangles()));
                }
                triangles += tris.len();
                let need = triangles as u64 * BYTES_PER_TRIANGLE;
                if let Some(available) = memory
                    && need > available
                {
                    return Err((
                        obj.ordinal,
                        format!(
                            "the meshes placed up to here are {triangles} triangles, which need about {:.2} GB ({BYTES_PER_TRIANGLE} bytes a triangle at the peak of loading and rendering), and {:.2} GB are available to this process",
                            need as f64 / 1e9,
                            available as f64 / 1e9
                        ),
                    ));
                }
                let (t, sc) = (translate.map_or(DVec3::ZERO, v), scale.map_or(1.0, |s| s.0));
                let placed: Vec<ObjTriangle> = match rotate.map(v).filter(|r| *r != DVec3::ZERO) {
                    None => tris
                        .iter()
                        .map(|&(p, n, uv)| (p.map(|q| q * sc + t), n, uv))
                        .collect(),
                    Some(deg) => {
                        let r = glam::DQuat::from_euler(
                            glam::EulerRot::ZYX,
                            deg.z.to_radians(),
                            deg.y.to_radians(),
                            deg.x.to_radians(),
                        );
                        tris.iter()
                            .map(|&(p, n, uv)| (p.map(|q| r * (q * sc) + t), n.map(|n| n.map(|m| r * m)), uv))
                            .collect()
                    }
                };
                // As a sphere's radius or a quad's edge: the mesh's extent, placed, against
                // the least size where it is.
                let (lo, hi) = placed
                    .iter()
                    .flat_map(|(p, _, _)| p.iter())
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &q| {
                        (lo.min(q), hi.max(q))
                    });
                // Placed out of reach, it is said so (its size would be judged against the
                // least size out there instead, which says nothing of the `translate`).
                let far = lo.abs().max(hi.abs()).max_element();
                if far > MAX_COORD {
                    return Err((obj.ordinal, beyond_reach("mesh", far)));
                }
                let (size, least) = (
                    (hi - lo).max_element(),
                    crate::geometry::min_size(0.5 * (lo + hi)),
                );
                if size.is_nan() || size < least {
                    return Err((
                        obj.ordinal,
                        format!(
                            "this mesh is {} m across after its `scale`; {}",
                            cov_core::approx(size),
                            at_least(least)
                        ),
                    ));
                }
                for (p, n, uv) in placed {
                    push(Shape::triangle(p, n, uv));
                }
            }
        }
        // Where the shape is placed: a sphere's centre, a quad's corner, a mesh's file.
        let (ordinal, what) = match s {
            ShapeDesc::Mesh { obj, .. } => (obj.ordinal, "mesh"),
            ShapeDesc::Sphere { center, .. } => (center.ordinal, "sphere"),
            ShapeDesc::Quad { corner, .. } => (corner.ordinal, "quad"),
        };
        within_reach(prims, from, t0, t1, ordinal, what)?;
        let per_shape = !matches!(s, ShapeDesc::Mesh { .. });
        boxes.add(prims, from, (t0, t1), (ordinal, per_shape))?;
    }
    Ok(any_velocity)
}

fn quad_triangles(c: DVec3, eu: DVec3, ev: DVec3) -> [[DVec3; 3]; 2] {
    [[c, c + eu, c + eu + ev], [c, c + eu + ev, c + ev]]
}

/// The texture coordinates of [`quad_triangles`]' vertices: `u` along `edge_u`, `v` along
/// `edge_v`, 0 to 1.
const QUAD_UV: [[DVec2; 3]; 2] = [
    [DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0)],
    [DVec2::new(0.0, 0.0), DVec2::new(1.0, 1.0), DVec2::new(0.0, 1.0)],
];

type ObjTriangle = ([DVec3; 3], Option<[DVec3; 3]>, Option<[DVec2; 3]>);

/// An OBJ file as a mesh reads it: its triangles, and the distinct names its `usemtl`
/// lines give (which the mesh does not read: the scene gives it one material).
struct Obj {
    triangles: Vec<ObjTriangle>,
    usemtl: Vec<String>,
}

/// Peak resident memory of a scene's meshes per triangle (bytes): the slope of the peak
/// resident size (`/usr/bin/time -v`) between renders of 100 and 400 placements of
/// `examples/scenes/torus.obj` (2,304 triangles each) at 32×24 px, 1 spp: 929 bytes
/// (2026-12-02), rounded up. [`MAX_TRIANGLES`] of them take about 5 GB.
const BYTES_PER_TRIANGLE: u64 = 1000;

/// The message of a scene past [`MAX_TRIANGLES`], whether one file or its placements
/// bring it there.
fn too_many_triangles() -> String {
    format!("more than {MAX_TRIANGLES} triangles in the scene; meshes are read up to that")
}

/// The line (from 1) of the first vertex statement `v x y z` of an OBJ's `text` whose
/// coordinates are not all finite as the reader stores them (f32: `1e39` is infinite), so
/// that the error names it in a file of a million lines.
fn first_infinite_vertex(text: &str) -> Option<usize> {
    text.lines().enumerate().find_map(|(i, l)| {
        let mut words = l.split_whitespace();
        (words.next() == Some("v")
            && words
                .take(3)
                .any(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite())))
        .then_some(i + 1)
    })
}

/// Triangles (with vertex normals and texture coordinates when the file has them) of an
/// OBJ file, at most `limit`, and the names of its `usemtl` statements.
fn load_obj(path: &Path, limit: usize) -> Result<Obj, String> {
    crate::error::regular_file(path)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let bytes = read_bounded(path, MAX_OBJ_BYTES, "OBJ").map_err(|e| cov_core::one_line(&e))?;
    // A byte-order mark is not an OBJ statement, and a byte that is not UTF-8 (a Latin-1
    // letter in a comment or a name) stops the reader: both are read past, the second as
    // U+FFFD, which no number or index contains.
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(&bytes);
    let text = without_trailing_comments(&String::from_utf8_lossy(bytes)).into_owned();
    if text.contains('\r') && !text.contains('\n') {
        return Err(
            "its lines end with a lone carriage return (classic Mac OS); save it with LF or CRLF line ends"
                .into(),
        );
    }
    // Materials come from the scene: an `mtllib` line is not followed (it could name a
    // device or a pipe).
    let no_materials = |_: &Path| Ok((Vec::new(), Default::default()));
    let (models, _materials) =
        tobj::load_obj_buf(&mut text.as_bytes(), &opts, no_materials).map_err(|e| {
            match obj_error_line(&text, e, &opts) {
                Some((line, None)) => format!("line {line}: {}", obj_error(e)),
                Some((line, Some(why))) => format!("line {line}: {why}"),
                None => obj_error(e),
            }
        })?;
    let mut out = Vec::new();
    for m in &models {
        let mesh = &m.mesh;
        let get = |data: &[f32], i: u32| -> Option<DVec3> {
            let i = 3 * i as usize;
            let a = data.get(i..i + 3)?;
            let p = DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64);
            p.is_finite().then_some(p)
        };
        for f in mesh.indices.chunks_exact(3) {
            if out.len() >= limit {
                return Err(too_many_triangles());
            }
            // The reader checked every index against the file's vertices.
            let bad = || {
                let what = "a vertex (`v`) has a coordinate that is not a finite 32-bit number (NaN, inf, or past ±3.4e38: OBJ coordinates are read in single precision)";
                match first_infinite_vertex(&text) {
                    Some(line) => format!("line {line}: {what}"),
                    None => what.to_string(),
                }
            };
            let p = [
                get(&mesh.positions, f[0]).ok_or_else(bad)?,
                get(&mesh.positions, f[1]).ok_or_else(bad)?,
                get(&mesh.positions, f[2]).ok_or_else(bad)?,
            ];
            let n = if mesh.normals.is_empty() {
                None
            } else {
                match (
                    get(&mesh.normals, f[0]),
                    get(&mesh.normals, f[1]),
                    get(&mesh.normals, f[2]),
                ) {
                    (Some(a), Some(b), Some(c)) => Some([
                        a.normalize_or_zero(),
                        b.normalize_or_zero(),
                        c.normalize_or_zero(),
                    ]),
                    _ => None,
                }
            };
            let uv = if mesh.texcoords.is_empty() {
                None
            } else {
                let t = |i: u32| -> Option<DVec2> {
                    let i = 2 * i as usize;
                    let a = mesh.texcoords.get(i..i + 2)?;
                    let c = DVec2::new(a[0] as f64, a[1] as f64);
                    c.is_finite().then_some(c)
                };
                match (t(f[0]), t(f[1]), t(f[2])) {
                    (Some(a), Some(b), Some(c)) => Some([a, b, c]),
                    _ => None,
                }
            };
            out.push((p, n, uv));
        }
    }
    if out.is_empty() {
        return Err("the file has no triangles".into());
    }
    if out
        .iter()
        .all(|(p, _, _)| (p[1] - p[0]).cross(p[2] - p[0]) == DVec3::ZERO)
    {
        return Err(
            "every triangle of the file has zero area (a face of two points, or three in a line)".into(),
        );
    }
    // The reader keeps no material name without a material library, which is not
    // followed: the statements' names, in the order they first appear.
    let mut usemtl: Vec<String> = Vec::new();
    for line in text.lines() {
        if let Some(("usemtl", name)) = line.trim_start().split_once(char::is_whitespace) {
            let name = name.trim();
            if !name.is_empty() && !usemtl.iter().any(|n| n == name) {
                usemtl.push(name.to_string());
            }
        }
    }
    Ok(Obj {
        triangles: out,
        usemtl,
    })
}

/// An OBJ's `text` with a comment after a vertex, normal, texture coordinate or face
/// statement (`v 0 1 0 # top`) taken off, which the reader would read as more numbers;
/// every line stays where it was.
fn without_trailing_comments(text: &str) -> std::borrow::Cow<'_, str> {
    let statement = |l: &str| matches!(l.split_whitespace().next(), Some("v" | "vt" | "vn" | "f"));
    if !text.lines().any(|l| statement(l) && l.contains('#')) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len());
    for piece in text.split_inclusive('\n') {
        let (line, end) = match piece.strip_suffix('\n') {
            Some(l) => (l, "\n"),
            None => (piece, ""),
        };
        match line.find('#') {
            Some(k) if statement(line) => {
                out.push_str(&line[..k]);
                // A CRLF line keeps its carriage return.
                if line.ends_with('\r') {
                    out.push('\r');
                }
            }
            _ => out.push_str(line),
        }
        out.push_str(end);
    }
    std::borrow::Cow::Owned(out)
}

/// The line (from 1) of the first statement of an OBJ's `text` that the reader refuses
/// with `e` (the reader does not give its line), and what to say of it instead of
/// [`obj_error`]'s words, if anything; `None` when no line is found.
///
/// - A statement refused for its own text (a vertex, normal, texture coordinate or face
///   that does not parse, a weight of 0): the first statement of that kind that the
///   reader, given that line alone with the same `opts`, refuses with the same error.
/// - A face that refers to an element the file does not have: the first face with an
///   index beyond the vertices, texture coordinates or normals stated before it
///   (positive indices count from 1, negative ones back from the last).
fn obj_error_line(
    text: &str,
    e: tobj::LoadError,
    opts: &tobj::LoadOptions,
) -> Option<(usize, Option<String>)> {
    use tobj::LoadError as E;
    let no_materials = |_: &Path| Ok((Vec::new(), Default::default()));
    let alone = |line: &str| tobj::load_obj_buf(&mut line.as_bytes(), opts, no_materials).err() == Some(e);
    let keyword = match e {
        E::PositionParseError | E::ScalingByZeroError | E::ColorParseError => "v",
        E::NormalParseError => "vn",
        E::TexcoordParseError => "vt",
        E::FaceParseError | E::InvalidPolygon => "f",
        E::FaceVertexOutOfBounds | E::FaceTexCoordOutOfBounds | E::FaceNormalOutOfBounds => "",
        _ => return None,
    };
    if !keyword.is_empty() {
        return text.lines().enumerate().find_map(|(i, l)| {
            (l.split_whitespace().next() == Some(keyword) && alone(l)).then_some((i + 1, None))
        });
    }
    // Which part of a face's `v/vt/vn` entries is out of bounds. The reader resolves a
    // negative index against the elements stated so far and checks the result when it
    // closes the object (at the next `o` or `g` statement, or the file's end), against the
    // elements stated by then; an index that resolves to −1 is "none" for `vt` and `vn`.
    let part = match e {
        E::FaceVertexOutOfBounds => 0,
        E::FaceTexCoordOutOfBounds => 1,
        _ => 2,
    };
    fn first(l: &str) -> Option<&str> {
        l.split_whitespace().next()
    }
    let kind = |w: Option<&str>| match w {
        Some("v") => Some(0),
        Some("vt") => Some(1),
        Some("vn") => Some(2),
        _ => None,
    };
    // The count of the part's elements when each line's object closes: `before[i]` of
    // the lines before line `i`, and the count before the next `o` or `g` line.
    let lines: Vec<&str> = text.lines().collect();
    let mut before = Vec::with_capacity(lines.len() + 1);
    before.push(0i64);
    for l in &lines {
        let n = before.last().copied().unwrap_or(0);
        before.push(n + i64::from(kind(first(l)) == Some(part)));
    }
    let mut at_close = vec![0i64; lines.len()];
    let mut close = before[lines.len()];
    for (i, l) in lines.iter().enumerate().rev() {
        if matches!(first(l), Some("o" | "g")) {
            close = before[i];
        }
        at_close[i] = close;
    }
    let mut so_far = 0i64;
    for (i, l) in lines.iter().enumerate() {
        let mut words = l.split_whitespace();
        match words.next() {
            w if kind(w) == Some(part) => so_far += 1,
            Some("f") => {
                let beyond = words.find_map(|w| {
                    let k = w.split('/').nth(part).and_then(|t| t.parse::<i64>().ok())?;
                    let resolved = if k < 0 { so_far + k } else { k - 1 };
                    let none = part > 0 && resolved == -1;
                    (!none && (resolved < 0 || resolved >= at_close[i])).then_some(resolved)
                });
                if let Some(r) = beyond {
                    // An element the file states only after the object closed.
                    let later = r >= 0 && r < before[lines.len()];
                    let what = ["vertex (`v`)", "texture coordinate (`vt`)", "normal (`vn`)"][part];
                    let why = later.then(|| {
                        format!(
                            "a face (`f`) refers to a {what} stated only after its object ends (at the next `o` or `g` statement); state it before"
                        )
                    });
                    return Some((i + 1, why));
                }
            }
            _ => {}
        }
    }
    None
}

/// The reader's error in words that say which statement of the file is wrong (the reader
/// does not give its line).
fn obj_error(e: tobj::LoadError) -> String {
    use tobj::LoadError as E;
    match e {
        E::PositionParseError => "a vertex (`v`) whose coordinates are not three or four numbers".into(),
        E::NormalParseError => "a normal (`vn`) whose coordinates are not three numbers".into(),
        E::TexcoordParseError => "a texture coordinate (`vt`) that is not one to three numbers".into(),
        E::FaceParseError => "a face (`f`) whose entries are not `v`, `v/vt`, `v//vn` or `v/vt/vn` indices".into(),
        E::FaceVertexOutOfBounds => "a face (`f`) refers to a vertex (`v`) the file does not have (indices count from 1, or from −1 backwards)".into(),
        E::FaceTexCoordOutOfBounds => "a face (`f`) refers to a texture coordinate (`vt`) the file does not have".into(),
        E::FaceNormalOutOfBounds => "a face (`f`) refers to a normal (`vn`) the file does not have".into(),
        E::ScalingByZeroError => "a vertex (`v`) with a weight `w` of 0".into(),
        E::ColorParseError => {
            "a vertex (`v`) whose numbers are not three or four coordinates, or three and a colour of three".into()
        }
        E::FaceColorOutOfBounds => {
            "some vertices (`v`) have a colour and others none: give every vertex one, or none".into()
        }
        E::InvalidPolygon => "a face (`f`) without vertices".into(),
        e => cov_core::one_line(&e.to_string()),
    }
}

/// Frames per second of an animation when the scene does not say.
pub const DEFAULT_FRAME_RATE: f64 = 24.0;
/// Highest animation frame ([`World::at_frame`]): over an hour at 240 frames per second.
pub const MAX_FRAME: u32 = 1_000_000;

/// The files a scene reads besides itself (texture images, OBJ meshes), resolved against
/// `dir`, each once, in the order the scene first names them.
fn input_files(desc: &SceneFile, dir: &Path) -> Vec<std::path::PathBuf> {
    let mut seen = HashSet::new();
    let textures = desc.textures.values().filter_map(|t| match &t.value {
        TextureDesc::Image { file, .. } => Some(dir.join(&file.value)),
        _ => None,
    });
    let meshes = desc.shapes.value.iter().filter_map(|s| match s {
        ShapeDesc::Mesh { obj, .. } => Some(dir.join(&obj.value)),
        _ => None,
    });
    textures
        .chain(meshes)
        .filter(|p| seen.insert(p.clone()))
        .collect()
}

/// FNV-1a of `text` and of the bytes of `files` (a file that cannot be read adds its
/// name): [`World::fingerprint`]. The files were read when the scene was built, within
/// their size limits.
fn fingerprint(text: &str, files: &[std::path::PathBuf]) -> u64 {
    use std::hash::Hasher;
    let mut h = fnv::FnvHasher::default();
    h.write(text.as_bytes());
    for f in files {
        h.write(&[0xff]);
        // In chunks: the hash of the bytes as one write, in bounded memory.
        let mut read = || -> std::io::Result<()> {
            use std::io::Read;
            let mut file = std::fs::File::open(f)?;
            let mut buf = vec![0u8; 1 << 16];
            loop {
                match file.read(&mut buf)? {
                    0 => return Ok(()),
                    n => h.write(&buf[..n]),
                }
            }
        };
        if read().is_err() {
            h.write(f.display().to_string().as_bytes());
        }
    }
    h.finish()
}
