//! The check: every backend asked the same questions at once
//! ([`Checked`]), the exact referee that says which answers are right
//! ([`Referee`]), the ray sets of `compare`, and checked renders of scenes
//! with several mesh layers.

pub mod answer;
pub mod checked;
pub mod compare;
pub mod exact;
pub mod layered;
pub mod referee;

pub use answer::{Answer, DifferenceKind, Record, ray_bits};
pub use checked::{AGREEMENT_SAMPLE, BackendLog, CheckLog, Checked};
pub use compare::{RaySet, compare};
pub use referee::{Judgement, Referee};
