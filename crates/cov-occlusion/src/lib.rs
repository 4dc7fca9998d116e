//! # cov-occlusion: occluders, blockers and textures as windows
//!
//! **Primal definition** (docs/physics.md section 3): an occluder, a texture or any window `w`
//! multiplies the light field, `l'(z) = l(z)·w(z)`. By rule 2 the spectra convolve and
//! `Σ' = Σ + W`, `W` the spectrum covariance of `w`. Planar occluders act on the spatial
//! axes only; a thick occluder is sliced along its depth, with travel between slices.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Window` | `std_x` | m | required | > 0 | Std along x. |
//! |  | `std_y` | m | optional | > 0 | Std along y (`std_x` when left out). |
//! | `BlockerEdge` | `distance` | m | required | > 0 | Distance from the ray to the nearest blocker edge. |
//! | `Texture` | `feature` | m | optional | > 0 | Size of the texture's features (a Gaussian bump of that std); or give the spectrum `sxx`, `sxy`, `syy`. |
//! |  | `sxx` | (cycles/m)² | optional | ≥ 0 | Spectrum covariance xx. |
//! |  | `sxy` | (cycles/m)² | optional | finite | Spectrum covariance xy, `\|sxy\| ≤ √(sxx·syy)` (0 when left out). |
//! |  | `syy` | (cycles/m)² | optional | ≥ 0 | Spectrum covariance yy (`sxx` when left out). |
//! | `ThickOccluder` | `depth` | m | required | ≥ 0 | Depth of the occluder along the ray. |
//! |  | `slices` | – | required | in [1, 10000] | Number of slices, each a window and a travel. (At most 10⁴. The operator applies them in closed form, at the same cost for any number.) |
//! |  | `std` | m | required | > 0 | Window std of each slice. |
//! <!-- end of parameters -->
//!
//! The **blocker-edge rule** (the course's "largest unoccluded disk"): the local window
//! shrinks until no blocker is near-hit or near-missed, so a blocker edge at distance `r`
//! acts as a Gaussian window of std `r`: `W = 1/(4π² r²)` on each spatial axis. A hard edge
//! has unbounded bandwidth; the validator measures how far this Gaussian stand-in is from
//! a true half-plane (see `tests/validate.rs`).
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_occlusion::BlockerEdge;
//!
//! let mut c = Cov::<2>::zeros(); // uniform light
//! Operator::apply(&BlockerEdge::new(0.01)?, &mut c)?; // blocker 1 cm away
//! assert!((c.get(0, 0) - 1.0 / (4.0 * std::f64::consts::PI.powi(2) * 1e-4)).abs() < 1e-9);
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Window, BlockerEdge, Texture, ThickOccluder; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_occlusion::spec::register(&mut registry);
//! let text = r#"
//! Path(
//!     source: Gaussian(x: 0.3, y: 0.3),
//!     operators: [
//!         Window(std_x: 0.05, std_y: 0.1),
//!         BlockerEdge(distance: 0.02),
//!         Texture(sxx: 400.0, sxy: 10.0, syy: 100.0),
//!         ThickOccluder(depth: 0.3, slices: 3, std: 0.05),
//!     ],
//! )
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 4); // inferred from what the operators need
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, CovError, FOUR_PI_SQ, Operator, OperatorSpec, Param, Spectrum};

/// The spectrum variance `1/(4π² s²)` of a window of std `s` (checked > 0 by the spec),
/// the parameter `p`.
#[inline]
fn window_var(p: &Param, std: f64) -> Result<f64, CovError> {
    let w = 1.0 / (FOUR_PI_SQ * std * std);
    if w.is_finite() {
        return Ok(w);
    }
    // Reported on the user's std, not on the derived variance (which is what overflows).
    Err(p.error(
        std,
        "too small: the window's spectrum variance 1/(4π² s²) overflows f64 (s must be above about 1e-153 m)",
    ))
}

/// A Gaussian window across the ray: `w(x, y) = exp(−x²/2s_x² − y²/2s_y²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    wx: f64,
    wy: f64,
}

impl Window {
    /// Operator name.
    pub const NAME: &'static str = "Window";

    /// A window of std `std_x` along x and `std_y` along y (m).
    ///
    /// # Errors
    /// Non-finite or non-positive std, or one so small the spectrum overflows.
    #[inline]
    pub fn new(std_x: f64, std_y: f64) -> Result<Self, CovError> {
        spec::WindowSpec {
            std_x,
            std_y: Some(std_y),
        }
        .build()
    }

    /// The same std on both axes.
    ///
    /// # Errors
    /// As [`Window::new`].
    #[inline]
    pub fn isotropic(std: f64) -> Result<Self, CovError> {
        Self::new(std, std)
    }
}

impl Operator for Window {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        cov_core::typed!(cov, |cov| {
            cov.add_variance(Axis::X, self.wx)?;
            if cov.has(Axis::Y) {
                cov.add_variance(Axis::Y, self.wy)?;
            }
            Ok(())
        })
    }
}

/// A blocker edge at `distance` from the ray: a Gaussian window of std `distance` on
/// each spatial axis (the largest-unoccluded-disk rule).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockerEdge {
    window: Window,
    distance: f64,
}

impl BlockerEdge {
    /// Operator name.
    pub const NAME: &'static str = "BlockerEdge";

    /// # Errors
    /// Non-finite or non-positive `distance`.
    pub fn new(distance: f64) -> Result<Self, CovError> {
        spec::BlockerEdgeSpec { distance }.build()
    }

    /// The distance to the edge (m).
    pub fn distance(&self) -> f64 {
        self.distance
    }
}

impl Operator for BlockerEdge {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        Operator::apply(&self.window, cov)
    }
}

/// A texture: the spatial spectrum covariance of the reflectance variation around the hit
/// point, added to Σ (rule 2). In flatland only `sxx` is used.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texture {
    s: [f64; 3],
}

impl Texture {
    /// Operator name.
    pub const NAME: &'static str = "Texture";

    /// From the spectrum covariance entries ((cycles/m)²).
    ///
    /// # Errors
    /// Non-finite entries, or a matrix that is not PSD.
    pub fn new(sxx: f64, sxy: f64, syy: f64) -> Result<Self, CovError> {
        spec::TextureSpec {
            feature: None,
            sxx: Some(sxx),
            sxy: Some(sxy),
            syy: Some(syy),
        }
        .build()
    }

    /// A texture whose features are Gaussian bumps of std `feature` (m), isotropic.
    ///
    /// # Errors
    /// Non-finite or non-positive `feature`.
    pub fn gaussian_feature(feature: f64) -> Result<Self, CovError> {
        spec::TextureSpec {
            feature: Some(feature),
            sxx: None,
            sxy: None,
            syy: None,
        }
        .build()
    }

    /// The spectrum of a texture `A` (a reflectance factor) computed from its local
    /// averages over the footprint around the hit: `mean = ⟨A⟩`, `mean_sq = ⟨A²⟩` and the
    /// gradient moments `grad = [⟨A_x²⟩, ⟨A_x A_y⟩, ⟨A_y²⟩]` (1/m², derivatives along the
    /// window's axes). Every input is an average, so a renderer mip-maps them and needs no
    /// FFT (docs/physics.md section 3, "textures").
    ///
    /// With `P = ⟨A²⟩ − ⟨A⟩²` the power of the texture's variation and `G` its gradient
    /// moments, Parseval gives the second moment of the variation's *power* spectrum,
    /// `G / (4π² P)`. covtrace's Σ is a moment of the *amplitude* spectrum (section 1),
    /// where the mean (a Dirac at zero frequency, of mass `|⟨A⟩|`) and the variation (of
    /// mass `√(2P)` for a sinusoid) are weighed by their amplitudes:
    ///
    /// ```text
    /// W = √(2P) / (|⟨A⟩| + √(2P)) · G / (4π² P)
    /// ```
    ///
    /// This is exact for a sinusoid on a constant, `A = m + a·cos(2π f x)`: `W = |a| f² /
    /// (|m| + |a|)`. For broadband textures it is the same model, measured against their
    /// FFT in cov-render's texture tests.
    ///
    /// A variation below `1e-12 · ⟨A²⟩` (rounding in the averages of a constant texture)
    /// gives `W = 0`.
    ///
    /// # Errors
    /// Non-finite or negative `mean_sq`, a non-finite `mean`, gradient moments that are not
    /// finite or not PSD.
    pub fn from_moments(mean: f64, mean_sq: f64, grad: [f64; 3]) -> Result<Self, CovError> {
        cov_core::arg!(Self::NAME, mean).finite()?;
        cov_core::arg!(Self::NAME, mean_sq).non_negative()?;
        // The same checks as `new`, on the gradient moments.
        Self::new(grad[0], grad[1], grad[2])?;
        let [sxx, sxy, syy] = Self::moments_spectrum(mean, mean_sq, grad);
        Self::new(sxx, sxy, syy)
    }

    /// The spectrum covariance `[sxx, sxy, syy]` of [`Texture::from_moments`], without its
    /// checks: for a caller that reads many averages known to be valid (finite, `mean_sq ≥
    /// 0`, `grad` PSD: a renderer's mip-mapped moments) and checks what it makes of them
    /// once ([`Texture::new`]). For such inputs the result is finite and PSD, and the same
    /// to the bit as `from_moments`'s.
    #[inline]
    pub fn moments_spectrum(mean: f64, mean_sq: f64, grad: [f64; 3]) -> [f64; 3] {
        let p = mean_sq - mean * mean;
        if p <= 1e-12 * mean_sq {
            return [0.0; 3];
        }
        let amp = (2.0 * p).sqrt();
        let k = amp / (mean.abs() + amp) / (FOUR_PI_SQ * p);
        grad.map(|g| k * g)
    }

    /// The spectrum covariance `[sxx, sxy, syy]` ((cycles/m)²) this texture adds.
    pub fn spectrum(&self) -> [f64; 3] {
        self.s
    }
}

impl Operator for Texture {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        if cov.has(Axis::Y) {
            cov.add_window(&[Axis::X, Axis::Y], &[self.s[0], self.s[1], self.s[1], self.s[2]])
        } else {
            cov.add_variance(Axis::X, self.s[0])
        }
    }
}

/// An occluder of non-negligible depth: `slices` Gaussian windows of std `std`, each
/// followed by a travel of `depth / slices` (the ray ends at the far side). Applied in
/// closed form (one travel and one window block per pair of axes), at the same cost for
/// any number of slices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThickOccluder {
    window: Window,
    depth: f64,
    slices: u32,
}

impl ThickOccluder {
    /// Operator name.
    pub const NAME: &'static str = "ThickOccluder";

    /// # Errors
    /// Negative or non-finite `depth`, `slices == 0`, invalid `std`.
    pub fn new(depth: f64, slices: u32, std: f64) -> Result<Self, CovError> {
        spec::ThickOccluderSpec { depth, slices, std }.build()
    }
}

impl ThickOccluder {
    /// What the `k` slices add on one (position, direction) pair, in closed form. A slice
    /// is `Σ ← Mᵀ(Σ + W)M`, the window `W = w e_x e_xᵀ` and the travel `M = I + s e_x e_uᵀ`
    /// (`s = −depth/k`); `M^j = I + j s e_x e_uᵀ` and `(M^j)ᵀ e_x = e_x + j s e_u`, so
    /// `k` slices give `(M^k)ᵀ Σ M^k + w Σⱼ (e_x + j s e_u)(e_x + j s e_u)ᵀ` (j = 1..k):
    /// one travel of the whole depth, then the block `w [[k, s Σj], [s Σj, s² Σj²]]` on
    /// `(x, u)`, a sum of rank-one PSD terms. The sums of `j` and `j²` are exact integers
    /// in f64 (`k ≤ 10⁴`), so the work does not grow with `slices`.
    fn block(&self) -> [f64; 4] {
        let k = f64::from(self.slices);
        let (sum_j, sum_j2) = (k * (k + 1.0) / 2.0, k * (k + 1.0) * (2.0 * k + 1.0) / 6.0);
        let (w, s) = (self.window.wx, -self.depth / k);
        let xu = w * s * sum_j;
        [w * k, xu, xu, w * s * s * sum_j2]
    }
}

impl Operator for ThickOccluder {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        let block = self.block();
        for &(p, d) in cov.transverse_pairs() {
            cov.shear(p, d, -self.depth)?;
            cov.add_window(&[p, d], &block)?;
        }
        Ok(())
    }
}
