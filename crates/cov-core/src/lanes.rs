//! [`CovLanes`]: many covariance states stored structure-of-arrays, the layout the batch
//! kernels compute in, and [`Chain::eval_lanes`], which runs a chain over them in place
//! with no transposition.

use std::fmt;

use rayon::prelude::*;

use crate::batch::{CHUNK, LANES, Lane, lower_lanes, run_groups};
use crate::{Chain, Cov, CovError, Form};

/// Covariance states stored structure-of-arrays, in groups of [`LANES`]: within a
/// group, each of Σ's `N(N+1)/2` packed entries is one contiguous array over the
/// group's states. This is the layout [`Chain::eval_batch`] transposes a slice of
/// [`Cov`] into and back out of for every call; a renderer that keeps a tile's states
/// here saves both transpositions ([`Chain::eval_lanes`]) and stores only the entries
/// its layout uses (24 bytes a state in flatland, 80 in 4D, against 120 for a `Cov`).
///
/// Every state in it is a valid Σ (it only ever holds what a [`Cov`] held, or a
/// kernel's result). Memory grows with [`CovLanes::push`] as a `Vec` does; the last
/// group is padded to [`LANES`] states.
///
/// ```
/// use cov_core::{Cov, CovError, CovLanes};
/// let mut lanes: CovLanes<2> = (1..=100).map(|i| Cov::from_diagonal([i as f64, 1.0])).collect::<Result<_, _>>()?;
/// assert_eq!(lanes.len(), 100);
/// assert_eq!(lanes.get(9), Some(Cov::from_diagonal([10.0, 1.0])?));
/// lanes.set(9, Cov::from_diagonal([0.5, 2.0])?);
/// assert_eq!(lanes.iter().nth(9).map(|c| c.get(1, 1)), Some(2.0));
/// assert_eq!(lanes.get(100), None);
/// # Ok::<(), CovError>(())
/// ```
#[derive(Clone, Default, PartialEq)]
pub struct CovLanes<const N: usize> {
    /// Groups one after the other, `N(N+1)/2` lanes each.
    data: Vec<Lane>,
    len: usize,
}

impl<const N: usize> CovLanes<N> {
    /// Packed entries per state (lanes per group).
    const P: usize = Cov::<N>::PACKED_LEN;

    /// No states.
    pub fn new() -> Self {
        CovLanes {
            data: Vec::new(),
            len: 0,
        }
    }

    /// No states, with room for `n` without reallocating.
    pub fn with_capacity(n: usize) -> Self {
        CovLanes {
            data: Vec::with_capacity(n.div_ceil(LANES) * Self::P),
            len: 0,
        }
    }

    /// The number of states.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there is no state.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Removes every state (keeps the memory).
    pub fn clear(&mut self) {
        self.data.clear();
        self.len = 0;
    }

    /// Appends a state.
    pub fn push(&mut self, c: Cov<N>) {
        if self.len.is_multiple_of(LANES) {
            // A new group; its spare lanes hold Σ = 0 until filled.
            self.data.resize(self.data.len() + Self::P, [0.0; LANES]);
        }
        self.len += 1;
        write(&mut self.data, self.len - 1, &c);
    }

    /// State `i`, or `None` past the end.
    pub fn get(&self, i: usize) -> Option<Cov<N>> {
        (i < self.len).then(|| read(&self.data, i))
    }

    /// Replaces state `i`.
    ///
    /// # Panics
    /// If `i` is past the end (as slice indexing does).
    pub fn set(&mut self, i: usize, c: Cov<N>) {
        assert!(
            i < self.len,
            "CovLanes::set: index {i} past the end ({} states)",
            self.len
        );
        write(&mut self.data, i, &c);
    }

    /// The states in order, as [`Cov`] values.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Cov<N>> + '_ {
        (0..self.len).map(|i| read(&self.data, i))
    }

    /// The states as a `Vec` of [`Cov`].
    pub fn to_vec(&self) -> Vec<Cov<N>> {
        self.iter().collect()
    }
}

/// State `i` of groups stored as [`CovLanes`] holds them.
fn read<const N: usize>(data: &[Lane], i: usize) -> Cov<N> {
    let p = Cov::<N>::PACKED_LEN;
    let (g, l) = (i / LANES, i % LANES);
    let mut c = Cov::<N>::zeros();
    for (e, v) in c.raw_mut()[..p].iter_mut().enumerate() {
        *v = data[g * p + e][l];
    }
    c
}

/// Writes state `i` of groups stored as [`CovLanes`] holds them.
fn write<const N: usize>(data: &mut [Lane], i: usize, c: &Cov<N>) {
    let p = Cov::<N>::PACKED_LEN;
    let (g, l) = (i / LANES, i % LANES);
    for (e, v) in c.raw()[..p].iter().enumerate() {
        data[g * p + e][l] = *v;
    }
}

impl<const N: usize> fmt::Debug for CovLanes<N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<const N: usize> FromIterator<Cov<N>> for CovLanes<N> {
    fn from_iter<I: IntoIterator<Item = Cov<N>>>(iter: I) -> Self {
        let iter = iter.into_iter();
        let mut out = CovLanes::with_capacity(iter.size_hint().0);
        for c in iter {
            out.push(c);
        }
        out
    }
}

impl<const N: usize> From<&[Cov<N>]> for CovLanes<N> {
    fn from(states: &[Cov<N>]) -> Self {
        states.iter().copied().collect()
    }
}

impl<const N: usize> Extend<Cov<N>> for CovLanes<N> {
    fn extend<I: IntoIterator<Item = Cov<N>>>(&mut self, iter: I) {
        for c in iter {
            self.push(c);
        }
    }
}

impl Chain {
    /// Evaluates the chain in covariance form on every state of `states`, in place, in
    /// parallel: [`Chain::eval_batch`] on states already stored structure-of-arrays, so
    /// nothing is transposed. Same results, bit for bit, as [`Chain::eval_batch`] in
    /// [`Form::Covariance`] (and so as the chain's compiled [`Chain::eval_in`]).
    ///
    /// Returns the states that failed, with their error (step, operator, value, as
    /// [`Chain::eval_in`] reports it); those states are left as they were.
    ///
    /// ```
    /// use cov_core::{Axis, Chain, Cov, CovError, CovLanes, Form, Operator, Spectrum};
    /// # #[derive(Debug)] struct Travel(f64);
    /// # impl Operator for Travel {
    /// #     fn apply(&self, c: &mut dyn Spectrum) -> Result<(), CovError> { c.shear(Axis::X, Axis::U, -self.0) }
    /// # }
    /// let chain = Chain::new().with(Travel(1.0)).with(Travel(2.0));
    /// let states: Vec<Cov<2>> = (1..=100)
    ///     .map(|i| Cov::gaussian([0.01 * i as f64, 1.0]))
    ///     .collect::<Result<_, _>>()?;
    /// let mut lanes = CovLanes::from(&states[..]);
    /// assert!(chain.eval_lanes(&mut lanes).is_empty());
    /// assert_eq!(lanes.get(7), Some(chain.eval_in(Form::Covariance, states[7])?));
    /// # Ok::<(), CovError>(())
    /// ```
    pub fn eval_lanes<const N: usize>(&self, states: &mut CovLanes<N>) -> Vec<(usize, CovError)> {
        let Some(tape) = self.tape::<Cov<N>>(true) else {
            return Vec::new(); // unreachable: a forced tape is always built
        };
        let prog = lower_lanes(tape);
        let len = states.len;
        let per_task = CHUNK / LANES * CovLanes::<N>::P;
        let mut failed: Vec<(usize, CovError)> = states
            .data
            .par_chunks_mut(per_task)
            .enumerate()
            .flat_map_iter(|(c, chunk)| {
                let base = c * CHUNK;
                let in_chunk = len.saturating_sub(base).min(CHUNK);
                let mut bad = Vec::new();
                match &prog {
                    Some(prog) => {
                        let mut poisoned = Vec::new();
                        run_groups::<N>(prog, chunk, &mut poisoned);
                        // A lane the program refused is restored: the checked path
                        // decides. Spare lanes of the last group are not states.
                        for k in poisoned.into_iter().filter(|&k| k < in_chunk) {
                            let mut s = read::<N>(chunk, k);
                            self.report_failure(Form::Covariance, &mut s, base + k, &mut bad);
                            write(chunk, k, &s);
                        }
                    }
                    None => {
                        for k in 0..in_chunk {
                            let mut s = read::<N>(chunk, k);
                            self.run_one(tape, Form::Covariance, &mut s, base + k, &mut bad);
                            write(chunk, k, &s);
                        }
                    }
                }
                bad
            })
            .collect();
        failed.sort_by_key(|(i, _)| *i);
        failed
    }
}
