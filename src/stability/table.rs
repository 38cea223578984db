//! The catalogue's results as a plain-text table for the terminal.

use super::CaseResult;
use std::fmt::Write as _;

/// The columns shown for every case; `-` where a count does not apply.
pub const COLUMNS: [&str; 14] = [
    "case",
    "rays",
    "ours_wrong",
    "embree_wrong",
    "robust_wrong",
    "ambiguous",
    "panics",
    "nan ours",
    "nan embree",
    "nan robust",
    "leaks ours",
    "leaks embree",
    "leaks robust",
    "self_hits",
];

/// One row of [`COLUMNS`] per case.
pub fn rows(results: &[CaseResult]) -> Vec<[String; 14]> {
    let optional = |v: Option<u64>| v.map_or("-".to_string(), |v| v.to_string());
    results
        .iter()
        .map(|r| {
            [
                r.name.clone(),
                r.rays.to_string(),
                r.ours_wrong.to_string(),
                r.embree_wrong.to_string(),
                r.embree_robust_wrong.to_string(),
                r.ambiguous.to_string(),
                r.panics.to_string(),
                r.nan_outputs.ours.to_string(),
                r.nan_outputs.embree.to_string(),
                r.nan_outputs.embree_robust.to_string(),
                optional(r.leaks.map(|l| l.ours)),
                optional(r.leaks.map(|l| l.embree)),
                optional(r.leaks.map(|l| l.embree_robust)),
                optional(r.self_hits),
            ]
        })
        .collect()
}

pub fn to_text(results: &[CaseResult]) -> String {
    let rows = rows(results);
    let width = |c: usize| {
        rows.iter()
            .map(|r| r[c].len())
            .chain([COLUMNS[c].len()])
            .max()
            .unwrap_or(0)
    };
    let widths: Vec<usize> = (0..COLUMNS.len()).map(width).collect();
    let mut out = String::new();
    let mut line = |cells: &[String]| {
        for (i, cell) in cells.iter().enumerate() {
            let _ = if i == 0 {
                write!(out, "{cell:<w$}", w = widths[i])
            } else {
                write!(out, "  {cell:>w$}", w = widths[i])
            };
        }
        out.push('\n');
    };
    line(&COLUMNS.map(String::from));
    for row in &rows {
        line(row);
    }
    out
}
