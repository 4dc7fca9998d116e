//! Batch evaluation: one chain over many states ([`Chain::eval_batch`]), what a renderer
//! calls for a tile of paths, and per-state operators ([`eval_batch_with`], and
//! [`eval_batch_typed`] for operators applied through their typed bodies). The chain
//! is compiled once ([`Tape`]); states run in parallel over cores (rayon, in chunks of
//! [`CHUNK`]). In covariance form, groups of [`LANES`] states are stored
//! structure-of-arrays (each entry of Σ one contiguous array over the group), and the
//! compiled program runs over a group instruction by instruction: one dispatch, then a
//! loop over the lanes that the compiler vectorises, compiled for AVX-512, AVX2 and the
//! baseline target and chosen at run time. Every lane computes exactly what the scalar
//! kernels compute (same operations in the same order, no fused multiply-add), so a
//! covariance batch gives the same bits as [`Chain::eval_in`]. A square-root batch runs
//! the chain's compiled program state by state. States kept structure-of-arrays
//! ([`crate::CovLanes`], [`Chain::eval_lanes`]) skip the transposition in and out.

use rayon::prelude::*;

use crate::form::Kernels;
use crate::tape::{Direct, Instr, flat_dispatch};
use crate::{Chain, Cov, CovError, CovFactor, Form, Spectrum, Tape};

/// States stored side by side in a structure-of-arrays group: each entry of Σ is one
/// contiguous array over the group's states (7.5 KB for layout 5). 64 was measured
/// fastest of 32, 64, 128 and 256 on the bounce chain: larger groups spill the lobe's
/// temporaries out of the first-level cache, smaller ones pay the dispatch more often.
pub const LANES: usize = 64;

/// States per parallel task.
pub const CHUNK: usize = 512;

/// One entry of Σ over a group's [`LANES`] states.
pub(crate) type Lane = [f64; LANES];

/// A group as [`run_chunk`] holds it: every slot a layout may use.
type Lanes = [Lane; 15];

/// Packed index of `(i, j)`, as `Cov<N>` stores it.
#[inline(always)]
const fn ix<const N: usize>(i: usize, j: usize) -> usize {
    Cov::<N>::idx(i, j)
}

impl Chain {
    /// Evaluates the chain on every state in place, in `form`, in parallel: the
    /// batched form of [`Chain::eval_in`], with the result bits of its compiled path (a
    /// chain's evaluations from the second on; the first runs checked, which in
    /// square-root form can differ in rounding where a window adds several variances).
    ///
    /// Returns the states that failed, with their error (as [`Chain::eval_in`] reports
    /// it: step, operator, value); those states are left as they were.
    ///
    /// ```
    /// use cov_core::{Axis, Chain, Cov, CovError, Form, Operator, Spectrum};
    /// # #[derive(Debug)] struct Travel(f64);
    /// # impl Operator for Travel {
    /// #     fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> { c.shear(Axis::X, Axis::U, -self.0) }
    /// # }
    /// let chain = Chain::new().with(Travel(1.0)).with(Travel(2.0));
    /// let mut states: Vec<Cov<2>> = (1..=100)
    ///     .map(|i| Cov::gaussian([0.01 * i as f64, 1.0]))
    ///     .collect::<Result<_, _>>()?;
    /// let one = chain.eval_in(Form::Covariance, states[7])?;
    /// let failed = chain.eval_batch(Form::Covariance, &mut states);
    /// assert!(failed.is_empty());
    /// assert_eq!(states[7], one);
    /// # Ok::<(), CovError>(())
    /// ```
    pub fn eval_batch<const N: usize>(&self, form: Form, states: &mut [Cov<N>]) -> Vec<(usize, CovError)> {
        // The chain's cached tape, lowered for the form; in covariance form also the
        // lane program (`None` if a kernel has no lane form: each state then runs alone).
        let (tape, lanes) = match form {
            Form::Covariance => {
                let tape = self.tape::<Cov<N>>(true);
                (tape, tape.and_then(lower_lanes))
            }
            Form::SquareRoot => (self.tape::<CovFactor<N>>(true), None),
        };
        let Some(tape) = tape else {
            return Vec::new(); // unreachable: a forced tape is always built
        };
        let mut failed: Vec<(usize, CovError)> = states
            .par_chunks_mut(CHUNK)
            .enumerate()
            .flat_map_iter(|(c, chunk)| {
                let mut bad = Vec::new();
                match &lanes {
                    Some(prog) => self.run_lanes(prog, chunk, c * CHUNK, &mut bad),
                    None => {
                        for (i, s) in chunk.iter_mut().enumerate() {
                            self.run_one(tape, form, s, c * CHUNK + i, &mut bad);
                        }
                    }
                }
                bad
            })
            .collect();
        failed.sort_by_key(|(i, _)| *i);
        failed
    }

    /// One state through the tape; on failure the checked path reports it.
    pub(crate) fn run_one<const N: usize>(
        &self,
        tape: &Tape,
        form: Form,
        s: &mut Cov<N>,
        index: usize,
        bad: &mut Vec<(usize, CovError)>,
    ) {
        let ok = match form {
            Form::Covariance => {
                let mut c = *s;
                let ok = tape.run(&mut c);
                if ok {
                    *s = c;
                }
                ok
            }
            Form::SquareRoot => {
                let mut f = CovFactor::from_cov(s);
                tape.run(&mut f) && f.to_cov().map(|c| *s = c).is_ok()
            }
        };
        if !ok {
            self.report_failure(form, s, index, bad);
        }
    }

    /// A state the compiled path refused (an overflow): the checked path decides. It
    /// reports the failing step, and the state is left as it was; or, if it succeeds
    /// (the square-root program folds a window's variances at once, which rounds
    /// differently from one fold per axis), its result is the state's.
    pub(crate) fn report_failure<const N: usize>(
        &self,
        form: Form,
        s: &mut Cov<N>,
        index: usize,
        bad: &mut Vec<(usize, CovError)>,
    ) {
        let checked = match form {
            Form::Covariance => {
                let mut c = *s;
                self.apply_checked(&mut c).map(|()| c)
            }
            Form::SquareRoot => {
                let mut f = CovFactor::from_cov(s);
                self.apply_checked(&mut f).and_then(|()| f.to_cov())
            }
        };
        match checked {
            Ok(c) => *s = c,
            Err(e) => bad.push((index, e)),
        }
    }

    /// Groups of [`LANES`] states in structure-of-arrays form through `prog` (the tape's
    /// lane program, [`run_chunk`]); failing lanes go through the checked path.
    fn run_lanes<const N: usize>(
        &self,
        prog: &[LaneOp],
        chunk: &mut [Cov<N>],
        base: usize,
        bad: &mut Vec<(usize, CovError)>,
    ) {
        let mut poisoned = Vec::new();
        run_chunk::<N>(prog, chunk, &mut poisoned);
        for i in poisoned {
            self.report_failure(Form::Covariance, &mut chunk[i], base + i, bad);
        }
    }
}

/// Evaluates every state through its own operators, in place, in `form`, in parallel
/// (rayon, chunks of [`CHUNK`]): the batch with per-state parameters, what a renderer
/// calls for a tile of paths whose operators differ from path to path. `ops(i, s)`
/// applies state `i`'s operators to `s` (built on the stack: nothing is allocated per
/// state). Each state runs as a chain's first [`Chain::eval_in`] does: the operators
/// on the unchecked kernels, then, only if the result is not clean, again on the
/// checked kernels, which report the failing operator.
///
/// Returns the states that failed with what `ops` reported, or an overflow if `ops`
/// left Σ non-finite; those states are left as they were.
///
/// Operators whose typed bodies are known (`apply_to` in the operator crates) run
/// faster through [`eval_batch_typed`], which takes them as a [`StateOps`] value.
///
/// ```
/// use cov_core::{Axis, Cov, CovError, Form, Spectrum, eval_batch_with};
/// // Travel by a distance of its own per state.
/// let distances: Vec<f64> = (0..100).map(|i| 0.1 * i as f64).collect();
/// let mut states = vec![Cov::<2>::from_diagonal([0.5, 1.0])?; 100];
/// let failed = eval_batch_with(Form::Covariance, &mut states, |i, s: &mut dyn Spectrum| {
///     s.shear(Axis::X, Axis::U, -distances[i])
/// });
/// assert!(failed.is_empty());
/// // Travel spreads spatial content into the direction axis: Σ_uu = 1 + d² Σ_xx.
/// assert_eq!(states[0].get(1, 1), 1.0);
/// assert!((states[99].get(1, 1) - (1.0 + 9.9f64.powi(2) * 0.5)).abs() < 1e-12);
/// # Ok::<(), CovError>(())
/// ```
pub fn eval_batch_with<const N: usize, F>(form: Form, states: &mut [Cov<N>], ops: F) -> Vec<(usize, CovError)>
where
    F: Fn(usize, &mut dyn Spectrum) -> Result<(), CovError> + Sync,
{
    each_state(form, states, &Dyn(ops), "eval_batch_with")
}

/// Per-state operators for [`eval_batch_typed`]: `apply(i, s)` applies state `i`'s
/// operators to `s`, whatever the concrete spectrum type `S` is. Being generic (a
/// closure cannot be), it lets the operators' typed bodies (`apply_to`, the operator
/// crates' convention) inline the unchecked kernels with constant indices, where the
/// closure of [`eval_batch_with`] reaches every kernel through `dyn Spectrum`.
///
/// ```
/// use cov_core::{Axis, CovError, Spectrum, StateOps};
/// /// Travel by a distance of its own per state.
/// struct Distances(Vec<f64>);
/// impl StateOps for Distances {
///     fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
///         s.shear(Axis::X, Axis::U, -self.0[i])
///     }
/// }
/// # let _ = Distances(vec![1.0]);
/// ```
pub trait StateOps: Sync {
    /// Applies state `i`'s operators to `s`.
    ///
    /// # Errors
    /// What the operators report (a missing axis, say); the batch then reports state `i`.
    fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError>;
}

/// The closure of [`eval_batch_with`] as [`StateOps`] (every spectrum through `dyn`).
struct Dyn<F>(F);

impl<F> StateOps for Dyn<F>
where
    F: Fn(usize, &mut dyn Spectrum) -> Result<(), CovError> + Sync,
{
    #[inline]
    fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
        (self.0)(i, s)
    }
}

/// [`eval_batch_with`] with the per-state operators given as [`StateOps`], whose generic
/// `apply` sees the concrete spectrum: the operators' typed bodies then compile to the
/// unchecked kernels with constant indices, inlined. Same semantics, same results and
/// errors as [`eval_batch_with`] with the same operators (each state runs as a chain's
/// first evaluation does; a state that is not clean runs again on the checked kernels,
/// which report the failing operator, and is left as it was).
///
/// ```
/// use cov_core::{Axis, Cov, CovError, Form, Spectrum, StateOps, eval_batch_typed};
/// struct Distances(Vec<f64>);
/// impl StateOps for Distances {
///     fn apply<S: Spectrum>(&self, i: usize, s: &mut S) -> Result<(), CovError> {
///         s.shear(Axis::X, Axis::U, -self.0[i])
///     }
/// }
/// let ops = Distances((0..100).map(|i| 0.1 * i as f64).collect());
/// let mut states = vec![Cov::<2>::from_diagonal([0.5, 1.0])?; 100];
/// assert!(eval_batch_typed(Form::Covariance, &mut states, &ops).is_empty());
/// // Travel spreads spatial content into the direction axis: Σ_uu = 1 + d² Σ_xx.
/// assert!((states[99].get(1, 1) - (1.0 + 9.9f64.powi(2) * 0.5)).abs() < 1e-12);
/// // A layout without the axis fails state by state, with the operator's own error.
/// let mut flat = vec![Cov::<2>::from_diagonal([0.5, 1.0])?; 3];
/// struct Turn;
/// impl StateOps for Turn {
///     fn apply<S: Spectrum>(&self, _: usize, s: &mut S) -> Result<(), CovError> {
///         s.shear(Axis::Y, Axis::V, 1.0)
///     }
/// }
/// assert_eq!(eval_batch_typed(Form::Covariance, &mut flat, &Turn).len(), 3);
/// # Ok::<(), CovError>(())
/// ```
pub fn eval_batch_typed<const N: usize, O: StateOps>(
    form: Form,
    states: &mut [Cov<N>],
    ops: &O,
) -> Vec<(usize, CovError)> {
    each_state(form, states, ops, "eval_batch_typed")
}

/// The body of [`eval_batch_with`] and [`eval_batch_typed`]; `name` is the caller's,
/// for the overflow of a state that `ops` left non-finite without an error of its own.
fn each_state<const N: usize, O: StateOps>(
    form: Form,
    states: &mut [Cov<N>],
    ops: &O,
    name: &str,
) -> Vec<(usize, CovError)> {
    let one = |i: usize, s: &mut Cov<N>| -> Result<(), CovError> {
        let finite = |sp: &dyn Spectrum| match sp.first_non_finite() {
            None => Ok(()),
            Some((row, col, value)) => Err(CovError::Overflow {
                operator: name.into(),
                row,
                col,
                value,
            }),
        };
        // The fast path first: the operators on the unchecked kernels (`Direct`), one
        // finiteness check at the end; if anything is not clean, the checked kernels
        // from the start, which report exactly what failed.
        match form {
            Form::Covariance => {
                let mut c = *s;
                if ops.apply(i, &mut Direct(&mut c)).is_ok() && c.all_finite() {
                    *s = c;
                    return Ok(());
                }
                let mut c = *s;
                ops.apply(i, &mut c)?;
                finite(&c)?;
                *s = c;
            }
            Form::SquareRoot => {
                let start = CovFactor::from_cov(s);
                let mut f = start;
                if ops.apply(i, &mut Direct(&mut f)).is_ok()
                    && f.all_finite()
                    && let Ok(c) = f.to_cov()
                {
                    *s = c;
                    return Ok(());
                }
                let mut f = start;
                ops.apply(i, &mut f)?;
                finite(&f)?;
                *s = f.to_cov()?;
            }
        }
        Ok(())
    };
    let mut failed: Vec<(usize, CovError)> = states
        .par_chunks_mut(CHUNK)
        .enumerate()
        .flat_map_iter(|(c, chunk)| {
            let mut bad = Vec::new();
            for (k, s) in chunk.iter_mut().enumerate() {
                let i = c * CHUNK + k;
                if let Err(e) = one(i, s) {
                    bad.push((i, e));
                }
            }
            bad
        })
        .collect();
    failed.sort_by_key(|(i, _)| *i);
    failed
}

/// One instruction of the lane program: the compiled program's [`Instr::Op`] (its flat
/// code and two parameters).
pub(crate) type LaneOp = (u8, f64, f64);

/// The tape's compiled program as lane instructions (`None` if an instruction has no
/// lane form, a window or a general kernel: the states then run one by one).
pub(crate) fn lower_lanes(tape: &Tape) -> Option<Vec<LaneOp>> {
    tape.program()?
        .iter()
        .map(|ins| match *ins {
            Instr::Op { f, a, b } => Some((f, a, b)),
            _ => None,
        })
        .collect()
}

/// A chunk of states through the lane program, [`LANES`] at a time: each group is
/// transposed to structure-of-arrays (each entry of Σ a contiguous array over the
/// group's states), runs the program instruction by instruction (one dispatch per
/// instruction and group, then a unit-stride loop over the lanes), and is transposed
/// back; the indices (in `chunk`) of states whose lanes became non-finite are pushed to
/// `poisoned`, and those states are left as they were.
///
/// Compiled once per instruction set and chosen at run time (AVX-512, AVX2, or the
/// target's baseline): the lane loops are written for the compiler to vectorise, so
/// the width of the machine's vectors is the width of a step. No fused multiply-add is
/// enabled, so every lane computes exactly what the scalar kernels compute.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512dq+avx512vl", "x86_64+avx2"))]
fn run_chunk<const N: usize>(prog: &[LaneOp], chunk: &mut [Cov<N>], poisoned: &mut Vec<usize>) {
    let mut a: Box<Lanes> = Box::new([[0.0; LANES]; 15]);
    for (g, group) in chunk.chunks_mut(LANES).enumerate() {
        // A ragged tail runs as a partial group (the spare lanes hold copies of its
        // first state and are discarded), so every state takes the same arithmetic.
        for l in 0..LANES {
            let s = group[l.min(group.len() - 1)].raw();
            for e in 0..Cov::<N>::PACKED_LEN {
                a[e][l] = s[e];
            }
        }
        run_group::<N>(prog, &mut a[..]);
        let mut bad = [false; LANES];
        mark_non_finite::<N>(&a[..], &mut bad);
        for (l, s) in group.iter_mut().enumerate() {
            if bad[l] {
                poisoned.push(g * LANES + l);
                continue;
            }
            let s = s.raw_mut();
            for e in 0..Cov::<N>::PACKED_LEN {
                s[e] = a[e][l];
            }
        }
    }
}

/// Groups already stored structure-of-arrays ([`crate::CovLanes`]: `N(N+1)/2` lanes
/// per group) through the lane program, in place: no transposition. Each group is
/// copied first (a contiguous copy of its used entries); the lanes that become
/// non-finite are restored from the copy and their index (group-relative to `groups`)
/// pushed to `poisoned`.
#[multiversion::multiversion(targets("x86_64+avx512f+avx512dq+avx512vl", "x86_64+avx2"))]
pub(crate) fn run_groups<const N: usize>(prog: &[LaneOp], groups: &mut [Lane], poisoned: &mut Vec<usize>) {
    let p = Cov::<N>::PACKED_LEN;
    let mut backup: Lanes = [[0.0; LANES]; 15];
    for (g, a) in groups.chunks_exact_mut(p).enumerate() {
        backup[..p].copy_from_slice(a);
        run_group::<N>(prog, a);
        let mut bad = [false; LANES];
        mark_non_finite::<N>(a, &mut bad);
        for (l, _) in bad.iter().enumerate().filter(|(_, b)| **b) {
            for (e, saved) in a.iter_mut().zip(&backup) {
                e[l] = saved[l];
            }
            poisoned.push(g * LANES + l);
        }
    }
}

/// The lane program on one group: each instruction dispatched to its constant-index
/// kernel, inlined here (and so compiled for the instruction set of [`run_chunk`]).
#[inline(always)]
fn run_group<const N: usize>(prog: &[LaneOp], a: &mut [Lane]) {
    // One length check for every constant index below (each is under `N(N+1)/2`).
    assert!(a.len() >= Cov::<N>::PACKED_LEN, "a group holds every entry of Σ");
    for &(f, x, y) in prog {
        flat_dispatch!(f;
            shear |i, j| shear::<N>(a, i, j, x);
            rotate |i, j| rotate::<N>(a, i, j, x, y);
            scale |i| scale::<N>(a, i, x);
            variance |i| add_variance::<N>(a, i, x);
            // The lane snap, as the scalar one, keeps an ∞ non-finite: the check at
            // the end sees it (`Kernels::LOBE_1_KEEPS_NON_FINITE`).
            lobe |i| lobe_1::<N>(a, i, x);
            pairs {
                shear::<N>(a, 0, 2, x);
                shear::<N>(a, 1, 3, y);
            }, {
                shear::<N>(a, 2, 0, x);
                shear::<N>(a, 3, 1, y);
            }, {
                rotate::<N>(a, 0, 1, x, y);
                rotate::<N>(a, 2, 3, x, y);
            }, {
                scale::<N>(a, 2, x);
                scale::<N>(a, 3, y);
            }, {
                add_variance::<N>(a, 0, x);
                add_variance::<N>(a, 1, y);
            }
        )
    }
}

/// `Σ_ii += w`, lane by lane.
#[inline(always)]
fn add_variance<const N: usize>(a: &mut [Lane], i: usize, w: f64) {
    for v in a[ix::<N>(i, i)].iter_mut() {
        *v += w;
    }
}

/// Marks the lanes holding a non-finite entry: `x − x` is `+0` for a finite `x` and NaN
/// for ±∞ or NaN, so the lane's sum of them is NaN exactly when one entry is not
/// finite (two vector operations per entry, no mask conversion per entry).
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` is the test itself: NaN exactly for a non-finite `x`.
fn mark_non_finite<const N: usize>(a: &[Lane], poisoned: &mut [bool; LANES]) {
    let mut acc = [0.0f64; LANES];
    for e in a.iter().take(N * (N + 1) / 2) {
        for l in 0..LANES {
            acc[l] += e[l] - e[l];
        }
    }
    for l in 0..LANES {
        poisoned[l] |= acc[l] != 0.0;
    }
}

// The lane kernels: each is the scalar kernel's arithmetic (same operations, same
// order) in one loop over the lanes, with per-lane locals and no row copies, so that
// the compiler turns the loop body into vector operations across lanes.

/// `Cov::shear_col` then commit, lane by lane.
#[inline(always)]
fn shear<const N: usize>(a: &mut [Lane], i: usize, j: usize, s: f64) {
    let (ii, ij, jj) = (ix::<N>(i, i), ix::<N>(i, j), ix::<N>(j, j));
    for l in 0..LANES {
        let diag = (a[jj][l] + s * (2.0 * a[ij][l] + s * a[ii][l])).abs();
        for k in 0..N {
            if k != j {
                let (kj, ki) = (ix::<N>(k, j), ix::<N>(k, i));
                a[kj][l] += s * a[ki][l];
            }
        }
        a[jj][l] = diag;
    }
}

/// `Cov::scale_col` then commit, lane by lane.
#[inline(always)]
fn scale<const N: usize>(a: &mut [Lane], i: usize, c: f64) {
    for l in 0..LANES {
        for k in 0..N {
            let f = if k == i { c * c } else { c };
            a[ix::<N>(k, i)][l] *= f;
        }
    }
}

/// `Cov::rotate_idx`, lane by lane.
#[inline(always)]
fn rotate<const N: usize>(a: &mut [Lane], i: usize, j: usize, c: f64, s: f64) {
    let (ii, ij, jj) = (ix::<N>(i, i), ix::<N>(i, j), ix::<N>(j, j));
    let cs = c * s;
    for l in 0..LANES {
        let (sii, sij, sjj) = (a[ii][l], a[ij][l], a[jj][l]);
        for k in 0..N {
            if k != i && k != j {
                let (ki, kj) = (ix::<N>(k, i), ix::<N>(k, j));
                let (x, y) = (a[ki][l], a[kj][l]);
                a[ki][l] = c * x + s * y;
                a[kj][l] = c * y - s * x;
            }
        }
        a[ii][l] = (c * c * sii + 2.0 * cs * sij + s * s * sjj).abs();
        a[jj][l] = (s * s * sii - 2.0 * cs * sij + c * c * sjj).abs();
        a[ij][l] = cs * (sjj - sii) + (c * c - s * s) * sij;
    }
}

/// `Cov::lobe_product_1` with its snap, lane by lane.
#[inline(always)]
fn lobe_1<const N: usize>(a: &mut [Lane], p: usize, s: f64) {
    let mut before = [[0.0; LANES]; 5];
    for (i, b) in before.iter_mut().enumerate().take(N) {
        *b = a[ix::<N>(i, i)];
    }
    let pp = ix::<N>(p, p);
    let spp = a[pp];
    let mut inv = [0.0; LANES];
    let mut t = [0.0; LANES];
    for l in 0..LANES {
        let m = s + spp[l];
        (inv[l], t[l]) = if m > 0.0 { (1.0 / m, s / m) } else { (0.0, 0.0) };
    }
    let mut col = [[0.0; LANES]; 5];
    for (o, c) in col.iter_mut().enumerate().take(N) {
        *c = a[ix::<N>(o, p)];
    }
    for x in 0..N {
        if x == p {
            continue;
        }
        let mut g = [0.0; LANES];
        for l in 0..LANES {
            g[l] = col[x][l] * inv[l];
        }
        for y in x..N {
            if y != p {
                let e = &mut a[ix::<N>(x, y)];
                for l in 0..LANES {
                    e[l] -= g[l] * col[y][l];
                }
            }
        }
        let e = &mut a[ix::<N>(x, p)];
        for l in 0..LANES {
            e[l] = col[x][l] * t[l];
        }
    }
    for l in 0..LANES {
        a[pp][l] = spp[l] * t[l];
    }
    // `Cov::snap_cancelled`: a diagonal that is negative, had no content, or (off the
    // lobe's axis) cancelled to SCHUR_SNAP of its value is noise; its row and column
    // become 0. Entry (x, y) is zeroed if row x or row y is noise (one pass per packed
    // entry, and none at all for a row no lane snaps: the usual case).
    let mut noise = [[false; LANES]; 5];
    let mut any = [false; 5];
    for x in 0..N {
        let d = &a[ix::<N>(x, x)];
        let mut hit = false;
        // Off the lobe's axis, `d < 0` implies `d <= SCHUR_SNAP · before` whenever
        // `before > 0` (and `d` is NaN otherwise): the same decisions with one test less.
        if x == p {
            for l in 0..LANES {
                let n = d[l] < 0.0 || before[x][l] <= 0.0;
                noise[x][l] = n;
                hit |= n;
            }
        } else {
            for l in 0..LANES {
                let n = before[x][l] <= 0.0 || d[l] <= crate::SCHUR_SNAP * before[x][l];
                noise[x][l] = n;
                hit |= n;
            }
        }
        any[x] = hit;
    }
    for x in 0..N {
        for y in x..N {
            if any[x] || any[y] {
                let e = &mut a[ix::<N>(x, y)];
                for l in 0..LANES {
                    if noise[x][l] || noise[y][l] {
                        e[l] -= e[l];
                    }
                }
            }
        }
    }
}
