//! `raycheck stability`: a catalogue of stiff and extreme cases, each run
//! through every selected backend (`--backends`, by default ours, Embree
//! and Embree robust), every disagreement and a sample of the agreements
//! judged by the exact referee ([`crate::check::exact`]).
//!
//! Each case returns a [`CaseResult`] with every backend's verdicts and
//! typed details ([`CaseDetails`]); a panic inside a case is caught and
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
pub mod recorder;
pub mod scale;
pub mod self_intersection;
pub mod shapes;
mod signed_zeros;
mod slivers;
pub mod table;
mod ties;
mod traversal;

use crate::backends::{BackendName, BuildContext};
use crate::results::Verdicts;
use crate::run::RunContext;
use self_intersection::SpawnStats;
use serde::Serialize;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What one case found; one object of `raycheck stability --json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct CaseResult {
    pub name: String,
    /// Rays the case traced, judged or not.
    pub rays: u64,
    /// Every backend's verdicts on the judged rays, in rays.
    pub verdicts: Verdicts,
    /// Whether the case's rays had to hit (from inside a closed mesh, at an
    /// interior point), so that it counts each backend's leaks.
    pub counts_leaks: bool,
    /// Cases that panicked or failed (0 or 1), with `failure` saying why.
    pub panics: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
    /// Spawned rays that hit the surface they left, with our offset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub self_hits: Option<u64>,
    /// Queries where our BVHs (wide and binary) and the loop over all
    /// triangles differ in any bit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub traversal_mismatches: Option<u64>,
    /// Case-specific measurements.
    pub details: CaseDetails,
}

/// The measurements a case family adds to its verdicts.
#[derive(Clone, Debug, Default, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum CaseDetails {
    #[default]
    None,
    /// Sub-trials (placements, angles, aspect ratios), each with every
    /// backend's verdicts (cases 1, 5, 7).
    Trials { trials: Vec<Trial> },
    /// Spawned rays per method at scale 1 (case 11).
    Spawns { methods: Vec<SpawnStats> },
    /// Per placement: leaks, grazing rays and our offset's spawns (case 8).
    Placements {
        placements: Vec<scale::PlacementResult>,
    },
    /// Triangles with a NaN, infinite or huge corner, dropped (case 10).
    Dropped { dropped_triangles: usize },
    /// Rays whose `t` did not scale exactly with the direction (case 13).
    Scaling { t_scaling_violations: u64 },
    /// Rays whose exact closest hit is a tie on which ours did not return
    /// the tie's lowest primID (case 12).
    Ties { tie_not_lowest_prim: u64 },
}

/// One sub-trial of a case.
#[derive(Clone, Debug, Serialize)]
pub struct Trial {
    /// What the trial varies, e.g. `icosphere, radius 2, centre (148376, 1234, -223423)`.
    pub label: String,
    pub verdicts: Verdicts,
}

impl CaseResult {
    /// The result of a case whose only measurement is `verdicts`.
    pub fn judged(name: &str, verdicts: Verdicts) -> Self {
        Self {
            name: name.to_string(),
            rays: verdicts.rays,
            verdicts,
            ..Default::default()
        }
    }

    /// The same, for a case that counts leaks.
    pub fn with_leaks(mut self) -> Self {
        self.counts_leaks = true;
        self
    }

    /// The leaks of the backend at `index`, where the case counts them.
    pub fn leaks(&self, index: usize) -> Option<u64> {
        self.counts_leaks
            .then(|| self.verdicts.backends.get(index).map(|b| b.leaks))
            .flatten()
    }
}

/// What every case gets: the backends to check, what they are built with,
/// and the run's size.
pub struct Context<'a> {
    pub backends: &'a [BackendName],
    pub build: BuildContext<'a>,
    pub quick: bool,
    /// When given, every batch the case judges (a mesh and the rays asked
    /// of it) is kept here, in order (so `raycheck rays` can export a
    /// case's queries).
    pub recorder: Option<&'a Recorder>,
}

pub use recorder::{Batch, Recorder};

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

/// `raycheck stability`: every case (or those whose name contains
/// `filter`) through `backends` on the run's workers, in the quick form
/// unless the run is full.
pub fn run(run: &RunContext, backends: &[BackendName], filter: Option<&str>) -> Vec<CaseResult> {
    let context = Context {
        backends,
        build: run.build_context(),
        quick: !run.form().is_full(),
        recorder: None,
    };
    run.install(|| run_catalogue(&context, filter))
}

/// Panics, failures and the first backend's faults over `results`: what
/// makes `raycheck stability` exit 1.
pub fn faults(results: &[CaseResult]) -> u64 {
    results
        .iter()
        .map(|r| r.panics + r.verdicts.faults_of_first())
        .sum()
}

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
        failure: Some(message),
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
