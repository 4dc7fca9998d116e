//! The one error type of cov-core.

use crate::Axis;

/// Everything that can go wrong in cov-core and in operators built on it.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CovError {
    /// A parameter is NaN or infinite where a finite value is required.
    #[error("{operator}: parameter `{parameter}` must be finite, got {value}")]
    NonFinite {
        /// Operator or function that rejected the value.
        operator: String,
        /// Name of the parameter.
        parameter: String,
        /// The rejected value.
        value: f64,
    },
    /// A parameter is finite but outside its domain.
    #[error("{operator}: parameter `{parameter}` = {} is out of range: {expected}", num(*value))]
    OutOfRange {
        /// Operator or function that rejected the value.
        operator: String,
        /// Name of the parameter.
        parameter: String,
        /// The rejected value.
        value: f64,
        /// What the domain is, in words (e.g. "must be > 0").
        expected: String,
    },
    /// Parameters that exclude each other were given together, or none of a required
    /// choice was (`Curvature(k: 2, kx: 1)`): said of the parameter to change, with the
    /// forms the operator takes.
    #[error("{operator}: parameter `{parameter}`: {expected}")]
    Choice {
        /// Operator that rejected the combination.
        operator: String,
        /// The parameter the message is about (where a path author looks).
        parameter: String,
        /// What to give instead, in words.
        expected: String,
    },
    /// An operator needs an axis the layout does not have.
    #[error("axis `{axis}` is not in the layout of size {layout}")]
    MissingAxis {
        /// The axis asked for.
        axis: Axis,
        /// The layout size N.
        layout: usize,
    },
    /// A matrix or slice has the wrong shape.
    #[error("{what}: expected {expected}, got {got}")]
    Shape {
        /// What was being built.
        what: String,
        /// Expected shape, in words.
        expected: String,
        /// Shape that was given.
        got: String,
    },
    /// A matrix given as a covariance is not symmetric.
    #[error("matrix is not symmetric: entry ({row},{col}) = {} but ({col},{row}) = {}", num(*a), num(*b))]
    NotSymmetric {
        /// Row of the offending entry.
        row: usize,
        /// Column of the offending entry.
        col: usize,
        /// Value at (row, col).
        a: f64,
        /// Value at (col, row).
        b: f64,
    },
    /// A matrix given as a covariance is not positive semi-definite.
    #[error(
        "matrix is not positive semi-definite: smallest eigenvalue {min_eigenvalue:e} (tolerance {tolerance:e})"
    )]
    NotPsd {
        /// The smallest eigenvalue found.
        min_eigenvalue: f64,
        /// The tolerance it was compared against (negative).
        tolerance: f64,
    },
    /// A result overflowed or became NaN (an operator was applied to values too large
    /// for f64).
    #[error(
        "{operator}: result is not finite (entry ({row},{col}) = {value}); the input or parameters overflow f64"
    )]
    Overflow {
        /// Operator whose result overflowed.
        operator: String,
        /// Row of the first non-finite entry.
        row: usize,
        /// Column of the first non-finite entry.
        col: usize,
        /// The non-finite value.
        value: f64,
    },
    /// A physical situation in which no light passes (e.g. total internal reflection
    /// asked for a transmitted ray).
    #[error("{operator}: {reason}")]
    NoTransport {
        /// Operator that found it.
        operator: String,
        /// Why nothing is transported.
        reason: String,
    },
    /// A step of a chain failed; wraps the error with the step index and name.
    #[error("step {index} ({operator}): {}", own_words(operator, source))]
    Step {
        /// Zero-based index of the step in the chain.
        index: usize,
        /// Name of the operator at that step.
        operator: String,
        /// The error it returned.
        source: Box<CovError>,
    },
}

/// A step's error in the path author's words: without the operator's name when it begins
/// with it (the step already names the operator: `step 1 (Integrate): …`, not `step 1
/// (Integrate): Integrate: …`), and a non-finite value met inside one of core's kernels
/// (`add_window`, `scale`: names the author never wrote) said as the overflow it is.
fn own_words(operator: &str, source: &CovError) -> String {
    let s = source.to_string();
    if let CovError::NonFinite { operator: kernel, .. } | CovError::Overflow { operator: kernel, .. } = source
        && kernel != operator
        && kernel.chars().all(|c| c.is_ascii_lowercase() || c == '_')
    {
        return format!(
            "Σ overflows f64 here: the parameters, or Σ arriving here, are beyond what f64 carries (in `{kernel}`: {})",
            s.strip_prefix(kernel.as_str())
                .and_then(|r| r.strip_prefix(": "))
                .unwrap_or(&s)
        );
    }
    match s.strip_prefix(operator).and_then(|r| r.strip_prefix(": ")) {
        Some(rest) => rest.to_string(),
        None => s,
    }
}

impl CovError {
    /// [`CovError::Overflow`] of `operator` at `(row, col, value)`, the first non-finite
    /// entry.
    #[cold]
    pub(crate) fn overflow(operator: &str, (row, col, value): (usize, usize, f64)) -> CovError {
        CovError::Overflow {
            operator: operator.into(),
            row,
            col,
            value,
        }
    }
}

/// A number as messages print it: plainly between `1e-4` and `1e6` (`0.25`, `1500`),
/// else in scientific form with the fewest digits that read back exactly (`1e300`,
/// `3.2e-9`), so that no message prints a 300-digit decimal.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-4..1e6).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A value the program computed (a least size, a reach), as a message shows it: six
/// significant digits in [`num`]'s notation, so that `4.9000000000000005e-6` reads
/// `4.9e-6` (rounding noise gone, and a value compared with a limit still told from it
/// unless the two agree to six digits). A value the user wrote is echoed with [`num`],
/// exactly.
///
/// ```
/// assert_eq!(cov_core::approx(4.9000000000000005e-6), "4.9e-6");
/// assert_eq!(cov_core::approx(9.999999999999999e299), "1e300");
/// assert_eq!(cov_core::approx(0.30000000000000004), "0.3");
/// ```
pub fn approx(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let rounded: f64 = format!("{v:.5e}").parse().unwrap_or(v);
    num(rounded)
}

/// Longest piece of user input echoed in a message (characters).
pub const ECHO_MAX: usize = 64;

/// User input as messages echo it: control characters (a line break, a tab, an escape)
/// written as escapes (`\n`, `\t`, `\u{1b}`), so that a message stays one line, and cut
/// to [`ECHO_MAX`] characters with `…` and its length when longer, so that a 50 MB name
/// never becomes a 50 MB error line.
pub fn echo(s: &str) -> String {
    let n = s.chars().count();
    let mut out = one_line(&s.chars().take(ECHO_MAX).collect::<String>());
    if n > ECHO_MAX {
        out.push_str(&format!("… ({n} characters)"));
    }
    out
}

/// `s` on one line, whole: control characters (a line break, a tab, an escape) written as
/// escapes (`\n`, `\t`, `\u{1b}`), everything else as it is. For text that is not the
/// user's to bound (a file path, a library's message); [`echo`] also cuts.
pub fn one_line(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// Line and column (1-based, columns in characters) of the end of `before`: the position
/// of whatever follows it, for messages about text files.
pub fn line_col(before: &str) -> (usize, usize) {
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Where `bytes` stop being UTF-8: line and column of the first invalid byte, and that byte
/// (`None` when all of it is UTF-8).
pub fn utf8_error_at(bytes: &[u8]) -> Option<(usize, usize, u8)> {
    let e = std::str::from_utf8(bytes).err()?;
    let good = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or("");
    let (line, col) = line_col(good);
    Some((line, col, bytes[e.valid_up_to()]))
}
