//! # cov-render: a renderer driven by covariance tracing
//!
//! A CPU path tracer (area lights with soft shadows, one indirect bounce, defocus over a
//! thin lens, motion blur over the shutter) whose scenes are RON files ([`scene`]), and a
//! **covariance pass** ([`covpass`]) that builds, for each pixel, the operator chains of
//! the covtrace library along a few camera paths and reduces them to the sensor's
//! decisions: how many samples the pixel needs over pixel × lens × time, and how wide its
//! reconstruction filter may be. The renderer never re-derives an operator's formula: it
//! only chooses the operators and their parameters from what the rays hit.
//!
//! ```no_run
//! use cov_render::{World, covariance_maps, render};
//!
//! let world = World::load(std::path::Path::new("examples/scenes/cornell.ron"))?;
//! let image = render(&world, 16, 1); // 16 samples per pixel, seed 1
//! let maps = covariance_maps(&world, 4, 1)?; // 4 covariance paths per pixel
//! println!("{} px, predicted {:.1} spp at the centre", image.pixels.len(),
//!     maps.pixels[maps.pixels.len() / 2].spp);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Rendering with the covariance pass ([`mod@bench`]): samples are allocated to pixels in
//! proportion to the predicted density, and each pixel's samples are reconstructed by a
//! Gaussian filter made from its image-space Σ ([`film`]), scaled per pixel to balance the
//! bias the spectrum predicts against the noise of the samples it averages. The baselines a
//! user would pick without covariance tracing (uniform sampling with a box or a fixed
//! Gaussian filter, two-pass variance-driven sampling) run through the same film, and
//! `covtrace render-bench` measures image error against wall-clock time for all of them.
//!
//! Determinism: pixels draw from their own Owen-scrambled Sobol sequences ([`sampler`])
//! and the covariance pass's tiles from generators seeded by the scene seed and the tile
//! index; results are added in a fixed order, so an image is the same on any number of
//! threads.

#![warn(missing_docs)]

pub mod bench;
pub mod covpass;
pub mod film;
pub mod geometry;
pub mod material;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod trace;
pub mod validate;
pub mod world;

pub use render::{CovMaps, Image, MAX_COV_PATHS, MAX_SPP, covariance_maps, render, render_adaptive};
pub use scene::SceneError;
pub use world::World;

pub use cov_core::echo;
