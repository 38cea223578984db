//! The feature gallery: for each scene that shows one feature, its render,
//! its most telling debug view, its samples per pixel and its render time
//! on our BVH and on Embree, every figure and table stamped with the
//! run's machine, date, commit and thread count.

use super::measure::REFERENCE;
use super::section::Section;
use crate::backends::ours::OURS;
use crate::check::layered::{LayeredBackend, render_debug_view};
use crate::parallel::Workers;
use crate::render::RenderSettings;
use crate::render::debug::DebugView;
use crate::render::image::Image;
use crate::render::pipeline::Passes;
use crate::results::RunMeta;
use crate::results::table::Table;
use crate::scene;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The feature scenes, each with its most telling debug view at
/// `resolution` (the rays views pick their pixel as a fraction of the
/// image: a spot where the feature's rays show).
pub fn gallery_views(resolution: u32) -> [(&'static str, DebugView); 11] {
    let rays = |fx: f32, fy: f32| DebugView::Rays {
        x: (fx * resolution as f32) as u32,
        y: (fy * resolution as f32) as u32,
    };
    [
        ("cornell-area", rays(0.2, 0.925)),
        ("cornell-segment", rays(0.2, 0.925)),
        ("cornell-glossy", rays(0.375, 0.55)),
        ("cornell-transparent", rays(0.3, 0.76)),
        ("cornell-bloom", DebugView::BloomMask),
        // The cube's own BVH root at its rest position, with the blur beside it.
        ("motion-blur", DebugView::BvhLevel(0)),
        ("textured-quad", DebugView::Texcoords),
        ("textured-cube", DebugView::Texcoords),
        ("monkey-smooth", DebugView::Normals),
        // Every sampled feature at once: the pixel's camera, light and
        // glossy samples.
        ("cornell-sampled", rays(0.375, 0.55)),
        // The uniform light over a diffuse plane whose image has a closed
        // form (the sweep's bias check).
        ("analytic-area", rays(0.5, 0.5)),
    ]
}

/// One scene of the gallery.
#[derive(Clone, Debug, Serialize)]
pub struct GalleryEntry {
    pub scene: String,
    /// The passes the render runs (see [`Passes`]).
    pub passes: String,
    pub samples_per_pixel: u32,
    pub view: String,
    /// How to read the debug view.
    pub legend: String,
    pub ours_render_ms: f64,
    pub embree_render_ms: f64,
    #[serde(skip)]
    pub render: Image,
    #[serde(skip)]
    pub debug: Image,
}

/// Every gallery scene at one resolution.
#[derive(Clone, Debug, Serialize)]
pub struct Gallery {
    pub resolution: u32,
    pub entries: Vec<GalleryEntry>,
}

/// Renders every gallery scene on both backends, and its debug view on
/// ours, on `workers`.
pub fn measure(workers: &Workers, resolution: u32) -> anyhow::Result<Gallery> {
    workers.install(|| measure_on_workers(workers, resolution))
}

fn measure_on_workers(workers: &Workers, resolution: u32) -> anyhow::Result<Gallery> {
    let device = workers.build_context();
    let settings = RenderSettings::square(resolution);
    let mut entries = Vec::new();
    for (name, view) in gallery_views(resolution) {
        let scene = scene::load(name)?;
        let ours = LayeredBackend::build(&OURS, &scene, device)?;
        let reference = LayeredBackend::build(&REFERENCE, &scene, device)?;
        let (render, ours_render_ms) = timed(|| ours.render(&scene, &settings));
        let (_, embree_render_ms) = timed(|| reference.render(&scene, &settings));
        let debug = render_debug_view(&OURS, &scene, device, view, &settings)?;
        let passes = Passes::for_scene(&scene);
        entries.push(GalleryEntry {
            scene: scene.name.clone(),
            passes: passes.to_string(),
            samples_per_pixel: passes.samples_per_pixel,
            view: view.to_string(),
            legend: debug.legend,
            ours_render_ms,
            embree_render_ms,
            render,
            debug: debug.image,
        });
    }
    Ok(Gallery {
        resolution,
        entries,
    })
}

fn timed<T>(run: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let value = run();
    (value, start.elapsed().as_secs_f64() * 1e3)
}

impl GalleryEntry {
    fn render_file(&self) -> String {
        format!("gallery-{}.png", self.scene)
    }

    fn debug_file(&self) -> String {
        let view = self.view.replace(['=', ','], "-");
        format!("gallery-{}-{view}.png", self.scene)
    }

    fn figure_caption(&self, caption: &str) -> String {
        format!(
            "{}: left the render (ours), right the {} debug view: {}. {caption}",
            self.scene, self.view, self.legend
        )
    }
}

impl Gallery {
    /// Writes every render and debug view into `images`, stamped.
    fn write_images(&self, images: &Path, meta: &RunMeta) -> anyhow::Result<()> {
        for e in &self.entries {
            let render = meta.stamp(&format!("{}, ours", e.scene));
            e.render
                .save_stamped(&images.join(e.render_file()), &render)?;
            let debug = meta.stamp(&format!("{}, debug view {}", e.scene, e.view));
            e.debug.save_stamped(&images.join(e.debug_file()), &debug)?;
        }
        Ok(())
    }

    fn table(&self, caption: &str) -> Table {
        let res = self.resolution;
        let mut table = Table::new(
            &format!("Feature gallery: renders at {res}×{res}, one run each"),
            &[
                "scene",
                "passes",
                "samples per pixel",
                "render ms, ours",
                "render ms, Embree",
                "debug view",
            ],
            caption,
        );
        for e in &self.entries {
            table.push([
                e.scene.clone(),
                e.passes.clone(),
                e.samples_per_pixel.to_string(),
                format!("{:.1}", e.ours_render_ms),
                format!("{:.1}", e.embree_render_ms),
                e.view.clone(),
            ]);
        }
        table
    }

    /// The gallery section; the images go to `images`.
    pub fn section(&self, images: &Path, meta: &RunMeta) -> anyhow::Result<Section> {
        self.write_images(images, meta)?;
        let caption = meta.caption();
        let mut section = Section::new("gallery", "Feature gallery", INTRO);
        section.table(&self.table(&caption));
        for e in &self.entries {
            section.subheading(&e.scene);
            section.images(
                &[
                    (e.render_file(), e.scene.clone()),
                    (e.debug_file(), format!("{}, {}", e.scene, e.view)),
                ],
                &e.figure_caption(&caption),
            );
        }
        Ok(section.finish())
    }
}

const INTRO: &str = "One scene per feature of the tracer, each rendered through ours (its \
every query also answered by Embree in the tests, which pin these renders bit for bit), \
beside the debug view that shows the feature at work: the passes the scene needs are the \
only ones it runs. Render times are one run each, ours and Embree on the same code.";
