//! Exact ray/triangle decisions for the referee: expansion arithmetic
//! (Shewchuk 1997) behind an error-bounded f64 filter, the per-triangle
//! contact and hit order, and the exact answers against a whole mesh.

pub mod contact;
pub mod expansion;
pub mod filtered;
pub mod number;
pub mod oracle;

pub use oracle::{Oracle, one_ulp_neighbours};
