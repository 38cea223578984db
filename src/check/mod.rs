//! The check: Embree as an intersector, the checked pair that asks both,
//! the referee that says who is right, and the `compare` run.

pub mod checked;
pub mod compare;
pub mod difference;
pub mod exact;
pub mod layered;
pub mod referee;

pub use checked::{CheckLog, Checked, VerdictCounts};
pub use compare::{CompareSummary, compare};
pub use difference::Difference;
pub use referee::{Referee, Verdict};
