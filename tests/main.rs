//! Integration tests, one binary with a module per topic.

mod agreement;
mod builders;
mod cli;
mod debug_views;
mod determinism;
mod fast;
mod features;
mod known_answers;
mod passes;
mod stability;
mod support;
mod third_party;
