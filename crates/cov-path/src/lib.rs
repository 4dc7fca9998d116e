//! # cov-path: light paths in RON
//!
//! A path file names a source and a list of operators; operators are found by name in an
//! explicit [`Registry`] (each operator crate registers its own; a third party registers
//! theirs with one call). Parameters are plain structs that deny unknown fields, fed to
//! serde through a `DeserializeSeed`, so RON keeps its `Name(field: value)` syntax and
//! every error carries the file's line and column.
//!
//! ```ron
//! // A 10 cm area light, 1 m of travel, a glossy reflection, 2 m to the camera.
//! Path(
//!     layout: 4,                          // optional: inferred when left out
//!     source: Gaussian(x: 0.1, y: 0.1),   // primal std per axis; others constant
//!     operators: [
//!         Travel(distance: 1.0),
//!         Reflect(cos_in: 0.8, cos_out: 0.8, curvature: (kx: 2.0, ky: 2.0), lobe: Phong(exponent: 200)),
//!         Travel(distance: 2.0),
//!     ],
//! )
//! ```
//!
//! **Layout inference**: without `layout`, the path is traced in the smallest layout that
//! holds every axis the source and the operators need (no time → no `t`; no `y`/`v` →
//! flatland). A declared layout that lacks an axis some operator needs is an error that
//! names both.

#![warn(missing_docs)]

mod de;
mod error;
mod eval;
mod path;
mod registry;
mod scan;
mod source;

pub use error::PathError;
pub use eval::{EvalStep, Evaluation, StepReport};
pub use path::{
    MAX_PATH_BYTES, Path, beyond_float, decimal_for_whole, expected_value, not_decimal, number_start,
    ron_options, whole_number_at,
};
pub use registry::{Entry, Registry};
pub use scan::{
    blank_or_comment, element_at, enclosing_field, field_at, odd_space_before, token_error, value_position,
    written_after_close,
};
pub use source::Source;
