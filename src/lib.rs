//! # covtrace
//!
//! Covariance tracing: frequency analysis of light transport. Along a light path a small
//! symmetric matrix Σ describes the local Fourier spectrum of radiance around the ray;
//! each event on the path is an operator on Σ, and at the sensor Σ tells a renderer how
//! many samples a pixel needs and how wide its reconstruction filter may be.
//!
//! This facade re-exports [`cov_core`] at its root and each operator crate as a module,
//! behind a Cargo feature of the same name (all on by default), so a renderer for a scene
//! without, say, refraction builds with `default-features = false, features = [...]`
//! and never compiles what it does not use.
//!
//! ```
//! use covtrace::{Axis, Cov, CovError, Spectrum};
//!
//! let mut c = Cov::<4>::gaussian([1e-3, 1e-3, f64::INFINITY, f64::INFINITY])?;
//! c.shear(Axis::X, Axis::U, -1.0)?;
//! c.shear(Axis::Y, Axis::V, -1.0)?;
//! println!("{c}");
//! # Ok::<(), CovError>(())
//! ```

pub use cov_core::*;

/// RON light paths and the operator registry (crate `cov-path`).
#[cfg(feature = "path")]
pub use cov_path as path;

/// Each operator feature with its crate, named once: what [`register_all`] registers and
/// what [`registry`] notes as left out.
macro_rules! operator_features {
    ($($feature:literal => $krate:ident),* $(,)?) => {
        /// Registers every operator compiled in (one feature per operator crate) with `r`.
        pub fn register_all<R: Registrar>(r: &mut R) {
            let _ = &r;
            $(
                #[cfg(feature = $feature)]
                $krate::spec::register(r);
            )*
        }

        /// The operator features this build leaves out, for the message about an unknown
        /// operator's name.
        #[cfg(feature = "path")]
        const LEFT_OUT: &[&str] = &[$(#[cfg(not(feature = $feature))] $feature,)*];
    };
}

operator_features! {
    "travel" => cov_travel,
    "occlusion" => cov_occlusion,
    "projection" => cov_projection,
    "curvature" => cov_curvature,
    "brdf" => cov_brdf,
    "refraction" => cov_refraction,
    "motion" => cov_motion,
    "defocus" => cov_defocus,
    "sensor" => cov_sensor,
    "media" => cov_media,
}

/// A registry with every operator this build includes (one per enabled feature).
///
/// ```
/// let registry = covtrace::registry();
/// let path = covtrace::path::Path::parse(
///     "Path(source: Gaussian(x: 0.01), operators: [Travel(distance: 2.0), Brdf(lobe: Phong(exponent: 50))])",
///     &registry,
/// )?;
/// let result = path.eval()?;
/// assert_eq!(result.layout, 2); // inferred: nothing needs y, v or t
/// # Ok::<(), covtrace::path::PathError>(())
/// ```
#[cfg(feature = "path")]
pub fn registry() -> cov_path::Registry {
    let mut r = cov_path::Registry::new();
    register_all(&mut r);
    for f in LEFT_OUT {
        r.leave_out(f);
    }
    r
}

#[cfg(feature = "travel")]
pub use cov_travel as travel;

/// Occluders, blocker edges, textures (crate `cov-occlusion`, feature `occlusion`).
#[cfg(feature = "occlusion")]
pub use cov_occlusion as occlusion;

/// Projection, mirror symmetry, frame rotation (crate `cov-projection`, feature `projection`).
#[cfg(feature = "projection")]
pub use cov_projection as projection;

/// Curvature (crate `cov-curvature`, feature `curvature`).
#[cfg(feature = "curvature")]
pub use cov_curvature as curvature;

/// BRDF lobes and reflection (crate `cov-brdf`, feature `brdf`).
#[cfg(feature = "brdf")]
pub use cov_brdf as brdf;

/// Refraction (crate `cov-refraction`, feature `refraction`).
#[cfg(feature = "refraction")]
pub use cov_refraction as refraction;

/// Moving objects and cameras, shutters (crate `cov-motion`, feature `motion`).
#[cfg(feature = "motion")]
pub use cov_motion as motion;

/// Thin lens and pinhole (crate `cov-defocus`, feature `defocus`).
#[cfg(feature = "defocus")]
pub use cov_defocus as defocus;

/// Sensor decisions: pixel filter, density, reconstruction filter (crate `cov-sensor`,
/// feature `sensor`).
#[cfg(feature = "sensor")]
pub use cov_sensor as sensor;

/// Participating media: absorption, segments, scattering (crate `cov-media`, feature
/// `media`).
#[cfg(feature = "media")]
pub use cov_media as media;
