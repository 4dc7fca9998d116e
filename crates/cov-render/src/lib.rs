//! # cov-render: a renderer driven by covariance tracing
//!
//! A CPU path tracer (area lights with soft shadows, one indirect bounce, defocus over a
//! thin lens, motion blur over the shutter) whose scenes are RON files, and a
//! **covariance pass** that builds, for each pixel, the operator chains of the covtrace
//! library along a few camera paths and reduces them to the sensor's decisions: how many
//! samples the pixel needs over pixel × lens × time, and how wide its reconstruction
//! filter may be. The renderer never re-derives an operator's formula: it only chooses the
//! operators and their parameters from what the rays hit.
//!
//! ```no_run
//! use cov_render::{RenderSettings, Renderer, World};
//!
//! let world = World::load(std::path::Path::new("examples/scenes/cornell.ron"))?;
//! // Covariance tracing (the default method) at 16 samples per pixel on average.
//! let mut renderer = Renderer::new(&world, RenderSettings::default())?;
//! let out = renderer.render(None)?;
//! println!("{} px, {} samples, covariance pass {:.2} s of {:.2} s", out.image.pixels.len(),
//!     out.samples, out.timing.covariance, out.timing.total());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The modules, in the order data flows through them (each uses only those above it):
//!
//! | module | job |
//! |---|---|
//! | [`scene`] | the scene description a user writes (RON), checked where it is written |
//! | [`world`] | the scene as the renderer uses it: camera, lights, materials, geometry |
//! | [`texture`] | reflectance maps and their mip pyramid of colours and spectra |
//! | [`geometry`], [`material`] | shapes under a BVH; BRDFs and their covariance lobes |
//! | [`trace`] | the path tracer's radiance estimate of one camera ray |
//! | [`sampler`] | each pixel's Owen-scrambled Sobol sequence |
//! | [`film`] | where samples land (tiles, per-pixel sums) and how they become pixels |
//! | [`covpass`] | the covariance pass: operator chains per path, the per-pixel maps |
//! | [`adaptive`] | sample allocation and per-pixel filters from the maps |
//! | [`guard`] | the samples check the maps' filters, pixel by pixel |
//! | [`renderer`] | one renderer for every method: [`Renderer`], [`RenderSettings`] |
//! | [`parts`] | a render split into parts (a Slurm job array), merged exactly |
//! | [`denoise`] | Intel Open Image Denoise after reconstruction (feature `oidn`) |
//! | [`metrics`], [`mod@bench`] | image error against a reference; error against time |
//! | [`output`], [`validate`] | files written; the maps checked against reference images |
//! | [`memory`] | the memory a render may take (machine, `ulimit -v`, the job's cgroup) |
//!
//! Errors are [`RenderError`]s (scene errors are positioned [`SceneError`]s), one line each.

#![warn(missing_docs)]

pub mod adaptive;
pub mod bench;
pub mod covpass;
pub mod denoise;
mod error;
pub mod film;
pub mod geometry;
pub mod guard;
pub mod material;
pub mod memory;
pub mod metrics;
pub mod output;
pub mod parts;
pub mod renderer;
pub mod sampler;
pub mod scene;
pub mod texture;
pub mod trace;
pub mod validate;
pub mod world;

pub use covpass::{CovMaps, DEFAULT_DEPTH, MAX_COV_PATHS, MAX_DEPTH, covariance_maps};
pub use error::RenderError;
pub use film::{Image, MAX_SPP};
pub use renderer::{Method, RenderSettings, Rendered, Renderer, render};
pub use scene::SceneError;
pub use world::World;

pub use cov_core::echo;
