//! The sweep's numbers as tables, for the terminal and the report.

use super::SweepReport;
use super::equal_time::Reading;
use super::robustness::CATALOGUE;
use super::sampled::{REQUIRED_MARGIN, Target};
use crate::fit::LogLogFit;
use crate::results::{Cell, Table, Tone};

/// A slope with its interval: `-1.02 [-1.08, -0.96]`.
pub fn slope(fit: &LogLogFit) -> String {
    format!(
        "{:.2} [{:.2}, {:.2}]",
        fit.slope, fit.slope_low, fit.slope_high
    )
}

/// The whole frame counts from `from` to `to` (`None`: on for ever), as
/// `3`, `3–7` or `≥ 3`; `None` when no whole count lies between.
pub fn frame_range(from: f64, to: Option<f64>) -> Option<String> {
    let first = from.ceil();
    match to.map(f64::floor) {
        None => Some(format!("≥ {first}")),
        Some(last) if last < first => None,
        Some(last) if last == first => Some(format!("{first}")),
        Some(last) => Some(format!("{first}–{last}")),
    }
}

fn optional_slope(fit: Option<&LogLogFit>) -> Cell {
    fit.map_or_else(Cell::not_applicable, |f| slope(f).into())
}

fn sci(value: f64) -> String {
    format!("{value:.2e}")
}

/// A value read off a curve, starred when extrapolated by the fit.
fn reading(r: &Reading, format: fn(f64) -> String) -> String {
    let star = if r.extrapolated { "*" } else { "" };
    format!("{}{star}", format(r.value))
}

fn milliseconds(seconds: f64) -> String {
    format!("{:.1}", seconds * 1e3)
}

impl SweepReport {
    /// Every table, in the order the report shows them.
    pub fn tables(&self) -> Vec<Table> {
        vec![
            self.slopes_table(),
            self.references_table(),
            self.points_table(),
            self.equal_time_table(),
            self.equal_error_table(),
            self.embree_table(),
            self.bvh_table(),
            self.robustness_table(),
        ]
    }

    fn caption(&self) -> String {
        let load = |l: Option<[f64; 3]>| {
            l.map_or("unknown".into(), |[a, b, c]| {
                format!("{a:.2} {b:.2} {c:.2}")
            })
        };
        format!(
            "{} · {} sweep in {:.0} s · load average {} at the end",
            self.meta.caption(),
            if self.quick { "quick" } else { "full" },
            self.timing.total_seconds,
            load(self.timing.load_average_end),
        )
    }

    pub fn slopes_table(&self) -> Table {
        let mut table = Table::new(
            "Sampling error: fitted slope k of error ≈ c·x^k on log-log axes, with its 95% interval, over every seed's render",
            &[
                "scene",
                "swept",
                "against",
                "sampler",
                "relMSE ~ samples^k",
                "relMSE ~ time^k",
                "FLIP ~ samples^k",
                "FLIP ~ time^k",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            for c in &s.samplers {
                table.push([
                    Cell::from(s.scene.as_str()),
                    s.swept.name().into(),
                    target_name(s.target).into(),
                    c.sampler.as_str().into(),
                    slope(&c.fits.rel_mse_vs_samples).into(),
                    slope(&c.fits.rel_mse_vs_seconds).into(),
                    optional_slope(c.fits.flip_vs_samples.as_ref()),
                    optional_slope(c.fits.flip_vs_seconds.as_ref()),
                ]);
            }
        }
        table
    }

    pub fn references_table(&self) -> Table {
        let mut table = Table::new(
            &format!(
                "Converged references: own relMSE from two independent halves, at least {REQUIRED_MARGIN}× below the smallest relMSE swept"
            ),
            &[
                "scene",
                "samples per pixel",
                "own relMSE",
                "smallest swept relMSE",
                "margin",
                "render s",
                "from cache",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            let Some(r) = &s.reference else {
                continue;
            };
            let tone = if r.converged_enough {
                Tone::Good
            } else {
                Tone::Bad
            };
            table.push([
                Cell::from(s.scene.as_str()),
                format!("{} {}", r.summary.samples, s.swept.name()).into(),
                sci(r.summary.rel_mse).into(),
                sci(r.smallest_swept_rel_mse).into(),
                Cell::new(format!("{:.0}×", r.margin), tone),
                format!("{:.1}", r.summary.seconds).into(),
                if r.summary.cached { "yes" } else { "no" }.into(),
            ]);
        }
        table
    }

    pub fn points_table(&self) -> Table {
        let seeds = self.sampled.first().map_or(0, |s| s.seeds);
        let mut table = Table::new(
            &format!("Error per sample count: mean and standard deviation over {seeds} seeds"),
            &[
                "scene",
                "sampler",
                "samples",
                "ms",
                "relMSE",
                "relMSE sd",
                "FLIP",
                "FLIP sd",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            for c in &s.samplers {
                for p in &c.points {
                    table.push([
                        Cell::from(s.scene.as_str()),
                        c.sampler.as_str().into(),
                        p.samples.to_string().into(),
                        milliseconds(p.seconds.mean).into(),
                        sci(p.rel_mse.mean).into(),
                        sci(p.rel_mse.std_dev).into(),
                        format!("{:.4}", p.flip.mean).into(),
                        format!("{:.4}", p.flip.std_dev).into(),
                    ]);
                }
            }
        }
        table
    }

    pub fn equal_time_table(&self) -> Table {
        let mut table = Table::new(
            "Equal time: relMSE of both samplers in the time of each stratified count (* extrapolated by the fitted power law)",
            &[
                "scene",
                "ms",
                "stratified samples",
                "stratified relMSE",
                "independent relMSE",
                "independent / stratified",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            for row in &s.equal_time {
                table.push([
                    Cell::from(s.scene.as_str()),
                    milliseconds(row.seconds).into(),
                    row.stratified_samples.to_string().into(),
                    sci(row.stratified_rel_mse).into(),
                    reading(&row.independent_rel_mse, sci).into(),
                    format!("{:.2}", row.error_ratio).into(),
                ]);
            }
        }
        table
    }

    pub fn equal_error_table(&self) -> Table {
        let mut table = Table::new(
            "Time to equal error: the time each sampler needs for the relMSE of each independent count (* extrapolated by the fitted power law)",
            &[
                "scene",
                "relMSE",
                "independent samples",
                "independent ms",
                "stratified ms",
                "speed-up",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            for row in &s.equal_error {
                table.push([
                    Cell::from(s.scene.as_str()),
                    sci(row.rel_mse).into(),
                    row.independent_samples.to_string().into(),
                    milliseconds(row.independent_seconds).into(),
                    reading(&row.stratified_seconds, milliseconds).into(),
                    format!("{:.2}×", row.speedup).into(),
                ]);
            }
        }
        table
    }

    pub fn embree_table(&self) -> Table {
        let mut table = Table::new(
            "Ours against Embree with the same sample sequences (seed 0, stratified): the image difference beside the noise, and the rays on which the two disagree, judged exactly",
            &[
                "scene",
                "samples",
                "relMSE Embree vs ours",
                "noise relMSE",
                "pixels differing",
                "queries",
                "disagreements",
                "ambiguous",
                "wrong: Embree",
                "wrong: ours",
            ],
            &self.caption(),
        );
        for s in &self.sampled {
            for d in &s.embree {
                let wrong = |i: usize| {
                    d.verdicts
                        .backends
                        .get(i)
                        .map_or_else(Cell::not_applicable, |b| Cell::wrong_count(b.wrong))
                };
                table.push([
                    Cell::from(s.scene.as_str()),
                    d.samples.to_string().into(),
                    sci(d.rel_mse).into(),
                    sci(d.noise_rel_mse).into(),
                    format!("{} of {}", d.differing_pixels, d.pixels).into(),
                    d.verdicts.rays.to_string().into(),
                    d.verdicts.disagreements.to_string().into(),
                    d.verdicts.ambiguous.to_string().into(),
                    wrong(0),
                    wrong(1),
                ]);
            }
        }
        table
    }

    pub fn bvh_table(&self) -> Table {
        let mut table = Table::new(
            "BVH choices: build and frame time (medians), SAH cost, memory; the frame count from which each is cheaper in total (build + frames) than the next cheaper build, and the frame counts at which it is the cheapest of all",
            &[
                "scene",
                "choice",
                "build ms",
                "frame ms",
                "SAH cost",
                "SAH model",
                "MiB",
                "next cheaper build",
                "cheaper than it from frame",
                "cheapest of all at frames",
            ],
            &self.caption(),
        );
        for scene in &self.bvh {
            for (index, c) in scene.choices.iter().enumerate() {
                let (next, from) = match &c.overtaking {
                    None => ("—".to_string(), "—".to_string()),
                    Some(o) => (
                        scene.choices[o.next_cheaper].choice.clone(),
                        // The first whole frame count past the crossing.
                        o.frames
                            .map_or("never".into(), |f| format!("{}", f.floor() + 1.0)),
                    ),
                };
                let spans: Vec<String> = scene
                    .frontier
                    .iter()
                    .filter(|s| s.choice == index)
                    .filter_map(|s| frame_range(s.from_frames, s.to_frames))
                    .collect();
                table.push([
                    Cell::from(scene.scene.as_str()),
                    c.choice.as_str().into(),
                    format!("{:.2}", c.build_ms.median).into(),
                    format!("{:.2}", c.frame_ms.median).into(),
                    format!("{:.1}", c.sah_cost).into(),
                    format!("{:?}", c.sah_model).to_lowercase().into(),
                    c.bytes.map_or_else(Cell::not_applicable, |b| {
                        format!("{:.2}", b as f64 / (1024.0 * 1024.0)).into()
                    }),
                    next.into(),
                    from.into(),
                    if spans.is_empty() {
                        Cell::from("never")
                    } else {
                        Cell::new(spans.join(", "), Tone::Good)
                    },
                ]);
            }
        }
        table
    }

    pub fn robustness_table(&self) -> Table {
        let mut table = Table::new(
            &format!(
                "What robustness costs: rays the exact referee calls wrong, against speed ({} rays per side for the scenes; the {CATALOGUE} at each backend's speed over them all)",
                self.robustness.resolution
            ),
            &[
                "backend",
                "rays from",
                "rays",
                "wrong",
                "wrong rate",
                "Mrays/s",
            ],
            &self.caption(),
        );
        for p in &self.robustness.points {
            let rate = match p.zero_wrong_bound {
                Some(bound) => format!("0 (< {bound:.1e}, 95%)"),
                None => sci(p.wrong_rate),
            };
            table.push([
                Cell::from(p.backend.as_str()),
                p.rays_from.as_str().into(),
                p.rays.to_string().into(),
                Cell::wrong_count(p.wrong),
                rate.into(),
                format!("{:.2}", p.mrays_per_second).into(),
            ]);
        }
        table
    }
}

fn target_name(target: Target) -> &'static str {
    match target {
        Target::Analytic => "exact image",
        Target::Reference => "reference",
    }
}
