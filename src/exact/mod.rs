//! Exact geometric predicates on f32 inputs: expansion arithmetic
//! (Shewchuk 1997) behind an error-bounded f64 filter. Below `geometry`, so
//! both the triangle test and the referee (`check::exact`) decide with it.

pub mod edge;
pub mod expansion;
pub mod filtered;
pub mod number;
pub mod orientation;

pub use edge::edge_sign;
pub use orientation::{normal_side, plane_side};
