//! # cov-sensor: what a renderer does with Σ at the sensor
//!
//! At the sensor, Σ (with the aperture and shutter windows of cov-defocus and cov-motion
//! applied) becomes per-pixel decisions (PHYSICS.md section 4):
//!
//! 1. the **pixel filter** is a window on the sensor position (rule 2), a Gaussian of std
//!    `filter` pixels;
//! 2. the **image-space covariance** is Σ integrated over the lens (`u`, `v`) and the
//!    shutter (`t`) (rule 4), converted to pixel units: frequencies in cycles per pixel,
//!    `Σ_px = Σ_m · pitch²`, with `pitch = 2·distance·tan(fov_x/2) / width` (m per pixel);
//! 3. the **sampling density** over the sampled domain, image × lens × time, in
//!    coordinates (pixels, lens position in m, s): `(2k)ⁿ √det Σ`, with the **Nyquist factor**
//!    `k` (default 2: a spectrum of std σ is taken to extend to ±2σ, so samples are spaced
//!    `1/(4σ)`); samples per pixel multiply it by the domain's extent, `1 px` per image axis,
//!    `√(2π)·aperture` per lens axis and `√(2π)·shutter` for time (the integrals of the
//!    Gaussian windows);
//! 4. the **reconstruction filter**: the Gaussian whose spectrum matches the image-space Σ,
//!    primal covariance `(4π² Σ_px)⁻¹` in pixels², clamped at `max_filter` pixels where Σ
//!    is singular.
//!
//! The lens position `p` of a ray reaching the sensor at `x_s` with direction `u` is
//! `p = x_s − distance·u`, the change of variables used for the lens part of the density.
//!
//! | operator | parameter | unit | domain | meaning |
//! |---|---|---|---|---|
//! | [`Sensor`] | `width` | px | ≥ 1 | image width |
//! | [`Sensor`] | `fov_x` | rad | (0, π) | horizontal field of view |
//! | [`Sensor`] | `distance` | m | > 0 | lens (or pinhole) to sensor, default 1 |
//! | [`Sensor`] | `filter` | px | > 0 | pixel filter std, default 0.5 |
//! | [`Sensor`] | `aperture` | m | > 0, optional | the lens's aperture std (sampled lens axes) |
//! | [`Sensor`] | `shutter` | s | > 0, optional | the shutter's std (sampled time axis) |
//! | [`Sensor`] | `nyquist` | – | > 0 | Nyquist factor `k`, default 2 |
//! | [`Sensor`] | `max_filter` | px | > 0 | largest filter std, default 8 |
//! | [`Integrate`] | `axes` | | list | integrate over these axes (rule 4) |
//!
//! As an operator, `Sensor` applies the pixel filter and integrates over `u`, `v`, `t`:
//! the path's final Σ is then the image-space covariance in metres.
//!
//! **Worked example** (flatland, `width = 1000`, `fov_x = 0.5`, `distance = 1`): the pitch is
//! `2·tan(0.25)/1000 = 5.107e-4 m`. An image-space `Σ_xx = 1e5 (cycles/m)²` is
//! `1e5 × 5.107e-4² = 0.0261 (cycles/px)²` (bandwidth 0.16 cycles/px). With the default
//! `k = 2` that needs `4 × 0.16 = 0.65` samples per pixel, and the matching filter std is
//! `1/(2π·0.16) = 0.99 px`.
//!
//! ```
//! use cov_core::Cov;
//! use cov_sensor::{Sensor, SensorParams};
//!
//! let sensor = Sensor::new(SensorParams { width: 1000, fov_x: 0.5, ..SensorParams::default() })?;
//! assert!((sensor.pitch() - 2.0 * 0.25f64.tan() / 1000.0).abs() < 1e-18);
//! let at_sensor = Cov::<2>::from_diagonal([1e5, 0.0])?;
//! let d = sensor.decisions(&at_sensor)?;
//! assert!(d.image_bandwidth_px[0] > 0.0 && d.samples_per_pixel > 0.0);
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! In RON (a path that ends at a `Sensor`; `covtrace eval` then prints the decisions):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_sensor::spec::register(&mut registry);
//! let text = "Path(source: Gaussian(x: 0.001, u: 0.01, t: 0.1), operators: [
//!     Integrate(axes: [t]),
//!     Sensor(width: 640, fov_x: 0.7, filter: 0.5),
//! ])";
//! let result = cov_path::Path::parse(text, &registry)?.eval()?;
//! assert_eq!(result.layout, 3);
//! # Ok::<(), cov_path::PathError>(())
//! ```

#![warn(missing_docs)]

pub mod spec;

use std::f64::consts::PI;

use cov_core::{Axis, AxisSet, Cov, CovError, FOUR_PI_SQ, NYQUIST_K, Operator, Spectrum};
use serde::{Deserialize, Serialize};

/// Parameters of a [`Sensor`] (see the crate docs for units and defaults).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SensorParams {
    /// Image width (px).
    pub width: u32,
    /// Horizontal field of view (rad).
    pub fov_x: f64,
    /// Lens (or pinhole) to sensor (m).
    #[serde(default = "one")]
    pub distance: f64,
    /// Pixel filter std (px).
    #[serde(default = "half")]
    pub filter: f64,
    /// Aperture std (m), when the lens is sampled.
    #[serde(default)]
    pub aperture: Option<f64>,
    /// Shutter std (s), when time is sampled.
    #[serde(default)]
    pub shutter: Option<f64>,
    /// Nyquist factor k.
    #[serde(default = "nyquist")]
    pub nyquist: f64,
    /// Largest filter std (px).
    #[serde(default = "eight")]
    pub max_filter: f64,
}

fn one() -> f64 {
    1.0
}
fn half() -> f64 {
    0.5
}
fn nyquist() -> f64 {
    NYQUIST_K
}
fn eight() -> f64 {
    8.0
}

impl Default for SensorParams {
    fn default() -> Self {
        SensorParams {
            width: 1024,
            fov_x: 0.8,
            distance: 1.0,
            filter: 0.5,
            aperture: None,
            shutter: None,
            nyquist: NYQUIST_K,
            max_filter: 8.0,
        }
    }
}

/// The sensor: pixel filter, integration, and per-pixel decisions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sensor {
    p: SensorParams,
    pitch: f64,
}

/// What a renderer needs per pixel (see the crate docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PixelDecisions {
    /// Image axes (`x`, or `x, y`).
    pub image_axes: Vec<String>,
    /// Image-space Σ in (cycles/px)², row by row.
    pub image_cov_px: Vec<Vec<f64>>,
    /// √Σ_ii of the image, cycles per pixel.
    pub image_bandwidth_px: Vec<f64>,
    /// Reconstruction filter: std along its principal axes (px), ascending.
    pub filter_std_px: Vec<f64>,
    /// Principal directions of the filter (columns), in image axes.
    pub filter_directions: Vec<Vec<f64>>,
    /// Whether the filter was clamped at `max_filter`.
    pub filter_clamped: bool,
    /// Axes of the sampled domain (`x_px`, …, `lens_x` …, `t`).
    pub sampled_axes: Vec<String>,
    /// Samples per unit volume of the sampled domain (px^i · m^l · s^t).
    pub density: f64,
    /// Samples per pixel (density × lens area × shutter span).
    pub samples_per_pixel: f64,
}

impl Sensor {
    /// Operator name.
    pub const NAME: &'static str = "Sensor";

    /// # Errors
    /// Any parameter outside its domain (named).
    pub fn new(p: SensorParams) -> Result<Self, CovError> {
        if p.width == 0 {
            return Err(CovError::OutOfRange {
                operator: Self::NAME.into(),
                parameter: "width".into(),
                value: 0.0,
                expected: "must be ≥ 1".into(),
            });
        }
        CovError::check_range(
            Self::NAME,
            "fov_x",
            p.fov_x,
            |f| f > 0.0 && f < PI,
            "must be in (0, π)",
        )?;
        CovError::check_positive(Self::NAME, "distance", p.distance)?;
        CovError::check_positive(Self::NAME, "filter", p.filter)?;
        CovError::check_positive(Self::NAME, "nyquist", p.nyquist)?;
        CovError::check_positive(Self::NAME, "max_filter", p.max_filter)?;
        if let Some(a) = p.aperture {
            CovError::check_positive(Self::NAME, "aperture", a)?;
        }
        if let Some(s) = p.shutter {
            CovError::check_positive(Self::NAME, "shutter", s)?;
        }
        let pitch = 2.0 * p.distance * (0.5 * p.fov_x).tan() / f64::from(p.width);
        CovError::check_positive(Self::NAME, "pitch", pitch)?;
        Ok(Sensor { p, pitch })
    }

    /// Metres per pixel on the sensor plane.
    pub fn pitch(&self) -> f64 {
        self.pitch
    }

    /// The parameters.
    pub fn params(&self) -> &SensorParams {
        &self.p
    }

    fn pixel_filter<const N: usize>(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        let s = self.p.filter * self.pitch;
        let w = 1.0 / (FOUR_PI_SQ * s * s);
        for &a in Cov::<N>::spatial_axes() {
            cov.add_variance(a, w)?;
        }
        Ok(())
    }

    /// The per-pixel decisions from Σ arriving at the sensor (before the sensor operator).
    ///
    /// # Errors
    /// Overflow, or an aperture/shutter given for a layout without `u`/`t`.
    pub fn decisions<const N: usize>(&self, at_sensor: &Cov<N>) -> Result<PixelDecisions, CovError> {
        let mut c = *at_sensor;
        self.pixel_filter(&mut c)?;
        let image_axes = Cov::<N>::spatial_axes();
        let n_img = image_axes.len();
        // Image-space Σ: integrate over everything but position, in pixel units.
        let img_px = scaled_block(&c, image_axes, self.pitch)?;
        let image_cov_px: Vec<Vec<f64>> = (0..n_img)
            .map(|i| (0..n_img).map(|j| img_px.get(i, j)).collect())
            .collect();
        let filter = img_px.reconstruction_filter(&vec![self.p.max_filter; n_img])?;
        // Sampled domain: image, lens (with an aperture), time (with a shutter).
        let mut keep: Vec<Axis> = image_axes.to_vec();
        if self.p.aperture.is_some() {
            keep.extend_from_slice(Cov::<N>::direction_axes());
        }
        if self.p.shutter.is_some() {
            Cov::<N>::index(Axis::T)?;
            keep.push(Axis::T);
        }
        let block = c.integrated(&keep)?.to_dmatrix();
        let k = keep.len();
        // Change of variables (x_px, lens, t) → (x_s, u, t): x_s = pitch·x_px,
        // u = (pitch·x_px − lens)/distance.
        let mut a = nalgebra::DMatrix::<f64>::zeros(k, k);
        for i in 0..n_img {
            a[(i, i)] = self.pitch;
        }
        if self.p.aperture.is_some() {
            for i in 0..n_img {
                a[(n_img + i, i)] = self.pitch / self.p.distance;
                a[(n_img + i, n_img + i)] = -1.0 / self.p.distance;
            }
        }
        if self.p.shutter.is_some() {
            a[(k - 1, k - 1)] = 1.0;
        }
        let sampled = a.transpose() * block * &a;
        let det = sampled
            .clone()
            .symmetric_eigen()
            .eigenvalues
            .iter()
            .map(|v| v.max(0.0))
            .product::<f64>();
        let density = (2.0 * self.p.nyquist).powi(k as i32) * det.sqrt();
        let root2pi = (2.0 * PI).sqrt();
        let mut span = 1.0;
        let mut sampled_axes: Vec<String> = image_axes.iter().map(|a| format!("{a}_px")).collect();
        if let Some(ap) = self.p.aperture {
            span *= (root2pi * ap).powi(n_img as i32);
            sampled_axes.extend(image_axes.iter().map(|a| format!("lens_{a}")));
        }
        if let Some(sh) = self.p.shutter {
            span *= root2pi * sh;
            sampled_axes.push("t".into());
        }
        let n = filter.extents.len();
        Ok(PixelDecisions {
            image_axes: image_axes.iter().map(|a| a.name().to_string()).collect(),
            image_bandwidth_px: image_cov_px
                .iter()
                .enumerate()
                .map(|(i, r)| r[i].max(0.0).sqrt())
                .collect(),
            image_cov_px,
            filter_std_px: filter.extents.clone(),
            filter_directions: (0..n)
                .map(|i| (0..n).map(|j| filter.directions[(i, j)]).collect())
                .collect(),
            filter_clamped: filter.clamped,
            sampled_axes,
            density,
            samples_per_pixel: density * span,
        })
    }

    /// [`Sensor::decisions`] for a layout-erased Σ (`N` rows of `N` numbers).
    ///
    /// # Errors
    /// As [`Sensor::decisions`], or a matrix that is not a valid Σ of size 2 to 5.
    pub fn decisions_rows(&self, rows: &[Vec<f64>]) -> Result<PixelDecisions, CovError> {
        fn go<const N: usize>(s: &Sensor, rows: &[Vec<f64>]) -> Result<PixelDecisions, CovError> {
            if rows.iter().any(|r| r.len() != N) {
                return Err(CovError::Shape {
                    what: "Sensor::decisions_rows".into(),
                    expected: format!("{N} numbers per row"),
                    got: "ragged rows".into(),
                });
            }
            let m = nalgebra::SMatrix::<f64, N, N>::from_fn(|i, j| rows[i][j]);
            s.decisions(&Cov::<N>::from_matrix(&m)?)
        }
        match rows.len() {
            2 => go::<2>(self, rows),
            3 => go::<3>(self, rows),
            4 => go::<4>(self, rows),
            5 => go::<5>(self, rows),
            n => Err(CovError::Shape {
                what: "Sensor::decisions_rows".into(),
                expected: "2 to 5 rows".into(),
                got: format!("{n}"),
            }),
        }
    }
}

/// The image block in pixel units, from Σ integrated over everything but position.
fn scaled_block<const N: usize>(
    c: &Cov<N>,
    image: &[Axis],
    pitch: f64,
) -> Result<cov_core::CovBlock, CovError> {
    let mut s = *c;
    let others: Vec<Axis> = Cov::<N>::axes()
        .iter()
        .copied()
        .filter(|a| !image.contains(a))
        .collect();
    if !others.is_empty() {
        s.integrate(&others)?;
    }
    // x_m = pitch·x_px, so l_px(x) = l(pitch·x): rule 1 scales Σ's rows by the pitch.
    for &a in image {
        s.scale(a, pitch)?;
    }
    s.marginal(image)
}

impl<const N: usize> Operator<N> for Sensor {
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        self.pixel_filter(cov)?;
        let mut rest: Vec<Axis> = Cov::<N>::direction_axes().to_vec();
        if Cov::<N>::has(Axis::T) {
            rest.push(Axis::T);
        }
        cov.integrate(&rest)
    }
    fn name(&self) -> &str {
        Self::NAME
    }
}

/// Integration over the given axes (rule 4) as an operator: `Integrate(axes: [t])`.
#[derive(Clone, Debug, PartialEq)]
pub struct Integrate {
    axes: Vec<Axis>,
}

impl Integrate {
    /// Operator name.
    pub const NAME: &'static str = "Integrate";

    /// # Errors
    /// An empty list.
    pub fn new(axes: Vec<Axis>) -> Result<Self, CovError> {
        if axes.is_empty() {
            return Err(CovError::Shape {
                what: "Integrate: axes".into(),
                expected: "at least one axis".into(),
                got: "none".into(),
            });
        }
        Ok(Integrate { axes })
    }
}

impl<const N: usize> Operator<N> for Integrate {
    fn apply(&self, cov: &mut dyn Spectrum<N>) -> Result<(), CovError> {
        cov.integrate(&self.axes)
    }
    fn name(&self) -> &str {
        Self::NAME
    }
    fn requires(&self) -> AxisSet {
        AxisSet::of(&self.axes).union(AxisSet::FLAT)
    }
}
