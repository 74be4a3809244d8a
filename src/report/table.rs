//! A table written three ways: Markdown, CSV and HTML.

use super::svg::esc;

/// Rows of strings under a header.
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// Column names.
    pub header: Vec<String>,
    /// Rows.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// An empty table with these columns.
    pub fn new(header: &[&str]) -> Self {
        Table {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row.
    pub fn push(&mut self, row: Vec<String>) {
        self.rows.push(row);
    }

    /// Markdown.
    pub fn markdown(&self) -> String {
        let mut s = format!(
            "| {} |\n|{}\n",
            self.header.join(" | "),
            "---|".repeat(self.header.len())
        );
        for r in &self.rows {
            s += &format!("| {} |\n", r.join(" | "));
        }
        s
    }

    /// CSV (fields with commas or quotes are quoted).
    pub fn csv(&self) -> String {
        let q = |f: &String| {
            if f.contains([',', '"']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.clone()
            }
        };
        let mut s = self.header.iter().map(q).collect::<Vec<_>>().join(",") + "\n";
        for r in &self.rows {
            s += &(r.iter().map(q).collect::<Vec<_>>().join(",") + "\n");
        }
        s
    }

    /// HTML.
    pub fn html(&self) -> String {
        let mut s = String::from("<table><tr>");
        for h in &self.header {
            s += &format!("<th>{}</th>", esc(h));
        }
        s += "</tr>";
        for r in &self.rows {
            s += "<tr>";
            for f in r {
                s += &format!("<td>{}</td>", esc(f));
            }
            s += "</tr>";
        }
        s + "</table>"
    }
}
