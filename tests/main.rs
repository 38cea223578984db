//! Integration tests, one binary with a module per topic.

mod adapters;
mod agreement;
mod bare_meshes;
mod browser;
mod builders;
mod bundles;
mod cache;
mod cli;
mod debug_views;
mod determinism;
mod exchange;
mod fast;
mod features;
mod known_answers;
mod passes;
mod programs;
mod report;
mod stability;
mod support;
mod sweep;
mod third_party;
