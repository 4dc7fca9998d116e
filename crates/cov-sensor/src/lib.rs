//! # cov-sensor: what a renderer does with Σ at the sensor
//!
//! At the sensor, Σ (with the aperture and shutter windows of cov-defocus and cov-motion
//! applied) becomes per-pixel decisions (docs/physics.md section 4):
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
//! 4. the **reconstruction filter**: the Gaussian whose spectrum matches the image's
//!    content, the image-space Σ before the pixel filter's window, primal covariance
//!    `(4π² Σ_px)⁻¹` in pixels², clamped at `max_filter` pixels where Σ is singular. (The
//!    window belongs to what one pixel's samples integrate, so it sets the density; with it,
//!    no filter could be wider than the pixel filter.)
//!
//! The lens position `p` of a ray reaching the sensor at `x_s` with direction `u` is
//! `p = x_s − distance·u`, the change of variables used for the lens part of the density.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Sensor` | `width` | px | required | ≥ 1 | Image width. |
//! |  | `fov_x` | rad | required | in (0, π) | Horizontal field of view. |
//! |  | `distance` | m | `1.0` | > 0 | Lens (or pinhole) to sensor. |
//! |  | `filter` | px | `0.5` | > 0 | Pixel filter std. |
//! |  | `aperture` | m | optional | in (0, 1e6] | Aperture std, when the lens is sampled. |
//! |  | `shutter` | s | optional | in (0, 1e6] | Shutter std, when time is sampled (needs axis `t`). |
//! |  | `nyquist` | – | `2.0` | in (0, 1e3] | Nyquist factor k (core's `NYQUIST_K`). |
//! |  | `max_filter` | px | `8.0` | in (0, 1e6] | Largest filter std. (The upper bounds here are far beyond any use, so that no decision overflows f64: a squared `max_filter` of 1e155 px would.) |
//! | `Integrate` | `axes` | – | required | – | Axes to integrate over: a list of `x`, `y`, `u`, `v`, `t`. |
//! <!-- end of parameters -->
//!
//! As an operator, `Sensor` applies the pixel filter and integrates over `u`, `v`, `t`:
//! the path's final Σ is then the image-space covariance in metres.
//!
//! **Worked example** (flatland, `width = 1000`, `fov_x = 0.5`, `distance = 1`, the default
//! pixel filter of 0.5 px): the pitch is `2·tan(0.25)/1000 = 5.107e-4 m`. An image-space
//! `Σ_xx = 1e5 (cycles/m)²` is `1e5 × 5.107e-4² = 0.02608 (cycles/px)²` (bandwidth 0.16
//! cycles/px), and the matching filter std is `1/(2π·0.1615) = 0.986 px`. The pixel filter's
//! window adds `1/(4π²·0.5²) = 0.1013 (cycles/px)²`, so a pixel integrates a band of
//! `√0.1274 = 0.357` cycles/px, and with the default `k = 2` that needs
//! `4 × 0.357 = 1.43` samples per pixel.
//!
//! ```
//! use cov_core::Cov;
//! use cov_sensor::{Sensor, SensorParams};
//!
//! let sensor = Sensor::new(SensorParams { width: 1000, fov_x: 0.5, ..SensorParams::default() })?;
//! assert!((sensor.pitch() - 2.0 * 0.25f64.tan() / 1000.0).abs() < 1e-18);
//! let at_sensor = Cov::<2>::from_diagonal([1e5, 0.0])?;
//! let d = sensor.decisions(&at_sensor)?;
//! assert!((d.filter_std_px[0] - 0.986).abs() < 1e-3);
//! assert!((d.image_bandwidth_px[0] - 0.357).abs() < 1e-3);
//! assert!((d.samples_per_pixel - 1.428).abs() < 1e-3);
//! # Ok::<(), cov_core::CovError>(())
//! ```

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

use cov_core::{
    AnyCov, Axis, AxisSet, CovError, FOUR_PI_SQ, Field, NYQUIST_K, Operator, OperatorSpec, Report,
    ReportField, Spectrum, axis_index,
};
use serde::{Deserialize, Serialize};

/// Parameters of a [`Sensor`]: `Sensor(width: 640, fov_x: 0.8, …)` in a path file
/// (`covtrace list` prints this table).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, cov_core::OperatorSpec)]
#[operator(
    name = "Sensor",
    summary = "the sensor: pixel filter, integration over lens and shutter, per-pixel decisions"
)]
pub struct SensorParams {
    /// Image width.
    #[param(unit = "px", ge = 1)]
    pub width: u32,
    /// Horizontal field of view.
    #[param(unit = "rad", gt = 0, lt = PI)]
    pub fov_x: f64,
    /// Lens (or pinhole) to sensor.
    #[param(unit = "m", default = 1.0, positive)]
    pub distance: f64,
    /// Pixel filter std.
    #[param(unit = "px", default = 0.5, positive)]
    pub filter: f64,
    /// Aperture std, when the lens is sampled.
    #[param(unit = "m", default, gt = 0, le = 1e6)]
    pub aperture: Option<f64>,
    /// Shutter std, when time is sampled (needs axis `t`).
    #[param(unit = "s", default, gt = 0, le = 1e6)]
    pub shutter: Option<f64>,
    /// Nyquist factor k (core's `NYQUIST_K`).
    #[param(default = 2.0, gt = 0, le = 1e3)]
    pub nyquist: f64,
    /// Largest filter std. (The upper bounds here are far beyond any use, so that no
    /// decision overflows f64: a squared `max_filter` of 1e155 px would.)
    #[param(unit = "px", default = 8.0, gt = 0, le = 1e6)]
    pub max_filter: f64,
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

/// Largest layout (`cov_core::linalg`'s matrix side).
const MAX: usize = cov_core::linalg::MAX;

/// The per-pixel sampling rates ([`Sensor::rates`]): what a renderer needs per path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelRates {
    /// Image axes (1 or 2).
    pub image_dims: usize,
    /// Image-space Σ in (cycles/px)² (the first `image_dims` rows and columns).
    pub image_cov_px: [[f64; 2]; 2],
    /// Axes of the sampled domain (image, lens, time).
    pub sampled_dims: usize,
    /// Samples per unit volume of the sampled domain (px^i · m^l · s^t).
    pub density: f64,
    /// Samples per pixel (density × lens area × shutter span).
    pub samples_per_pixel: f64,
}

/// What a renderer needs per pixel (see the crate docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PixelDecisions {
    /// Image axes (`x`, or `x, y`).
    pub image_axes: Vec<String>,
    /// Image-space Σ in (cycles/px)², row by row, with the pixel filter's window (the
    /// spectrum of what a pixel's samples integrate, which sets the density).
    pub image_cov_px: Vec<Vec<f64>>,
    /// √Σ_ii of the image, cycles per pixel (with the pixel filter's window).
    pub image_bandwidth_px: Vec<f64>,
    /// Reconstruction filter of the image's content (Σ before the pixel filter's
    /// window): std along its principal axes (px), ascending; `max_filter` where the
    /// content is flat.
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
        p.build()
    }

    /// Metres per pixel on the sensor plane.
    pub fn pitch(&self) -> f64 {
        self.pitch
    }

    /// The parameters.
    pub fn params(&self) -> &SensorParams {
        &self.p
    }

    fn pixel_filter(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        let s = self.p.filter * self.pitch;
        let w = 1.0 / (FOUR_PI_SQ * s * s);
        for &a in cov.spatial_axes() {
            cov.add_variance(a, w)?;
        }
        Ok(())
    }

    /// The per-pixel sampling rates from Σ arriving at the sensor (before the sensor
    /// operator): the image-space Σ and the sample density. What a renderer needs per
    /// path, without the filter's eigen-directions or any allocation of names
    /// ([`Sensor::decisions`] adds those).
    ///
    /// # Errors
    /// Overflow, or a shutter given for a layout without `t`.
    pub fn rates(&self, at_sensor: &AnyCov) -> Result<PixelRates, CovError> {
        let mut c: AnyCov = *at_sensor;
        self.pixel_filter(c.as_spectrum_mut())?;
        let s = c.as_spectrum_mut();
        let image_axes = s.spatial_axes();
        let direction_axes = s.direction_axes();
        let n_img = image_axes.len();
        // Image-space Σ: integrate over everything but position, in pixel units.
        let img_px = scaled_block(&c, image_axes, self.pitch)?;
        let mut image_cov_px = [[0.0; 2]; 2];
        for (i, row) in image_cov_px.iter_mut().enumerate().take(n_img) {
            for (j, v) in row.iter_mut().enumerate().take(n_img) {
                *v = img_px.get(i, j);
            }
        }
        // Sampled domain: image, lens (with an aperture), time (with a shutter).
        let mut keep = [Axis::X; 5];
        let mut k = 0;
        for &a in image_axes {
            keep[k] = a;
            k += 1;
        }
        if self.p.aperture.is_some() {
            for &a in direction_axes {
                keep[k] = a;
                k += 1;
            }
        }
        if self.p.shutter.is_some() {
            axis_index(c.dim(), Axis::T)?;
            keep[k] = Axis::T;
            k += 1;
        }
        let block = c.integrated(&keep[..k])?;
        // Change of variables (x_px, lens, t) → (x_s, u, t): x_s = pitch·x_px,
        // u = (pitch·x_px − lens)/distance. A is sparse: column j of A has its entries on
        // rows j and, for an image axis with a lens, n_img + j.
        let mut a = [[0.0; 5]; 5];
        for (i, row) in a.iter_mut().enumerate().take(n_img) {
            row[i] = self.pitch;
        }
        if self.p.aperture.is_some() {
            for i in 0..n_img {
                a[n_img + i][i] = self.pitch / self.p.distance;
                a[n_img + i][n_img + i] = -1.0 / self.p.distance;
            }
        }
        if self.p.shutter.is_some() {
            a[k - 1][k - 1] = 1.0;
        }
        // sampled = Aᵀ B A.
        let mut b = [[0.0; MAX]; MAX];
        for (i, row) in b.iter_mut().enumerate().take(k) {
            for (j, v) in row.iter_mut().enumerate().take(k) {
                *v = block.get(i, j);
            }
        }
        let mut ba = [[0.0; MAX]; MAX];
        for i in 0..k {
            for j in 0..k {
                ba[i][j] = (0..k).map(|l| b[i][l] * a[l][j]).sum();
            }
        }
        let mut sampled = [[0.0; MAX]; MAX];
        for i in 0..k {
            for j in 0..k {
                sampled[i][j] = (0..k).map(|l| a[l][i] * ba[l][j]).sum();
            }
        }
        let det = cov_core::linalg::psd_det(k, &mut sampled);
        let density = (2.0 * self.p.nyquist).powi(k as i32) * det.sqrt();
        let root2pi = (2.0 * PI).sqrt();
        let mut span = 1.0;
        if let Some(ap) = self.p.aperture {
            span *= (root2pi * ap).powi(n_img as i32);
        }
        if let Some(sh) = self.p.shutter {
            span *= root2pi * sh;
        }
        if !(density.is_finite() && (density * span).is_finite()) {
            return Err(CovError::NoTransport {
                operator: Self::NAME.into(),
                reason: format!(
                    "the sampling density overflows f64 (density {density:e}, over a domain of {span:e}): Σ at the sensor is beyond what a renderer can sample"
                ),
            });
        }
        Ok(PixelRates {
            image_dims: n_img,
            image_cov_px,
            sampled_dims: k,
            density,
            samples_per_pixel: density * span,
        })
    }

    /// The per-pixel decisions from Σ arriving at the sensor (before the sensor operator):
    /// [`Sensor::rates`] with the reconstruction filter and the axes named.
    ///
    /// # Errors
    /// Overflow, or an aperture/shutter given for a layout without `u`/`t`.
    pub fn decisions(&self, at_sensor: impl Into<AnyCov>) -> Result<PixelDecisions, CovError> {
        let mut c: AnyCov = at_sensor.into();
        let r = self.rates(&c)?;
        let image_axes = c.as_spectrum_mut().spatial_axes();
        let n_img = r.image_dims;
        let image_cov_px: Vec<Vec<f64>> = (0..n_img).map(|i| r.image_cov_px[i][..n_img].to_vec()).collect();
        // The filter matches the image's content, Σ before the pixel filter's window: with
        // the window, no filter could be wider than the pixel filter itself.
        let filter =
            scaled_block(&c, image_axes, self.pitch)?
                .reconstruction_filter(&vec![self.p.max_filter; n_img])?;
        let mut sampled_axes: Vec<String> = image_axes.iter().map(|a| format!("{a}_px")).collect();
        if self.p.aperture.is_some() {
            sampled_axes.extend(image_axes.iter().map(|a| format!("lens_{a}")));
        }
        if self.p.shutter.is_some() {
            sampled_axes.push("t".into());
        }
        let n = filter.extents.len();
        if !filter.extents.iter().all(|v| v.is_finite()) {
            return Err(CovError::NoTransport {
                operator: Self::NAME.into(),
                reason: "the reconstruction filter overflows f64: Σ at the sensor is beyond what a renderer can sample".into(),
            });
        }
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
            density: r.density,
            samples_per_pixel: r.samples_per_pixel,
        })
    }

    /// [`Sensor::decisions`] for Σ given as rows.
    ///
    /// # Errors
    /// As [`Sensor::decisions`], or a matrix that is not a valid Σ of size 2 to 5.
    pub fn decisions_rows(&self, rows: &[Vec<f64>]) -> Result<PixelDecisions, CovError> {
        self.decisions(AnyCov::from_rows(rows)?)
    }
}

/// The image block in pixel units, from Σ integrated over everything but position.
fn scaled_block(c: &AnyCov, image: &[Axis], pitch: f64) -> Result<cov_core::CovBlock, CovError> {
    let mut any = *c;
    let s = any.as_spectrum_mut();
    let others: Vec<Axis> = s.axes().iter().copied().filter(|a| !image.contains(a)).collect();
    if !others.is_empty() {
        s.integrate(&others)?;
    }
    // x_m = pitch·x_px, so l_px(x) = l(pitch·x): rule 1 scales Σ's rows by the pitch.
    for &a in image {
        s.scale(a, pitch)?;
    }
    any.marginal(image)
}

impl Operator for Sensor {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        self.pixel_filter(cov)?;
        let mut rest: Vec<Axis> = cov.direction_axes().to_vec();
        if cov.has(Axis::T) {
            rest.push(Axis::T);
        }
        cov.integrate(&rest)
    }
    /// A shutter samples time: the path needs `t`.
    fn requires(&self) -> AxisSet {
        if self.p.shutter.is_some() {
            AxisSet::FLAT_TIME
        } else {
            AxisSet::FLAT
        }
    }
    /// The per-pixel decisions ([`PixelDecisions`]) from Σ arriving at the sensor.
    fn report(&self, before: &AnyCov) -> Result<Option<Report>, CovError> {
        Ok(Some(self.decisions(*before)?.to_report()))
    }
    /// A sensor ends a path.
    fn is_terminal(&self) -> bool {
        true
    }
}

impl PixelDecisions {
    /// The decisions as a [`Report`] (fields named as `covtrace eval` prints them; the
    /// typed value is this struct).
    pub fn to_report(&self) -> Report {
        let f = |name: &str, unit: &str, value: Field| ReportField::new(name, unit, value);
        Report::new(
            "per pixel (sensor)",
            vec![
                f("image axes", "", Field::Text(self.image_axes.clone())),
                f(
                    "image covariance",
                    "(cycles/px)²",
                    Field::Matrix(self.image_cov_px.clone()),
                ),
                f(
                    "image bandwidth",
                    "cycles/px",
                    Field::Numbers(self.image_bandwidth_px.clone()),
                ),
                f("filter std", "px", Field::Numbers(self.filter_std_px.clone())),
                f(
                    "filter directions",
                    "",
                    Field::Matrix(self.filter_directions.clone()),
                ),
                f("filter clamped", "", Field::Flag(self.filter_clamped)),
                f("sampled domain", "", Field::Text(self.sampled_axes.clone())),
                f(
                    "density",
                    "samples per px, m (lens) and s (time) of the sampled domain",
                    Field::Number(self.density),
                ),
                f("samples per pixel", "", Field::Number(self.samples_per_pixel)),
            ],
            self.clone(),
        )
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

impl Operator for Integrate {
    /// # Errors
    /// Every axis of the layout integrated: Σ would be the empty matrix, which describes
    /// nothing (a renderer integrates over what it samples and keeps the image axes).
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        if cov.axes().iter().all(|a| self.axes.contains(a)) {
            let all: Vec<String> = cov.axes().iter().map(ToString::to_string).collect();
            return Err(CovError::Shape {
                what: "Integrate: axes".into(),
                expected: "at least one axis of the layout left out".into(),
                got: format!(
                    "all of them ({}): integrating every axis leaves nothing to describe",
                    all.join(", ")
                ),
            });
        }
        cov.integrate(&self.axes)
    }
    fn requires(&self) -> AxisSet {
        AxisSet::of(&self.axes).union(AxisSet::FLAT)
    }
}
