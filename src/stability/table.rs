//! The catalogue's results as tables, a column per backend: what the
//! terminal prints and the report shows.

use super::CaseResult;
use crate::results::{Cell, RunMeta, Table};

/// The backends' names, from the first case that ran.
fn backend_names(results: &[CaseResult]) -> Vec<String> {
    results
        .iter()
        .find(|r| !r.verdicts.backends.is_empty())
        .map(|r| r.verdicts.backends.iter().map(|b| b.name.clone()).collect())
        .unwrap_or_default()
}

/// An optional count, "-" where it does not apply.
fn optional(value: Option<u64>, wrong_if_nonzero: bool) -> Cell {
    match value {
        None => Cell::from("-"),
        Some(v) if wrong_if_nonzero => Cell::wrong_count(v),
        Some(v) => Cell::from(v.to_string()),
    }
}

/// Wrong answers per case and backend, with the case-wide counts.
pub fn verdict_table(results: &[CaseResult], caption: &str) -> Table {
    let names = backend_names(results);
    let wrong: Vec<String> = names.iter().map(|n| format!("wrong: {n}")).collect();
    let mut headers = vec!["case", "rays", "judged", "ambiguous"];
    headers.extend(wrong.iter().map(String::as_str));
    headers.extend([
        "panics",
        "self-hits (our offset)",
        "traversal ≠ brute force",
    ]);
    let mut table = Table::new(
        "Wrong answers per case and backend, in rays (the exact referee judges every ray on which two backends differ and 1% of the others)",
        &headers,
        caption,
    );
    for r in results {
        let mut row = vec![
            Cell::from(r.name.as_str()),
            r.rays.to_string().into(),
            r.verdicts.judged.to_string().into(),
            r.verdicts.ambiguous.to_string().into(),
        ];
        row.extend((0..names.len()).map(|i| {
            r.verdicts
                .backends
                .get(i)
                .map_or_else(|| Cell::from("-"), |b| Cell::wrong_count(b.wrong))
        }));
        row.extend([
            Cell::wrong_count(r.panics),
            optional(r.self_hits, true),
            optional(r.traversal_mismatches, true),
        ]);
        table.push(row);
    }
    table
}

/// Distances off, non-finite outputs and leaks per case and backend.
pub fn output_table(results: &[CaseResult], caption: &str) -> Table {
    let names = backend_names(results);
    let columns: Vec<String> = ["undecided", "t off", "NaN", "leaks", "no build"]
        .iter()
        .flat_map(|what| names.iter().map(move |n| format!("{what}: {n}")))
        .collect();
    let mut headers = vec!["case"];
    headers.extend(columns.iter().map(String::as_str));
    let mut table = Table::new(
        "Rays the referee left undecided, distances off, non-finite outputs, leaks (misses of rays that had to hit, and exactly hit the mesh) and meshes a backend could not be built over, per case and backend",
        &headers,
        caption,
    );
    for r in results {
        let mut row = vec![Cell::from(r.name.as_str())];
        let per_backend = |f: &dyn Fn(usize) -> Option<u64>| -> Vec<Cell> {
            (0..names.len()).map(|i| optional(f(i), true)).collect()
        };
        row.extend((0..names.len()).map(|i| {
            r.verdicts
                .backends
                .get(i)
                .map_or_else(|| Cell::from("-"), |b| Cell::undecided_count(b.undecided))
        }));
        row.extend(per_backend(&|i| {
            r.verdicts.backends.get(i).map(|b| b.t_off)
        }));
        row.extend(per_backend(&|i| {
            r.verdicts.backends.get(i).map(|b| b.nan_outputs)
        }));
        row.extend(per_backend(&|i| r.leaks(i)));
        row.extend(per_backend(&|i| {
            r.verdicts.backends.get(i).map(|b| b.build_failures)
        }));
        table.push(row);
    }
    table
}

/// Both tables as a Markdown page, headed by the run's stamp and the
/// command that made it.
pub fn markdown_page(
    results: &[CaseResult],
    meta: &RunMeta,
    quick: bool,
    backends: &str,
) -> String {
    let caption = meta.caption();
    format!(
        "# raycheck stability\n\n_{caption}_\n\nMade by `raycheck stability{} --backends {backends}`; \
         the cases are described in docs/stability.md.\n\n{}\n{}",
        if quick { " --quick" } else { "" },
        verdict_table(results, &caption).to_markdown(),
        output_table(results, &caption).to_markdown()
    )
}

/// Both tables as aligned text for the terminal.
pub fn to_text(results: &[CaseResult], caption: &str) -> String {
    format!(
        "{}\n{}",
        verdict_table(results, caption).to_text(),
        output_table(results, caption).to_text()
    )
}
