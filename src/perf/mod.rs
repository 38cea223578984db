//! `raycheck perf`: our fast BVH and Embree side by side in one process.
//!
//! For each scene and thread count, and for each Embree configuration
//! ([`measure::EMBREE_CONFIGS`]): build time, throughput of primary, shadow
//! and diffuse rays (the fixed [`rays::RaySets`]), and bytes per triangle,
//! ours and Embree's measured in turn, run by run, medians over runs; then
//! the scaling of build time and time per ray with the triangle count.

pub mod measure;
pub mod rays;
pub mod scaling;

use crate::bvh::wide::{Kernel, WideBvh};
use crate::parallel::thread_pool;
use crate::report::meta::RunMeta;
use crate::report::table::Table;
use crate::scene;
use measure::{EMBREE_CONFIGS, PerfRow, measure};
use rays::RaySets;
use scaling::Scaling;
use serde::Serialize;

#[derive(Clone, Debug)]
pub struct PerfOptions {
    pub quick: bool,
    /// Measure on this many threads only; default: 1 and all cores.
    pub threads: Option<usize>,
}

impl PerfOptions {
    pub fn scenes(&self) -> &'static [&'static str] {
        crate::scene::benchmark_scenes(self.quick)
    }

    /// Primary rays per side of the view.
    pub fn resolution(&self) -> u32 {
        if self.quick { 128 } else { 512 }
    }

    pub fn runs(&self) -> usize {
        if self.quick { 3 } else { 7 }
    }

    pub fn thread_counts(&self) -> Vec<usize> {
        match self.threads {
            Some(n) => vec![n.max(1)],
            None => {
                let all = std::thread::available_parallelism().map_or(1, |n| n.get());
                if all > 1 { vec![1, all] } else { vec![1] }
            }
        }
    }
}

/// Everything `raycheck perf` measured; its JSON.
#[derive(Clone, Debug, Serialize)]
pub struct PerfReport {
    /// The machine, date and commit; `threads` is the largest count measured.
    pub meta: RunMeta,
    /// The traversal kernel our BVH ran with.
    pub kernel: String,
    pub resolution: u32,
    pub rows: Vec<PerfRow>,
    /// One per thread count and Embree configuration.
    pub scaling: Vec<Scaling>,
}

/// Runs every measurement; `progress` hears each step.
pub fn run(options: &PerfOptions, progress: &dyn Fn(&str)) -> anyhow::Result<PerfReport> {
    let thread_counts = options.thread_counts();
    let mut rows = Vec::new();
    for name in options.scenes() {
        progress(&format!("{name}: loading"));
        let scene = scene::load(name)?;
        let rays = {
            let pool = thread_pool(None)?;
            pool.install(|| {
                let bvh = WideBvh::build(&scene.mesh);
                RaySets::cached(&scene, &bvh, options.resolution())
            })
        };
        for &threads in &thread_counts {
            let pool = thread_pool(Some(threads))?;
            for config in EMBREE_CONFIGS {
                progress(&format!("{name}: {threads} thread(s), Embree {}", config.0));
                rows.push(measure(&scene, &rays, &pool, config, options.runs())?);
            }
        }
    }
    let scaling = thread_counts
        .iter()
        .flat_map(|&threads| {
            let rows = &rows;
            EMBREE_CONFIGS.iter().filter_map(move |(label, _)| {
                let selected: Vec<&PerfRow> = rows
                    .iter()
                    .filter(|r| r.threads == threads && r.embree == *label)
                    .collect();
                Scaling::from_rows(&selected)
            })
        })
        .collect();
    Ok(PerfReport {
        meta: RunMeta::collect(thread_counts.iter().copied().max().unwrap_or(1)),
        kernel: format!("{:?}", Kernel::detect()),
        resolution: options.resolution(),
        rows,
        scaling,
    })
}

impl PerfReport {
    /// Where, when and how the numbers were measured, for every caption.
    pub fn caption(&self) -> String {
        format!(
            "{} · kernel {} · {}² primary rays per scene · medians of {} runs",
            self.meta.caption(),
            self.kernel,
            self.resolution,
            self.rows.first().map_or(0, |r| r.runs)
        )
    }

    /// The side-by-side table, then one scaling table per thread count and
    /// Embree configuration.
    pub fn tables(&self) -> Vec<Table> {
        let caption = self.caption();
        let mut side_by_side = Table::new(
            "Ours (fast path) and Embree side by side",
            &[
                "scene",
                "triangles",
                "threads",
                "Embree",
                "build ms (ours / Embree)",
                "primary Mrays/s",
                "shadow Mrays/s",
                "diffuse Mrays/s",
                "bytes/tri",
                "ratios ours/Embree: build, primary, shadow, diffuse, bytes",
            ],
            &caption,
        );
        for r in &self.rows {
            let ratios: Vec<String> = r.ratios().iter().map(|x| format!("{x:.2}")).collect();
            side_by_side.push(vec![
                r.scene.clone(),
                r.triangles.to_string(),
                r.threads.to_string(),
                r.embree.clone(),
                format!("{:.2} / {:.2}", r.build_ms, r.embree_build_ms),
                format!("{:.2} / {:.2}", r.mrays_primary, r.embree_mrays_primary),
                format!("{:.2} / {:.2}", r.mrays_shadow, r.embree_mrays_shadow),
                format!("{:.2} / {:.2}", r.mrays_diffuse, r.embree_mrays_diffuse),
                format!("{:.0} / {:.0}", r.bytes_per_tri, r.embree_bytes_per_tri),
                ratios.join(", "),
            ]);
        }
        let mut tables = vec![side_by_side];
        for s in &self.scaling {
            let mut table = Table::new(
                &format!(
                    "Scaling, {} thread(s), Embree {}: build time ~ n^{:.2} (Embree n^{:.2}), \
                     time per primary ray ~ n^{:.2} (Embree n^{:.2})",
                    s.threads,
                    s.embree,
                    s.build_exponent,
                    s.embree_build_exponent,
                    s.ns_per_ray_exponent,
                    s.embree_ns_per_ray_exponent
                ),
                &[
                    "scene",
                    "triangles",
                    "build ms (ours / Embree)",
                    "ns per primary ray (ours / Embree)",
                ],
                &caption,
            );
            for p in &s.points {
                table.push(vec![
                    p.scene.clone(),
                    p.triangles.to_string(),
                    format!("{:.2} / {:.2}", p.build_ms, p.embree_build_ms),
                    format!("{:.0} / {:.0}", p.ns_per_ray, p.embree_ns_per_ray),
                ]);
            }
            tables.push(table);
        }
        tables
    }

    /// The tables as Markdown.
    pub fn markdown(&self) -> String {
        let tables: Vec<String> = self.tables().iter().map(Table::to_markdown).collect();
        tables.join("\n")
    }
}
