//! A report section built once as Markdown and as HTML: a heading, tables
//! and SVG figures, each with its caption.

use super::plot::Plot;
use crate::results::table::{Table, escape_html};
use std::path::Path;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Section {
    pub markdown: String,
    pub html: String,
}

impl Section {
    pub fn new(heading: &str) -> Self {
        Self {
            markdown: format!("\n## {heading}\n\n"),
            html: format!("<h2>{}</h2>\n", escape_html(heading)),
        }
    }

    pub fn table(&mut self, table: &Table) {
        self.markdown += &table.to_markdown();
        self.markdown += "\n";
        self.html += &table.to_html();
    }

    /// Saves `plot` as `images/name` and shows it with `caption` under it.
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
}
