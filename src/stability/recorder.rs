//! The queries a case asks, as it asks them: per judged batch, the mesh
//! and the rays asked of each query kind. `raycheck rays --set CASE`
//! exports them as a bundle of (mesh, rays) pairs, and a tracer outside
//! the process can be handed them batch by batch.

use crate::geometry::{Ray, TriangleMesh};
use std::sync::{Arc, Mutex};

/// One judged batch: a mesh and the rays asked of it, by query kind.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    pub mesh: Arc<TriangleMesh>,
    /// Rays asked for their closest hit.
    pub closest: Vec<Ray>,
    /// Rays asked whether anything lies in their interval (any hit).
    pub any_hit: Vec<Ray>,
    /// Whether every ray had to hit: misses of rays that exactly hit the
    /// mesh are then counted as leaks.
    pub must_hit: bool,
}

impl Batch {
    /// A batch asking both queries of every one of `rays`, as the
    /// stability harness does.
    pub fn both_queries(mesh: &TriangleMesh, rays: &[Ray], must_hit: bool) -> Self {
        Self {
            mesh: Arc::new(mesh.clone()),
            closest: rays.to_vec(),
            any_hit: rays.to_vec(),
            must_hit,
        }
    }

    /// The rays the batch asks (a ray asked both queries counts once): the
    /// longer of its two lists.
    pub fn rays(&self) -> usize {
        self.closest.len().max(self.any_hit.len())
    }
}

/// Collects every batch a run judges, in the order judged.
#[derive(Debug, Default)]
pub struct Recorder {
    batches: Mutex<Vec<Batch>>,
}

impl Recorder {
    pub fn record(&self, batch: Batch) {
        self.batches
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
            .push(batch);
    }

    /// The batches recorded, in order.
    pub fn into_batches(self) -> Vec<Batch> {
        self.batches
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}
