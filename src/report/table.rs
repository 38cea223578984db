//! A table of text cells, written as Markdown and as HTML.

/// A titled table; every row has as many cells as there are headers.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Table {
    pub title: String,
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
    /// A line under the table: where and when its numbers were measured.
    pub caption: String,
}

impl Table {
    pub fn new(title: &str, headers: &[&str], caption: &str) -> Self {
        Self {
            title: title.into(),
            headers: headers.iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
            caption: caption.into(),
        }
    }

    pub fn push(&mut self, row: Vec<String>) {
        debug_assert_eq!(row.len(), self.headers.len());
        self.rows.push(row);
    }

    pub fn to_markdown(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let mut out = format!("**{}**\n\n", self.title);
        out += &line(&self.headers);
        out += &line(&vec!["---".to_string(); self.headers.len()]);
        for row in &self.rows {
            out += &line(row);
        }
        out += &format!("\n_{}_\n", self.caption);
        out
    }

    pub fn to_html(&self) -> String {
        let cells = |tag: &str, row: &[String]| {
            row.iter()
                .map(|c| format!("<{tag}>{}</{tag}>", escape_html(c)))
                .collect::<String>()
        };
        let mut out = format!("<table>\n<caption>{}</caption>\n", escape_html(&self.title));
        out += &format!("<tr>{}</tr>\n", cells("th", &self.headers));
        for row in &self.rows {
            out += &format!("<tr>{}</tr>\n", cells("td", row));
        }
        out += "</table>\n";
        out += &format!("<p class=\"meta\">{}</p>\n", escape_html(&self.caption));
        out
    }
}

pub fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_and_html() {
        let mut t = Table::new("T", &["a", "b"], "m");
        t.push(vec!["1".into(), "<2>".into()]);
        assert_eq!(
            t.to_markdown(),
            "**T**\n\n| a | b |\n| --- | --- |\n| 1 | <2> |\n\n_m_\n"
        );
        let html = t.to_html();
        assert!(html.contains("<td>&lt;2&gt;</td>"), "{html}");
        assert!(html.contains("<th>a</th><th>b</th>"), "{html}");
    }
}
