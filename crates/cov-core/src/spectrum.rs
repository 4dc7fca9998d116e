//! [`Spectrum`]: Σ in some form and layout, with the four rules as in-place operations.
//!
//! This is the one kernel surface of covtrace. The provided methods ([`Spectrum::shear`],
//! [`Spectrum::convolve`], …) validate their parameters and resolve axis names against
//! the layout once, then call the form's raw index kernels (`raw_*`), which the two forms
//! implement: the covariance [`Cov`] (`form/cov.rs`) and the square-root [`CovFactor`]
//! (`form/factor.rs`). An [`crate::Operator`] acts on `&mut dyn Spectrum` and reads the
//! layout at run time ([`Spectrum::dim`], [`Spectrum::has`],
//! [`Spectrum::transverse_pairs`]), so one operator body serves every layout and form.

use std::fmt;

use crate::axis::{axis_index, layout_axes};
use crate::linalg::{MAX, Small, sym_eigen};
use crate::spec::Arg;
use crate::{AnyCov, AnySpectrum, Axis, Cov, CovError, CovFactor, PSD_RTOL};

/// How a chain holds Σ while it is evaluated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Form {
    /// Σ itself ([`crate::Cov`]): the cheapest kernels; a chain that moves Σ into a frame
    /// where one block dwarfs another and back loses the small block's digits like
    /// `ε · Σ_big/Σ_small` per event.
    Covariance,
    /// `Σ = L Lᵀ` ([`crate::CovFactor`]), updated by Potter's and the array algorithms:
    /// the same loss is `ε · √(Σ_big/Σ_small)`, and Σ is PSD by construction. The
    /// default: on the stiff suite's 10⁴-operator bounce chains it reaches 4e-13 to
    /// 2.4e-12 where the covariance form reaches 4.1e-9 (docs/stability.md).
    #[default]
    SquareRoot,
}

/// Σ in some form and layout: the four rules as in-place operations.
///
/// **Provided methods** (what operators call) take axis names and user-facing
/// parameters, check them (finite, in range, axes in the layout and distinct) and then
/// call the raw kernels once. **Required methods** are the form's state and its raw
/// kernels, which take indices already resolved and parameters already checked; they
/// report only what depends on the result (an overflow), and leave Σ unchanged when they
/// do.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, CovFactor, Spectrum};
///
/// // The same calls on either form, through the trait object an operator sees.
/// let start = Cov::<2>::gaussian([1e-3, 0.05])?;
/// let mut c = start;
/// let mut f = CovFactor::from_cov(&start);
/// for s in [&mut c as &mut dyn Spectrum, &mut f] {
///     s.shear(Axis::X, Axis::U, -0.5)?; // travel 0.5 m
///     s.convolve(&[Axis::U], &[100.0])?; // a glossy lobe
///     assert_eq!(s.dim(), 2);
///     assert!(!s.has(Axis::Y));
/// }
/// approx::assert_relative_eq!(f.to_cov()?, c, max_relative = 1e-12);
/// # Ok::<(), CovError>(())
/// ```
pub trait Spectrum: fmt::Debug {
    // ---- state -----------------------------------------------------------------

    /// The layout size N (2: x,u; 3: x,u,t; 4: x,y,u,v; 5: x,y,u,v,t).
    fn dim(&self) -> usize;
    /// The form Σ is held in.
    fn form(&self) -> Form;
    /// Σ now.
    ///
    /// # Errors
    /// [`CovError::Overflow`] if Σ exceeds the f64 range (possible in square-root form).
    fn cov(&self) -> Result<AnyCov, CovError>;
    /// Replaces Σ (converting to this form).
    ///
    /// # Errors
    /// A non-finite entry, or a Σ of another layout ([`CovError::Shape`]).
    fn assign(&mut self, c: &AnyCov) -> Result<(), CovError>;
    /// Saves Σ exactly as held.
    fn snapshot(&self) -> AnySpectrum;
    /// Restores a [`Spectrum::snapshot`] of the same layout (converting if it was taken
    /// in the other form); a snapshot of another layout is ignored.
    fn restore(&mut self, s: &AnySpectrum);
    /// The first stored number that is not finite, as (row, column, value), if any.
    fn first_non_finite(&self) -> Option<(usize, usize, f64)>;

    /// The concrete form behind this trait object, so that a [`crate::Chain`] can run its
    /// unchecked fast path on it. Default: [`Concrete::Other`], which
    /// takes the checked path (a third-party `Spectrum` needs nothing more).
    fn concrete(&mut self) -> Concrete<'_> {
        Concrete::Other
    }

    // ---- raw kernels: indices resolved, parameters checked. Each fails only with
    // [`CovError::Overflow`] naming `op`, and leaves Σ unchanged when it does. --------

    /// Rule 1, `Σ' = Aᵀ Σ A`, with `a[l][j] = A_lj` (the first `dim` rows and columns).
    fn raw_congruence(&mut self, op: &str, a: &Small) -> Result<(), CovError>;
    /// Rule 1, elementary shear `z'_i = z_i + s·z_j` (indices `i ≠ j`).
    fn raw_shear(&mut self, op: &str, i: usize, j: usize, s: f64) -> Result<(), CovError>;
    /// Rule 1, scaling `z'_i = c·z_i`.
    fn raw_scale(&mut self, op: &str, i: usize, c: f64) -> Result<(), CovError>;
    /// Rule 1, rotations by the same angle (`cos`, `sin`) in each plane of `planes`
    /// (pairs of distinct indices, the pairs disjoint).
    fn raw_rotate(&mut self, op: &str, planes: &[(usize, usize)], cos: f64, sin: f64)
    -> Result<(), CovError>;
    /// Rule 2, `Σ_pp += W` for the distinct indices `p`, `W` symmetric PSD (`p.len()`
    /// rows and columns of `w`).
    fn raw_add_window(&mut self, op: &str, p: &[usize], w: &Small) -> Result<(), CovError>;
    /// Rule 2 on one axis, `Σ_ii += w` (`w ≥ 0`): the common window, kept apart from
    /// [`Spectrum::raw_add_window`] because it is the hot path of every occluder.
    fn raw_add_variance(&mut self, op: &str, i: usize, w: f64) -> Result<(), CovError>;
    /// Rule 3 along one axis `p` with lobe spectrum `s ≥ 0` (rule 4 is `s = 0`): the
    /// common lobe and integration, kept apart from [`Spectrum::raw_lobe`] for speed.
    fn raw_lobe_1(&mut self, op: &str, p: usize, s: f64) -> Result<(), CovError>;
    /// Rule 3 along the distinct indices `p` with lobe spectrum `S` (symmetric PSD); rule
    /// 4 is `S = 0`.
    fn raw_lobe(&mut self, op: &str, p: &[usize], s: &Small) -> Result<(), CovError>;

    // ---- layout ---------------------------------------------------------------------

    /// The axes of this layout, in order.
    fn axes(&self) -> &'static [Axis] {
        layout_axes(self.dim()).unwrap_or(&[])
    }

    /// Whether this layout has `axis`.
    fn has(&self, axis: Axis) -> bool {
        axis_index(self.dim(), axis).is_ok()
    }

    /// Index of `axis` in this layout.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] if the layout has no such axis.
    #[inline]
    fn index(&self, axis: Axis) -> Result<usize, CovError> {
        axis_index(self.dim(), axis)
    }

    /// The (position, direction) axis pairs of this layout: `[(x, u)]` in flatland,
    /// `[(x, u), (y, v)]` in 3D. Flatland operator definitions apply to each pair.
    fn transverse_pairs(&self) -> &'static [(Axis, Axis)] {
        if self.dim() >= 4 {
            &[(Axis::X, Axis::U), (Axis::Y, Axis::V)]
        } else {
            &[(Axis::X, Axis::U)]
        }
    }

    /// The direction axes of this layout: `[u]` or `[u, v]`.
    fn direction_axes(&self) -> &'static [Axis] {
        if self.dim() >= 4 {
            &[Axis::U, Axis::V]
        } else {
            &[Axis::U]
        }
    }

    /// The spatial axes of this layout: `[x]` or `[x, y]`.
    fn spatial_axes(&self) -> &'static [Axis] {
        if self.dim() >= 4 {
            &[Axis::X, Axis::Y]
        } else {
            &[Axis::X]
        }
    }

    // ---- the four rules, checked ----------------------------------------------------

    /// Rule 1 with a dense matrix: `l'(z) = l(A z)` gives `Σ' = Aᵀ Σ A`; `a` holds `A`
    /// row-major (`dim²` numbers).
    ///
    /// # Errors
    /// Wrong size, a non-finite entry in `a`, or an overflowing result.
    fn congruence(&mut self, a: &[f64]) -> Result<(), CovError> {
        let n = self.dim();
        if a.len() != n * n {
            return Err(CovError::Shape {
                what: "congruence: A".into(),
                expected: format!("{} numbers ({n}×{n} row-major)", n * n),
                got: format!("{} numbers", a.len()),
            });
        }
        let mut m = [[0.0; MAX]; MAX];
        for l in 0..n {
            for j in 0..n {
                m[l][j] = Arg::new("congruence", "A", a[l * n + j]).finite()?;
            }
        }
        self.raw_congruence("congruence", &m)
    }

    /// Rule 1, elementary shear: `l'(z) = l(z')` with `z'_target = z_target + s·z_source`.
    ///
    /// In the spectrum this adds `s ×` row/column `target` to row/column `source`.
    /// Travel by `d` is `shear(X, U, −d)`; curvature `k` is `shear(U, X, k)`.
    ///
    /// # Errors
    /// Missing axis, `target == source`, non-finite `s`, or an overflowing result.
    #[inline(always)]
    fn shear(&mut self, target: Axis, source: Axis, s: f64) -> Result<(), CovError> {
        crate::arg!("shear", s).finite()?;
        let (i, j) = two_axes(self.dim(), "shear", target, source)?;
        if s == 0.0 {
            return Ok(());
        }
        self.raw_shear("shear", i, j, s)
    }

    /// Rule 1, scaling: `l'(z) = l(z')` with `z'_axis = c·z_axis` (a projection by a
    /// cosine is `scale(X, cos θ)`). Row and column `axis` of Σ are multiplied by `c`.
    ///
    /// # Errors
    /// Missing axis, non-finite `c`, or an overflowing result.
    #[inline(always)]
    fn scale(&mut self, axis: Axis, c: f64) -> Result<(), CovError> {
        crate::arg!("scale", c).finite()?;
        let i = self.index(axis)?;
        self.raw_scale("scale", i, c)
    }

    /// Rule 1, rotation in the plane of two axes: `l'(z) = l(z')` with
    /// `(z'_a, z'_b) = (cos α·z_a − sin α·z_b, sin α·z_a + cos α·z_b)`, α in radians.
    ///
    /// # Errors
    /// Missing axis, `a == b`, non-finite `angle`.
    #[inline(always)]
    fn rotate(&mut self, a: Axis, b: Axis, angle: f64) -> Result<(), CovError> {
        crate::arg!("rotate", angle).finite()?;
        let (i, j) = two_axes(self.dim(), "rotate", a, b)?;
        let (s, c) = angle.sin_cos();
        self.raw_rotate("rotate", &[(i, j)], c, s)
    }

    /// Rotation of the 3D tangent frame by `angle` (radians): `(x, y)` and `(u, v)` turn
    /// together, as [`Spectrum::rotate`] on both pairs.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] in flatland (N = 2, 3); non-finite `angle`.
    #[inline(always)]
    fn rotate_frame(&mut self, angle: f64) -> Result<(), CovError> {
        self.rotate_frame_by(Turn::new(crate::arg!("rotate_frame", angle))?)
    }

    /// [`Spectrum::rotate_frame`] by a [`Turn`], whose cosine and sine were computed when
    /// it was built: an operator that turns the frame by a fixed angle builds its `Turn`
    /// once and pays no trigonometry per application. For a turn from [`Turn::new`], the
    /// same result bits as `rotate_frame(turn.angle())`.
    ///
    /// # Errors
    /// [`CovError::MissingAxis`] in flatland (N = 2, 3).
    #[inline(always)]
    fn rotate_frame_by(&mut self, turn: Turn) -> Result<(), CovError> {
        let (x, y, u, v) = (
            self.index(Axis::X)?,
            self.index(Axis::Y)?,
            self.index(Axis::U)?,
            self.index(Axis::V)?,
        );
        self.raw_rotate("rotate_frame", &[(x, y), (u, v)], turn.cos, turn.sin)
    }

    /// Rule 2 on one axis: multiplying the primal by a window adds its spectrum variance,
    /// `Σ_aa += w` ((cycles/unit)²). A Gaussian window of std `s` has `w = 1/(4π²s²)`.
    ///
    /// # Errors
    /// Missing axis, `w` negative or non-finite, overflow.
    #[inline(always)]
    fn add_variance(&mut self, axis: Axis, w: f64) -> Result<(), CovError> {
        crate::arg!("add_variance", w).non_negative()?;
        let i = self.index(axis)?;
        if w == 0.0 {
            return Ok(());
        }
        self.raw_add_variance("add_variance", i, w)
    }

    /// Rule 2: `Σ' = Σ + W`, with `W` the spectrum covariance of the window on `axes`,
    /// given row-major as `axes.len()²` numbers (symmetric PSD).
    ///
    /// # Errors
    /// Missing or repeated axis, wrong size, `W` not finite, symmetric and PSD; overflow.
    fn add_window(&mut self, axes: &[Axis], w: &[f64]) -> Result<(), CovError> {
        let (idx, k) = resolve(self.dim(), "add_window", axes)?;
        let wm = block_from_slice("add_window", "W", k, w)?;
        self.raw_add_window("add_window", &idx[..k], &wm)
    }

    /// Rule 3: convolution along `axes` with a lobe whose spectrum covariance is `S`
    /// (row-major, `axes.len()²` numbers, symmetric PSD):
    /// `Σ' = Σ − Σ Pᵀ (S + P Σ Pᵀ)⁻¹ P Σ`, computed without inverting Σ.
    ///
    /// The convolved block and the cross terms use the forms `Σ_pp (S+Σ_pp)⁻¹ S` and
    /// `Σ_op (S+Σ_pp)⁻¹ S`, which are exactly zero for `S = 0` (a perfectly diffuse lobe
    /// removes all content on those axes) and tend to the identity as `S → ∞` (a mirror:
    /// callers skip the kernel). A singular `S + Σ_pp` uses the pseudo-inverse.
    ///
    /// # Errors
    /// Missing or repeated axis, wrong size, `S` not finite/symmetric/PSD; overflow.
    #[inline(always)]
    fn convolve(&mut self, axes: &[Axis], s: &[f64]) -> Result<(), CovError> {
        if let ([axis], [s1]) = (axes, s) {
            // One axis: S is a non-negative number; no eigen-check needed.
            let p = self.index(*axis)?;
            Arg::new("convolve", "S", *s1).non_negative()?;
            return self.raw_lobe_1("convolve", p, *s1);
        }
        lobe_block(self, "convolve", axes, Some(s))
    }

    /// Rule 4, in place: integration of the primal over `axes` (lens, shutter, sensor
    /// angle). The kept block becomes the Schur complement `Σ_kk − Σ_kr Σ_rr⁺ Σ_rk`
    /// (pseudo-inverse where Σ_rr is singular) and the integrated axes become 0: the
    /// integrated field no longer depends on them. The same as [`Spectrum::convolve`]
    /// with `S = 0`.
    ///
    /// # Errors
    /// Missing or repeated axis.
    #[inline(always)]
    fn integrate(&mut self, axes: &[Axis]) -> Result<(), CovError> {
        if let [axis] = axes {
            let p = self.index(*axis)?;
            return self.raw_lobe_1("integrate", p, 0.0);
        }
        lobe_block(self, "integrate", axes, None)
    }
}

/// [`Spectrum::convolve`] (`s` given) or [`Spectrum::integrate`] (`S = 0`) on several
/// axes: checked and run out of line, so that the one-axis case inlines into a caller that
/// knows its spectrum type.
#[inline(never)]
fn lobe_block<S: Spectrum + ?Sized>(
    spec: &mut S,
    op: &'static str,
    axes: &[Axis],
    s: Option<&[f64]>,
) -> Result<(), CovError> {
    let (idx, k) = resolve(spec.dim(), op, axes)?;
    let sm = s.map_or(Ok([[0.0; MAX]; MAX]), |s| block_from_slice(op, "S", k, s))?;
    spec.raw_lobe(op, &idx[..k], &sm)
}

/// What a `&mut dyn Spectrum` holds ([`Spectrum::concrete`]): one of the two forms in one
/// of the four layouts, or something else.
#[derive(Debug)]
pub enum Concrete<'a> {
    /// `Cov<2>`.
    Cov2(&'a mut Cov<2>),
    /// `Cov<3>`.
    Cov3(&'a mut Cov<3>),
    /// `Cov<4>`.
    Cov4(&'a mut Cov<4>),
    /// `Cov<5>`.
    Cov5(&'a mut Cov<5>),
    /// `CovFactor<2>`.
    Factor2(&'a mut CovFactor<2>),
    /// `CovFactor<3>`.
    Factor3(&'a mut CovFactor<3>),
    /// `CovFactor<4>`.
    Factor4(&'a mut CovFactor<4>),
    /// `CovFactor<5>`.
    Factor5(&'a mut CovFactor<5>),
    /// Any other implementation.
    Other,
}

/// Reads a `k × k` row-major symmetric PSD block (a window or lobe spectrum).
#[inline(always)]
pub(crate) fn block_from_slice(
    op: &'static str,
    name: &'static str,
    k: usize,
    w: &[f64],
) -> Result<Small, CovError> {
    if w.len() != k * k {
        return Err(CovError::Shape {
            what: format!("{op}: {name}"),
            expected: format!("{} numbers ({k}×{k} row-major)", k * k),
            got: format!("{} numbers", w.len()),
        });
    }
    let m = symmetric(op, name, k, |a, b| w[a * k + b])?;
    let (vals, _) = sym_eigen(k, &m);
    let tol = PSD_RTOL * vals[..k].iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
    if vals[0] < -tol {
        return Err(CovError::NotPsd {
            min_eigenvalue: vals[0],
            tolerance: -tol,
        });
    }
    Ok(m)
}

/// Reads the `k × k` matrix `at(row, col)` given to `op` as `name`: every entry finite
/// (an error names entry `name[row·k + col]`), symmetric to `1e-12 ×` its largest
/// entry (the rounding of a matrix computed symmetric), then averaged to exact symmetry
/// as `½a + ½b` (which cannot overflow).
#[inline(always)]
pub(crate) fn symmetric(
    op: &'static str,
    name: &'static str,
    k: usize,
    at: impl Fn(usize, usize) -> f64,
) -> Result<Small, CovError> {
    let mut m = [[0.0; MAX]; MAX];
    let mut scale = 0.0f64;
    for a in 0..k {
        for b in 0..k {
            let mut arg = Arg::new(op, name, at(a, b));
            arg.index = Some(a * k + b);
            m[a][b] = arg.finite()?;
            scale = scale.max(m[a][b].abs());
        }
    }
    for a in 0..k {
        for b in (a + 1)..k {
            if (m[a][b] - m[b][a]).abs() > 1e-12 * scale {
                return Err(CovError::NotSymmetric {
                    row: a,
                    col: b,
                    a: m[a][b],
                    b: m[b][a],
                });
            }
            let avg = 0.5 * m[a][b] + 0.5 * m[b][a];
            m[a][b] = avg;
            m[b][a] = avg;
        }
    }
    Ok(m)
}

/// The indices of `axes` in layout `n` (at most `n`, distinct), for kernel `op`.
#[inline(always)]
pub(crate) fn resolve(n: usize, op: &str, axes: &[Axis]) -> Result<([usize; MAX], usize), CovError> {
    let mut idx = [0usize; MAX];
    if axes.is_empty() || axes.len() > n {
        return Err(CovError::Shape {
            what: op.into(),
            expected: format!("1 to {n} axes"),
            got: format!("{} axes", axes.len()),
        });
    }
    for (a, axis) in axes.iter().enumerate() {
        idx[a] = axis_index(n, *axis)?;
        if idx[..a].contains(&idx[a]) {
            return Err(CovError::Shape {
                what: op.into(),
                expected: "distinct axes".into(),
                got: format!("`{axis}` twice"),
            });
        }
    }
    Ok((idx, axes.len()))
}

/// The indices of two different axes `a`, `b` of layout `n`, for kernel `op`.
#[inline(always)]
pub(crate) fn two_axes(n: usize, op: &str, a: Axis, b: Axis) -> Result<(usize, usize), CovError> {
    let (i, j) = (axis_index(n, a)?, axis_index(n, b)?);
    if i == j {
        return Err(CovError::Shape {
            what: op.into(),
            expected: "two different axes".into(),
            got: format!("{a} and {b}"),
        });
    }
    Ok((i, j))
}

/// A rotation of the tangent frame by a finite angle (radians), with its cosine and sine
/// computed once, when it is built ([`Spectrum::rotate_frame_by`]). Operators that turn
/// the frame by a parameter (a projection, a principal curvature frame, a reflection's
/// turn) hold one, so their per-application cost has no trigonometry.
///
/// ```
/// use cov_core::{Cov, Spectrum, Turn};
/// let angle = 0.3;
/// let turn = Turn::new(cov_core::arg!("MyOperator", angle))?;
/// let (mut a, mut b) = (Cov::<4>::from_diagonal([1.0, 2.0, 3.0, 4.0])?, Cov::<4>::from_diagonal([1.0, 2.0, 3.0, 4.0])?);
/// a.rotate_frame_by(turn)?;
/// b.rotate_frame(0.3)?;
/// assert_eq!(a, b); // the same bits
/// // A non-finite angle names the operator and parameter it came from.
/// let angle = f64::NAN;
/// let err = Turn::new(cov_core::arg!("MyOperator", angle)).unwrap_err().to_string();
/// assert!(err.contains("MyOperator") && err.contains("angle"));
/// # Ok::<(), cov_core::CovError>(())
/// ```
///
/// Two turns are equal when their cosines and sines are; their [`Turn::angle`]s may still
/// differ in the last bits (a turn from [`Turn::new`] keeps its argument, one from
/// [`Turn::towards`] takes the `atan2` of its sine and cosine).
#[derive(Clone, Copy)]
pub struct Turn {
    /// The angle, or NaN for a turn made from a direction ([`Turn::towards`]), whose
    /// angle is found when asked for.
    angle: f64,
    cos: f64,
    sin: f64,
}

impl PartialEq for Turn {
    fn eq(&self, other: &Turn) -> bool {
        self.cos == other.cos && self.sin == other.sin
    }
}

impl std::fmt::Debug for Turn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Turn")
            .field("angle", &self.angle())
            .field("cos", &self.cos)
            .field("sin", &self.sin)
            .finish()
    }
}

impl Turn {
    /// No rotation.
    pub const ZERO: Turn = Turn {
        angle: 0.0,
        cos: 1.0,
        sin: 0.0,
    };

    /// The rotation by an angle (radians) given as an [`Arg`](crate::spec::Arg), which
    /// names it in the error: `Turn::new(arg!("MyOperator", angle))`, or
    /// `Turn::new(MySpec::ANGLE.of(angle))` for a spec's parameter.
    ///
    /// # Errors
    /// [`CovError::NonFinite`] for a non-finite angle.
    #[inline]
    pub fn new(angle: crate::spec::Arg) -> Result<Turn, CovError> {
        let angle = angle.finite()?;
        if angle == 0.0 {
            // The common "no turn": `sin_cos(±0)` is exactly (±0, 1), without the call.
            return Ok(Turn {
                angle,
                cos: 1.0,
                sin: angle,
            });
        }
        let (sin, cos) = angle.sin_cos();
        Ok(Turn { angle, cos, sin })
    }

    /// The rotation by the angle of the direction `(x, y)`, of any length: its cosine and
    /// sine are the direction's components over its length, without [`Turn::new`]'s
    /// `sin_cos`; its angle (an `atan2`) is computed only if [`Turn::angle`] asks for it.
    /// `None` where the length is 0 or not finite. The length is `√(x² + y²)`, or
    /// `hypot` where the squares' sum underflows to a subnormal or overflows (components
    /// below about 1e-154 or above about 1e154), so the cosine and sine stay unit.
    #[inline]
    pub fn towards(x: f64, y: f64) -> Option<Turn> {
        #[cold]
        fn hypot(x: f64, y: f64) -> f64 {
            x.hypot(y)
        }
        let r2 = x * x + y * y;
        let r = if (f64::MIN_POSITIVE..=f64::MAX).contains(&r2) {
            r2.sqrt()
        } else {
            hypot(x, y)
        };
        (r > 0.0 && r.is_finite()).then(|| Turn {
            angle: f64::NAN,
            cos: x / r,
            sin: y / r,
        })
    }

    /// Whether it turns nothing (`cos = 1`, `sin = ±0`: an angle of ±0, or a direction
    /// along `+x`), without computing an angle.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.sin == 0.0 && self.cos == 1.0
    }

    /// The rotation back, by `-angle`: `(cos, -sin)`, without trigonometry. For a turn
    /// from [`Turn::new`], the same bits as `Turn::new(.., -angle)` wherever `sin` is odd
    /// to the bit, as glibc's is
    /// (`tests/turn.rs` checks it through the operators that use it).
    pub fn inverse(&self) -> Turn {
        Turn {
            angle: -self.angle,
            cos: self.cos,
            sin: -self.sin,
        }
    }

    /// The angle (radians): as given to [`Turn::new`], or in `[−π, π]` for a turn made
    /// from a direction ([`Turn::towards`]).
    pub fn angle(&self) -> f64 {
        if self.angle.is_nan() {
            self.sin.atan2(self.cos)
        } else {
            self.angle
        }
    }

    /// `cos(angle)`.
    pub fn cos(&self) -> f64 {
        self.cos
    }

    /// `sin(angle)`.
    pub fn sin(&self) -> f64 {
        self.sin
    }
}
