//! Scene files in RON: the description a user writes, checked where it is written.
//!
//! ```ron
//! Scene(
//!     camera: (
//!         position: (0.0, 1.0, 4.0), look_at: (0.0, 1.0, 0.0),
//!         fov: 40.0,                       // horizontal, degrees
//!         width: 160, height: 120,
//!         lens: (aperture: 0.03, focus_distance: 4.0),   // aperture: the lens radius (m); left out: a pinhole
//!         shutter: (open: 0.0, close: 0.02),             // left out: no time axis
//!     ),
//!     materials: { "white": Diffuse(albedo: (0.7, 0.7, 0.7)) },
//!     lights: [Rect(corner: (-0.3, 1.99, -0.3), edge_u: (0.6, 0.0, 0.0), edge_v: (0.0, 0.0, 0.6), radiance: (15.0, 15.0, 15.0))],
//!     shapes: [Sphere(center: (0.0, 0.5, 0.0), radius: 0.5, material: "white", velocity: (0.5, 0.0, 0.0))],
//! )
//! ```
//!
//! What the format does not have (a user's list, 2026-12-02): quads and meshes that turn
//! while the shutter is open, motion other than a constant velocity and a sphere's spin,
//! emissive materials, textured lights, point, directional and environment lights, glass
//! and other dielectrics, per-face OBJ materials, non-uniform or mirrored mesh scale. The operator
//! library has what the covariance pass would need for some of them (cov-refraction's
//! Snell interfaces, cov-motion's rotations); the renderer does not yet use them.
//!
//! Every number is checked as it is read (finite, in range), so a bad value is reported
//! at its own line and column; names that refer elsewhere (a material, an OBJ file) are
//! checked after reading and reported where they are written. An OBJ file the reader
//! refuses is reported at the `Mesh` that names it, with the OBJ's own line: a statement
//! that does not parse, a face that refers to a vertex the file does not have by the end
//! of the face's object (or a texture coordinate or normal, where the file has some: the
//! reader ignores `vt` and `vn` indices otherwise), a vertex coordinate that is not
//! finite. A comment after a statement (`v 0 1 0 # top`) is read past.
//!
//! | field | unit | meaning |
//! |---|---|---|
//! | `max_depth` | vertices | the path tracer's depth, as pbrt-v4's `maxdepth`: the surface vertices at which a path takes direct light, 1 (direct light only) to [`MAX_PATH_DEPTH`] (32); default [`DEFAULT_PATH_DEPTH`] (2, one indirect bounce); Russian roulette from the third vertex |
//! | `camera.position`, `look_at`, `up` | m | pinhole / lens centre, aim point (both within ±[`crate::geometry::MAX_COORD`]), up vector (default +y) |
//! | `camera.fov` | degrees | horizontal field of view, from [`MIN_FOV`] (1e-6) to below 180 |
//! | `camera.width`, `height` | px | 1 to [`MAX_RESOLUTION`] each |
//! | `camera.lens.aperture` | m | lens radius: 0 (pinhole) or [`LENS_RANGE`] (1e-9 to 1e6) |
//! | `camera.lens.focus_distance` | m | distance of the plane in focus, above the focal length and at most [`crate::geometry::MAX_COORD`] |
//! | `camera.lens.focal_length` | m | focal length (default 0.05) in [`LENS_RANGE`], < focus distance |
//! | `camera.shutter.open`, `close` | s | shutter interval, `close − open` in [`SHUTTER_RANGE`] (1e-15 to 1e6) |
//! | `camera.velocity` | m/s | camera motion during the shutter; the camera stays within ±[`crate::geometry::MAX_COORD`] of the origin over it (and at every frame rendered) |
//! | `camera.angular_velocity` | rad/s | camera rotation about its lens centre, in the world's axes: the axis times the rate (`(0.0, 0.5, 0.0)` turns the view from −z towards −x at 0.5 rad/s, a pan to the left for a camera looking along −z with +y up), at most [`MAX_ANGULAR_VELOCITY`] (2000π, a thousand turns a second) in length. `look_at` and `up` give the view at time 0, not at the shutter's opening; the camera turns at every instant a ray is traced, a still's (its frame's, `--frame`) too. A camera moving at `v` along its right while turning at `+v/d` about its up axis tracks a point at distance `d` ahead |
//! | `camera.frame_rate` | 1/s | frames per second of an animation (`--frame K` moves the shutter and a still's instant by `K / frame_rate`), default 24 |
//! | `textures` | | named `Checker(checks, a, b)`, `Stripes(count, duty, a, b)`, `Noise(cells, a, b, seed)` (generated; `size` texels per side, default 1024), `Image(file)` (PNG, sRGB, 8 or 16 bits, grey or colour, its alpha ignored; or EXR, linear, with R, G and B channels or one grey channel Y; relative to the scene file; texels clamped to 0 to 1, NaN to 0); all take `repeat: (u, v)` |
//! | `materials` | | named `Diffuse(albedo)`, `Phong(albedo, exponent)` (exponent 0 to 1e12), `Ggx(albedo, alpha)` (alpha at least 1e-6: a narrower lobe is below what f64 resolves), each with an optional `texture` that multiplies the albedo |
//! | `lights` | | `Rect(corner, edge_u, edge_v, radiance)`, `Sphere(center, radius, radiance)`; radiance in W/(m² sr) per channel |
//! | `shapes` | | `Sphere(center, radius, material, velocity, spin)` (`spin`: rad/s about the centre, axis times rate, at most [`MAX_ANGULAR_VELOCITY`]; a ball rolling at `v` on a floor of normal `up` spins at `up × v / r`), `Quad(corner, edge_u, edge_v, material, velocity)`, `Mesh(obj, material, translate, scale, rotate, velocity)` (`rotate`: degrees about the world's `x`, then `y`, then `z` axes through the mesh's origin, after `scale` and before `translate`; one material for the whole mesh: the OBJ's `mtllib` and `usemtl` lines are not read, and `usemtl` lines naming several materials are a warning: split such a file, one OBJ and one `Mesh` per material; a mesh without texture coordinates `vt` reads its material's texture at `(0, 0)`) |
//! | colours (`albedo`, texture colours, `radiance`) | | each entry 0 to [`MAX_COLOUR`] (1e9) as it is read; a material's `albedo` and a texture's colours at most 1 (a surface reflects no more than it receives) |
//! | every shape and light | m | within ±[`crate::geometry::MAX_COORD`] (1e12) of the origin, with its motion over the shutter (and at every frame rendered) |
//! | copies | | at most [`MAX_SHARED_BOX`] (256) shapes, lights and mesh triangles lying exactly on one another (a quad counts once) (the BVH builder's time grows as the square of their number); at most [`MAX_TRIANGLES`] triangles over all meshes, each placement counted |
//! | a sphere's radius, a quad's or rect light's edges, a mesh's extent | m | at least [`crate::geometry::MIN_SIZE`] × (1 m + the largest \|coordinate\| of its centre or corner) |

use std::collections::BTreeMap;

use serde::Deserialize;
use serde::de::{Deserializer, Error as _};

pub use crate::error::SceneError;

/// Largest image side (px): bounds memory (a float RGB image of 8192² is 800 MB).
pub const MAX_RESOLUTION: u32 = 8192;
/// Smallest horizontal field of view (degrees): a pixel of the widest image
/// ([`MAX_RESOLUTION`]) then spans about 2e-12 rad, and the covariance pass's
/// spectra, which grow as the inverse square of a pixel's angle, stay far inside f64 (at
/// 1e-300 degrees the sensor's filter spectrum overflowed).
pub const MIN_FOV: f64 = 1e-6;

/// The range (m) of a lens's radius (besides 0, a pinhole) and of its focal length: a
/// nanometre to a thousand kilometres. The covariance pass's lens spectra grow as the
/// inverse square of these lengths, and the sensor holds apertures up to 1e6; an aperture
/// of 1e-155 m overflowed, one of 1e-30 predicted no samples at all.
pub const LENS_RANGE: (f64, f64) = (1e-9, 1e6);
/// The range (s) of the shutter's opening time `close − open`: a femtosecond to the
/// sensor's largest shutter. One of 1e-160 s overflowed the shutter's spectrum.
pub const SHUTTER_RANGE: (f64, f64) = (1e-15, 1e6);

/// Largest scene file read (bytes).
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// Largest number of triangles over all meshes of a scene.
pub const MAX_TRIANGLES: usize = 5_000_000;
/// Most primitives (shapes, lights, a mesh's triangles) that may share one bounding box
/// exactly. The BVH builder (obvhs's PLOC) pairs neighbours by the area of their union; in
/// a run of equal boxes every pair ties, one pair merges per pass, and the build's time
/// grows as the square of the run (40,000 copies of one triangle took 58 s, 10,000 took
/// 3.6 s). A scene shares a box between a few primitives at most (a face and its reversed
/// twin); copies beyond that render as one of them anyway.
pub const MAX_SHARED_BOX: u32 = 256;

/// Defines a checked number type: `$name(f64)` deserialised and validated at once, so a
/// bad value is reported where it is written.
macro_rules! checked {
    ($(#[$m:meta])* $name:ident, $ok:expr, $what:literal) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct $name(pub f64);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let v = f64::deserialize(d)?;
                let ok: fn(f64) -> bool = $ok;
                if ok(v) { Ok($name(v)) } else { Err(D::Error::custom(format!(concat!("must be ", $what, ", got {}"), v))) }
            }
        }
    };
}

checked!(
    /// A finite number.
    Finite, f64::is_finite, "finite"
);
checked!(
    /// A finite number > 0.
    Positive, |v| v.is_finite() && v > 0.0, "finite and > 0"
);
checked!(
    /// A finite number ≥ 0.
    NonNegative, |v| v.is_finite() && v >= 0.0, "finite and ≥ 0"
);

/// A texture's repeat `(u, v)`: how many times it tiles the surface's UV square, each
/// finite and > 0. Read as one value, so that an error names it (a tuple's entries have
/// no field name of their own).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repeat(pub f64, pub f64);

impl<'de> Deserialize<'de> for Repeat {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (u, v) = <(f64, f64)>::deserialize(d)?;
        if [u, v].iter().all(|x| x.is_finite() && *x > 0.0) {
            return Ok(Repeat(u, v));
        }
        let [u, v] = [u, v].map(cov_core::num);
        Err(D::Error::custom(format!(
            "each entry must be finite and > 0, got ({u}, {v})"
        )))
    }
}

/// A point or vector `(x, y, z)`, finite.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct V3(pub [f64; 3]);

impl<'de> Deserialize<'de> for V3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        triple(d, |x| x.is_finite(), "a vector must be finite").map(V3)
    }
}

/// Reads `(a, b, c)` whose every entry passes `ok`, else the error `what, got (a, b, c)`.
fn triple<'de, D: Deserializer<'de>>(
    d: D,
    ok: impl Fn(f64) -> bool,
    what: &str,
) -> Result<[f64; 3], D::Error> {
    let (a, b, c) = <(f64, f64, f64)>::deserialize(d)?;
    if [a, b, c].into_iter().all(ok) {
        Ok([a, b, c])
    } else {
        let [a, b, c] = [a, b, c].map(cov_core::num);
        Err(D::Error::custom(format!("{what}, got ({a}, {b}, {c})")))
    }
}

/// Largest entry of a colour (an albedo, a texture's colour, a light's radiance in
/// W·sr⁻¹·m⁻², the sun's being about 2e7): a pixel is a product of at most four of them
/// (a light, two reflections, a texture), and `MAX_COLOUR⁴ = 1e36` stays below the
/// largest single-precision number (3.4e38), which the EXR stores.
pub const MAX_COLOUR: f64 = 1e9;

/// A colour `(r, g, b)`, each entry finite, ≥ 0 and at most [`MAX_COLOUR`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rgb(pub [f64; 3]);

impl<'de> Deserialize<'de> for Rgb {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        triple(
            d,
            |x| (0.0..=MAX_COLOUR).contains(&x),
            "a colour must be finite, ≥ 0 and ≤ 1e9",
        )
        .map(Rgb)
    }
}

/// An image side in pixels, 1 to [`MAX_RESOLUTION`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Resolution(pub u32);

impl<'de> Deserialize<'de> for Resolution {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = u64::deserialize(d)?;
        if (1..=MAX_RESOLUTION as u64).contains(&v) {
            Ok(Resolution(v as u32))
        } else {
            Err(D::Error::custom(format!(
                "must be 1 to {MAX_RESOLUTION} px, got {v}"
            )))
        }
    }
}

/// Largest camera rotation rate (rad/s, `camera.angular_velocity`): a thousand turns a
/// second. Faster is no camera, and the covariance pass's time shears grow with it.
pub const MAX_ANGULAR_VELOCITY: f64 = 2.0e3 * std::f64::consts::PI;

/// Longest path the tracer follows: surface vertices at which a path takes direct light
/// (`max_depth`). Each vertex takes six random numbers (the light's choice and point, the
/// next direction, Russian roulette), so a path of this depth stays within the sampler's
/// independent dimensions ([`crate::sampler`]).
pub const MAX_PATH_DEPTH: u32 = 32;

/// The tracer's depth when the scene does not give `max_depth`: direct light at the first
/// two vertices (camera → x₁ → light and camera → x₁ → x₂ → light), one indirect bounce.
pub const DEFAULT_PATH_DEPTH: u32 = 2;

/// A path's depth, 1 to [`MAX_PATH_DEPTH`] ([`SceneFile::max_depth`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathDepth(pub u32);

impl<'de> Deserialize<'de> for PathDepth {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = u64::deserialize(d)?;
        if (1..=u64::from(MAX_PATH_DEPTH)).contains(&v) {
            Ok(PathDepth(v as u32))
        } else {
            Err(D::Error::custom(format!(
                "must be 1 to {MAX_PATH_DEPTH} surface vertices, got {v}"
            )))
        }
    }
}

/// The whole file, written `Scene(...)`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Scene")]
pub struct SceneFile {
    /// The path tracer's depth: the surface vertices at which a path takes direct light,
    /// as pbrt-v4's `maxdepth` (1: direct light only; default [`DEFAULT_PATH_DEPTH`]).
    #[serde(default)]
    pub max_depth: Option<PathDepth>,
    /// The camera.
    pub camera: CameraDesc,
    /// Named textures (materials refer to them by name), each name once.
    #[serde(default, deserialize_with = "unique_names")]
    pub textures: BTreeMap<At<String>, At<TextureDesc>>,
    /// Named materials, each name once.
    #[serde(default, deserialize_with = "unique_names")]
    pub materials: BTreeMap<At<String>, MaterialDesc>,
    /// Emitters.
    pub lights: At<Vec<LightDesc>>,
    /// Geometry (empty is a warning: light falls on nothing).
    pub shapes: At<Vec<ShapeDesc>>,
}

/// A map of names to definitions in which a name given twice is an error (where the
/// second definition ends), not a silent replacement of the first.
fn unique_names<'de, D, V>(d: D) -> Result<BTreeMap<At<String>, V>, D::Error>
where
    D: Deserializer<'de>,
    V: Deserialize<'de>,
{
    struct Names<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Names<V> {
        type Value = BTreeMap<At<String>, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a map of names to definitions")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
            let mut out: BTreeMap<At<String>, V> = BTreeMap::new();
            while let Some((name, value)) = map.next_entry::<At<String>, V>()? {
                if let Some((first, _)) = out.get_key_value(&name) {
                    // Positioned by `SceneFile::parse` at the second name, the first's
                    // place said ([`TWICE_MARK`]).
                    return Err(A::Error::custom(format!(
                        "{TWICE_MARK}{} {}{TWICE_MARK}`{}` is defined twice",
                        name.ordinal,
                        first.ordinal,
                        crate::echo(&name.value)
                    )));
                }
                out.insert(name, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Names(std::marker::PhantomData))
}

/// The camera.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Camera")]
pub struct CameraDesc {
    /// Centre of the lens (m).
    pub position: At<V3>,
    /// Point aimed at (m).
    pub look_at: At<V3>,
    /// Up vector (default +y).
    #[serde(default)]
    pub up: Option<At<V3>>,
    /// Horizontal field of view (degrees).
    pub fov: At<Positive>,
    /// Image width (px).
    pub width: Resolution,
    /// Image height (px).
    pub height: Resolution,
    /// A thin lens; none: a pinhole.
    #[serde(default)]
    pub lens: Option<LensDesc>,
    /// The shutter interval; none: a still image (no time axis).
    #[serde(default)]
    pub shutter: Option<ShutterDesc>,
    /// Camera velocity during the shutter (m/s).
    #[serde(default)]
    pub velocity: Option<At<V3>>,
    /// Camera rotation during the shutter (rad/s): the axis times the rate, about the lens
    /// centre; the view direction, the image's right and up turn together (a pan, a tilt,
    /// a roll). At most [`MAX_ANGULAR_VELOCITY`] in length.
    #[serde(default)]
    pub angular_velocity: Option<At<V3>>,
    /// Frames per second of an animation ([`crate::World::at_frame`]); default 24.
    #[serde(default)]
    pub frame_rate: Option<Positive>,
}

/// A thin lens.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Lens")]
pub struct LensDesc {
    /// Lens radius (m); 0 is a pinhole.
    pub aperture: At<NonNegative>,
    /// Distance in focus (m).
    pub focus_distance: At<Positive>,
    /// Focal length (m), default 0.05.
    #[serde(default)]
    pub focal_length: Option<At<Positive>>,
}

/// The shutter interval (s).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Shutter")]
pub struct ShutterDesc {
    /// Opening time.
    pub open: Finite,
    /// Closing time (> open).
    pub close: At<Finite>,
}

/// A material.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Material")]
pub enum MaterialDesc {
    /// Lambertian.
    Diffuse {
        /// Reflectance per channel, ≤ 1.
        albedo: At<Rgb>,
        /// A texture from `textures` that multiplies the albedo.
        #[serde(default)]
        texture: Option<At<String>>,
    },
    /// Normalised modified Phong around the mirror direction (the cov-brdf Phong lobe).
    Phong {
        /// Reflectance per channel, ≤ 1.
        albedo: At<Rgb>,
        /// Exponent, 0 to 1e12 (`world::MIN_LOBE_WIDTH`).
        exponent: At<NonNegative>,
        /// A texture from `textures` that multiplies the albedo.
        #[serde(default)]
        texture: Option<At<String>>,
    },
    /// GGX microfacets (the cov-brdf GGX lobe).
    Ggx {
        /// Reflectance per channel, ≤ 1.
        albedo: At<Rgb>,
        /// Roughness, at least 1e-6 (`world::MIN_LOBE_WIDTH`).
        alpha: At<Positive>,
        /// A texture from `textures` that multiplies the albedo.
        #[serde(default)]
        texture: Option<At<String>>,
    },
}

/// A texture: a reflectance map over a surface's `(u, v)` (quads: `u` along `edge_u`,
/// `v` along `edge_v`; spheres: longitude from +x towards −z and latitude from the south
/// pole, so that an equirectangular image reads from outside as on a quad, u = 0.5 facing
/// +x; meshes: the OBJ's coordinates).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Texture")]
pub enum TextureDesc {
    /// An image file (PNG, sRGB; or EXR, linear), path relative to the scene file.
    Image {
        /// The file.
        file: At<String>,
        /// Repeats over a unit of `u` and `v` (default 1, 1).
        #[serde(default)]
        repeat: Option<At<Repeat>>,
    },
    /// A checkerboard.
    Checker {
        /// Squares along `u` and `v`.
        checks: At<(u32, u32)>,
        /// The two colours (reflectances).
        a: At<Rgb>,
        /// The second colour.
        b: At<Rgb>,
        /// Texels per side it is rasterised on (default 1024).
        #[serde(default)]
        size: Option<At<u32>>,
        /// Repeats over a unit of `u` and `v` (default 1, 1).
        #[serde(default)]
        repeat: Option<At<Repeat>>,
    },
    /// Stripes along `v` (bands running along `u`).
    Stripes {
        /// Periods over a unit of `v`.
        count: At<u32>,
        /// Fraction of each period in colour `b`, centred in it (default 0.5).
        #[serde(default)]
        duty: Option<At<Positive>>,
        /// The background colour.
        a: At<Rgb>,
        /// The stripes' colour.
        b: At<Rgb>,
        /// Texels per side (default 1024).
        #[serde(default)]
        size: Option<At<u32>>,
        /// Repeats over a unit of `u` and `v` (default 1, 1).
        #[serde(default)]
        repeat: Option<At<Repeat>>,
    },
    /// Smooth value noise between two colours.
    Noise {
        /// Lattice cells per side.
        cells: At<u32>,
        /// The colour at 0.
        a: At<Rgb>,
        /// The colour at 1.
        b: At<Rgb>,
        /// Seed of the lattice (default 0).
        #[serde(default)]
        seed: Option<u64>,
        /// Texels per side (default 1024).
        #[serde(default)]
        size: Option<At<u32>>,
        /// Repeats over a unit of `u` and `v` (default 1, 1).
        #[serde(default)]
        repeat: Option<At<Repeat>>,
    },
}

/// An area light.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Light")]
pub enum LightDesc {
    /// A parallelogram emitting on the side of `edge_u × edge_v`.
    Rect {
        /// A corner (m).
        corner: At<V3>,
        /// First edge (m).
        edge_u: At<V3>,
        /// Second edge (m).
        edge_v: V3,
        /// Radiance.
        radiance: Rgb,
    },
    /// A sphere emitting outwards.
    Sphere {
        /// Centre (m).
        center: At<V3>,
        /// Radius (m).
        radius: At<Positive>,
        /// Radiance.
        radiance: Rgb,
    },
}

/// A shape.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields, rename = "Shape")]
pub enum ShapeDesc {
    /// A sphere.
    Sphere {
        /// Centre at time 0 (m).
        center: At<V3>,
        /// Radius (m).
        radius: At<Positive>,
        /// Material name.
        material: At<String>,
        /// Velocity (m/s).
        #[serde(default)]
        velocity: Option<V3>,
        /// Angular velocity about the centre (rad/s, axis times rate; at most
        /// [`MAX_ANGULAR_VELOCITY`] in length): the texture turns with the surface. A ball
        /// of radius `r` rolling at velocity `v` on a floor of normal `up` spins at
        /// `up × v / r`: `(0, 0, −v/r)` rolling along +x on a floor facing +y.
        #[serde(default)]
        spin: Option<At<V3>>,
    },
    /// A parallelogram.
    Quad {
        /// A corner (m).
        corner: At<V3>,
        /// First edge (m).
        edge_u: At<V3>,
        /// Second edge (m).
        edge_v: V3,
        /// Material name.
        material: At<String>,
        /// Velocity (m/s).
        #[serde(default)]
        velocity: Option<V3>,
    },
    /// A triangle mesh from an OBJ file (path relative to the scene file).
    Mesh {
        /// The OBJ file.
        obj: At<String>,
        /// Material name.
        material: At<String>,
        /// Translation (m), applied after scaling.
        #[serde(default)]
        translate: Option<V3>,
        /// Uniform scale.
        #[serde(default)]
        scale: Option<Positive>,
        /// Rotation (degrees) about the mesh's own origin, after scaling and before the
        /// translation: about `x` first, then `y`, then `z` (the world's axes).
        #[serde(default)]
        rotate: Option<V3>,
        /// Velocity (m/s).
        #[serde(default)]
        velocity: Option<V3>,
    },
}

/// A value whose place in the file the parser can give back: every `At` is numbered in
/// the order the parser reads it, and [`SceneFile::locate`] parses the text again, stopping
/// at that number, so that ron reports its own line and column there. Checks made after
/// parsing (a material that does not exist, a lens that cannot focus) are positioned this
/// way, from the parser's spans, never by searching the text.
#[derive(Clone, Debug)]
pub struct At<T> {
    /// The value.
    pub value: T,
    /// Its number in reading order.
    pub ordinal: u32,
}

impl<T: PartialEq> PartialEq for At<T> {
    fn eq(&self, other: &Self) -> bool {
        self.value == other.value
    }
}

impl<T: Eq> Eq for At<T> {}

impl<T: Ord> PartialOrd for At<T> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<T: Ord> Ord for At<T> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.value.cmp(&other.value)
    }
}

/// The message with which a located parse stops (never shown to a user).
const LOCATE_MARK: &str = "\u{0}covtrace-locate";

/// Encloses, at the start of a name-defined-twice message, the two names' [`At`]
/// numbers (the second's, then the first's), which `SceneFile::parse` turns into
/// positions (never shown to a user).
const TWICE_MARK: &str = "\u{0}covtrace-twice";

thread_local! {
    /// While parsing: the number the next [`At`] gets, and the one to stop at.
    static PROBE: std::cell::Cell<(u32, Option<u32>)> = const { std::cell::Cell::new((0, None)) };
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for At<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let (ordinal, target) = PROBE.with(|p| {
            let (n, t) = p.get();
            p.set((n.saturating_add(1), t));
            (n, t)
        });
        if target == Some(ordinal) {
            return Err(D::Error::custom(LOCATE_MARK));
        }
        Ok(At {
            value: T::deserialize(d)?,
            ordinal,
        })
    }
}

/// The byte offset in `text` of line `line` (1-based).
fn line_start(text: &str, line: usize) -> Option<usize> {
    Some(
        text.split_inclusive('\n')
            .take(line.checked_sub(1)?)
            .map(str::len)
            .sum(),
    )
}

/// What the text holds at `line:col` (1-based, as the parser reports it), quoted: the word
/// or number that starts there, or its one character (at most 24 characters, on one line),
/// or "the end of the file"; and the column where it starts (ron may stop at the blank
/// before it).
fn found_at(text: &str, line: usize, col: usize) -> (String, usize) {
    let Some(l) = line_start(text, line).and_then(|s| text.get(s..)) else {
        return ("the end of the file".into(), col);
    };
    let blanks = l
        .chars()
        .skip(col.saturating_sub(1))
        .take_while(|c| *c == ' ' || *c == '\t')
        .count();
    let mut chars = l.chars().skip(col.saturating_sub(1) + blanks).peekable();
    let at = col + blanks;
    let word = |c: &char| c.is_alphanumeric() || matches!(*c, '_' | '.' | '-' | '+');
    let token: String = match chars.peek() {
        None => return ("the end of the file".into(), at),
        Some('\n' | '\r') => return ("the end of the line".into(), at),
        Some(c) if word(c) => chars.take_while(word).take(24).collect(),
        Some(_) => chars.take(1).collect(),
    };
    (format!("`{token}`"), at)
}

/// A value written from `(line, col)` of `text` (or from the number ron stopped inside)
/// that begins as a number and is none, `0x1` or `4O.0`, where ron read the leading digits
/// and then stopped: the field's name, the value's index in its tuple or list (`None`:
/// the field's value itself), and the value as written.
fn not_a_number(text: &str, line: usize, col: usize) -> Option<(String, Option<usize>, String)> {
    let (name, index, written) = cov_path::whole_number_at(text, line, col)?;
    let token = written.split([' ', ')', ']']).next().unwrap_or("");
    let digits = token.trim_start_matches(['-', '+']);
    let is_number = digits.starts_with(|c: char| c.is_ascii_digit() || c == '.');
    (is_number && token.parse::<f64>().is_err() && token.chars().any(|c| c.is_alphabetic()))
        .then(|| (name, index, token.to_string()))
}

/// ron's message `message` of the form `PREFIX `name` in `Type`…` (a field it did not
/// expect, one given twice, one left out): the field's name and the type's, if said.
fn named<'m>(message: &'m str, prefix: &str) -> Option<(&'m str, Option<&'m str>)> {
    let (name, rest) = message
        .strip_prefix(prefix)?
        .strip_prefix(" `")?
        .split_once('`')?;
    let owner = rest.strip_prefix(" in `").and_then(|o| o.split('`').next());
    Some((name, owner))
}

/// How [`tuple_words`] ends its message for a tuple whose `)` is missing (reported at
/// the tuple's start).
const NOT_CLOSED: &str = " (it opens here)";

/// A decimal number where a whole number belongs, at `(line, col)` of `text` (its `.`,
/// or its start): said of its field, or of its place in a tuple.
fn whole_words(text: &str, line: usize, col: usize) -> Option<String> {
    const WORDS: &str = "expected a whole number, found a decimal number";
    Some(match cov_path::whole_number_at(text, line, col)? {
        (name, None, value) => format!("`{name}` = {}: {WORDS}", cov_core::echo(&value)),
        (name, Some(k), value) => format!("`{name}`: value {} = {}: {WORDS}", k + 1, cov_core::echo(&value)),
    })
}

/// Whether a check's message `m` (`…, got N`) was given the whole part of `written`,
/// a decimal number: the parser reads `0.5` where a whole number belongs as 0, and a
/// bound refuses the 0 before the parser reaches the `.`.
fn truncated(m: &str, written: &str) -> bool {
    let Ok(value) = written.trim().parse::<f64>() else {
        return false;
    };
    let got = m
        .rsplit_once("got ")
        .and_then(|(_, g)| g.trim().parse::<f64>().ok());
    value.is_finite() && value.fract() != 0.0 && got.is_some_and(|g| g == value.trunc())
}

/// The digits after the comma if the whole number `written`, the value of the field at
/// `(line, col)` of `text`, is followed by a comma and a digit: `0,4`, a decimal comma,
/// read as 0 and a next entry.
fn decimal_comma(text: &str, line: usize, col: usize, written: &str) -> Option<String> {
    if !written.chars().all(|c| c.is_ascii_digit() || c == '-') {
        return None;
    }
    let (l, c) = cov_path::value_position(text, line, col)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let row: Vec<char> = text.lines().nth(l.checked_sub(1)?)?.chars().collect();
    let after = c.checked_sub(1)? + written.chars().count();
    if row.get(after) != Some(&',') {
        return None;
    }
    let digits: String = row[after + 1..]
        .iter()
        .take_while(|c| c.is_ascii_digit())
        .take(24)
        .collect();
    (!digits.is_empty()).then_some(digits)
}

/// ron's message `message` at `(line, col)` of `text` said of a tuple's field, when it
/// is about the tuple: its number of values (`position: (0.0, 0.8)`), a value of the wrong
/// type in it (`radiance: (10.0, nan, 9.0)`), one value too many, or values where named
/// fields belong (`shutter: (0.0, 0.1)`). `None` otherwise.
fn tuple_words(text: &str, line: usize, col: usize, message: &str) -> Option<String> {
    if let Some(rest) = message.strip_prefix("Expected a tuple of size ")
        && let Some((want, found)) = rest.split_once(" but found ")
        && let Some((name, _, value)) = cov_path::field_at(text, line, col)
    {
        let found = found.split(' ').next().unwrap_or("");
        return Some(format!(
            "`{name}` = {}: expected {want} values, found {found}",
            cov_core::echo(&value)
        ));
    }
    // A negative number is reported after its sign.
    let start = cov_path::number_start(text, line, col);
    let ((name, _, _), index, element) = cov_path::element_at(text, line, start)?;
    let element = cov_core::echo(&element);
    if message.starts_with("Found invalid std identifier") {
        return Some(format!(
            "`{name}`: expected named fields (`name: value`) in the parentheses, found `{element}`"
        ));
    }
    if message.starts_with("Expected closing `)`") {
        // One value too many follows a comma; after a value, a comma is missing.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let before = text
            .lines()
            .take(line.saturating_sub(1))
            .flat_map(|l| l.chars().chain(['\n']))
            .chain(
                text.lines()
                    .nth(line.saturating_sub(1))
                    .unwrap_or("")
                    .chars()
                    .take(col.saturating_sub(1)),
            )
            .filter(|c| !c.is_whitespace())
            .last();
        if before != Some(',') {
            return None;
        }
        // `name:` where a value belongs: the next field, so the tuple's `)` is missing.
        let after: String = line_start(text, line)
            .and_then(|s| text.get(s..))
            .unwrap_or("")
            .chars()
            .skip(col.saturating_sub(1))
            .skip_while(|c| c.is_whitespace() || *c == ',')
            .take_while(|c| !matches!(c, '(' | ')' | ',' | '"'))
            .take(64)
            .collect();
        if let Some((next, _)) = after.split_once(':')
            && let next = next.trim()
            && !next.is_empty()
            && next.chars().all(|c| c.is_alphanumeric() || c == '_')
        {
            return Some(format!(
                "`{name}` is not closed: a `)` is missing before `{next}`{NOT_CLOSED}"
            ));
        }
        return Some(format!(
            "`{name}` has more than {index} values (found `{element}`)"
        ));
    }
    let what = cov_path::expected_value(message, &element)?;
    Some(if element.is_empty() {
        format!("`{name}`: value {} is missing: expected {what}", index + 1)
    } else if what.is_empty() {
        format!(
            "`{name}`: value {} = {element} is out of range for a whole number",
            index + 1
        )
    } else {
        format!("`{name}`: value {} = {element}: expected {what}", index + 1)
    })
}

impl SceneFile {
    /// Parses scene text; `file` names it in errors.
    ///
    /// # Errors
    /// Malformed RON, unknown fields or variants, bad numbers: positioned.
    pub fn parse(text: &str, file: &str) -> Result<SceneFile, SceneError> {
        Self::parse_probed(text, None).map_err(|e| {
            let (line, col) = (e.span.start.line, e.span.start.col);
            if let Some(((line, col), message)) = cov_path::odd_space_before(text, line, col) {
                return SceneError {
                    file: file.to_string(),
                    at: Some((line, col)),
                    message,
                };
            }
            let mut message = e.code.to_string();
            if let Some((at, words)) = cov_path::token_error(text, line, col, &message) {
                return SceneError {
                    file: file.to_string(),
                    at: Some(at),
                    message: words,
                };
            }
            // Where the message points: ron's position, or the start of the value it is
            // about (ron stops after a sign, inside a number or before a string's blank).
            let mut at = (line, col);
            if let Some((ordinals, words)) = message
                .strip_prefix(TWICE_MARK)
                .and_then(|m| m.split_once(TWICE_MARK))
            {
                // A name defined twice: at the second, the first's place said.
                let mut place = ordinals
                    .split(' ')
                    .filter_map(|o| o.parse().ok())
                    .map(|o| Self::locate(text, o));
                let (second, first) = (place.next().flatten(), place.next().flatten());
                return SceneError {
                    file: file.to_string(),
                    at: Some(second.unwrap_or((line, col))),
                    message: cov_core::one_line(&match first {
                        Some((l, c)) => format!("{words} (first at {l}:{c})"),
                        None => words.to_string(),
                    }),
                };
            }
            if message.starts_with("Expected opening `(` for struct `Scene`") && cov_path::blank_or_comment(text) {
                return SceneError {
                    file: file.to_string(),
                    at: Some((line, col)),
                    message: "the file holds no scene: expected `Scene(…)`".into(),
                };
            }
            let field = || cov_path::field_at(text, line, col);
            let value_at = || cov_path::value_position(text, line, col).unwrap_or((line, col));
            // `0x1` where a decimal belongs: ron reads the `0` (so a checked type refuses 0,
            // or ron stops at the `x`).
            if let Some((name, _, value)) = field()
                && let Some(words) = cov_path::not_decimal(&value)
            {
                message = format!("`{name}` = {}: {words}", cov_core::echo(&value));
                at = value_at();
            } else if cov_path::decimal_for_whole(&message, text, line, col)
                && let Some(words) = whole_words(text, line, col)
            {
                message = words;
                at = (line, cov_path::number_start(text, line, col));
            } else if let Some((name, owner)) = named(&message, "Unexpected duplicate field named") {
                // ron's `in `Camera``: the type's name, which the scene writes in lower case
                // only as a field (`camera: (…)`); said as the type.
                let owner = owner.map(|o| format!(" in `{o}`")).unwrap_or_default();
                message = format!("`{name}` is given twice{owner}: remove one");
            } else if let ron::Error::Message(m) = &e.code
                && let Some((_, _, value)) = field()
                && truncated(m, &value)
                && let Some(words) = whole_words(text, line, col)
            {
                // A decimal where a whole number belongs, read as its whole part (`0.5`
                // as 0), which a bound then refused: said as the decimal it is.
                message = words;
                at = value_at();
            } else if let ron::Error::Message(_) = &e.code
                && let Some((name, _, value)) = field()
                && let Some(words) = cov_path::beyond_float(&value)
            {
                message = format!("`{name}` = {}: {words}", cov_core::echo(&value));
                at = value_at();
            } else if let ron::Error::Message(_) = &e.code
                && let Some((name, _, value)) = field()
                && let Some(digits) = decimal_comma(text, line, col, &value)
            {
                message = format!(
                    "`{name}` = {value},{digits}: a comma ends a value; a decimal number is written with a point (`{value}.{digits}`)"
                );
                at = value_at();
            } else if let ron::Error::Message(m) = &e.code
                && let Some((name, ..)) = field()
            {
                message = if m.starts_with("must be ") {
                    format!("`{name}` {m}")
                } else {
                    format!("`{name}`: {m}")
                };
                at = value_at();
            } else if let Some((name, _, value)) = field()
                && let Some(what) = cov_path::expected_value(&message, &value)
            {
                // A value of the wrong type: its field, what it holds and what it needs.
                let value = cov_core::echo(&value);
                message = if what.is_empty() && value.starts_with('-') {
                    format!("`{name}` = {value}: must not be negative")
                } else if what.is_empty() {
                    format!("`{name}` = {value} is out of range for a whole number")
                } else {
                    format!("`{name}` = {value}: expected {what}")
                };
                at = value_at();
            } else if message.starts_with("Expected opening `(`")
                && let Some((name, _, value)) = field()
            {
                // A tuple or a struct's fields belong here: `position: 3.9`.
                let what = match message.split_once(" for struct `") {
                    Some((_, t)) => format!("`{}`'s fields in parentheses, `(name: value, …)`", t.split('`').next().unwrap_or("")),
                    None => "values in parentheses, `(…)`".to_string(),
                };
                message = format!("`{name}` = {}: expected {what}", cov_core::echo(&value));
                at = value_at();
            } else if let Some((found, Some(owner))) = named(&message, "Unexpected field named")
                && found.starts_with(|c: char| c.is_ascii_uppercase())
            {
                // Every field is in lower case: a name in capitals (`Sphere`) is the next
                // entry of a list, read as a field because a `)` is missing before it.
                message = format!(
                    "found `{found}` among `{owner}`'s fields: is the `)` that closes the `{owner}` before it missing?"
                );
            } else if let Some(words) = tuple_words(text, line, col, &message) {
                // The tuple's count at its start; a value in it at its own start (ron
                // stops after a sign).
                at = if message.starts_with("Expected a tuple of size") || words.ends_with(NOT_CLOSED) {
                    value_at()
                } else {
                    (line, cov_path::number_start(text, line, col))
                };
                message = words;
            } else if let Some((found, Some(owner))) = named(&message, "Unexpected field named")
                && let Some((outer, (l, c))) = cov_path::enclosing_field(text, line, col)
                && line > l
                && col <= c
            {
                // A field of the enclosing struct, written where it would be, read as one of
                // this struct's because the `)` that closes this one is missing.
                message = format!(
                    "`{found}` is no field of `{owner}`: is the `)` that closes `{outer}` (at {l}:{c}) missing before it?"
                );
            } else if let Some((name, owner)) = named(&message, "Unexpected missing field named") {
                let owner = owner.map(|o| format!(" from `{o}`")).unwrap_or_default();
                // A `)` too many closed the struct before the rest of its fields.
                message = if cov_path::written_after_close(text, line, col, name) {
                    format!("`{name}` is missing{owner}: this `)` closes it before `{name}` is read; is it one too many?")
                } else {
                    format!("`{name}` is missing{owner}: it has no default")
                };
            } else if let Some((name, index, written)) = not_a_number(text, line, col) {
                // `0x1` or `4O.0` in a tuple: ron read the leading digits and stopped.
                let words = cov_path::not_decimal(&written).unwrap_or("not a number");
                let written = cov_core::echo(&written);
                message = match index {
                    Some(i) => format!("`{name}`: value {} = {written}: {words}", i + 1),
                    None => format!("`{name}` = {written}: {words}"),
                };
                at = (line, cov_path::number_start(text, line, col));
            } else if message.starts_with("Expected") && !message.contains(" found ") {
                // A syntax error: say what stands where something else was expected.
                let (found, c) = found_at(text, line, col);
                message = format!("{message}, found {found}");
                at = (line, c);
            }
            SceneError {
                file: file.to_string(),
                at: Some(at),
                message: cov_core::one_line(&message),
            }
        })
    }

    /// Parses with the [`At`] numbered `target` (if any) stopping the parser.
    fn parse_probed(text: &str, target: Option<u32>) -> Result<SceneFile, ron::error::SpannedError> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        PROBE.with(|p| p.set((0, target)));
        let r = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
            .from_str(text);
        PROBE.with(|p| p.set((0, None)));
        r
    }

    /// Line and column (1-based) where the [`At`] numbered `ordinal` is written in `text`
    /// (the text this scene was parsed from), as the parser reports it.
    pub fn locate(text: &str, ordinal: u32) -> Option<(usize, usize)> {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        match Self::parse_probed(text, Some(ordinal)) {
            // The parser stops before the value, after the `:` or `,` that precedes it:
            // the value starts at the next character that is not white space.
            Err(e) if e.code.to_string().contains(LOCATE_MARK) => {
                let (mut line, mut col) = (e.span.start.line, e.span.start.col);
                let rest = text.get(line_start(text, line)?..)?;
                for c in rest.chars().skip(col.saturating_sub(1)) {
                    match c {
                        '\n' => {
                            line += 1;
                            col = 1;
                        }
                        c if c.is_whitespace() => col += 1,
                        _ => return Some((line, col)),
                    }
                }
                None
            }
            _ => None,
        }
    }
}
