//! Exact ray/triangle decisions for the referee, on the predicates of
//! [`crate::exact`]: the per-triangle contact and hit order, the exact
//! answers against a whole mesh, and the one-ulp neighbourhood of a ray
//! the referee searches for admissible answers.

pub mod contact;
pub mod cull;
pub mod neighbourhood;
pub mod oracle;
pub mod perturbed;

pub use neighbourhood::{Change, Claim, Neighbourhood};
pub use oracle::{MovedVertex, Oracle, one_ulp_neighbours, one_ulp_vertex_moves};
