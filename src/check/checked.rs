//! Two intersectors asked every question: the answer is the first one's,
//! every difference from the second is recorded.

use super::difference::{Difference, DifferenceKind, T_TOLERANCE, relative_error};
use super::referee::{Referee, Verdict};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// Runs `ours` and `reference` on every ray and returns `ours`' answer, so a
/// render or a ray set through `Checked` is exactly the render through
/// `ours`, with each disagreement logged for the referee.
pub struct Checked<'a, A: ?Sized, B: ?Sized> {
    ours: &'a A,
    reference: &'a B,
    intersect_queries: AtomicU64,
    occluded_queries: AtomicU64,
    agreeing_hits: AtomicU64,
    // Largest errors on agreeing hits, as f32 bits: non-negative floats order
    // like their bit patterns, so `fetch_max` on the bits is a float max.
    max_rel_t_error: AtomicU32,
    max_uv_error: AtomicU32,
    differences: Mutex<Vec<Difference>>,
}

/// What a [`Checked`] run saw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CheckLog {
    pub intersect_queries: u64,
    pub occluded_queries: u64,
    /// Closest-hit queries where both hit the same triangle.
    pub agreeing_hits: u64,
    /// Largest relative `t` difference on agreeing hits.
    pub max_rel_t_error: f32,
    /// Largest `|Δu|` or `|Δv|` on agreeing hits.
    pub max_uv_error: f32,
    /// Every difference, sorted by ray bits.
    pub differences: Vec<Difference>,
}

impl CheckLog {
    /// The log of two runs together.
    pub fn merge(mut self, other: CheckLog) -> CheckLog {
        self.intersect_queries += other.intersect_queries;
        self.occluded_queries += other.occluded_queries;
        self.agreeing_hits += other.agreeing_hits;
        self.max_rel_t_error = self.max_rel_t_error.max(other.max_rel_t_error);
        self.max_uv_error = self.max_uv_error.max(other.max_uv_error);
        self.differences.extend(other.differences);
        self.differences.sort_by_key(Difference::sort_key);
        self
    }

    /// The referee's verdict on every difference, in order.
    pub fn judge(&self, mesh: &TriangleMesh) -> Vec<Verdict> {
        let referee = Referee::new(mesh);
        self.differences
            .par_iter()
            .map(|d| referee.judge(d))
            .collect()
    }
}

/// How many differences got each verdict, with decisions (hit or miss,
/// which triangle, occluded or not) apart from distances (same triangle,
/// `t` apart): a `t` off in the fifth digit is imprecision, not a wrong hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct VerdictCounts {
    pub ours_wrong: u64,
    pub embree_wrong: u64,
    pub ambiguous: u64,
    /// Same triangle, our `t` further than the tolerance from the exact one.
    pub ours_t_off: u64,
    /// Same triangle, Embree's `t` further than the tolerance from the exact one.
    pub embree_t_off: u64,
}

impl VerdictCounts {
    pub fn tally(differences: &[Difference], verdicts: &[Verdict]) -> Self {
        let mut counts = Self::default();
        for (difference, verdict) in differences.iter().zip(verdicts) {
            let slot = match Finding::of(difference, *verdict) {
                Finding::OursWrong => &mut counts.ours_wrong,
                Finding::EmbreeWrong => &mut counts.embree_wrong,
                Finding::OursTOff => &mut counts.ours_t_off,
                Finding::EmbreeTOff => &mut counts.embree_t_off,
                Finding::Ambiguous => &mut counts.ambiguous,
            };
            *slot += 1;
        }
        counts
    }
}

/// A verdict read with the kind of difference it is about: a wrong answer
/// on a distance alone is imprecision, counted apart from wrong decisions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finding {
    OursWrong,
    EmbreeWrong,
    Ambiguous,
    OursTOff,
    EmbreeTOff,
}

impl Finding {
    pub fn of(difference: &Difference, verdict: Verdict) -> Self {
        let distance = difference.kind() == DifferenceKind::Distance;
        match (verdict, distance) {
            (Verdict::OursWrong, false) => Finding::OursWrong,
            (Verdict::EmbreeWrong, false) => Finding::EmbreeWrong,
            (Verdict::OursWrong, true) => Finding::OursTOff,
            (Verdict::EmbreeWrong, true) => Finding::EmbreeTOff,
            (Verdict::Ambiguous, _) => Finding::Ambiguous,
        }
    }

    /// The name the JSON and the tables use.
    pub fn name(self) -> &'static str {
        match self {
            Finding::OursWrong => "ours_wrong",
            Finding::EmbreeWrong => "embree_wrong",
            Finding::Ambiguous => "ambiguous",
            Finding::OursTOff => "ours_t_off",
            Finding::EmbreeTOff => "embree_t_off",
        }
    }
}

impl<'a, A: Intersector + ?Sized, B: Intersector + ?Sized> Checked<'a, A, B> {
    pub fn new(ours: &'a A, reference: &'a B) -> Self {
        Self {
            ours,
            reference,
            intersect_queries: AtomicU64::new(0),
            occluded_queries: AtomicU64::new(0),
            agreeing_hits: AtomicU64::new(0),
            max_rel_t_error: AtomicU32::new(0),
            max_uv_error: AtomicU32::new(0),
            differences: Mutex::new(Vec::new()),
        }
    }

    /// Everything recorded so far.
    pub fn into_log(self) -> CheckLog {
        let mut differences = self
            .differences
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        differences.sort_by_key(Difference::sort_key);
        CheckLog {
            intersect_queries: self.intersect_queries.into_inner(),
            occluded_queries: self.occluded_queries.into_inner(),
            agreeing_hits: self.agreeing_hits.into_inner(),
            max_rel_t_error: f32::from_bits(self.max_rel_t_error.into_inner()),
            max_uv_error: f32::from_bits(self.max_uv_error.into_inner()),
            differences,
        }
    }

    fn record(&self, difference: Difference) {
        self.differences
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .push(difference);
    }

    fn compare_hits(&self, ray: &Ray, ours: &Option<Hit>, reference: &Option<Hit>) {
        let same = match (ours, reference) {
            (None, None) => true,
            (Some(a), Some(b)) if a.prim == b.prim => {
                let t_error = relative_error(a.t, b.t);
                let uv_error = (a.u - b.u).abs().max((a.v - b.v).abs());
                self.agreeing_hits.fetch_add(1, Ordering::Relaxed);
                self.max_rel_t_error
                    .fetch_max(t_error.to_bits(), Ordering::Relaxed);
                self.max_uv_error
                    .fetch_max(uv_error.to_bits(), Ordering::Relaxed);
                t_error <= T_TOLERANCE
            }
            _ => false,
        };
        if !same {
            self.record(Difference::Intersect {
                ray: *ray,
                ours: *ours,
                reference: *reference,
            });
        }
    }
}

impl<A: Intersector + ?Sized, B: Intersector + ?Sized> Intersector for Checked<'_, A, B> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_queries.fetch_add(1, Ordering::Relaxed);
        let ours = self.ours.intersect(ray);
        let reference = self.reference.intersect(ray);
        self.compare_hits(ray, &ours, &reference);
        ours
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_queries.fetch_add(1, Ordering::Relaxed);
        let ours = self.ours.occluded(ray);
        let reference = self.reference.occluded(ray);
        if ours != reference {
            self.record(Difference::Occluded {
                ray: *ray,
                ours,
                reference,
            });
        }
        ours
    }
}
