//! The one table type every subcommand prints through: plain text for the
//! terminal, Markdown, CSV and HTML for the report, and JSON through serde.

use serde::Serialize;
use std::fmt::Write as _;

/// How a cell reads at a glance; the HTML colours it, the legend says why.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Tone {
    #[default]
    Plain,
    /// As it should be (no wrong answer, a goal met).
    Good,
    /// Worth a look (ambiguous answers, a goal nearly met).
    Warn,
    /// Wrong answers, a missed goal.
    Bad,
    /// Not applicable: the backend does not give this part of an answer.
    NotApplicable,
}

/// One cell: its text and its tone.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Cell {
    pub text: String,
    #[serde(skip_serializing_if = "is_plain")]
    pub tone: Tone,
}

fn is_plain(tone: &Tone) -> bool {
    *tone == Tone::Plain
}

impl Cell {
    pub fn new(text: impl Into<String>, tone: Tone) -> Self {
        Self {
            text: text.into(),
            tone,
        }
    }

    /// "n/a", for a part of an answer a backend does not give.
    pub fn not_applicable() -> Self {
        Self::new("n/a", Tone::NotApplicable)
    }

    /// A count of wrong answers: good at zero, bad above.
    pub fn wrong_count(count: u64) -> Self {
        let tone = if count == 0 { Tone::Good } else { Tone::Bad };
        Self::new(count.to_string(), tone)
    }

    /// A count of answers the referee left undecided: good at zero, worth
    /// a look above.
    pub fn undecided_count(count: u64) -> Self {
        let tone = if count == 0 { Tone::Good } else { Tone::Warn };
        Self::new(count.to_string(), tone)
    }
}

impl From<String> for Cell {
    fn from(text: String) -> Self {
        Self::new(text, Tone::Plain)
    }
}

impl From<&str> for Cell {
    fn from(text: &str) -> Self {
        Self::new(text, Tone::Plain)
    }
}

/// A titled table; every row has as many cells as there are headers.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Table {
    pub title: String,
    pub headers: Vec<String>,
    pub rows: Vec<Vec<Cell>>,
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

    /// Appends a row.
    ///
    /// # Panics
    /// If the row's length is not the number of headers.
    pub fn push<C: Into<Cell>>(&mut self, row: impl IntoIterator<Item = C>) {
        let row: Vec<Cell> = row.into_iter().map(Into::into).collect();
        assert_eq!(
            row.len(),
            self.headers.len(),
            "a row of '{}' has {} cells for {} headers",
            self.title,
            row.len(),
            self.headers.len()
        );
        self.rows.push(row);
    }

    fn texts(&self) -> impl Iterator<Item = Vec<&str>> {
        self.rows
            .iter()
            .map(|row| row.iter().map(|c| c.text.as_str()).collect())
    }

    /// Aligned columns for the terminal: the first left-aligned, the others
    /// right-aligned, under the title and above the caption.
    pub fn to_text(&self) -> String {
        let headers: Vec<&str> = self.headers.iter().map(String::as_str).collect();
        let rows: Vec<Vec<&str>> = std::iter::once(headers).chain(self.texts()).collect();
        let widths: Vec<usize> = (0..self.headers.len())
            .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
            .collect();
        let mut out = format!("{}\n", self.title);
        for row in &rows {
            for (i, cell) in row.iter().enumerate() {
                let pad = widths[i] - cell.chars().count();
                let _ = if i == 0 {
                    write!(out, "{cell}{}", " ".repeat(pad))
                } else {
                    write!(out, "  {}{cell}", " ".repeat(pad))
                };
            }
            out.push('\n');
        }
        if !self.caption.is_empty() {
            out += &format!("{}\n", self.caption);
        }
        out
    }

    pub fn to_markdown(&self) -> String {
        let line = |cells: &[&str]| format!("| {} |\n", cells.join(" | "));
        let headers: Vec<&str> = self.headers.iter().map(String::as_str).collect();
        let mut out = format!("**{}**\n\n", self.title);
        out += &line(&headers);
        out += &line(&vec!["---"; self.headers.len()]);
        for row in self.texts() {
            out += &line(&row);
        }
        out += &format!("\n_{}_\n", self.caption);
        out
    }

    /// RFC 4180 CSV: the header row, then the rows; fields with commas,
    /// quotes or line breaks quoted.
    pub fn to_csv(&self) -> String {
        let field = |text: &str| {
            if text.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", text.replace('"', "\"\""))
            } else {
                text.to_string()
            }
        };
        let line = |cells: Vec<&str>| {
            let fields: Vec<String> = cells.into_iter().map(field).collect();
            fields.join(",") + "\r\n"
        };
        let mut out = line(self.headers.iter().map(String::as_str).collect());
        for row in self.texts() {
            out += &line(row);
        }
        out
    }

    /// The table in a box that scrolls sideways when it is wider than the
    /// page; toned cells carry the class `good`, `warn`, `bad` or `na`.
    pub fn to_html(&self) -> String {
        let mut out = format!(
            "<div class=\"table-scroll\"><table>\n<caption>{}</caption>\n<tr>",
            escape_html(&self.title)
        );
        for header in &self.headers {
            out += &format!("<th>{}</th>", escape_html(header));
        }
        out += "</tr>\n";
        for row in &self.rows {
            out += "<tr>";
            for cell in row {
                let class = match cell.tone {
                    Tone::Plain => "",
                    Tone::Good => " class=\"good\"",
                    Tone::Warn => " class=\"warn\"",
                    Tone::Bad => " class=\"bad\"",
                    Tone::NotApplicable => " class=\"na\"",
                };
                out += &format!("<td{class}>{}</td>", escape_html(&cell.text));
            }
            out += "</tr>\n";
        }
        out += "</table></div>\n";
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

    fn table() -> Table {
        let mut t = Table::new("T", &["a", "bee"], "m");
        t.push(["1".into(), Cell::new("<2>", Tone::Bad)]);
        t.push(["x,\"y\"", "0"]);
        t
    }

    #[test]
    fn markdown() {
        assert_eq!(
            table().to_markdown(),
            "**T**\n\n| a | bee |\n| --- | --- |\n| 1 | <2> |\n| x,\"y\" | 0 |\n\n_m_\n"
        );
    }

    #[test]
    fn html_escapes_and_tones() {
        let html = table().to_html();
        assert!(html.contains("<td class=\"bad\">&lt;2&gt;</td>"), "{html}");
        assert!(html.contains("<th>a</th><th>bee</th>"), "{html}");
        assert!(html.starts_with("<div class=\"table-scroll\">"), "{html}");
    }

    #[test]
    fn csv_quotes_what_needs_it() {
        assert_eq!(table().to_csv(), "a,bee\r\n1,<2>\r\n\"x,\"\"y\"\"\",0\r\n");
    }

    #[test]
    fn text_aligns_columns() {
        assert_eq!(
            table().to_text(),
            "T\na      bee\n1      <2>\nx,\"y\"    0\nm\n"
        );
    }

    #[test]
    #[should_panic(expected = "has 1 cells for 2 headers")]
    fn a_short_row_is_refused() {
        table().push(["only one"]);
    }
}
