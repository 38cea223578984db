//! The results layer every subcommand stands on: the run's metadata
//! ([`meta`]), one table type printed as text, Markdown, CSV and HTML
//! ([`table`]), the referee's verdicts per backend counted in rays
//! ([`tally`]), and what `compare` found on a scene ([`agreement`]).
//! `perf`, `stability`, `sweep` and `report` build on it; it depends only
//! on the layers below (check, render, scene, backends, bvh, geometry).

pub mod agreement;
pub mod meta;
pub mod pixels;
pub mod table;
pub mod tally;

pub use agreement::{CompareSummary, compare_scene};
pub use meta::RunMeta;
pub use table::{Cell, Table, Tone};
pub use tally::{BackendTally, Verdicts};

use crate::scene;

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
