//! # cov-travel: free-space travel
//!
//! **Primal definition** (docs/physics.md section 3): travel by a distance `d` along the ray
//! shears position by direction, `l'(x,u) = l(x − d·u, u)`, and `(y, v)` likewise in 3D.
//! Time is unchanged (light is instantaneous at scene scales).
//!
//! **Spectrum**: rule 1 with `A = [[1, −d], [0, 1]]`, i.e. `Σ_uu += −2d Σ_xu + d² Σ_xx`
//! and `Σ_xu −= d Σ_xx`: spatial frequencies leak into angle as light travels.
//!
//! Parameters, as written in a path file (`covtrace list` prints the same):
//!
//! <!-- parameters: generated from the specs (`COVTRACE_BLESS=1 cargo test --test param_tables`) -->
//! | operator | parameter | unit | default | domain | meaning |
//! |---|---|---|---|---|---|
//! | `Travel` | `distance` | m | required | finite | Distance; negative travels back. |
//! <!-- end of parameters -->
//!
//! Layouts: all (N = 2, 3, 4, 5); needs `x, u`.
//!
//! ```
//! use cov_core::{Cov, Operator};
//! use cov_travel::Travel;
//!
//! let mut c = Cov::<2>::gaussian([0.01, f64::INFINITY])?; // a 1 cm spot, diffuse emitter
//! Operator::apply(&Travel::new(2.0)?, &mut c)?;
//! // Σ_uu = d² Σ_xx: the spot's spatial content now shows in angle.
//! assert!((c.get(1, 1) - 4.0 * c.get(0, 0)).abs() < 1e-9 * c.get(1, 1));
//! # Ok::<(), cov_core::CovError>(())
//! ```

//!
//! **In a RON path** (Travel; register with [`spec::register`]):
//!
//! ```
//! let mut registry = cov_path::Registry::new();
//! cov_travel::spec::register(&mut registry);
//! let text = r#"
//! Path(source: Gaussian(x: 0.01), operators: [Travel(distance: 2.0)])
//! "#;
//! let path = cov_path::Path::parse(text, &registry)?;
//! let result = path.eval()?;
//! assert_eq!(result.layout, 2); // inferred from what the operators need
//! # Ok::<(), cov_path::PathError>(())
//! ```
#![warn(missing_docs)]

pub mod spec;

use cov_core::{Axis, CovError, Operator, OperatorSpec, Spectrum};

/// Travel by `distance` metres along the ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Travel {
    distance: f64,
}

impl Travel {
    /// Operator name used in tables, errors and RON files.
    pub const NAME: &'static str = "Travel";

    /// # Errors
    /// [`CovError::NonFinite`] if `distance` is NaN or infinite.
    #[inline]
    pub fn new(distance: f64) -> Result<Self, CovError> {
        spec::TravelSpec { distance }.build()
    }

    /// The distance (m).
    pub fn distance(&self) -> f64 {
        self.distance
    }
}

impl Operator for Travel {
    fn apply(&self, cov: &mut dyn Spectrum) -> Result<(), CovError> {
        // Each plane written out (not a loop over `transverse_pairs`), so that every
        // shear has constant axes once the spectrum's type is known.
        cov_core::typed!(cov, |cov| {
            cov.shear(Axis::X, Axis::U, -self.distance)?;
            if cov.has(Axis::Y) {
                cov.shear(Axis::Y, Axis::V, -self.distance)?;
            }
            Ok(())
        })
    }
}
