//! Pearson's χ² goodness-of-fit test of a direction sampler against the
//! density it claims, the way Mitsuba 3 tests its samplers (`mitsuba.chi2`,
//! after Jakob's χ² tests in Mitsuba 0.5): the sphere is cut into a grid of
//! cells in (θ, φ) about a pole, the sampler's directions are counted per
//! cell, the density is integrated over each cell for the counts expected,
//! cells expecting fewer than 5 samples are pooled (Pearson's statistic is
//! χ²-distributed only where counts are not small), and the statistic's
//! p-value is compared with a significance level corrected for the number
//! of tests run (Šidák 1967).
//!
//! A sampler may return no direction (a sample its estimator drops, such
//! as a glossy reflection below the surface); those samples form one more
//! cell, whose expected share is the mass the density leaves out,
//! `1 − ∫ pdf`.

use crate::random::Rng;
use glam::{DVec3, Vec2, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::{PI, TAU};

/// Cells expecting fewer samples than this are pooled.
pub const MIN_EXPECTED: f64 = 5.0;

/// A grid over the sphere: `theta_cells` equal steps of the angle from
/// `pole` by `phi_cells` equal steps of azimuth about it. `theta_cells` is
/// even, so the pole's equator is a cell edge: a density that stops at a
/// surface with normal `pole` is smooth inside every cell, and each side of
/// the equator is decided by the sign of `dir · pole`, the test a sampler
/// makes.
#[derive(Clone, Copy, Debug)]
pub struct SphereGrid {
    pole: DVec3,
    x: DVec3,
    y: DVec3,
    theta_cells: u32,
    phi_cells: u32,
}

/// The outcome of one χ² test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chi2Outcome {
    pub statistic: f64,
    /// Cells after pooling, less one.
    pub freedom: usize,
    /// The probability of a statistic at least this large if the sampler
    /// draws from the density; 0 when a sample fell where the density is 0.
    pub p_value: f64,
    /// Samples the sampler dropped.
    pub dropped: u64,
}

impl Chi2Outcome {
    /// Whether the sampler is consistent with the density at `level` (see
    /// [`corrected_level`]).
    pub fn passes(&self, level: f64) -> bool {
        self.p_value >= level
    }
}

/// The level each of `tests` independent tests must pass at for the whole
/// family to reject a right sampler with probability `significance` (Šidák).
pub fn corrected_level(significance: f64, tests: u32) -> f64 {
    1.0 - (1.0 - significance).powf(1.0 / tests as f64)
}

impl SphereGrid {
    /// # Panics
    /// If `theta_cells` is odd or either count is 0, or `pole` is not finite
    /// and non-zero.
    pub fn about(pole: Vec3, theta_cells: u32, phi_cells: u32) -> Self {
        assert!(theta_cells > 0 && theta_cells.is_multiple_of(2) && phi_cells > 0);
        let pole = pole.as_dvec3().normalize();
        assert!(pole.is_finite(), "the pole must be a direction");
        let (x, y) = pole.any_orthonormal_pair();
        Self {
            pole,
            x,
            y,
            theta_cells,
            phi_cells,
        }
    }

    fn cells(&self) -> usize {
        (self.theta_cells * self.phi_cells) as usize
    }

    /// The cell `dir` falls in.
    fn cell(&self, dir: Vec3) -> usize {
        let d = dir.as_dvec3().normalize();
        let theta = d.dot(self.pole).clamp(-1.0, 1.0).acos();
        let phi = d.dot(self.y).atan2(d.dot(self.x)).rem_euclid(TAU);
        let half = self.theta_cells / 2;
        let row = ((theta / PI * self.theta_cells as f64) as u32).min(self.theta_cells - 1);
        // The side of the equator as the sampler sees it.
        let row = if dir.dot(self.pole.as_vec3()) > 0.0 {
            row.min(half - 1)
        } else {
            row.max(half)
        };
        let column = ((phi / TAU * self.phi_cells as f64) as u32).min(self.phi_cells - 1);
        (row * self.phi_cells + column) as usize
    }

    /// `pdf` integrated over every cell, in solid angle: 4×4-point
    /// Gauss–Legendre per cell in (θ, φ), with the Jacobian sin θ. Its nodes
    /// are inside the cell, so a density that jumps at a cell edge is
    /// integrated from the right side.
    fn integrate(&self, pdf: &impl Fn(Vec3) -> f64) -> Vec<f64> {
        // Nodes on [-1, 1] and their weights (Abramowitz & Stegun, table 25.4).
        const NODES: [f64; 4] = [
            -0.861_136_311_594_052_6,
            -0.339_981_043_584_856_3,
            0.339_981_043_584_856_3,
            0.861_136_311_594_052_6,
        ];
        const WEIGHTS: [f64; 4] = [
            0.347_854_845_137_453_9,
            0.652_145_154_862_546_1,
            0.652_145_154_862_546_1,
            0.347_854_845_137_453_9,
        ];
        let d_theta = PI / self.theta_cells as f64;
        let d_phi = TAU / self.phi_cells as f64;
        let mut integrals = Vec::with_capacity(self.cells());
        for row in 0..self.theta_cells {
            for column in 0..self.phi_cells {
                let mut sum = 0.0;
                for (a, wa) in NODES.iter().zip(WEIGHTS) {
                    let theta = (row as f64 + 0.5 + 0.5 * a) * d_theta;
                    let (sin_t, cos_t) = theta.sin_cos();
                    for (b, wb) in NODES.iter().zip(WEIGHTS) {
                        let phi = (column as f64 + 0.5 + 0.5 * b) * d_phi;
                        let (sin_p, cos_p) = phi.sin_cos();
                        let dir = cos_t * self.pole + sin_t * (cos_p * self.x + sin_p * self.y);
                        sum += wa * wb * pdf(dir.as_vec3()) * sin_t;
                    }
                }
                integrals.push(sum * 0.25 * d_theta * d_phi);
            }
        }
        integrals
    }
}

/// Tests `sample` (a direction, or none, from a uniform point of the unit
/// square) against `pdf` (per unit solid angle) with `samples` independent
/// uniform points drawn from `seed`, binned on `grid`.
pub fn test_directions(
    grid: &SphereGrid,
    samples: u32,
    seed: u64,
    sample: impl Fn(Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2Outcome {
    let mut observed = vec![0u64; grid.cells() + 1];
    let dropped_cell = grid.cells();
    let mut rng = Rng::new(seed);
    for _ in 0..samples {
        let xi = Vec2::new(rng.unit_f32(), rng.unit_f32());
        match sample(xi) {
            Some(dir) => observed[grid.cell(dir)] += 1,
            None => observed[dropped_cell] += 1,
        }
    }
    let mut expected: Vec<f64> = grid
        .integrate(&pdf)
        .into_iter()
        .map(|p| p * samples as f64)
        .collect();
    let covered: f64 = expected.iter().sum();
    expected.push((samples as f64 - covered).max(0.0));
    let dropped = observed[dropped_cell];
    let (statistic, freedom) = pearson(&observed, &expected);
    let p_value = match ChiSquared::new(freedom.max(1) as f64) {
        Ok(chi2) if statistic.is_finite() => chi2.sf(statistic),
        _ => 0.0,
    };
    Chi2Outcome {
        statistic,
        freedom,
        p_value,
        dropped,
    }
}

/// Pearson's statistic Σ (O − E)²/E and its degrees of freedom (cells − 1),
/// with small cells pooled: in increasing order of expectation, cells are
/// gathered until the pool expects at least [`MIN_EXPECTED`]; a pool still
/// short at the end joins the last cell. Infinite when a cell expecting
/// nothing holds a sample.
fn pearson(observed: &[u64], expected: &[f64]) -> (f64, usize) {
    let mut cells: Vec<(f64, f64)> = Vec::new();
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let mut pool = (0.0, 0.0);
    for i in order {
        let (o, e) = (observed[i] as f64, expected[i]);
        if e <= 0.0 {
            if o > 0.0 {
                return (f64::INFINITY, 0);
            }
            continue;
        }
        pool = (pool.0 + o, pool.1 + e);
        if pool.1 >= MIN_EXPECTED {
            cells.push(pool);
            pool = (0.0, 0.0);
        }
    }
    if pool.1 > 0.0 {
        match cells.last_mut() {
            Some(last) => *last = (last.0 + pool.0, last.1 + pool.1),
            None => cells.push(pool),
        }
    }
    let statistic = cells.iter().map(|(o, e)| (o - e).powi(2) / e).sum();
    (statistic, cells.len().saturating_sub(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::glossy::{lobe_pdf, phong_exponent, reflect, sample_lobe};

    const SAMPLES: u32 = 1_000_000;

    /// A unit normal and a mirror direction `elevation` degrees above its
    /// surface (below it for a negative angle, as a shading normal can give).
    fn setting(elevation: f32) -> (Vec3, Vec3) {
        let normal = Vec3::new(0.2, 1.0, -0.3).normalize();
        let (t, _) = normal.any_orthonormal_pair();
        let e = elevation.to_radians();
        (normal, e.cos() * t + e.sin() * normal)
    }

    /// The density of [`reflect`]: the lobe where it is above the surface.
    fn above(mirror: Vec3, normal: Vec3, exponent: f32) -> impl Fn(Vec3) -> f64 {
        move |d: Vec3| {
            if d.dot(normal) > 0.0 {
                lobe_pdf(mirror, exponent, d) as f64
            } else {
                0.0
            }
        }
    }

    #[test]
    fn uniform_directions_fit_the_uniform_density() {
        let grid = SphereGrid::about(Vec3::Z, 36, 72);
        let outcome = test_directions(
            &grid,
            SAMPLES,
            1,
            |xi| {
                let z = 1.0 - 2.0 * xi.x;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * xi.y;
                Some(Vec3::new(r * phi.cos(), r * phi.sin(), z))
            },
            |_| 0.25 / PI,
        );
        assert!(outcome.passes(0.01), "{outcome:?}");
        assert_eq!(outcome.dropped, 0);
    }

    #[test]
    fn glossy_directions_fit_their_density_down_to_grazing() {
        // The brushed metal of the scenes (0.12), a rougher and a very rough
        // lobe; mirror directions from steep to grazing and just below.
        let roughnesses = [0.12, 0.3, 0.7];
        let elevations = [60.0, 10.0, 1.0, -1.0];
        let level = corrected_level(0.01, (roughnesses.len() * elevations.len()) as u32);
        for (i, roughness) in roughnesses.into_iter().enumerate() {
            for (j, elevation) in elevations.into_iter().enumerate() {
                let exponent = phong_exponent(roughness);
                let (normal, mirror) = setting(elevation);
                let grid = SphereGrid::about(normal, 180, 360);
                let outcome = test_directions(
                    &grid,
                    SAMPLES,
                    (i * 10 + j) as u64,
                    |xi| reflect(mirror, normal, exponent, xi),
                    above(mirror, normal, exponent),
                );
                assert!(
                    outcome.passes(level),
                    "roughness {roughness}, {elevation}°: {outcome:?} (level {level})"
                );
                if elevation < 10.0 {
                    assert!(outcome.dropped > 0, "{roughness}, {elevation}°");
                }
            }
        }
    }

    #[test]
    fn a_density_that_does_not_match_is_rejected() {
        let grid_for = |normal| SphereGrid::about(normal, 180, 360);
        // A lobe 5% narrower than the sampler's.
        let exponent = phong_exponent(0.3);
        let (normal, mirror) = setting(45.0);
        let narrower = test_directions(
            &grid_for(normal),
            SAMPLES,
            3,
            |xi| reflect(mirror, normal, exponent, xi),
            above(mirror, normal, exponent * 1.05),
        );
        assert!(!narrower.passes(0.01), "{narrower:?}");
        // Samples below the surface moved onto the mirror direction: a
        // point mass the density does not have.
        let (normal, mirror) = setting(2.0);
        let fallback = test_directions(
            &grid_for(normal),
            SAMPLES,
            4,
            |xi| {
                let dir = sample_lobe(mirror, exponent, xi);
                Some(if dir.dot(normal) > 0.0 { dir } else { mirror })
            },
            above(mirror, normal, exponent),
        );
        assert!(!fallback.passes(0.01), "{fallback:?}");
    }

    #[test]
    fn pooling_merges_small_cells_and_an_impossible_sample_fails() {
        // Two cells of 2.5 pool into one of 5; the rest stand alone.
        let (statistic, freedom) = pearson(&[3, 2, 10, 12], &[2.5, 2.5, 10.0, 12.5]);
        let by_hand = 0.0 / 5.0 + 0.0 / 10.0 + 0.25 / 12.5;
        assert!((statistic - by_hand).abs() < 1e-12, "{statistic}");
        assert_eq!(freedom, 2);
        // A last pool short of 5 joins the next cell: (1 + 10) vs (1 + 10).
        assert_eq!(pearson(&[1, 10], &[1.0, 10.0]), (0.0, 0));
        assert_eq!(pearson(&[1, 10], &[0.0, 11.0]).0, f64::INFINITY);
        // Twelve tests at the corrected level keep the family at 1%.
        assert!((corrected_level(0.01, 1) - 0.01).abs() < 1e-15);
        let family = 1.0 - (1.0 - corrected_level(0.01, 12)).powi(12);
        assert!((family - 0.01).abs() < 1e-12, "{family}");
    }
}
