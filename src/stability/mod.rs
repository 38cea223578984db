//! `raycheck stability`: a catalogue of stiff and extreme cases, each run
//! through our BVH, Embree default and Embree robust, every difference
//! judged by the exact referee ([`crate::check::exact`]).
//!
//! Each case returns a [`CaseResult`]; a panic inside a case is caught and
//! counted, never fatal. `quick` runs every case with few rays (for CI);
//! the full run uses at least a million rays where the issue asks for it.

mod bounds;
mod degenerate;
mod flat;
mod grazing;
mod grid_edges;
pub mod harness;
mod invalid;
pub mod leaks;
mod long_rays;
pub mod scale;
pub mod self_intersection;
pub mod shapes;
mod signed_zeros;
mod slivers;
pub mod table;
mod ties;
mod traversal;

use harness::{PerBackend, Tally};
use raycheck_reference::Device;
use serde::Serialize;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What one case found; one object of `raycheck stability --json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CaseResult {
    pub name: String,
    pub rays: u64,
    pub ours_wrong: u64,
    pub embree_wrong: u64,
    pub embree_robust_wrong: u64,
    pub ambiguous: u64,
    /// Same triangle, our `t` beyond the referee's distance tolerance.
    pub ours_t_off: u64,
    pub panics: u64,
    /// Hits with a non-finite `t`, `u`, `v` or normal, per backend.
    pub nan_outputs: PerBackend,
    /// Rays that had to hit (from inside a closed mesh, at an interior
    /// point) and did not, per backend.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leaks: Option<PerBackend>,
    /// Spawned rays that hit the surface they left, with our offset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_hits: Option<u64>,
    /// Queries where our BVH and the loop over all triangles differ in any bit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub traversal_mismatches: Option<u64>,
    /// Case-specific measurements.
    #[serde(skip_serializing_if = "serde_json::Value::is_null")]
    pub details: serde_json::Value,
}

impl CaseResult {
    pub fn from_tally(name: &str, tally: &Tally) -> Self {
        Self {
            name: name.to_string(),
            rays: tally.rays,
            ours_wrong: tally.ours_wrong,
            embree_wrong: tally.embree_wrong,
            embree_robust_wrong: tally.embree_robust_wrong,
            ambiguous: tally.ambiguous,
            ours_t_off: tally.ours_t_off,
            nan_outputs: tally.nan_outputs,
            ..Default::default()
        }
    }

    /// With the misses of rays that had to hit counted as leaks.
    pub fn with_leaks(mut self, tally: &Tally) -> Self {
        self.leaks = Some(tally.misses);
        self
    }
}

/// What every case gets: the Embree device and the run's size.
pub struct Context<'a> {
    pub device: &'a Device,
    pub quick: bool,
}

impl Context<'_> {
    /// `full` rays in a full run, `quick` in a quick one.
    pub fn rays(&self, full: usize, quick: usize) -> usize {
        if self.quick { quick } else { full }
    }
}

type Case = fn(&Context) -> anyhow::Result<CaseResult>;

/// The catalogue, in the order.
pub const CASES: [(&str, Case); 14] = [
    ("closed_mesh_leaks", leaks::run),
    ("grid_edges", grid_edges::run),
    ("axis_parallel_and_signed_zeros", signed_zeros::run),
    ("flat_boxes", flat::run),
    ("grazing_rays", grazing::run),
    ("degenerate_triangles", degenerate::run),
    ("slivers_and_small_triangles", slivers::run),
    ("scale_and_offset", scale::run),
    ("tnear_tfar_boundaries", bounds::run),
    ("nan_and_inf", invalid::run),
    ("self_intersection", self_intersection::run),
    ("ties", ties::run),
    ("long_rays_and_unnormalized_directions", long_rays::run),
    ("traversal_against_brute_force", traversal::run),
];

/// Runs every case (or those whose name contains `filter`); a case that
/// panics or fails is reported with `panics = 1` and its message.
pub fn run_catalogue(context: &Context, filter: Option<&str>) -> Vec<CaseResult> {
    CASES
        .iter()
        .filter(|(name, _)| filter.is_none_or(|f| name.contains(f)))
        .map(|&(name, case)| {
            let outcome = catch_unwind(AssertUnwindSafe(|| case(context)));
            match outcome {
                Ok(Ok(result)) => result,
                Ok(Err(error)) => failed(name, format!("error: {error:#}")),
                Err(panic) => failed(name, panic_message(&panic)),
            }
        })
        .collect()
}

fn failed(name: &str, message: String) -> CaseResult {
    CaseResult {
        name: name.to_string(),
        panics: 1,
        details: serde_json::json!({ "failure": message }),
        ..Default::default()
    }
}

fn panic_message(panic: &Box<dyn std::any::Any + Send>) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panic".to_string())
}
