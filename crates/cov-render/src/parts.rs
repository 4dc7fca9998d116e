//! A render split into parts, for many processes or machines (a Slurm job array,
//! `examples/slurm/`), and merged into exactly the image one process renders.
//!
//! **What a part owns.** Part `I` of `N` ([`Part`]) owns whole tile rows,
//! `⌊(I−1)·T/N⌋ .. ⌊I·T/N⌋` of the image's `T` tile rows
//! ([`part_rows`]), so the parts cover every row once. Each
//! part spends its own pixels' share of the budget: the render in parts is the render with
//! [`RenderSettings::parts`] = `N` (`covtrace render --parts N` in one process), whose
//! allocation is split the same way. `N = 1`, the default, spreads the budget over the
//! whole image; splitting keeps samples from moving between parts, which costs some error
//! where the detail is unevenly spread over the rows (docs/render-bench.md).
//!
//! **What a part computes.** Everything its own pixels' samples depend on, and nothing
//! else ([`Renderer::render_part`](crate::Renderer::render_part)):
//! - the covariance pass over its rows and [`GUIDE_MARGIN`](crate::renderer::GUIDE_MARGIN)
//!   rows on each side;
//! - the pilot over its rows and [`PILOT_MARGIN`](crate::renderer::PILOT_MARGIN) rows on
//!   each side;
//! - the allocation of its rows, and the rest of their samples.
//!
//! The margins are as deep as the allocation reads. A pixel's share follows the guard's
//! choice, which averages the candidates' error estimates over 3×3 pixels. Each estimate
//! reads the pilot's samples within [`CUTOFF`](crate::film::CUTOFF) standard deviations
//! of the widest filter ([`MAX_FILTER`](crate::adaptive::MAX_FILTER) px), and their 3×3
//! mean luminance: 1 + 24 rows, rounded up to whole tiles (32). The filters of those rows
//! are kept off the edges that the pass saw up to
//! [`EDGE_REACH`](crate::adaptive::EDGE_REACH) × `MAX_FILTER` = 16 rows further: 41 rows
//! of covariance, 48 in tiles.
//! Tiles of the pass and pixels of the film draw their random numbers from generators
//! seeded by their place in the whole image, and every sum is added in the same order, so
//! a part's pixels are bit for bit the single render's.
//!
//! **What a part writes** ([`PartFilm::write`]): a multi-layer OpenEXR of its rows (the
//! layer's data window is placed at its first row). Layer `film` holds every per-pixel
//! sum of the film (sample count `count`, radiance, luminance moments, the features) and
//! layer `cov` the covariance maps, each `f64` as two `u32` channels (`NAME.hi`, `NAME.lo`:
//! its bits), so that nothing is rounded; `R`, `G`, `B` (`f32`) preview the part's pixels.
//! A JSON key of the scene (a hash of its file and of every file it reads), the size, the
//! frame and the settings is stored in the header, so that parts of different renders are
//! never mixed, with a digest of the part's data (FNV-1a of every count and every `f64`'s
//! bits), so that a file damaged after it was written is refused, not merged.
//!
//! **Merging** ([`merge`]) checks that the parts share one key and cover every row once,
//! assembles the film and the maps, and reconstructs the image as the single render does
//! (the guard's filters, the denoiser): the result is the single render's, bit for bit.

use std::ops::Range;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::adaptive::Guide;
use crate::covpass::{CovMaps, PixelCov};
use crate::denoise::Denoise;
use crate::film::Progress;
use crate::film::{Film, Image};
use crate::guard::candidates;
use crate::renderer::{
    Method, RenderSettings, Renderer, Sampled, Timing, Window, part_rows, reads_covariance, reconstruct,
    timed,
};
use crate::{RenderError, World};

pub use crate::renderer::MAX_PARTS;
/// Version of the part file's layout and key (3: covariance tracing followed by a
/// denoiser below 3 spp carries no covariance layer; 4: the film's `lum.top`; 5: the
/// digest of the data in the header).
pub const FORMAT: u32 = 5;
/// Most channels a layer of a part file may hold (the film's holds 36: a count, a
/// preview's R, G, B and two per sum; the maps' 10).
const MAX_CHANNELS: usize = 64;

/// Part `index` (1-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Part {
    /// Which part, from 1.
    pub index: u32,
    /// Of how many.
    pub count: u32,
}

impl Part {
    /// Parses `I/N` (`1 ≤ I ≤ N`).
    ///
    /// # Errors
    /// Not of that form, or `I` outside `1..=N`.
    pub fn parse(s: &str) -> Result<Part, String> {
        let bad = || format!("--part must be I/N with 1 ≤ I ≤ N, got `{}`", crate::echo(s));
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            i.trim().parse::<u32>().map_err(|_| bad())?,
            n.trim().parse::<u32>().map_err(|_| bad())?,
        );
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Part { index, count })
    }

    /// The rows this part owns in an image of `height` rows (module docs).
    ///
    /// # Errors
    /// More parts than the image has tile rows.
    pub fn rows(self, height: u32) -> Result<Range<u32>, RenderError> {
        part_rows(height, self.index, self.count)
    }

    /// The rows each stage of this part computes.
    pub(crate) fn window(self, height: u32) -> Result<Window, RenderError> {
        let owned = self.rows(height)?;
        Ok(Window::around(owned, height))
    }
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Renderer<'_> {
    /// Renders one part of the image ([module docs](self)): the rows `part` owns, with the
    /// covariance pass and the pilot over the margins their filters need. The image is not
    /// reconstructed: [`merge`] does that from all the parts.
    ///
    /// # Errors
    /// A part whose count is not the settings' [`RenderSettings::parts`]; a time limit (a
    /// part renders a fixed budget); a renderer given a guide ([`Renderer::with_guide`]),
    /// for a method that traces the covariance; the covariance pass's errors.
    pub fn render_part(&mut self, part: Part, progress: Progress<'_>) -> Result<PartFilm, RenderError> {
        if part.count != self.settings().parts {
            return Err(RenderError::setting(
                "parts",
                format!("the part's count (part {part})"),
                self.settings().parts,
            ));
        }
        if self.settings().time.is_some() {
            return Err(RenderError::setting(
                "time",
                "left out when rendering a part (a part renders a fixed budget)",
                self.settings().time.unwrap_or_default(),
            ));
        }
        let win = part.window(self.world.camera.height)?;
        let Sampled { film, timing, .. } = self.sample(&win, progress)?;
        if self.reads_guide() && self.maps().is_none() {
            // A guide given to the renderer has no maps for the part file to carry.
            return Err(RenderError::Parts(
                "a part traces its own covariance pass: render it without a given guide".into(),
            ));
        }
        Ok(PartFilm::new(
            self.world,
            self.settings(),
            part,
            &win,
            &film,
            self.maps(),
            timing,
        ))
    }

    /// How many times [`Renderer::render_part`] calls its progress callback.
    ///
    /// # Errors
    /// As [`Part::rows`].
    pub fn part_progress_len(&self, part: Part) -> Result<usize, RenderError> {
        let win = part.window(self.world.camera.height)?;
        Ok(self.window_progress_len(&win))
    }
}

/// What makes two parts belong to one render: the scene, the size, the frame and every
/// setting that changes a pixel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartKey {
    /// [`FORMAT`].
    pub format: u32,
    /// The scene's fingerprint ([`World::fingerprint`]), in hex.
    pub scene: String,
    /// Image width (px).
    pub width: u32,
    /// Image height (px).
    pub height: u32,
    /// The animation frame ([`World::frame`]).
    pub frame: u32,
    /// The method's name.
    pub method: String,
    /// Average samples per pixel.
    pub spp: f64,
    /// Seed.
    pub seed: u64,
    /// Covariance paths per block.
    pub cov_paths: u32,
    /// Side of the covariance grid's blocks (px).
    pub cov_stride: u32,
    /// Surface vertices per covariance path.
    pub cov_depth: u32,
    /// The luminance clamp, as text (`inf` for none).
    pub max_luminance: String,
    /// The denoiser's name.
    pub denoise: String,
    /// Parts the render is split into ([`RenderSettings::parts`]).
    pub parts: u32,
}

impl PartKey {
    /// The key of `world` rendered with `settings`.
    pub fn new(world: &World, settings: &RenderSettings) -> PartKey {
        PartKey {
            format: FORMAT,
            scene: format!("{:016x}", world.fingerprint),
            width: world.camera.width,
            height: world.camera.height,
            frame: world.frame,
            method: settings.method.name().into(),
            spp: settings.spp,
            seed: settings.seed,
            cov_paths: settings.cov_paths,
            cov_stride: settings.cov_stride,
            cov_depth: settings.cov_depth,
            max_luminance: settings.max_luminance.to_string(),
            denoise: settings.denoise.name().into(),
            parts: settings.parts,
        }
    }

    /// The method and the denoiser the key names.
    ///
    /// # Errors
    /// A name this covtrace does not know, as a message.
    fn method_and_denoiser(&self) -> Result<(Method, Denoise), String> {
        let method = Method::from_name(&self.method)
            .ok_or_else(|| format!("an unknown method `{}`", crate::echo(&self.method)))?;
        let denoise = Denoise::from_name(&self.denoise)
            .ok_or_else(|| format!("an unknown denoiser `{}`", crate::echo(&self.denoise)))?;
        Ok((method, denoise))
    }

    /// The settings the key records, each in its range ([`RenderSettings::check`]) and the
    /// frame at most [`crate::world::MAX_FRAME`]: a part file is user input, and a header
    /// edited by hand must not reach the image or the report (`spp: 1e308`).
    ///
    /// # Errors
    /// The first value out of range, as a message.
    fn check(&self) -> Result<(), String> {
        let (method, denoise) = self.method_and_denoiser()?;
        let max_luminance = if self.max_luminance == "inf" {
            f64::INFINITY
        } else {
            self.max_luminance
                .parse()
                .map_err(|_| format!("a luminance clamp `{}`", crate::echo(&self.max_luminance)))?
        };
        RenderSettings {
            method,
            spp: self.spp,
            seed: self.seed,
            time: None,
            cov_paths: self.cov_paths,
            cov_stride: self.cov_stride,
            cov_depth: self.cov_depth,
            max_luminance,
            denoise,
            parts: self.parts,
        }
        .check()
        .map_err(|e| e.to_string())?;
        if self.frame > crate::world::MAX_FRAME {
            return Err(format!(
                "frame {}; at most {}",
                self.frame,
                crate::world::MAX_FRAME
            ));
        }
        Ok(())
    }

    /// The first field in which `self` and `other` differ, with both values.
    fn difference(&self, other: &PartKey) -> Option<String> {
        let (a, b) = (
            serde_json::to_value(self).ok()?,
            serde_json::to_value(other).ok()?,
        );
        let (a, b) = (a.as_object()?, b.as_object()?);
        a.iter().find(|(k, v)| b.get(*k) != Some(*v)).map(|(k, v)| {
            format!(
                "`{k}` is {v} against {}",
                b.get(k).map_or("nothing".into(), |x| x.to_string())
            )
        })
    }
}

/// One part of a render: its rows of the film and of the covariance maps.
#[derive(Clone, Debug, PartialEq)]
pub struct PartFilm {
    /// The render it belongs to.
    pub key: PartKey,
    /// Which part.
    pub part: Part,
    /// The rows it owns.
    pub rows: Range<u32>,
    /// The film of those rows (`width × rows.len()` pixels).
    pub film: Film,
    /// The covariance maps of those rows, for the methods that trace them.
    pub maps: Option<Vec<PixelCov>>,
    /// The covariance pass's layout (its number of axes), 0 without maps.
    pub layout: usize,
    /// Where the part's time went.
    pub timing: Timing,
    /// Where it came from (its file, once read), for messages.
    pub source: String,
}

/// Rows `rows` of a `width`-wide per-pixel vector.
fn crop<T: Clone>(v: &[T], width: u32, rows: &Range<u32>) -> Vec<T> {
    let w = width as usize;
    v[rows.start as usize * w..rows.end as usize * w].to_vec()
}

impl PartFilm {
    /// The part `part` of a render, from the film and maps its window rendered.
    pub(crate) fn new(
        world: &World,
        settings: &RenderSettings,
        part: Part,
        win: &Window,
        film: &Film,
        maps: Option<&CovMaps>,
        timing: Timing,
    ) -> PartFilm {
        let (w, rows) = (film.width, win.owned.clone());
        let cropped = Film {
            width: w,
            height: rows.len() as u32,
            count: crop(&film.count, w, &rows),
            emitted: crop(&film.emitted, w, &rows),
            reflected: crop(&film.reflected, w, &rows),
            lum: crop(&film.lum, w, &rows),
            lum_top: crop(&film.lum_top, w, &rows),
            albedo: crop(&film.albedo, w, &rows),
            normal: crop(&film.normal, w, &rows),
            depth: crop(&film.depth, w, &rows),
        };
        let uses = reads_covariance(settings.method, settings.denoise, settings.spp, false);
        PartFilm {
            key: PartKey::new(world, settings),
            part,
            maps: maps.filter(|_| uses).map(|m| crop(&m.pixels, w, &rows)),
            layout: maps.filter(|_| uses).map_or(0, |m| m.layout),
            rows,
            film: cropped,
            timing,
            source: format!("part {part}"),
        }
    }

    /// Samples the part took.
    pub fn samples(&self) -> u64 {
        self.film.count.iter().map(|&c| u64::from(c)).sum()
    }

    /// A digest of what the part file stores of its film and maps: FNV-1a (64 bits) of
    /// every count and of the bits of every `f64` sum, in the file's channel order.
    pub fn digest(&self) -> u64 {
        use std::hash::Hasher;
        let mut h = fnv::FnvHasher::default();
        let n = self.film.count.len();
        for &c in &self.film.count {
            h.write_u32(c);
        }
        for (_, get, _) in FILM_FIELDS {
            for i in 0..n {
                h.write_u64(get(&self.film, i).to_bits());
            }
        }
        for m in self.maps.iter().flatten() {
            for (_, get, _) in MAP_FIELDS {
                h.write_u64(get(m).to_bits());
            }
        }
        h.finish()
    }
}

/// A per-pixel `f64` of a film: its channel name, how to read it and how to write it.
type FilmField = (&'static str, fn(&Film, usize) -> f64, fn(&mut Film, usize, f64));

/// The film's `f64` sums, as channels.
const FILM_FIELDS: [FilmField; 16] = [
    ("emitted.R", |f, i| f.emitted[i].x, |f, i, v| f.emitted[i].x = v),
    ("emitted.G", |f, i| f.emitted[i].y, |f, i, v| f.emitted[i].y = v),
    ("emitted.B", |f, i| f.emitted[i].z, |f, i, v| f.emitted[i].z = v),
    (
        "reflected.R",
        |f, i| f.reflected[i].x,
        |f, i, v| f.reflected[i].x = v,
    ),
    (
        "reflected.G",
        |f, i| f.reflected[i].y,
        |f, i, v| f.reflected[i].y = v,
    ),
    (
        "reflected.B",
        |f, i| f.reflected[i].z,
        |f, i, v| f.reflected[i].z = v,
    ),
    ("lum.sum", |f, i| f.lum[i][0], |f, i, v| f.lum[i][0] = v),
    ("lum.sum2", |f, i| f.lum[i][1], |f, i, v| f.lum[i][1] = v),
    ("lum.top", |f, i| f.lum_top[i], |f, i, v| f.lum_top[i] = v),
    ("albedo.R", |f, i| f.albedo[i].x, |f, i, v| f.albedo[i].x = v),
    ("albedo.G", |f, i| f.albedo[i].y, |f, i, v| f.albedo[i].y = v),
    ("albedo.B", |f, i| f.albedo[i].z, |f, i, v| f.albedo[i].z = v),
    ("normal.X", |f, i| f.normal[i].x, |f, i, v| f.normal[i].x = v),
    ("normal.Y", |f, i| f.normal[i].y, |f, i, v| f.normal[i].y = v),
    ("normal.Z", |f, i| f.normal[i].z, |f, i, v| f.normal[i].z = v),
    ("depth.Z", |f, i| f.depth[i], |f, i, v| f.depth[i] = v),
];

/// A per-pixel `f64` of the covariance maps, as [`FilmField`].
type MapField = (&'static str, fn(&PixelCov) -> f64, fn(&mut PixelCov, f64));

/// The maps' values, as channels.
const MAP_FIELDS: [MapField; 5] = [
    ("sigma.xx", |p| p.sigma[0], |p, v| p.sigma[0] = v),
    ("sigma.xy", |p| p.sigma[1], |p, v| p.sigma[1] = v),
    ("sigma.yy", |p| p.sigma[2], |p, v| p.sigma[2] = v),
    ("spp", |p| p.spp, |p, v| p.spp = v),
    ("weight", |p| p.weight, |p, v| p.weight = v),
];

/// The header attribute holding the key.
const KEY_ATTR: &str = "covtrace.key";
/// The header attribute holding the part, its rows, its layout and its timing.
const PART_ATTR: &str = "covtrace.part";

/// What a part file says of itself besides its key.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartInfo {
    index: u32,
    rows: [u32; 2],
    layout: usize,
    /// Seconds: covariance, sampling, allocation.
    timing: [f64; 3],
    /// [`PartFilm::digest`] of the data, in hex.
    digest: String,
}

impl PartFilm {
    /// Writes the part as a multi-layer OpenEXR file (module docs).
    ///
    /// # Errors
    /// The file cannot be written.
    pub fn write(&self, path: &Path) -> Result<(), RenderError> {
        use exr::prelude::*;
        let (w, rows) = (self.film.width as usize, self.rows.len());
        let n = w * rows;
        let bits = |name: &str, v: Vec<f64>| -> [AnyChannel<FlatSamples>; 2] {
            let hi = v.iter().map(|x| (x.to_bits() >> 32) as u32).collect();
            let lo = v.iter().map(|x| x.to_bits() as u32).collect();
            [
                AnyChannel::new(format!("{name}.hi").as_str(), FlatSamples::U32(hi)),
                AnyChannel::new(format!("{name}.lo").as_str(), FlatSamples::U32(lo)),
            ]
        };
        let preview = self.film.box_image();
        let mut film: Vec<AnyChannel<FlatSamples>> = vec![AnyChannel::new(
            "count",
            FlatSamples::U32(self.film.count.clone()),
        )];
        for (k, get) in [("R", 0), ("G", 1), ("B", 2)] {
            let v = preview.pixels.iter().map(|p| p[get] as f32).collect();
            film.push(AnyChannel::new(k, FlatSamples::F32(v)));
        }
        for (name, get, _) in FILM_FIELDS {
            film.extend(bits(name, (0..n).map(|i| get(&self.film, i)).collect()));
        }
        let position = Vec2(0, self.rows.start as i32);
        let layer = |name: &str, channels: Vec<AnyChannel<FlatSamples>>| {
            let mut a = LayerAttributes::named(name);
            a.layer_position = position;
            Layer::new(
                (w, rows),
                a,
                crate::output::EXR_ENCODING,
                AnyChannels::sort(SmallVec::from_vec(channels)),
            )
        };
        let mut layers = vec![layer("film", film)];
        if let Some(maps) = &self.maps {
            let mut cov = Vec::new();
            for (name, get, _) in MAP_FIELDS {
                cov.extend(bits(name, maps.iter().map(get).collect()));
            }
            layers.push(layer("cov", cov));
        }
        let mut attrs = ImageAttributes::new(IntegerBounds::from_dimensions((
            self.key.width as usize,
            self.key.height as usize,
        )));
        let info = PartInfo {
            index: self.part.index,
            rows: [self.rows.start, self.rows.end],
            layout: self.layout,
            timing: [
                self.timing.covariance,
                self.timing.sampling,
                self.timing.allocation,
            ],
            digest: format!("{:016x}", self.digest()),
        };
        let json = |v: std::result::Result<String, serde_json::Error>| -> std::result::Result<AttributeValue, RenderError> {
            let t = v.map_err(|e| RenderError::file(path, e))?;
            Ok(AttributeValue::Text(Text::from(t.as_str())))
        };
        attrs
            .other
            .insert(Text::from(KEY_ATTR), json(serde_json::to_string(&self.key))?);
        attrs
            .other
            .insert(Text::from(PART_ATTR), json(serde_json::to_string(&info))?);
        Image::from_layers(attrs, layers)
            .write()
            .to_file(path)
            .map_err(|e| RenderError::file(path, e))
    }

    /// Reads a part file written by [`PartFilm::write`], checking it whole: its key, its
    /// rows against the part it claims, its layers and channels. The header is read
    /// first, so an oversized or foreign file is refused before its pixels are.
    ///
    /// # Errors
    /// A file that cannot be read, is not a covtrace part of this format, or is
    /// inconsistent; one line naming the file.
    pub fn read(path: &Path) -> Result<PartFilm, RenderError> {
        use exr::prelude::*;
        let bad = |m: String| RenderError::file(path, m);
        match std::fs::metadata(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(bad("no such file".into()));
            }
            Ok(m) if m.is_dir() => return Err(bad("a directory, not a part file".into())),
            _ => {}
        }
        let meta = exr::meta::MetaData::read_from_file(path, false)
            .map_err(|e| bad(format!("not a readable OpenEXR file ({e})")))?;
        let text = |h: &exr::meta::header::Header, name: &str| -> Option<String> {
            // Unknown text attributes read back as the layer's own (exr's reader).
            let name = Text::from(name);
            match h
                .own_attributes
                .other
                .get(&name)
                .or_else(|| h.shared_attributes.other.get(&name))
            {
                Some(AttributeValue::Text(t)) => Some(t.to_string()),
                _ => None,
            }
        };
        let first = meta
            .headers
            .first()
            .ok_or_else(|| bad("an OpenEXR file without layers".into()))?;
        let (Some(key), Some(info)) = (text(first, KEY_ATTR), text(first, PART_ATTR)) else {
            return Err(bad("not a covtrace part file (no `covtrace.key` in its header; `covtrace render --part I/N` writes them)".into()));
        };
        let key: PartKey = serde_json::from_str(&key).map_err(|e| bad(format!("a damaged part key: {e}")))?;
        if key.format != FORMAT {
            return Err(bad(format!(
                "a part file of format {}; this covtrace reads format {FORMAT}",
                key.format
            )));
        }
        key.check().map_err(|e| bad(format!("a damaged part key: {e}")))?;
        let info: PartInfo =
            serde_json::from_str(&info).map_err(|e| bad(format!("a damaged part header: {e}")))?;
        // Seconds, each 0 to 1e9 (30 years), so that their sum in the report is finite.
        if !info.timing.iter().all(|t| (0.0..=1e9).contains(t)) {
            return Err(bad(format!(
                "a damaged part header: timing {:?} (seconds, each 0 to 1e9)",
                info.timing.map(cov_core::num)
            )));
        }
        let max = crate::scene::MAX_RESOLUTION;
        if !(1..=max).contains(&key.width) || !(1..=max).contains(&key.height) {
            return Err(bad(format!(
                "an image of {}x{} px; at most {max} px a side",
                key.width, key.height
            )));
        }
        let part = Part {
            index: info.index,
            count: key.parts,
        };
        let rows = part.rows(key.height).map_err(|e| bad(e.to_string()))?;
        if [rows.start, rows.end] != info.rows {
            return Err(bad(format!(
                "part {part} of a {}-row image owns rows {}..{}, but the file says {}..{}",
                key.height, rows.start, rows.end, info.rows[0], info.rows[1]
            )));
        }
        let (method, denoise) = key.method_and_denoiser().map_err(bad)?;
        let reads = reads_covariance(method, denoise, key.spp, false);
        if (reads && !(2..=5).contains(&info.layout)) || (!reads && info.layout != 0) {
            return Err(bad(format!(
                "a damaged part header: layout {} (a part of `{}` at {} spp has {})",
                info.layout,
                method.with_denoiser(denoise),
                key.spp,
                if reads { "2 to 5" } else { "0, no covariance maps" }
            )));
        }
        let layers = if reads { 2 } else { 1 };
        let (w, h) = (key.width as usize, rows.len());
        if meta.headers.len() != layers
            || meta.headers.iter().any(|hd| {
                hd.layer_size != Vec2(w, h)
                    || hd.own_attributes.layer_position != Vec2(0, rows.start as i32)
                    || hd.channels.list.len() > MAX_CHANNELS
                    || hd.deep
            })
        {
            return Err(bad(format!(
                "its layers are not those of part {part}: {layers} layer(s) of {w}x{h} px at row {}",
                rows.start
            )));
        }
        let image = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .all_layers()
            .all_attributes()
            .from_file(path)
            .map_err(|e| bad(format!("cannot read its pixels ({e})")))?;
        let layer = |name: &str| {
            image
                .layer_data
                .iter()
                .find(|l| l.attributes.layer_name.as_ref().is_some_and(|n| n == name))
                .ok_or_else(|| bad(format!("no `{name}` layer")))
        };
        let u32s =
            |l: &Layer<AnyChannels<FlatSamples>>, name: &str| -> std::result::Result<Vec<u32>, RenderError> {
                match l.channel_data.list.iter().find(|c| c.name.to_string() == name) {
                    Some(AnyChannel {
                        sample_data: FlatSamples::U32(v),
                        ..
                    }) if v.len() == w * h => Ok(v.clone()),
                    _ => Err(bad(format!("no u32 channel `{name}` of {w}x{h} samples"))),
                }
            };
        let f64s =
            |l: &Layer<AnyChannels<FlatSamples>>, name: &str| -> std::result::Result<Vec<f64>, RenderError> {
                let (hi, lo) = (u32s(l, &format!("{name}.hi"))?, u32s(l, &format!("{name}.lo"))?);
                Ok(hi
                    .iter()
                    .zip(&lo)
                    .map(|(&a, &b)| f64::from_bits((u64::from(a) << 32) | u64::from(b)))
                    .collect())
            };
        let fl = layer("film")?;
        let mut film = Film::new(key.width, h as u32);
        film.count = u32s(fl, "count")?;
        for (name, _, set) in FILM_FIELDS {
            for (i, v) in f64s(fl, name)?.into_iter().enumerate() {
                set(&mut film, i, v);
            }
        }
        let maps = if reads {
            let cl = layer("cov")?;
            let mut m = vec![PixelCov::default(); w * h];
            for (name, _, set) in MAP_FIELDS {
                for (p, v) in m.iter_mut().zip(f64s(cl, name)?) {
                    set(p, v);
                }
            }
            Some(m)
        } else {
            None
        };
        let [covariance, sampling, allocation] = info.timing;
        let found = PartFilm {
            key,
            part,
            rows,
            film,
            maps,
            layout: info.layout,
            timing: Timing {
                covariance,
                sampling,
                allocation,
                ..Timing::default()
            },
            source: crate::echo(&path.display().to_string()),
        };
        let digest = format!("{:016x}", found.digest());
        if digest != info.digest {
            return Err(bad(format!(
                "its data do not match the digest it was written with ({digest} against {}): the file was changed or damaged after it was written; render the part again",
                crate::echo(&info.digest)
            )));
        }
        Ok(found)
    }
}

/// A merged render.
#[derive(Clone, Debug)]
pub struct Merged {
    /// The render's key.
    pub key: PartKey,
    /// The method.
    pub method: Method,
    /// The reconstructed (and denoised) image.
    pub image: Image,
    /// The whole film.
    pub film: Film,
    /// The whole covariance maps, for the methods that trace them.
    pub maps: Option<CovMaps>,
    /// The merge's own time: reconstruction and denoising.
    pub timing: Timing,
}

/// Merges the parts of one render into its image (module docs).
///
/// # Errors
/// No part; parts of different renders; a part missing or given twice; a denoiser this
/// build lacks.
pub fn merge(parts: &[PartFilm]) -> Result<Merged, RenderError> {
    let first = parts
        .first()
        .ok_or_else(|| RenderError::setting("parts", "at least one part file", "none"))?;
    let key = &first.key;
    let bad = RenderError::Parts;
    for p in &parts[1..] {
        if let Some(d) = p.key.difference(key) {
            return Err(bad(format!(
                "{} and {} are parts of different renders: {d}",
                p.source, first.source
            )));
        }
    }
    let (w, h) = (key.width, key.height);
    let mut owner: Vec<Option<&PartFilm>> = vec![None; key.parts as usize];
    for p in parts {
        let slot = &mut owner[(p.part.index - 1) as usize];
        if let Some(q) = slot {
            return Err(bad(format!(
                "part {} is given twice: {} and {}",
                p.part, q.source, p.source
            )));
        }
        *slot = Some(p);
    }
    if let Some(k) = owner.iter().position(Option::is_none) {
        let part = Part {
            index: k as u32 + 1,
            count: key.parts,
        };
        let rows = part.rows(h)?;
        return Err(bad(format!(
            "part {part} (rows {}..{}) is missing: the parts must cover every row once",
            rows.start, rows.end
        )));
    }
    let (method, denoise) = key.method_and_denoiser().map_err(bad)?;
    let wu = w as usize;
    let mut film = Film::new(w, h);
    let mut pixels = vec![PixelCov::default(); wu * h as usize];
    let mut layout = 0;
    for p in owner.into_iter().flatten() {
        let at = p.rows.start as usize * wu;
        let f = &p.film;
        let n = f.count.len();
        film.count[at..at + n].copy_from_slice(&f.count);
        film.emitted[at..at + n].copy_from_slice(&f.emitted);
        film.reflected[at..at + n].copy_from_slice(&f.reflected);
        film.lum[at..at + n].copy_from_slice(&f.lum);
        film.lum_top[at..at + n].copy_from_slice(&f.lum_top);
        film.albedo[at..at + n].copy_from_slice(&f.albedo);
        film.normal[at..at + n].copy_from_slice(&f.normal);
        film.depth[at..at + n].copy_from_slice(&f.depth);
        if let Some(m) = &p.maps {
            pixels[at..at + m.len()].copy_from_slice(m);
            layout = p.layout;
        }
    }
    let mut timing = Timing::default();
    let maps = reads_covariance(method, denoise, key.spp, false).then_some(CovMaps {
        width: w,
        height: h,
        pixels,
        paths_per_block: key.cov_paths,
        stride: key.cov_stride,
        layout,
    });
    let (guide, secs) = timed(|| maps.as_ref().map(|m| Guide::new(m, 0.0)));
    let cands = match (&guide, method) {
        // A denoiser reconstructs from the box image: the guard's candidates go unused.
        (Some(g), Method::Cov) if denoise == Denoise::None => candidates(g, 0..h),
        _ => Vec::new(),
    };
    timing.reconstruction += secs;
    let image = reconstruct(method, guide.as_ref(), &cands, &film, denoise, &mut timing)?;
    Ok(Merged {
        key: key.clone(),
        method,
        image,
        film,
        maps,
        timing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::adaptive::{EDGE_REACH, MAX_FILTER};
    use crate::film::{CUTOFF, TILE};
    use crate::renderer::{GUIDE_MARGIN, PILOT_MARGIN};

    /// The margins are as deep as the allocation reads (module docs), in whole tiles: the
    /// guard's choice at an owned row reads the error estimates one row away, which read
    /// the samples of sources within a filter's reach (and the 3×3 mean luminance), whose
    /// filters read the covariance within the edge clamp's reach. One row of slack on each
    /// reach for rounding.
    #[test]
    fn margins_cover_what_the_allocation_reads() {
        let splat = (CUTOFF * MAX_FILTER).ceil() as u32 + 1;
        let edge = (EDGE_REACH * MAX_FILTER).ceil() as u32 + 1;
        assert!(PILOT_MARGIN >= (1 + splat).max(2) && PILOT_MARGIN.is_multiple_of(TILE));
        assert!(GUIDE_MARGIN >= 1 + splat + edge && GUIDE_MARGIN.is_multiple_of(TILE));
    }

    #[test]
    fn parts_cover_every_row_once() {
        for h in [1u32, 31, 32, 33, 96, 100, 192, 1080] {
            let bands = h.div_ceil(TILE);
            for n in (1..=bands.min(9)).chain([bands]) {
                let mut next = 0;
                for i in 1..=n {
                    let r = Part { index: i, count: n }.rows(h).unwrap();
                    assert_eq!(r.start, next);
                    assert!(r.end > r.start);
                    next = r.end;
                }
                assert_eq!(next, h);
            }
            assert!(
                Part {
                    index: 1,
                    count: bands + 1
                }
                .rows(h)
                .is_err()
            );
        }
        assert_eq!(Part::parse("2/4"), Ok(Part { index: 2, count: 4 }));
        for bad in ["0/4", "5/4", "2", "a/b", "-1/3", ""] {
            assert!(Part::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_window_is_clipped_to_the_image() {
        let w = Window::around(32..64, 100);
        assert_eq!((w.pilot, w.guide), (0..96, 0..100));
    }
}
