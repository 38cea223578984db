//! The results layer every subcommand stands on: the run's metadata
//! ([`meta`]), one table type printed as text, Markdown, CSV and HTML
//! ([`table`]), the referee's verdicts per backend counted in rays
//! ([`tally`]), and what `compare` found on a scene ([`agreement`]).
//! `perf`, `stability`, `sweep` and `report` build on it; it depends only
//! on the layers below (check, render, scene, backends, bvh, geometry).

pub mod agreement;
pub mod meta;
pub mod pixels;
pub mod rendered;
pub mod table;
pub mod tally;

pub use agreement::{CompareSummary, compare_scene};
pub use meta::RunMeta;
pub use table::{Cell, Table, Tone};
pub use tally::{BackendTally, Verdicts};

use crate::backends::{BackendName, Registry};
use crate::scene;
use anyhow::Context;
use std::path::Path;

/// Every backend of `registry`, by group, with what it is.
pub fn backend_catalogue(registry: &Registry) -> Table {
    let mut table = Table::new("Backends", &["backend", "group", "what"], "");
    let mut names = registry.names().to_vec();
    names.sort_by_key(BackendName::group);
    for name in &names {
        table.push([name.as_str(), name.group().title(), name.about()]);
    }
    table
}

/// Writes `value` as pretty JSON to `path`.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> anyhow::Result<()> {
    std::fs::write(path, serde_json::to_string_pretty(value)?)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes `text` to `path`.
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text).with_context(|| format!("writing {}", path.display()))
}

/// Every built-in scene with its triangle count and features.
pub fn scene_catalogue() -> anyhow::Result<Table> {
    let mut table = Table::new("Built-in scenes", &["scene", "triangles", "features"], "");
    for name in scene::builtin_names()? {
        let scene = scene::load(&name)?;
        let features: Vec<String> = scene.features.iter().map(|f| f.to_string()).collect();
        table.push([
            name,
            scene.mesh.triangle_count().to_string(),
            features.join(", "),
        ]);
    }
    Ok(table)
}
