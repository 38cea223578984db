//! Counter-based random numbers: every value is a hash of (seed, pixel,
//! sample, dimension), so a render is the same whatever thread computes a
//! pixel and in whatever order (Salmon et al. 2011, "Parallel Random
//! Numbers: As Easy as 1, 2, 3", the counter-based idea; the mixing function
//! is the SplitMix64 finalizer of Steele, Lea, Flood 2014).
//!
//! A [`Sampler`] turns those numbers into the samples of one estimate:
//! stratified (jittered, Cook 1986, "Stochastic sampling in computer
//! graphics") or independent. Both draw the same dimensions of the stream in
//! the same order, so they differ only in where the samples fall.

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

/// How the `count` samples of one estimate (a pixel's camera samples, a
/// light's shadow rays, a glossy hit's reflection rays) are placed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Sampler {
    /// One sample per stratum, jittered inside it: [`stratified_1d`] and
    /// [`stratified_2d`]. Never worse than independent samples, and better
    /// where the integrand is smooth.
    #[default]
    Stratified,
    /// Every sample uniform over the whole domain, independently of the others.
    Independent,
}

impl Sampler {
    /// Sample `index` of `count` over [0, 1), from one dimension of `stream`.
    pub fn sample_1d(self, index: u32, count: u32, stream: &mut SampleStream) -> f32 {
        let jitter = stream.next_1d();
        match self {
            Sampler::Stratified => stratified_1d(index, count, jitter),
            Sampler::Independent => jitter,
        }
    }

    /// Sample `index` of `count` over the unit square, from two dimensions
    /// of `stream`.
    pub fn sample_2d(self, index: u32, count: u32, stream: &mut SampleStream) -> Vec2 {
        let jitter = stream.next_2d();
        match self {
            Sampler::Stratified => stratified_2d(index, count, jitter),
            Sampler::Independent => jitter,
        }
    }
}

/// The side k of the k×k grid that stratifies `count` samples over the
/// unit square: k = ⌊√count⌋.
pub fn grid_side(count: u32) -> u32 {
    count.isqrt()
}

/// Whether [`stratified_2d`] fills its grid exactly with `count` samples,
/// one per cell and none left over: true for the perfect squares 1, 4, 9,
/// 16, … Any other count leaves `count − k²` samples independent (see
/// [`stratified_2d`]). In one dimension every count fills its strata.
pub fn fills_grid(count: u32) -> bool {
    grid_side(count).pow(2) == count
}

/// Sample `index` of `count` over the unit square, jittered in its stratum:
/// the first k² samples (k = [`grid_side`]) fill a k×k grid of cells, one
/// each; any others are uniform over the square, so the estimate stays
/// unbiased for every count but is stratified only as far as the grid goes.
pub fn stratified_2d(index: u32, count: u32, jitter: Vec2) -> Vec2 {
    let k = grid_side(count);
    if index >= k * k {
        return jitter;
    }
    let cell = Vec2::new((index % k) as f32, (index / k) as f32);
    (cell + jitter) / k as f32
}

/// Sample `index` of `count` over [0, 1), jittered in its stratum: the
/// strata are the `count` equal intervals, so every count fills them.
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

    #[test]
    fn exactly_the_perfect_squares_fill_the_grid() {
        let filling: Vec<u32> = (1..=64).filter(|&n| fills_grid(n)).collect();
        assert_eq!(filling, [1, 4, 9, 16, 25, 36, 49, 64]);
        for count in [1, 4, 16, 64, 256] {
            // Every cell of the k×k grid gets exactly one of the samples.
            let k = grid_side(count);
            let mut seen = vec![0u32; count as usize];
            for i in 0..count {
                let p = stratified_2d(i, count, Vec2::new(0.25, 0.75)) * k as f32;
                seen[p.y as usize * k as usize + p.x as usize] += 1;
            }
            assert!(seen.iter().all(|&s| s == 1), "{count}: {seen:?}");
        }
    }

    #[test]
    fn both_samplers_draw_the_same_dimensions() {
        let mut stratified = SampleStream::new(3, 1, 2);
        let mut independent = stratified.clone();
        let s = Sampler::Stratified.sample_2d(5, 16, &mut stratified);
        let i = Sampler::Independent.sample_2d(5, 16, &mut independent);
        // Cell 5 of the 4×4 grid is column 1, row 1.
        assert_eq!(s, (Vec2::new(1.0, 1.0) + i) / 4.0);
        assert_eq!(stratified.next_1d(), independent.next_1d());
        let t = Sampler::Independent.sample_1d(2, 4, &mut independent);
        assert_eq!(
            Sampler::Stratified.sample_1d(2, 4, &mut stratified),
            (2.0 + t) / 4.0
        );
    }
}
