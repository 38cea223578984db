//! `raycheck render`: a scene rendered through one backend, as one of its
//! debug views, or through every backend at once with what the exact
//! referee found.

use super::{RunMeta, Table, Verdicts};
use crate::backends::BackendName;
use crate::check::layered::{LayeredBackend, render_checked, render_debug_view};
use crate::parallel::Workers;
use crate::render::RenderSettings;
use crate::render::debug::DebugView;
use crate::render::image::Image;
use crate::scene::Scene;

/// What to draw.
pub enum Drawing {
    /// The render through one backend.
    Render(BackendName),
    /// A debug view on one backend.
    Debug(BackendName, DebugView),
    /// The render through every backend at once (the first one's image),
    /// every difference judged.
    Checked(Vec<BackendName>),
}

/// An image, with its view's legend or the check's verdicts.
pub struct Drawn {
    pub image: Image,
    /// One line saying what a debug view shows.
    pub legend: Option<String>,
    pub verdicts: Option<Verdicts>,
}

/// Draws `drawing` of `scene` on `workers`.
pub fn draw(
    scene: &Scene,
    drawing: &Drawing,
    workers: &Workers,
    settings: &RenderSettings,
) -> anyhow::Result<Drawn> {
    let context = workers.build_context();
    workers.install(|| {
        Ok(match drawing {
            Drawing::Render(name) => Drawn {
                image: LayeredBackend::build(name, scene, context)?.render(scene, settings),
                legend: None,
                verdicts: None,
            },
            Drawing::Debug(name, view) => {
                let debug = render_debug_view(name, scene, context, *view, settings)?;
                Drawn {
                    image: debug.image,
                    legend: Some(format!("{view}: {}", debug.legend)),
                    verdicts: None,
                }
            }
            Drawing::Checked(names) => {
                let layered = names
                    .iter()
                    .map(|name| LayeredBackend::build(name, scene, context))
                    .collect::<anyhow::Result<Vec<_>>>()?;
                let run = render_checked(scene, &layered, settings);
                Drawn {
                    image: run.image,
                    legend: None,
                    verdicts: Some(Verdicts::judge_layers(scene, &run.logs)),
                }
            }
        })
    })
}

/// A checked render's verdicts as a table, a row per backend.
pub fn verdicts_table(verdicts: &Verdicts, meta: &RunMeta) -> Table {
    super::tally::table(
        &format!(
            "checked render: {} queries, {} judged, {} ambiguous",
            verdicts.rays, verdicts.judged, verdicts.ambiguous
        ),
        verdicts,
        &meta.caption(),
    )
}
