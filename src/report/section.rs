//! A report section built once as Markdown and as HTML: a heading with an
//! anchor, a sentence or two on what it measures, then tables (each also
//! kept for the CSV and JSON files) and figures, each with a caption.

use super::plot::Plot;
use crate::results::table::{Table, Tone, escape_html};
use std::path::Path;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    /// The anchor the contents link to, e.g. `stability`.
    pub id: String,
    pub title: String,
    pub markdown: String,
    pub html: String,
    /// Every table shown, in order: written again as CSV and JSON.
    pub tables: Vec<Table>,
}

/// What the colours of a toned table mean.
const LEGEND: &str = "<span class=\"good\">green</span>: nothing wrong, or a goal met; \
<span class=\"warn\">amber</span>: worth a look; <span class=\"bad\">red</span>: wrong \
answers, or a goal missed; <span class=\"na\">n/a</span>: a part of the answer that backend \
does not give.";

impl Section {
    /// A section titled `title`, anchored at `id`, opening with `intro`.
    pub fn new(id: &str, title: &str, intro: &str) -> Self {
        let mut section = Self {
            id: id.to_string(),
            title: title.to_string(),
            markdown: format!("\n## {title}\n\n"),
            html: format!(
                "<section id=\"{}\"><h2>{}</h2>\n",
                escape_html(id),
                escape_html(title)
            ),
            tables: Vec::new(),
        };
        section.paragraph(intro);
        section
    }

    pub fn paragraph(&mut self, text: &str) {
        self.markdown += &format!("{text}\n\n");
        self.html += &format!("<p>{}</p>\n", escape_html(text));
    }

    pub fn subheading(&mut self, text: &str) {
        self.markdown += &format!("### {text}\n\n");
        self.html += &format!("<h3>{}</h3>\n", escape_html(text));
    }

    /// Shows `table`, with a link to its CSV and, when it has toned cells,
    /// the legend of the tones.
    pub fn table(&mut self, table: &Table) {
        self.markdown += &table.to_markdown();
        self.markdown += "\n";
        self.html += &table.to_html();
        let csv = self.csv_file(self.tables.len());
        let toned = table
            .rows
            .iter()
            .flatten()
            .any(|cell| cell.tone != Tone::Plain);
        self.html += &format!(
            "<p class=\"meta\"><a href=\"{csv}\">CSV</a>{}</p>\n",
            if toned {
                format!(" · {LEGEND}")
            } else {
                String::new()
            }
        );
        self.tables.push(table.clone());
    }

    /// `tables/<id>-<n>.csv`, the CSV of table `n` of this section.
    pub fn csv_file(&self, n: usize) -> String {
        format!("tables/{}-{}.csv", self.id, n + 1)
    }

    /// Saves `plot` as `images/name` and shows it with `caption` under it
    /// (the SVG carries the run's stamp itself).
    pub fn figure(
        &mut self,
        images: &Path,
        name: &str,
        plot: &Plot,
        caption: &str,
    ) -> anyhow::Result<()> {
        plot.save(&images.join(name))?;
        self.markdown += &format!("![{}](images/{name})\n\n_{caption}_\n\n", plot.title);
        self.html += &format!(
            "<figure><img class=\"plot\" src=\"images/{name}\" alt=\"{}\">\
             <figcaption>{}</figcaption></figure>\n",
            escape_html(&plot.title),
            escape_html(caption)
        );
        Ok(())
    }

    /// Shows images already saved under `images/`, side by side, each with
    /// its alt text, over one caption.
    pub fn images(&mut self, files: &[(String, String)], caption: &str) {
        let markdown: Vec<String> = files
            .iter()
            .map(|(file, alt)| format!("![{alt}](images/{file})"))
            .collect();
        self.markdown += &format!("{}\n\n_{caption}_\n\n", markdown.join(" "));
        let html: String = files
            .iter()
            .map(|(file, alt)| {
                format!(
                    "<img src=\"images/{}\" alt=\"{}\">",
                    escape_html(file),
                    escape_html(alt)
                )
            })
            .collect();
        self.html += &format!(
            "<figure class=\"row\">{html}<figcaption>{}</figcaption></figure>\n",
            escape_html(caption)
        );
    }

    /// Closes the section's HTML.
    pub fn finish(mut self) -> Self {
        self.html += "</section>\n";
        self
    }
}
