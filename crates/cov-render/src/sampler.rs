//! Where a sample's random numbers come from: an Owen-scrambled Sobol sequence
//! (`sobol_burley`), stratified over every prefix of a power-of-two length, so that
//! adaptive sampling (any count per pixel) and a second pass (indices that continue the
//! first) stay stratified.
//!
//! Dimensions are served in pairs ("padding"): pair `k` of pixel `p` is the first two
//! dimensions of the sequence (a (0, 2)-sequence: every power-of-two prefix is stratified
//! in 2D) scrambled with its own seed `hash(seed, p, k)`. The first pair is the position in
//! the pixel, the second the lens, the third time and the light choice. Pairs are
//! statistically independent of each other, stratified within.

/// A source of the numbers in `[0, 1)` one sample consumes, dimension after dimension.
pub trait Sampler {
    /// The next dimension of the current sample.
    fn next(&mut self) -> f64;
}

/// Largest sample index the sequence supports (`sobol_burley` has 2¹⁶ points).
pub const MAX_INDEX: u32 = 1 << 16;

/// Number of pairs one sample may use. The path tracer uses 5 dimensions for the camera
/// ray and at most 6 per surface vertex (the light's choice and point, the next direction,
/// Russian roulette), 6 d + 4 in all at depth `d`: 196 at the deepest scene
/// (the scene file's largest `max_depth`, 32), within these 256. A sample that asked for more
/// would get pairs with wrapped seeds (still uniform, no longer independent of the first
/// ones), which this tracer never does. Pairs below 64 have the seeds they had when this
/// was 64.
const PAIRS: u32 = 128;

/// The padded Owen-scrambled Sobol sampler of one pixel.
#[derive(Clone, Debug)]
pub struct SobolSampler {
    seed: u32,
    index: u32,
    dim: u32,
    pair: [f32; 4],
}

/// A 32-bit mix (the finaliser of MurmurHash3): decorrelates nearby seeds.
fn mix(mut h: u32) -> u32 {
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

impl SobolSampler {
    /// The sampler of pixel `(x, y)` of an image of width `width`, for the render `seed`.
    pub fn new(seed: u64, width: u32, x: u32, y: u32) -> SobolSampler {
        let pixel = u64::from(y) * u64::from(width) + u64::from(x);
        let s = mix((seed as u32) ^ mix((seed >> 32) as u32) ^ mix(pixel as u32 ^ 0x9e37_79b9))
            ^ mix((pixel >> 32) as u32);
        SobolSampler {
            seed: s,
            index: 0,
            dim: 0,
            pair: [0.0; 4],
        }
    }

    /// Starts sample `index` (below [`MAX_INDEX`]; larger indices wrap).
    pub fn start(&mut self, index: u32) {
        self.index = index % MAX_INDEX;
        self.dim = 0;
    }
}

impl Sampler for SobolSampler {
    fn next(&mut self) -> f64 {
        let k = self.dim % 2;
        if k == 0 {
            let g = (self.dim / 2) % PAIRS;
            self.pair = sobol_burley::sample_4d(self.index, 0, mix(self.seed ^ mix(g)));
        }
        self.dim += 1;
        f64::from(self.pair[k as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first 16 samples of a pixel put one point in each cell of a 4×4 grid over
    /// the pixel, and one in each of 16 lens strata too: the sequence is stratified.
    #[test]
    fn prefixes_are_stratified() {
        let mut s = SobolSampler::new(7, 100, 3, 5);
        for n in [4u32, 16, 64] {
            let side = (n as f64).sqrt() as usize;
            let (mut pix, mut lens) = (vec![0; n as usize], vec![0; n as usize]);
            for i in 0..n {
                s.start(i);
                let v: Vec<f64> = (0..4).map(|_| s.next()).collect();
                let cell = |a: f64, b: f64| (a * side as f64) as usize * side + (b * side as f64) as usize;
                pix[cell(v[0], v[1])] += 1;
                lens[cell(v[2], v[3])] += 1;
            }
            assert!(pix.iter().all(|&c| c == 1), "{n} samples over the pixel: {pix:?}");
            assert!(
                lens.iter().all(|&c| c == 1),
                "{n} samples over the lens: {lens:?}"
            );
        }
    }

    /// Different pixels and different groups are scrambled differently.
    #[test]
    fn pixels_and_groups_differ() {
        let mut a = SobolSampler::new(1, 10, 0, 0);
        let mut b = SobolSampler::new(1, 10, 1, 0);
        a.start(0);
        b.start(0);
        let va: Vec<f64> = (0..8).map(|_| a.next()).collect();
        let vb: Vec<f64> = (0..8).map(|_| b.next()).collect();
        assert_ne!(va, vb);
        assert_ne!(va[..2], va[2..4]);
        assert!(va.iter().chain(&vb).all(|v| (0.0..1.0).contains(v)));
    }
}
