//! The report's numerical-stability section: the catalogue's table, the
//! leaks of every closed-mesh placement, the spawn trials of cases 11 and 8
//! (self-hits, false occlusions, smallest gap resolved), and two figures:
//! self-hits and false occlusions of fixed epsilons against our offset, and
//! the smallest gap our offset resolves across scales and translations.

use super::plot::{Mark, Plot, Scale, Series};
use super::section::Section;
use super::table::Table;
use crate::stability::CaseResult;
use crate::stability::table::{COLUMNS, rows};
use serde_json::Value;
use std::path::Path;

/// Builds the section from the catalogue's results; figures go to `images`.
pub fn section(images: &Path, results: &[CaseResult], caption: &str) -> anyhow::Result<Section> {
    let mut section = Section::new("Numerical stability");
    let mut table = Table::new(
        "The stability catalogue of `raycheck stability` (its quick form under `report --quick`): our BVH, Embree default and Embree ROBUST on the same rays, every difference judged exactly",
        &COLUMNS,
        caption,
    );
    for row in rows(results) {
        table.push(row.to_vec());
    }
    section.table(&table);
    if let Some(leaks) = case(results, "closed_mesh_leaks") {
        section.table(&leak_table(leaks, caption));
    }
    if let Some(spawns) = case(results, "self_intersection") {
        section.table(&spawn_table(
            "Spawned rays per method at scale 1 (case 11)",
            spawns.iter(),
            caption,
        ));
        section.figure(
            images,
            "stability-epsilon.svg",
            &epsilon_plot(spawns, caption),
            caption,
        )?;
    }
    if let Some(scales) = case(results, "scale_and_offset") {
        section.table(&spawn_table(
            "Rays spawned with our offset per placement (case 8); a placement f32 cannot represent yields none, and the other translations of its scale make them up",
            scales.iter().map(|p| &p["spawn"]),
            caption,
        ));
        section.figure(
            images,
            "stability-gap.svg",
            &gap_plot(scales, caption),
            caption,
        )?;
    }
    Ok(section)
}

fn case<'a>(results: &'a [CaseResult], name: &str) -> Option<&'a [Value]> {
    results
        .iter()
        .find(|r| r.name == name)
        .and_then(|r| r.details.as_array())
        .map(Vec::as_slice)
}

/// `1e-6`, `1e3`, and `0` rather than Rust's `0e0`.
fn power_of_ten(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        format!("{x:e}")
    }
}

fn number(value: &Value, key: &str) -> f64 {
    value[key].as_f64().unwrap_or(f64::NAN)
}

fn leak_table(placements: &[Value], caption: &str) -> Table {
    let mut table = Table::new(
        "Closed-mesh leaks per placement: rays from inside that hit nothing",
        &[
            "shape",
            "radius",
            "centre",
            "rays",
            "ours",
            "Embree",
            "Embree ROBUST",
        ],
        caption,
    );
    for p in placements {
        let leaks = &p["leaks"];
        table.push(vec![
            p["shape"].as_str().unwrap_or("?").to_string(),
            p["radius"].to_string(),
            p["centre"].to_string(),
            p["rays"].to_string(),
            leaks["ours"].to_string(),
            leaks["embree"].to_string(),
            leaks["embree_robust"].to_string(),
        ]);
    }
    table
}

/// One row per spawn trial: what it cost and what went wrong.
fn spawn_table<'a>(title: &str, trials: impl Iterator<Item = &'a Value>, caption: &str) -> Table {
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
        let gap = &trial["smallest_resolved_gap"];
        table.push(vec![
            trial["method"].as_str().unwrap_or("?").to_string(),
            power_of_ten(number(trial, "scale")),
            power_of_ten(number(trial, "translation")),
            trial["rays"].to_string(),
            trial["self_hits"].to_string(),
            trial["false_occlusions"].to_string(),
            gap.as_f64().map_or("none".into(), power_of_ten),
        ]);
    }
    table
}

/// Percent of spawned rays (half of a trial's rays leave the surface, half
/// go to a light) that hit what they should not.
fn rate(stats: &Value, key: &str) -> f64 {
    100.0 * number(stats, key) / (number(stats, "rays") / 2.0)
}

fn epsilon_plot(methods: &[Value], caption: &str) -> Plot {
    let epsilon = |m: &Value| {
        m["method"]
            .as_str()
            .and_then(|s| s.strip_prefix("epsilon "))
            .and_then(|e| e.parse::<f64>().ok())
    };
    let fixed: Vec<(f64, &Value)> = methods
        .iter()
        .filter_map(|m| Some((epsilon(m)?, m)))
        .collect();
    let offset = methods.iter().find(|m| epsilon(m).is_none());
    let series = |name: &str, key: &str| Series {
        name: name.to_string(),
        points: fixed.iter().map(|(e, m)| (*e, rate(m, key))).collect(),
        mark: Mark::LineAndPoints,
    };
    let flat = |name: &str, key: &str| Series {
        name: name.to_string(),
        points: offset
            .map(|m| fixed.iter().map(|(e, _)| (*e, rate(m, key))).collect())
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
            series("fixed epsilon: self-hits", "self_hits"),
            series("fixed epsilon: false occlusions", "false_occlusions"),
            flat("our offset: self-hits", "self_hits"),
            flat("our offset: false occlusions", "false_occlusions"),
        ],
        caption: caption.to_string(),
    }
}

/// The smallest gap our offset resolves (relative to the scale) against
/// the scale, one line per translation: what the offset costs. Placements
/// without samples or with no gap resolved have no point.
fn gap_plot(placements: &[Value], caption: &str) -> Plot {
    let mut translations: Vec<f64> = placements
        .iter()
        .map(|p| number(p, "translation"))
        .collect();
    translations.sort_by(f64::total_cmp);
    translations.dedup();
    let series = translations
        .iter()
        .map(|&t| Series {
            name: format!("translation {}", power_of_ten(t)),
            points: placements
                .iter()
                .filter(|p| number(p, "translation") == t)
                .filter_map(|p| {
                    Some((
                        number(p, "scale"),
                        p["spawn"]["smallest_resolved_gap"].as_f64()?,
                    ))
                })
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
