//! Integration tests, one binary with a module per topic.

mod agreement;
mod builders;
mod cli;
mod determinism;
mod stability;
