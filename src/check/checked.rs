//! Several backends asked every question: the answer is the first one's,
//! and every query on which two answers differ is recorded, with a fixed
//! sample of the queries on which all agree, for the referee.

use super::answer::{Answer, DifferenceKind, Record, ray_bits, relative_error};
use super::referee::{Judgement, Referee};
use crate::backends::Backend;
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::random::mix;
use crate::trace::Intersector;
use rayon::prelude::*;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};

/// One in this many agreeing queries is judged too, so that a mistake
/// every backend shares cannot hide. The draw hashes the ray's bits, so
/// the same queries are drawn whatever the thread count.
pub const AGREEMENT_SAMPLE: u64 = 100;

/// Runs every backend on every query and returns the first one's answer,
/// so a render or a ray set through `Checked` is exactly the render
/// through the first backend, with every disagreement logged for the
/// referee.
pub struct Checked<'a> {
    backends: Vec<&'a dyn Backend>,
    /// One in this many agreeing queries is recorded.
    sample_every: u64,
    counters: Vec<Counters>,
    intersect_queries: AtomicU64,
    occluded_queries: AtomicU64,
    records: Mutex<Vec<Record>>,
}

/// What one backend's answers showed, as atomics while the run goes on.
#[derive(Default)]
struct Counters {
    misses: AtomicU64,
    nan_outputs: AtomicU64,
    differences: [AtomicU64; 4],
    agreeing_hits: AtomicU64,
    // Largest errors against the first backend, as f32 bits: non-negative
    // floats order like their bit patterns, so `fetch_max` on the bits is
    // a float max.
    max_rel_t_error: AtomicU32,
    max_uv_error: AtomicU32,
}

/// What one backend's answers showed over a [`Checked`] run.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BackendLog {
    /// The backend's `--backends` name.
    pub name: String,
    /// Whether it gives `u`, `v` (else its `max_uv_error` means nothing).
    pub gives_uv: bool,
    /// Closest-hit queries it answered with a miss.
    pub misses: u64,
    /// Hits with a non-finite `t`, `u`, `v` or normal.
    pub nan_outputs: u64,
    /// Queries on which it differs from the first backend, by kind.
    pub hit_mismatch: u64,
    pub prim_mismatch: u64,
    pub t_mismatch: u64,
    pub occlusion_mismatch: u64,
    /// Closest-hit queries where it hits the first backend's triangle.
    pub agreeing_hits: u64,
    /// Largest relative `t` difference from the first backend's hit on
    /// the same triangle.
    pub max_rel_t_error: f32,
    /// Largest `|Δu|` or `|Δv|` from the first backend's hit on the same
    /// triangle.
    pub max_uv_error: f32,
}

/// What a [`Checked`] run saw.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CheckLog {
    pub intersect_queries: u64,
    pub occluded_queries: u64,
    /// One per backend, in the order given.
    pub backends: Vec<BackendLog>,
    /// Every disagreement and every sampled agreement, sorted by query and
    /// ray bits.
    pub records: Vec<Record>,
}

const KINDS: [DifferenceKind; 4] = [
    DifferenceKind::HitMiss,
    DifferenceKind::Prim,
    DifferenceKind::Distance,
    DifferenceKind::Occlusion,
];

impl CheckLog {
    /// The referee's judgement on every answer of every record, in order
    /// (records, then backends). Equal answers to one query are judged once.
    pub fn judge(&self, mesh: &TriangleMesh) -> Vec<Vec<Judgement>> {
        self.judge_reporting(mesh, &|| {})
    }

    /// [`CheckLog::judge`], calling `judged` after each record (for a
    /// progress bar).
    pub fn judge_reporting(
        &self,
        mesh: &TriangleMesh,
        judged: &(dyn Fn() + Sync),
    ) -> Vec<Vec<Judgement>> {
        let referee = Referee::new(mesh);
        self.records
            .par_iter()
            .map(|record| {
                let judgements = referee.judge_all(&record.ray, &record.answers);
                judged();
                judgements
            })
            .collect()
    }
}

impl<'a> Checked<'a> {
    /// # Panics
    /// If `backends` is empty.
    pub fn new(backends: Vec<&'a dyn Backend>) -> Self {
        assert!(!backends.is_empty(), "a check needs at least one backend");
        let counters = backends.iter().map(|_| Counters::default()).collect();
        Self {
            backends,
            sample_every: AGREEMENT_SAMPLE,
            counters,
            intersect_queries: AtomicU64::new(0),
            occluded_queries: AtomicU64::new(0),
            records: Mutex::new(Vec::new()),
        }
    }

    /// The same, recording every query, agreeing or not (for a handful of
    /// queries whose every answer should be judged).
    pub fn recording_every_query(backends: Vec<&'a dyn Backend>) -> Self {
        Self {
            sample_every: 1,
            ..Self::new(backends)
        }
    }

    /// Everything recorded so far.
    pub fn into_log(self) -> CheckLog {
        let mut records = self
            .records
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner());
        records.sort_by_key(Record::sort_key);
        let backends = self
            .backends
            .iter()
            .zip(self.counters)
            .map(|(backend, c)| {
                let [hit_mismatch, prim_mismatch, t_mismatch, occlusion_mismatch] =
                    c.differences.map(AtomicU64::into_inner);
                BackendLog {
                    name: backend.name(),
                    gives_uv: backend.answers().uv,
                    misses: c.misses.into_inner(),
                    nan_outputs: c.nan_outputs.into_inner(),
                    hit_mismatch,
                    prim_mismatch,
                    t_mismatch,
                    occlusion_mismatch,
                    agreeing_hits: c.agreeing_hits.into_inner(),
                    max_rel_t_error: f32::from_bits(c.max_rel_t_error.into_inner()),
                    max_uv_error: f32::from_bits(c.max_uv_error.into_inner()),
                }
            })
            .collect();
        CheckLog {
            intersect_queries: self.intersect_queries.into_inner(),
            occluded_queries: self.occluded_queries.into_inner(),
            backends,
            records,
        }
    }

    /// Compares every other backend's answer with the first one's; records
    /// the query when two differ or when it is drawn into the sample.
    fn check(&self, ray: &Ray, first: Answer, ask: impl Fn(&dyn Backend) -> Answer) {
        self.count(0, &first);
        let mut disagreement = false;
        for (index, backend) in self.backends.iter().enumerate().skip(1) {
            let answer = ask(*backend);
            self.count(index, &answer);
            if let Some(kind) = DifferenceKind::between(&first, &answer) {
                let slot = KINDS.iter().position(|&k| k == kind).unwrap_or(0);
                self.counters[index].differences[slot].fetch_add(1, Ordering::Relaxed);
                disagreement = true;
            } else {
                self.count_agreement(index, &first, &answer);
            }
        }
        if disagreement || sampled(ray, self.sample_every) {
            // Answers are deterministic: asking again gives the same ones.
            let answers = std::iter::once(first)
                .chain(self.backends.iter().skip(1).map(|b| ask(*b)))
                .collect();
            self.records
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .push(Record {
                    ray: *ray,
                    answers,
                    disagreement,
                });
        }
    }

    fn count(&self, index: usize, answer: &Answer) {
        let counters = &self.counters[index];
        match answer {
            Answer::Closest(None) => _ = counters.misses.fetch_add(1, Ordering::Relaxed),
            Answer::Closest(Some(hit)) if !is_finite_hit(hit, self.backends[index]) => {
                _ = counters.nan_outputs.fetch_add(1, Ordering::Relaxed)
            }
            _ => {}
        }
    }

    fn count_agreement(&self, index: usize, first: &Answer, answer: &Answer) {
        let (Answer::Closest(Some(a)), Answer::Closest(Some(b))) = (first, answer) else {
            return;
        };
        let counters = &self.counters[index];
        counters.agreeing_hits.fetch_add(1, Ordering::Relaxed);
        counters
            .max_rel_t_error
            .fetch_max(relative_error(b.t, a.t).to_bits(), Ordering::Relaxed);
        let uv_error = (a.u - b.u).abs().max((a.v - b.v).abs());
        counters
            .max_uv_error
            .fetch_max(uv_error.to_bits(), Ordering::Relaxed);
    }
}

/// Whether every part of `hit` that `backend` gives is finite.
fn is_finite_hit(hit: &Hit, backend: &dyn Backend) -> bool {
    let answers = backend.answers();
    hit.t.is_finite()
        && (!answers.uv || (hit.u.is_finite() && hit.v.is_finite()))
        && (!answers.normal || hit.ng.is_finite())
}

/// Whether the agreement on `ray` is drawn into a sample of one in `every`.
fn sampled(ray: &Ray, every: u64) -> bool {
    let key = ray_bits(ray)
        .iter()
        .fold(0u64, |h, &bits| mix(h ^ bits as u64));
    key.is_multiple_of(every)
}

impl Intersector for Checked<'_> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        self.intersect_queries.fetch_add(1, Ordering::Relaxed);
        let first = self.backends[0].intersect(ray);
        self.check(ray, Answer::Closest(first), |b| {
            Answer::Closest(b.intersect(ray))
        });
        first
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_queries.fetch_add(1, Ordering::Relaxed);
        let first = self.backends[0].occluded(ray);
        self.check(ray, Answer::Occluded(first), |b| {
            Answer::Occluded(b.occluded(ray))
        });
        first
    }
}
