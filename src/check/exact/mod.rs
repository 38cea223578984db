//! Exact ray/triangle decisions for the referee, on the predicates of
//! [`crate::exact`]: the per-triangle contact and hit order, and the exact
//! answers against a whole mesh.

pub mod contact;
pub mod cull;
pub mod oracle;

pub use oracle::{MovedVertex, Oracle, one_ulp_neighbours, one_ulp_vertex_moves};
