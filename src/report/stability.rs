//! The report's numerical-stability section: the catalogue's table, the
//! leaks of every closed-mesh placement, the spawn trials of cases 11 and 8
//! (self-hits, false occlusions, smallest gap resolved), and two figures:
//! self-hits and false occlusions of fixed epsilons against our offset, and
//! the smallest gap our offset resolves across scales and translations.

use super::ReportData;
use super::plot::{Mark, Plot, Scale, Series};
use super::section::Section;
use crate::results::{Cell, Table};
use crate::stability::self_intersection::SpawnStats;
use crate::stability::table::{output_table, verdict_table};
use crate::stability::{CaseDetails, Trial};
use std::path::Path;

/// Builds the section from the catalogue's results; figures go to `images`.
pub fn section(images: &Path, data: &ReportData) -> anyhow::Result<Section> {
    let caption = &data.meta.caption();
    let results = &data.stability;
    let intro = format!(
        "{INTRO} This report ran the {} catalogue{}.",
        if data.stability_quick {
            "quick"
        } else {
            "full"
        },
        if data.stability_quick {
            "; raycheck stability (or raycheck report --full) runs the full one, with a million \
             rays or more where it matters"
        } else {
            ""
        }
    );
    let mut section = Section::new("stability", "Numerical stability", &intro);
    section.table(&verdict_table(results, caption));
    section.table(&output_table(results, caption));
    for result in results {
        match &result.details {
            CaseDetails::Trials { trials } if result.name == "closed_mesh_leaks" => {
                section.table(&leak_table(trials, caption));
            }
            CaseDetails::Spawns { methods } => {
                section.table(&spawn_table(
                    "Spawned rays per method at scale 1 (case 11)",
                    methods.iter(),
                    caption,
                ));
                section.figure(
                    images,
                    "stability-epsilon.svg",
                    &epsilon_plot(methods, caption),
                    "Rays spawned from surface points with a fixed tnear epsilon (lines with \
                     points) against our offset (flat lines): small epsilons self-hit, large \
                     ones falsely occlude; our offset does neither at any epsilon's scale.",
                )?;
            }
            CaseDetails::Placements { placements } => {
                section.table(&spawn_table(
                    "Rays spawned with our offset per placement (case 8); a placement f32 cannot represent yields none, and the other translations of its scale make them up",
                    placements.iter().map(|p| &p.spawn),
                    caption,
                ));
                let spawns: Vec<&SpawnStats> = placements.iter().map(|p| &p.spawn).collect();
                section.figure(
                    images,
                    "stability-gap.svg",
                    &gap_plot(&spawns, caption),
                    "The price of our offset: the smallest gap to a parallel surface that every \
                     spawned ray still resolves, relative to the scale, per translation. About \
                     256 ulps of the coordinates' magnitude; lower is better.",
                )?;
            }
            _ => {}
        }
    }
    Ok(section.finish())
}

const INTRO: &str = "Stiff and extreme cases (closed meshes hit at vertices and edges, grazing \
and axis-parallel rays, degenerate and sliver triangles, scales from 1e-6 to 1e6, NaN and \
infinite inputs, spawned rays, ties, long rays) through every backend at once, every \
disagreement and 1% of the agreements judged exactly. Look at the wrong columns and the \
leaks: a watertight tracer has none.";

/// `1e-6`, `1e3`, and `0` rather than Rust's `0e0`.
fn power_of_ten(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:e}")
    }
}

fn leak_table(trials: &[Trial], caption: &str) -> Table {
    let names: Vec<String> = trials
        .first()
        .map(|t| t.verdicts.backends.iter().map(|b| b.name.clone()).collect())
        .unwrap_or_default();
    let mut headers = vec!["placement".to_string(), "rays".to_string()];
    headers.extend(names.iter().map(|n| format!("leaks: {n}")));
    let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
    let mut table = Table::new(
        "Closed-mesh leaks per placement: rays from inside that hit nothing",
        &headers,
        caption,
    );
    for trial in trials {
        let mut row = vec![
            Cell::from(trial.label.as_str()),
            trial.verdicts.rays.to_string().into(),
        ];
        row.extend(
            trial
                .verdicts
                .backends
                .iter()
                .map(|b| Cell::wrong_count(b.leaks)),
        );
        table.push(row);
    }
    table
}

/// One row per spawn trial: what it cost and what went wrong.
fn spawn_table<'a>(
    title: &str,
    trials: impl Iterator<Item = &'a SpawnStats>,
    caption: &str,
) -> Table {
    let mut table = Table::new(
        title,
        &[
            "method",
            "scale",
            "translation",
            "rays",
            "self-hits",
            "false occlusions",
            "smallest gap resolved (× scale)",
        ],
        caption,
    );
    for trial in trials {
        table.push([
            Cell::from(trial.method.as_str()),
            power_of_ten(trial.scale).into(),
            power_of_ten(trial.translation).into(),
            trial.rays.to_string().into(),
            Cell::wrong_count(trial.self_hits),
            Cell::wrong_count(trial.false_occlusions),
            trial
                .smallest_resolved_gap
                .map_or("none".into(), power_of_ten)
                .into(),
        ]);
    }
    table
}

/// Percent of spawned rays (half of a trial's rays leave the surface, half
/// go to a light) that hit what they should not.
fn rate(count: u64, stats: &SpawnStats) -> f64 {
    100.0 * count as f64 / (stats.rays as f64 / 2.0)
}

fn epsilon_plot(methods: &[SpawnStats], caption: &str) -> Plot {
    let epsilon = |m: &SpawnStats| {
        m.method
            .strip_prefix("epsilon ")
            .and_then(|e| e.parse::<f64>().ok())
    };
    let fixed: Vec<(f64, &SpawnStats)> = methods
        .iter()
        .filter_map(|m| Some((epsilon(m)?, m)))
        .collect();
    let offset = methods.iter().find(|m| epsilon(m).is_none());
    type Count = fn(&SpawnStats) -> u64;
    let series = |name: &str, count: Count| Series {
        name: name.to_string(),
        points: fixed.iter().map(|(e, m)| (*e, rate(count(m), m))).collect(),
        mark: Mark::LineAndPoints,
    };
    let flat = |name: &str, count: Count| Series {
        name: name.to_string(),
        points: offset
            .map(|m| fixed.iter().map(|(e, _)| (*e, rate(count(m), m))).collect())
            .unwrap_or_default(),
        mark: Mark::Line,
    };
    Plot {
        title: "Spawned rays against a fixed epsilon (scale 1)".into(),
        x_label: "epsilon".into(),
        y_label: "% of spawned rays".into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Linear,
        series: vec![
            series("fixed epsilon: self-hits", |m| m.self_hits),
            series("fixed epsilon: false occlusions", |m| m.false_occlusions),
            flat("our offset: self-hits", |m| m.self_hits),
            flat("our offset: false occlusions", |m| m.false_occlusions),
        ],
        caption: caption.to_string(),
    }
}

/// The smallest gap our offset resolves (relative to the scale) against
/// the scale, one line per translation: what the offset costs. Placements
/// without samples or with no gap resolved have no point.
fn gap_plot(spawns: &[&SpawnStats], caption: &str) -> Plot {
    let mut translations: Vec<f64> = spawns.iter().map(|p| p.translation).collect();
    translations.sort_by(f64::total_cmp);
    translations.dedup();
    let series = translations
        .iter()
        .map(|&t| Series {
            name: format!("translation {}", power_of_ten(t)),
            points: spawns
                .iter()
                .filter(|p| p.translation == t)
                .filter_map(|p| Some((p.scale, p.smallest_resolved_gap?)))
                .collect(),
            mark: Mark::LineAndPoints,
        })
        .collect();
    Plot {
        title: "Smallest gap to a parallel surface our offset resolves".into(),
        x_label: "scale".into(),
        y_label: "gap / scale".into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series,
        caption: caption.to_string(),
    }
}
