//! Writes the report folder: `index.html` and `report.md` (the summary,
//! the contents, then every section), `report.json` (every number),
//! `tables/*.csv` and `tables.json` (every table), and `images/`.

use super::section::Section;
use super::summary::Summary;
use super::{ReportData, agreement, performance, stability, sweep, tracers};
use crate::results::Table;
use crate::results::table::escape_html;
use crate::run::Form;
use anyhow::Context;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Writes everything under `out`; returns the path of `index.html`.
pub fn write(out: &Path, data: &ReportData) -> anyhow::Result<PathBuf> {
    let images = out.join("images");
    let tables = out.join("tables");
    for dir in [&images, &tables] {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let sections = vec![
        agreement::section(&images, data)?,
        tracers::section(data),
        data.gallery.section(&images, &data.meta)?,
        performance::section(&images, data)?,
        stability::section(&images, data)?,
        sweep::section(&images, &data.sweep, &data.meta.caption())?,
    ];
    let summary = Summary::of(data);
    let caption = data.meta.caption();
    let form = form_note(data.form);
    let contents: Vec<(String, String)> = sections
        .iter()
        .map(|s| (s.id.clone(), s.title.clone()))
        .collect();

    let mut markdown = format!(
        "# raycheck report\n\n_{caption}_\n\n{form}\n\n{}\n## Contents\n\n",
        summary.markdown()
    );
    for (id, title) in &contents {
        markdown += &format!("- [{title}](#{id})\n");
    }
    let mut html = format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width\">\
         <title>raycheck report</title>\n<style>{}</style></head><body>\n\
         <h1>raycheck report</h1>\n<p class=\"meta\">{}</p>\n<p>{}</p>\n{}<nav><h2>Contents</h2><ol>",
        super::style::STYLE,
        escape_html(&caption),
        escape_html(&form),
        summary.html()
    );
    for (id, title) in &contents {
        html += &format!(
            "<li><a href=\"#{}\">{}</a></li>",
            escape_html(id),
            escape_html(title)
        );
    }
    html += "</ol></nav>\n";
    for section in &sections {
        markdown += &section.markdown;
        html += &section.html;
    }
    let took = timing_note(&data.timings);
    markdown += &format!("\n_{took}_\n");
    html += &format!(
        "<footer><p class=\"meta\">{}</p></footer>\n",
        escape_html(&took)
    );
    html += "</body></html>\n";
    std::fs::write(out.join("report.md"), markdown)?;
    let index = out.join("index.html");
    std::fs::write(&index, html)?;
    std::fs::write(out.join("report.json"), serde_json::to_string_pretty(data)?)?;
    write_tables(out, &sections)?;
    Ok(index)
}

/// How long the report took, part by part.
fn timing_note(timings: &[(String, f64)]) -> String {
    let total: f64 = timings.iter().map(|(_, s)| s).sum();
    let parts: Vec<String> = timings
        .iter()
        .map(|(part, s)| format!("{part} {s:.0} s"))
        .collect();
    format!(
        "This report took {:.0} min {:.0} s to measure: {}.",
        (total / 60.0).floor(),
        total % 60.0,
        parts.join(", ")
    )
}

/// Which form ran, and how to run the full one.
fn form_note(form: Form) -> String {
    match form {
        Form::Quick => "The quick form: three small scenes, small images, quick forms of every \
                        section. raycheck report runs the standard form, raycheck report --full \
                        everything."
            .into(),
        Form::Standard => "The standard form: every section on every scene, with the quick \
                           forms of the stability catalogue and of the sweep to fit the time \
                           budget. raycheck report --full runs both in full (raycheck stability \
                           and raycheck sweep run them alone)."
            .into(),
        Form::Full => "The full form: every section in full.".into(),
    }
}

/// One table in `tables.json`, with where it is on the page.
#[derive(Serialize)]
struct TableEntry<'a> {
    section: &'a str,
    csv: String,
    #[serde(flatten)]
    table: &'a Table,
}

/// Every table as `tables/<section>-<n>.csv`, and all of them in
/// `tables.json`.
fn write_tables(out: &Path, sections: &[Section]) -> anyhow::Result<()> {
    let mut entries = Vec::new();
    for section in sections {
        for (n, table) in section.tables.iter().enumerate() {
            let csv = section.csv_file(n);
            std::fs::write(out.join(&csv), table.to_csv())?;
            entries.push(TableEntry {
                section: &section.id,
                csv,
                table,
            });
        }
    }
    std::fs::write(
        out.join("tables.json"),
        serde_json::to_string_pretty(&entries)?,
    )?;
    Ok(())
}
