//! The renderer: one implementation of every sampling and reconstruction method, used by
//! `covtrace render`, `render-bench` and `render-check` alike.
//!
//! A [`Renderer`] holds a [`World`] and its [`RenderSettings`]: the method, the average
//! budget of samples per pixel, the seed, an optional time limit, and the covariance
//! pass's grid. [`Renderer::render`] traces the covariance pass when the method needs it,
//! renders the samples in one or more passes over each pixel's own Sobol sequence
//! ([`crate::sampler`]), and reconstructs the image:
//!
//! | method | samples per pixel | reconstruction |
//! |---|---|---|
//! | `uniform` | the budget, everywhere | box (a pixel's own samples) |
//! | `gauss` | the budget, everywhere | a fixed Gaussian of [`FIXED_STD`] px |
//! | `variance` | a pilot pass, then the rest ∝ relative variance | box |
//! | `cov-density` | ∝ the predicted density over pixel × lens × time | box |
//! | `cov-filter` | the budget, everywhere | each pixel's Gaussian from Σ |
//! | `cov` (default) | ∝ the predicted density | each pixel's Gaussian from Σ |
//!
//! With a time limit ([`RenderSettings::time`]) the renderer keeps adding passes of the
//! budget, each continuing every pixel's sequence, while the next pass is expected to end
//! within the limit; the image is reconstructed once, from all of them.
//!
//! ```no_run
//! use cov_render::{Method, RenderSettings, Renderer, World};
//!
//! let world = World::load(std::path::Path::new("examples/scenes/cornell.ron"))?;
//! let settings = RenderSettings { method: Method::Cov, spp: 16.0, ..RenderSettings::default() };
//! let out = Renderer::new(&world, settings)?.render(None)?;
//! println!("{} samples in {:.2} s", out.samples, out.timing.total());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Determinism: pixels draw from their own sequences and the covariance pass's tiles from
//! generators seeded by the seed and the tile; results are added in a fixed order, so an
//! image does not depend on the number of threads.

use std::ops::Range;
use std::time::Instant;

use glam::DVec3;

use crate::RenderError;
use crate::adaptive::{Guide, MAX_RATIO, allocate_floors, filter_area, relative_variance, sees_light};
use crate::covpass::{CovMaps, DEFAULT_DEPTH, MAX_COV_PATHS, MAX_DEPTH, STRIDES, covariance_rows};
use crate::denoise::Denoise;
use crate::film::{Film, Filter, Gaussian, Image, MAX_SPP, Progress};
use crate::guard::{candidate, candidates, chosen_filters, guarded};
use crate::world::World;

/// Std of the fixed Gaussian filter of the `gauss` baseline (px).
pub const FIXED_STD: f64 = 1.0;
/// Longest time limit a render accepts (s): one week.
pub const MAX_TIME: f64 = 7.0 * 24.0 * 3600.0;

/// A sampling and reconstruction method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Uniform samples, box filter: plain Monte Carlo.
    Uniform,
    /// Uniform samples, a fixed Gaussian filter of [`FIXED_STD`] px.
    Gauss,
    /// Two passes: a pilot, then samples ∝ the pilot's relative variance (box filter).
    Variance,
    /// Samples ∝ the covariance density, box filter (ablation).
    CovDensity,
    /// Uniform samples, the covariance filter without the guard (ablation).
    CovFilter,
    /// Covariance tracing without the guard (ablation): a pilot, then samples ∝ the
    /// pilot's relative standard deviation over the square root of the pixels the matched
    /// filter averages, and the matched filters.
    CovUnguarded,
    /// Covariance tracing: a pilot; the guard ([`crate::guard`]) checks the covariance
    /// filters against the pilot's samples; samples ∝ the relative standard deviation
    /// over the square root of the pixels the guarded filter averages; the guarded
    /// reconstruction. Followed by a denoiser, the denoiser receives the box image
    /// instead: the guard then decides where samples go, the denoiser how they are
    /// reconstructed (a Σ-filtered input measured worse, docs/oidn.md); below 3 spp there
    /// is no pilot, so the samples are uniform and no pass is traced
    /// ([`reads_covariance`]).
    Cov,
}

impl Method {
    /// Every method, baselines first.
    pub const ALL: [Method; 7] = [
        Method::Uniform,
        Method::Gauss,
        Method::Variance,
        Method::CovDensity,
        Method::CovFilter,
        Method::CovUnguarded,
        Method::Cov,
    ];

    /// Whether it takes a pilot pass and allocates the rest from it.
    pub fn has_pilot(self) -> bool {
        matches!(self, Method::Variance | Method::CovUnguarded | Method::Cov)
    }

    /// Its name in tables and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Uniform => "uniform",
            Method::Gauss => "gauss",
            Method::Variance => "variance",
            Method::CovDensity => "cov-density",
            Method::CovFilter => "cov-filter",
            Method::CovUnguarded => "cov-unguarded",
            Method::Cov => "cov",
        }
    }

    /// The method of a name.
    pub fn from_name(s: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == s)
    }

    /// The name of this method followed by a denoiser, as render-bench writes it:
    /// `cov`, `cov+oidn`, `uniform+oidn-color`.
    pub fn with_denoiser(self, d: Denoise) -> String {
        match d {
            Denoise::None => self.name().to_string(),
            d => format!("{}+{}", self.name(), d.name()),
        }
    }

    /// The method and denoiser of a name written as [`Method::with_denoiser`] writes it.
    pub fn parse_with_denoiser(s: &str) -> Option<(Method, Denoise)> {
        match s.split_once('+') {
            None => Some((Method::from_name(s)?, Denoise::None)),
            Some((m, d)) => Some((
                Method::from_name(m)?,
                Denoise::from_name(d).filter(|d| *d != Denoise::None)?,
            )),
        }
    }

    /// Whether it is a covariance method, one that traces the covariance pass unless
    /// nothing reads it ([`reads_covariance`]).
    pub fn uses_covariance(self) -> bool {
        matches!(
            self,
            Method::CovDensity | Method::CovFilter | Method::CovUnguarded | Method::Cov
        )
    }
}

/// What to render and how.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// The sampling and reconstruction method.
    pub method: Method,
    /// Average samples per pixel of one pass (1 to [`MAX_SPP`]).
    pub spp: f64,
    /// Seed of the random numbers.
    pub seed: u64,
    /// Keep adding passes until this many seconds (covariance pass included) are spent;
    /// `None`: one pass.
    pub time: Option<f64>,
    /// Covariance paths per block of the covariance grid (1 to [`MAX_COV_PATHS`]).
    pub cov_paths: u32,
    /// Side of the covariance grid's blocks (px, one of [`STRIDES`]).
    pub cov_stride: u32,
    /// Surface vertices a covariance path follows (1 to the scene's
    /// [`World::max_depth`], the path tracer's, at most [`MAX_DEPTH`]; 1,
    /// [`DEFAULT_DEPTH`]: camera → hit → light only).
    pub cov_depth: u32,
    /// Every sample's luminance is clamped to this (colour scaled down); `∞` for an
    /// unbiased image. A finite clamp is biased: for measuring the spectrum of a reference
    /// without its rare caustic fireflies (`render-check`), never for an image.
    pub max_luminance: f64,
    /// A denoiser run on the reconstructed image ([`crate::denoise`]).
    pub denoise: Denoise,
    /// Parts the image's rows are split into (1 to [`MAX_PARTS`], at most one per tile
    /// row): each part spends its own pixels' share of the budget ([`part_rows`]). 1 (the
    /// default) distributes the budget over the whole image; a render in `N` parts (the
    /// `parts` module) is this render with `parts: N`, bit for bit.
    pub parts: u32,
}

impl Default for RenderSettings {
    /// Covariance tracing (`cov`) at 16 samples per pixel, seed 1, one pass, one
    /// covariance path per 4×4 block, through [`DEFAULT_DEPTH`] surface vertex.
    fn default() -> RenderSettings {
        RenderSettings {
            method: Method::Cov,
            spp: 16.0,
            seed: 1,
            time: None,
            cov_paths: 1,
            cov_stride: 4,
            cov_depth: DEFAULT_DEPTH,
            max_luminance: f64::INFINITY,
            denoise: Denoise::None,
            parts: 1,
        }
    }
}

impl RenderSettings {
    /// Checks every setting's range.
    ///
    /// # Errors
    /// The first setting out of range, named as in [`RenderSettings`].
    pub fn check(&self) -> Result<(), RenderError> {
        let max = f64::from(MAX_SPP);
        if !(self.spp.is_finite() && (1.0..=max).contains(&self.spp)) {
            return Err(RenderError::setting(
                "spp",
                format!("1 to {MAX_SPP} samples per pixel"),
                cov_core::num(self.spp),
            ));
        }
        if let Some(t) = self.time
            && !(t.is_finite() && t > 0.0 && t <= MAX_TIME)
        {
            return Err(RenderError::setting(
                "time",
                format!("more than 0 and at most {MAX_TIME} s"),
                cov_core::num(t),
            ));
        }
        if !(1..=MAX_COV_PATHS).contains(&self.cov_paths) {
            return Err(RenderError::setting(
                "cov_paths",
                format!("1 to {MAX_COV_PATHS}"),
                self.cov_paths,
            ));
        }
        if !STRIDES.contains(&self.cov_stride) {
            return Err(RenderError::setting(
                "cov_stride",
                format!("one of {STRIDES:?}"),
                self.cov_stride,
            ));
        }
        if !(1..=MAX_DEPTH).contains(&self.cov_depth) {
            return Err(RenderError::setting(
                "cov_depth",
                format!("1 to {MAX_DEPTH}"),
                self.cov_depth,
            ));
        }
        if !(1..=MAX_PARTS).contains(&self.parts) {
            return Err(RenderError::setting(
                "parts",
                format!("1 to {MAX_PARTS}"),
                self.parts,
            ));
        }
        if self.max_luminance.is_nan() || self.max_luminance <= 0.0 {
            return Err(RenderError::setting(
                "max_luminance",
                "more than 0",
                self.max_luminance,
            ));
        }
        Ok(())
    }
}

/// A rendered image and how it was made.
#[derive(Clone, Debug)]
pub struct Rendered {
    /// The method.
    pub method: Method,
    /// Average samples per pixel of one pass.
    pub budget: f64,
    /// Passes rendered (1 without a time limit).
    pub passes: u32,
    /// Whether the passes stopped before the time limit because every pixel holds
    /// [`MAX_SPP`] samples.
    pub capped: bool,
    /// Samples taken in all.
    pub samples: u64,
    /// The reconstructed image.
    pub image: Image,
    /// The samples, as the film holds them (sums, counts, luminance moments).
    pub film: Film,
    /// Where the time went.
    pub timing: Timing,
}

/// Renders a world with one method: see the module docs.
#[derive(Debug)]
pub struct Renderer<'w> {
    pub(crate) world: &'w World,
    settings: RenderSettings,
    maps: Option<CovMaps>,
    /// The rows `maps` were traced over.
    maps_rows: Range<u32>,
    guide: Option<Guide>,
    /// Whether `guide` was given ([`Renderer::with_guide`]) rather than traced.
    guide_given: bool,
}

impl<'w> Renderer<'w> {
    /// A renderer of `world` with `settings`.
    ///
    /// # Errors
    /// A setting out of range ([`RenderSettings::check`]), or more parts than the image
    /// has tile rows ([`part_rows`]).
    pub fn new(world: &'w World, settings: RenderSettings) -> Result<Renderer<'w>, RenderError> {
        settings.check()?;
        crate::covpass::check_depth(world, settings.cov_depth, "cov_depth")?;
        part_rows(world.camera.height, 1, settings.parts)?;
        let (w, h) = (world.camera.width, world.camera.height);
        check_memory(w, h, settings.method, available_memory())?;
        Ok(Renderer {
            world,
            settings,
            maps: None,
            maps_rows: 0..0,
            guide: None,
            guide_given: false,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Uses `guide` (made from this world's covariance maps at the same resolution, by
    /// another renderer or an earlier run) instead of tracing the pass again; its time
    /// is counted in the [`Timing::covariance`] of every render that reads it
    /// ([`Renderer::reads_guide`]).
    ///
    /// # Errors
    /// A guide of another size.
    pub fn with_guide(mut self, guide: Guide) -> Result<Renderer<'w>, RenderError> {
        let (w, h) = (self.world.camera.width, self.world.camera.height);
        let n = w as usize * h as usize;
        if guide.matched.len() != n || guide.density.len() != n {
            return Err(RenderError::Size {
                what: "a covariance guide against the image",
                a_w: guide.width,
                a_h: guide.height,
                b_w: w,
                b_h: h,
            });
        }
        self.guide = Some(guide);
        self.guide_given = true;
        Ok(self)
    }

    /// Traces the covariance pass (once; later calls keep the first maps) and makes the
    /// guide from it, reporting each finished tile to `progress`.
    ///
    /// # Errors
    /// An operator that rejects what the scene gives it, with the pixel.
    pub fn trace_covariance(&mut self, progress: Progress<'_>) -> Result<&CovMaps, RenderError> {
        self.trace_rows(0..self.world.camera.height, progress)?;
        self.maps
            .as_ref()
            .ok_or_else(|| RenderError::Camera("the covariance pass left no maps".into()))
    }

    /// How many times one [`Renderer::render`] without a time limit calls its progress
    /// callback: once per tile of every pass, and of the covariance pass when it is still
    /// to be traced.
    pub fn progress_len(&self) -> usize {
        self.window_progress_len(&Window::whole(self.world.camera.height))
    }

    /// The covariance maps, once traced.
    pub fn maps(&self) -> Option<&CovMaps> {
        self.maps.as_ref()
    }

    /// The guide (sample density and matched filters), once traced or given.
    pub fn guide(&self) -> Option<&Guide> {
        self.guide.as_ref()
    }

    /// Renders the image: the covariance pass first when the method needs it and no guide
    /// was given, then the passes, then the reconstruction. `progress` is called once per
    /// finished tile of every pass (the covariance pass's tiles included).
    ///
    /// # Errors
    /// The covariance pass's errors ([`Renderer::trace_covariance`]).
    pub fn render(&mut self, progress: Progress<'_>) -> Result<Rendered, RenderError> {
        let win = Window::whole(self.world.camera.height);
        let Sampled {
            film,
            mut timing,
            passes,
            capped,
            cands,
        } = self.sample(&win, progress)?;
        let method = self.settings.method;
        let guide = self.guide.as_ref().filter(|_| self.reads_guide());
        let image = reconstruct(method, guide, &cands, &film, self.settings.denoise, &mut timing)?;
        Ok(Rendered {
            method,
            budget: self.settings.spp,
            passes,
            capped,
            samples: film.count.iter().map(|&c| u64::from(c)).sum(),
            image,
            film,
            timing,
        })
    }

    /// Progress calls of a render of `win`: one per tile of each stage.
    pub(crate) fn window_progress_len(&self, win: &Window) -> usize {
        let (w, s) = (self.world.camera.width, &self.settings);
        let tiles = |r: &Range<u32>| {
            crate::film::tiles(w, self.world.camera.height)
                .iter()
                .filter(|t| r.contains(&t.1))
                .count()
        };
        let cov = if self.reads_guide() && !self.guide_given && !self.has_maps(&win.guide) {
            tiles(&win.guide)
        } else {
            0
        };
        let pilot = if s.method.has_pilot() && variance_pilot(s.spp).is_some() {
            tiles(&win.pilot)
        } else {
            0
        };
        cov + pilot + tiles(&win.owned)
    }

    /// Whether this render reads the covariance pass ([`reads_covariance`] of its
    /// settings).
    pub fn reads_guide(&self) -> bool {
        let s = &self.settings;
        reads_covariance(s.method, s.denoise, s.spp, s.time.is_some())
    }

    /// Whether maps of `rows` exist.
    fn has_maps(&self, rows: &Range<u32>) -> bool {
        self.maps.is_some() && self.maps_rows.start <= rows.start && rows.end <= self.maps_rows.end
    }

    /// Traces the covariance pass over `rows` unless maps of them exist.
    fn trace_rows(&mut self, rows: Range<u32>, progress: Progress<'_>) -> Result<(), RenderError> {
        if self.has_maps(&rows) {
            return Ok(());
        }
        let s = &self.settings;
        let (maps, secs) = timed(|| {
            covariance_rows(
                self.world,
                s.cov_paths,
                s.cov_stride,
                s.cov_depth,
                s.seed,
                rows.clone(),
                progress,
            )
        });
        let maps = maps?;
        if !self.guide_given {
            self.guide = Some(Guide::new(&maps, secs));
        }
        self.maps = Some(maps);
        self.maps_rows = rows;
        Ok(())
    }

    /// The samples of `win`'s rows: the covariance pass when the method needs it, the
    /// pilot and the passes; the film, the timing, the passes and the guard's candidates.
    pub(crate) fn sample(&mut self, win: &Window, progress: Progress<'_>) -> Result<Sampled, RenderError> {
        let start = Instant::now();
        let method = self.settings.method;
        let reads_guide = self.reads_guide();
        if reads_guide && !self.guide_given {
            self.trace_rows(win.guide.clone(), progress)?;
        }
        let guide = if reads_guide { self.guide.as_ref() } else { None };
        let mut timing = Timing {
            covariance: guide.map_or(0.0, |g| g.secs),
            ..Timing::default()
        };
        let (world, s) = (self.world, &self.settings);
        let (w, h) = (world.camera.width, world.camera.height);
        let n = w as usize * h as usize;
        let hi = ((s.spp * MAX_RATIO).ceil() as u32).clamp(1, MAX_SPP);
        let mut film = Film::new(w, h);
        let sample = |film: &mut Film, counts: &[u32], rows: &Range<u32>, timing: &mut Timing| {
            timing
                .sample(|| film.render_rows(world, counts, s.seed, s.max_luminance, rows.clone(), progress));
        };
        // Samples per pixel in proportion to `weights`, each part of the rows its own budget.
        let share = |weights: &[f64], floors: &[u32], hi: u32, pow2: bool| {
            allocate_parts(w, h, s.parts, &win.owned, weights, floors, s.spp, hi, pow2)
        };
        // The first pass.
        let (mut counts, t) = timed(|| match (method, guide) {
            (Method::CovDensity, Some(g)) => {
                let lo = ((s.spp / 4.0).floor() as u32).max(1);
                share(&g.density, &vec![lo; n], hi, false)
            }
            _ => share(&vec![1.0; n], &vec![1; n], MAX_SPP, false),
        });
        // The allocation after a pilot, per pixel: a weight and a floor. The weight is the
        // relative standard deviation (blurred over 3×3 pixels); for covariance tracing,
        // over the square root of the number of pixels its filter averages (`filter_area`:
        // the matched filter, or the one the guard chose on the samples so far). Counts ∝
        // these weights minimise the summed relative error Σ σᵢ²/(nᵢ Aᵢ (μᵢ² + ε)) of
        // pixels whose noise a filter averages over Aᵢ pixels, for a fixed total. The
        // guarded method also keeps, in every pixel whose samples the guard would not
        // filter, at least the budget: sample variances overstate the error of
        // quasi-Monte Carlo means where the integrand is smooth, so a pixel that no filter
        // helps never gets fewer samples than plain Monte Carlo gives it.
        // The guard's candidate filters, once per render (they depend on the guide alone).
        let (cands, secs) = timed(|| match (method, guide) {
            (Method::Cov, Some(g)) => candidates(g, win.pilot.clone()),
            _ => Vec::new(),
        });
        timing.allocation += secs;
        // A filter averages reflected light only: the emission of a light seen directly
        // stays in its pixel (the film's box), so a pixel near one ([`sees_light`]) takes its
        // samples as an unfiltered pixel does, whatever filter its reflected light has.
        let plan = |film: &Film, lo: u32| -> (Vec<f64>, Vec<u32>) {
            let rv = relative_variance(film, win.pilot.clone());
            match (method, guide) {
                (Method::CovUnguarded, Some(g)) => {
                    let lit = sees_light(film);
                    (
                        (0..n)
                            .map(|i| match lit[i] {
                                true => rv[i],
                                false => rv[i] / filter_area(g.matched[i]).sqrt(),
                            })
                            .collect(),
                        vec![lo; n],
                    )
                }
                (Method::Cov, Some(_)) => {
                    let chosen = chosen_filters(&cands, film, s.spp, win.pilot.clone());
                    let keep = (s.spp.floor() as u32).max(lo);
                    let lit = sees_light(film);
                    (0..n)
                        .map(|i| match chosen[i] {
                            Some(f) if !lit[i] => (rv[i] / filter_area(f.cov()).sqrt(), lo),
                            _ => (rv[i], keep),
                        })
                        .unzip()
                }
                _ => (rv, vec![lo; n]),
            }
        };
        match method {
            m if m.has_pilot() => {
                if let Some(p) = variance_pilot(s.spp) {
                    sample(&mut film, &vec![p; n], &win.pilot, &mut timing);
                    let (rest, secs) = timed(|| {
                        let (wts, floors) = plan(&film, p);
                        share(&wts, &floors, hi.max(p), true)
                            .into_iter()
                            .map(|c| c.saturating_sub(p))
                            .collect::<Vec<u32>>()
                    });
                    timing.allocation += secs;
                    sample(&mut film, &rest, &win.owned, &mut timing);
                } else {
                    sample(&mut film, &counts, &win.owned, &mut timing);
                }
            }
            _ => {
                if method == Method::CovDensity {
                    timing.allocation += t;
                }
                sample(&mut film, &counts, &win.owned, &mut timing);
            }
        }
        // More passes while the next one is expected to end within the time limit.
        let mut passes = 1u32;
        let mut capped = false;
        if let Some(limit) = s.time {
            loop {
                let pass_secs = timing.sampling / f64::from(passes);
                let elapsed = start.elapsed().as_secs_f64();
                if elapsed + pass_secs > limit {
                    break;
                }
                // A pixel at MAX_SPP takes no more (`Film::render`); the passes go on
                // while one of the rows' pixels has room.
                let w = film.width as usize;
                let rows = win.owned.start as usize * w..win.owned.end as usize * w;
                if film.count[rows].iter().all(|&c| c >= MAX_SPP) {
                    capped = true;
                    break;
                }
                if method.has_pilot() {
                    let (c, secs) = timed(|| {
                        let (wts, floors) = plan(&film, 1);
                        share(&wts, &floors, hi, true)
                    });
                    timing.allocation += secs;
                    counts = c;
                }
                sample(&mut film, &counts, &win.owned, &mut timing);
                passes += 1;
            }
        }
        Ok(Sampled {
            film,
            timing,
            passes,
            capped,
            cands,
        })
    }
}

/// What [`Renderer::sample`] gives: the film, the timing, the passes and the guard's
/// candidate filters (empty for the other methods).
pub(crate) struct Sampled {
    pub film: Film,
    pub timing: Timing,
    pub passes: u32,
    pub capped: bool,
    pub cands: Vec<Vec<Gaussian>>,
}

/// Peak resident memory of a render per pixel of its image (bytes), by method: the slope
/// of the peak resident size (`/usr/bin/time -v`) between renders of cornell at 1024×768
/// and 2048×1536 px, 4 spp, outputs written (2026-11-28), rounded up to the next 10. The
/// scene's own memory (meshes, textures) comes on top, but it is loaded before the check
/// and so is no longer counted as available.
pub fn peak_bytes_per_pixel(method: Method) -> u64 {
    match method {
        Method::Uniform => 240,
        Method::Variance => 250,
        Method::Gauss => 280,
        Method::CovDensity | Method::CovUnguarded => 470,
        Method::CovFilter => 490,
        Method::Cov => 790,
    }
}

pub use crate::memory::available_memory;

/// Refuses a render of `width × height` px with `method` whose peak memory
/// ([`peak_bytes_per_pixel`]) exceeds `available` bytes, in one line that says both, before
/// any allocation; a process that ran out of memory half way would abort instead.
///
/// # Errors
/// [`RenderError::Setting`] on the size.
pub fn check_memory(
    width: u32,
    height: u32,
    method: Method,
    available: Option<u64>,
) -> Result<(), RenderError> {
    let Some(available) = available else {
        return Ok(());
    };
    let per = peak_bytes_per_pixel(method);
    let need = u64::from(width) * u64::from(height) * per;
    if need <= available {
        return Ok(());
    }
    let gb = |b: u64| b as f64 / 1e9;
    Err(RenderError::setting(
        "size",
        format!(
            "an image this process can hold: `{}` needs about {:.1} GB at this size ({per} bytes a pixel at its peak), and {:.1} GB are available to it (the machine's free memory, `ulimit -v`, the job's cgroup)",
            method.name(),
            gb(need),
            gb(available)
        ),
        format!("{width}x{height}"),
    ))
}

/// The tile rows ([`crate::film::TILE`] px each, the last one possibly shorter) of an image
/// of `height` rows: the most parts it splits into ([`part_rows`]).
pub fn tile_rows(height: u32) -> u32 {
    height.div_ceil(crate::film::TILE)
}

/// Most parts a render splits into ([`RenderSettings::parts`]): one per tile row of the
/// tallest image.
pub const MAX_PARTS: u32 = crate::scene::MAX_RESOLUTION / crate::film::TILE;

/// The rows of part `index` (1-based) of `parts` in an image of `height` rows: whole tile
/// rows, `⌊(index−1)·T/parts⌋ .. ⌊index·T/parts⌋` of the image's `T` tile rows, so that the
/// parts cover every row once.
///
/// # Errors
/// `index` outside `1..=parts`, or more parts than the image has tile rows.
pub fn part_rows(height: u32, index: u32, parts: u32) -> Result<Range<u32>, RenderError> {
    let tile = crate::film::TILE;
    let rows = tile_rows(height);
    if parts == 0 || parts > rows {
        let s = if rows == 1 { "" } else { "s" };
        return Err(RenderError::setting(
            "parts",
            format!("1 to {rows} for this image (its {height} rows make {rows} tile row{s} of {tile})"),
            parts,
        ));
    }
    if index == 0 || index > parts {
        return Err(RenderError::setting(
            "part",
            format!("1 to {parts} of {parts}"),
            format!("part {index} of {parts}"),
        ));
    }
    let at = |k: u32| (u64::from(k) * u64::from(rows) / u64::from(parts)) as u32 * tile;
    Ok(at(index - 1)..at(index).min(height))
}

/// Rows of pilot samples a part of a render takes on each side of its own rows: the
/// guard's choice at an owned row reads error estimates one row away, which read the
/// samples within the widest filter's reach (`CUTOFF` × [`crate::adaptive::MAX_FILTER`] =
/// 24 rows) and their 3×3 mean luminance; 25 rows, in whole tiles.
pub const PILOT_MARGIN: u32 = 2 * crate::film::TILE;
/// Rows of the covariance pass a part of a render traces on each side of its own rows:
/// the filters of the pilot's rows that matter are kept off the edges the pass saw up to
/// `EDGE_REACH` × `MAX_FILTER` = 16 rows further; 41 rows, in whole tiles.
pub const GUIDE_MARGIN: u32 = 3 * crate::film::TILE;

/// The rows a render computes at each stage: its own, the pilot's and the covariance
/// pass's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Window {
    /// The rows whose samples the render keeps.
    pub owned: Range<u32>,
    /// The rows of the pilot.
    pub pilot: Range<u32>,
    /// The rows of the covariance pass.
    pub guide: Range<u32>,
}

impl Window {
    /// The whole image.
    pub fn whole(height: u32) -> Window {
        Window {
            owned: 0..height,
            pilot: 0..height,
            guide: 0..height,
        }
    }

    /// `owned` and its margins ([`PILOT_MARGIN`], [`GUIDE_MARGIN`]), clipped to the image.
    pub fn around(owned: Range<u32>, height: u32) -> Window {
        let grow = |m: u32| owned.start.saturating_sub(m)..(owned.end.saturating_add(m)).min(height);
        Window {
            pilot: grow(PILOT_MARGIN),
            guide: grow(GUIDE_MARGIN),
            owned,
        }
    }
}

/// Samples per pixel ∝ `weights` between `floors` and `hi` ([`allocate_floors`]), each of
/// the `parts` parts of an image of `height` rows ([`part_rows`]) that `owned` holds
/// spending `spp` times its pixels; 0 outside `owned`.
#[allow(clippy::too_many_arguments)]
fn allocate_parts(
    width: u32,
    height: u32,
    parts: u32,
    owned: &Range<u32>,
    weights: &[f64],
    floors: &[u32],
    spp: f64,
    hi: u32,
    pow2: bool,
) -> Vec<u32> {
    let w = width as usize;
    let mut counts = vec![0; weights.len()];
    for k in 1..=parts {
        // `Renderer::new` checked `parts` against the image.
        let Ok(rows) = part_rows(height, k, parts) else {
            continue;
        };
        if rows.start < owned.start || rows.end > owned.end {
            continue;
        }
        let r = rows.start as usize * w..rows.end as usize * w;
        let c = allocate_floors(
            &weights[r.clone()],
            spp * r.len() as f64,
            &floors[r.clone()],
            hi,
            pow2,
        );
        counts[r].copy_from_slice(&c);
    }
    counts
}

/// The image of `film` with `method`'s reconstruction (`cands`: the guard's candidates over
/// every row, for [`Method::Cov`]), then the denoiser; the time goes to `timing`.
pub(crate) fn reconstruct(
    method: Method,
    guide: Option<&Guide>,
    cands: &[Vec<Gaussian>],
    film: &Film,
    denoise: Denoise,
    timing: &mut Timing,
) -> Result<Image, RenderError> {
    let (w, h) = (film.width, film.height);
    let n = film.count.len();
    // A denoiser reconstructs the covariance method's samples itself, from the box image.
    let guarded_image = denoise == Denoise::None;
    let (image, secs) = timed(|| match (method, guide) {
        (Method::Cov, Some(_)) if guarded_image => {
            let gd = guarded(cands, film, 0..h);
            let pixels = (0..n)
                .map(|i| match film.count[i] {
                    0 => DVec3::ZERO,
                    c => film.emitted[i] / f64::from(c) + gd.reflected[i],
                })
                .collect();
            Image {
                width: w,
                height: h,
                pixels,
            }
        }
        _ => {
            let filter = match (method, guide) {
                (Method::Gauss, _) => Filter::Fixed(Gaussian::isotropic(FIXED_STD)),
                (Method::CovFilter | Method::CovUnguarded, Some(g)) => {
                    Filter::PerPixel(candidate(g, 1.0, 0..h))
                }
                _ => Filter::Box,
            };
            film.image(&filter)
        }
    });
    timing.reconstruction += secs;
    Ok(match denoise {
        Denoise::None => image,
        d => {
            let guides = (d == Denoise::Oidn).then(|| film.aovs());
            let (out, secs) = timed(|| crate::denoise::oidn(&image, guides.as_ref()));
            timing.denoising += secs;
            out?
        }
    })
}

/// Whether a render of `method` followed by `denoise` at `spp` (`time_limited`: with
/// [`RenderSettings::time`]) reads the covariance pass. Covariance tracing followed by a
/// denoiser reads Σ only to allocate samples after a pilot: at a budget too small for one
/// (below 3 spp, without a time limit) the pass and the guard's candidates would go
/// unused, so they are neither made nor timed, and the render is uniform sampling's with
/// its denoiser.
pub fn reads_covariance(method: Method, denoise: Denoise, spp: f64, time_limited: bool) -> bool {
    let unread =
        method == Method::Cov && denoise != Denoise::None && variance_pilot(spp).is_none() && !time_limited;
    method.uses_covariance() && !unread
}

/// The variance method's pilot: a quarter of the budget, at least 2 samples per pixel
/// (for a variance); `None` when the budget leaves nothing after it (one uniform pass).
fn variance_pilot(spp: f64) -> Option<u32> {
    let pilot = (spp / 4.0).floor().max(2.0);
    (spp >= pilot + 1.0).then_some(pilot as u32)
}

/// A uniform render of `spp` samples per pixel with the box filter: plain Monte Carlo
/// ([`Method::Uniform`] through [`Renderer`]); `spp` is clamped to 1..=[`MAX_SPP`].
pub fn render(world: &World, spp: u32, seed: u64) -> Image {
    let settings = RenderSettings {
        method: Method::Uniform,
        spp: f64::from(spp.clamp(1, MAX_SPP)),
        seed,
        ..RenderSettings::default()
    };
    // Uniform settings in range never fail: no covariance pass runs.
    Renderer::new(world, settings)
        .and_then(|mut r| r.render(None))
        .map_or_else(
            |_| Image::new(world.camera.width, world.camera.height),
            |r| r.image,
        )
}

/// Runs `f`, returning its result and the seconds it took.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64())
}

/// Where a run spent its time (wall-clock seconds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// The covariance pass (with the filters), for the covariance methods.
    pub covariance: f64,
    /// Tracing samples (every pass).
    pub sampling: f64,
    /// Reconstructing the image from the film (the filters' splat).
    pub reconstruction: f64,
    /// Allocating samples to pixels (the variance method's analysis of its pilot pass).
    pub allocation: f64,
    /// The denoiser, when one runs.
    pub denoising: f64,
}

impl Timing {
    /// The run's total.
    pub fn total(&self) -> f64 {
        self.covariance + self.sampling + self.reconstruction + self.allocation + self.denoising
    }

    fn sample(&mut self, f: impl FnOnce()) {
        let ((), secs) = timed(f);
        self.sampling += secs;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A render whose peak would exceed the memory available is refused before it starts,
    /// in one line naming the size, the method, the need and what is available; one that
    /// fits, or a machine that does not say, passes.
    #[test]
    fn a_render_larger_than_memory_is_refused_up_front() {
        let gb24 = Some(24_000_000_000);
        let e = check_memory(8192, 8192, Method::Cov, gb24)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "size must be an image this process can hold: `cov` needs about 53.0 GB at this size (790 bytes a pixel at its peak), and 24.0 GB are available to it (the machine's free memory, `ulimit -v`, the job's cgroup), got 8192x8192"
        );
        assert!(check_memory(8192, 8192, Method::Uniform, Some(20_000_000_000)).is_ok());
        assert!(check_memory(256, 192, Method::Cov, Some(100_000_000)).is_ok());
        assert!(check_memory(8192, 8192, Method::Cov, None).is_ok());
        // With the memory a process limit leaves (`ulimit -v 600000`), in one line.
        let e = check_memory(4096, 4096, Method::Uniform, Some(600_000 * 1024))
            .unwrap_err()
            .to_string();
        assert!(e.contains("4096x4096") && !e.contains('\n'), "{e}");
    }

    /// Only covariance tracing followed by a denoiser, with no pilot and no time limit,
    /// leaves Σ unread.
    #[test]
    fn what_reads_the_covariance_pass() {
        let (cov, oidn, none) = (Method::Cov, Denoise::Oidn, Denoise::None);
        assert!(!reads_covariance(cov, oidn, 1.0, false));
        assert!(!reads_covariance(cov, Denoise::OidnColor, 2.0, false));
        assert!(!reads_covariance(cov, oidn, 2.9, false));
        assert!(reads_covariance(cov, oidn, 3.0, false));
        assert!(reads_covariance(cov, oidn, 2.0, true));
        assert!(reads_covariance(cov, none, 1.0, false));
        assert!(reads_covariance(Method::CovFilter, oidn, 2.0, false));
        assert!(reads_covariance(Method::CovDensity, oidn, 2.0, false));
        assert!(!reads_covariance(Method::Uniform, none, 16.0, false));
    }
}
