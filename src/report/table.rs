//! A table written three ways: Markdown, CSV and HTML.

use super::escape::esc;

/// How a table shows a missing value.
pub const MISSING: &str = "—";

/// A tidy ASCII column key from a human header: lower case, `²` → `2`, `Δ` → `d`, every other
/// run of non-alphanumeric characters → `_` (`Var(FQ_test)` → `var_fq_test`).
pub fn key(label: &str) -> String {
    let mut k = String::new();
    for c in label.chars() {
        let c = match c {
            '²' => '2',
            '³' => '3',
            'Δ' => 'd',
            'μ' | 'µ' => 'u',
            c if c.is_ascii_alphanumeric() => c.to_ascii_lowercase(),
            _ => '_',
        };
        if c != '_' || !(k.is_empty() || k.ends_with('_')) {
            k.push(c);
        }
    }
    k.trim_end_matches('_').to_string()
}

/// Rows of strings under a header. Markdown and HTML show the header as written; the CSV
/// gets tidy ASCII keys derived from it ([`key`]: `FL R²` → `fl_r2`) and leaves a missing
/// value (`—`) empty, so pandas reads it without parsing.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
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

    /// CSV with [`key`] headers, one value per cell (fields with commas or quotes are
    /// quoted; `—` is written empty).
    pub fn csv(&self) -> String {
        let q = |f: &String| {
            if f.contains([',', '"']) {
                format!("\"{}\"", f.replace('"', "\"\""))
            } else {
                f.clone()
            }
        };
        let mut s = self
            .header
            .iter()
            .map(|h| key(h))
            .collect::<Vec<_>>()
            .join(",")
            + "\n";
        for r in &self.rows {
            let cells: Vec<String> = r
                .iter()
                .map(|f| if f == MISSING { String::new() } else { q(f) })
                .collect();
            s += &(cells.join(",") + "\n");
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_is_tidy() {
        assert_eq!(key("FL R²"), "fl_r2");
        assert_eq!(key("Var(FQ_test)"), "var_fq_test");
        assert_eq!(key("test RMSE kN"), "test_rmse_kn");
        assert_eq!(key("ΔQ/Q̄ 99.85 %"), "dq_q_99_85");
        let mut t = Table::new(&["model", "FL R²", "paper FL R²"]);
        t.push(vec!["cnn".into(), "0.9".into(), MISSING.into()]);
        t.push(vec!["a, b".into(), "1".into(), "0.5".into()]);
        assert_eq!(
            t.csv(),
            "model,fl_r2,paper_fl_r2\ncnn,0.9,\n\"a, b\",1,0.5\n"
        );
        assert!(t.markdown().contains("| FL R² |"));
    }
}
