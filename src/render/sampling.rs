//! Counter-based random numbers: every value is a hash of (seed, pixel,
//! sample, dimension), so a render is the same whatever thread computes a
//! pixel and in whatever order (Salmon et al. 2011, "Parallel Random
//! Numbers: As Easy as 1, 2, 3", the counter-based idea; the mixing function
//! is the SplitMix64 finalizer of Steele, Lea, Flood 2014).

use crate::random::mix;
use glam::Vec2;

/// The random numbers of one camera sample: dimension `d` of sample `s` of
/// pixel `p` is `hash(seed, p, s, d)`; dimensions are drawn in order.
#[derive(Clone, Debug)]
pub struct SampleStream {
    key: u64,
    dimension: u32,
}

impl SampleStream {
    pub fn new(seed: u64, pixel: u32, sample: u32) -> Self {
        let key = mix(mix(seed) ^ ((pixel as u64) << 32 | sample as u64));
        Self { key, dimension: 0 }
    }

    /// The next dimension, uniform in [0, 1).
    pub fn next_1d(&mut self) -> f32 {
        let bits = mix(self.key ^ mix(self.dimension as u64 + 1));
        self.dimension += 1;
        // The top 24 bits give every f32 multiple of 2^-24 below 1.
        (bits >> 40) as f32 * (1.0 / (1u64 << 24) as f32)
    }

    pub fn next_2d(&mut self) -> Vec2 {
        Vec2::new(self.next_1d(), self.next_1d())
    }
}

/// Sample `index` of `count` over the unit square, jittered in its stratum
/// (Cook 1986, "Stochastic sampling in computer graphics"): the first k²
/// samples (k = ⌊√count⌋) fill a k×k grid of cells, one each; any others
/// are uniform over the square, so the estimate stays unbiased for every
/// count.
pub fn stratified_2d(index: u32, count: u32, jitter: Vec2) -> Vec2 {
    let k = count.isqrt();
    if index >= k * k {
        return jitter;
    }
    let cell = Vec2::new((index % k) as f32, (index / k) as f32);
    (cell + jitter) / k as f32
}

/// Sample `index` of `count` over [0, 1), jittered in its stratum.
pub fn stratified_1d(index: u32, count: u32, jitter: f32) -> f32 {
    (index as f32 + jitter) / count as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_are_uniform_distinct_and_repeatable() {
        let mut a = SampleStream::new(7, 3, 0);
        let values: Vec<f32> = (0..10_000).map(|_| a.next_1d()).collect();
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
        let mean = values.iter().sum::<f32>() / values.len() as f32;
        assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
        assert_eq!(SampleStream::new(7, 3, 0).next_1d(), values[0]);
        assert_ne!(SampleStream::new(7, 3, 1).next_1d(), values[0]);
        assert_ne!(SampleStream::new(8, 3, 0).next_1d(), values[0]);
        assert_ne!(SampleStream::new(7, 4, 0).next_1d(), values[0]);
    }

    #[test]
    fn strata_cover_the_square_once_each() {
        let mut seen = [0u32; 9];
        for i in 0..9 {
            let p = stratified_2d(i, 9, Vec2::splat(0.5));
            seen[(p.y * 3.0) as usize * 3 + (p.x * 3.0) as usize] += 1;
        }
        assert_eq!(seen, [1; 9]);
        assert_eq!(
            stratified_2d(4, 5, Vec2::new(0.3, 0.9)),
            Vec2::new(0.3, 0.9)
        );
        assert_eq!(stratified_1d(3, 4, 0.5), 0.875);
    }
}
