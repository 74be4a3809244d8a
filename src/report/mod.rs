//! Reports: tables (Markdown, CSV, HTML), SVG charts, and the `index.html` that shows an
//! experiment's tables and figures together with the paper's numbers.

pub mod svg;
pub mod table;

use crate::error::Result;
use std::path::Path;
use svg::{Chart, esc};
use table::Table;

/// A part of a report.
#[derive(Default)]
pub struct Section {
    /// Heading.
    pub title: String,
    /// Paragraphs (plain text, escaped when rendered).
    pub text: Vec<String>,
    /// Tables: caption, table, file stem (written as `stem.md` and `stem.csv`).
    pub tables: Vec<(String, Table, String)>,
    /// Figures: caption, chart, file name (`.svg`).
    pub figures: Vec<(String, Chart, String)>,
}

impl Section {
    /// Writes the section's tables and figures into `dir`.
    pub fn write_files(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| crate::Error::io(dir, e))?;
        for (_, t, stem) in &self.tables {
            let md = t.markdown();
            crate::io::write_atomic(&dir.join(format!("{stem}.md")), |w| {
                w.write_all(md.as_bytes())
            })?;
            let csv = t.csv();
            crate::io::write_atomic(&dir.join(format!("{stem}.csv")), |w| {
                w.write_all(csv.as_bytes())
            })?;
        }
        for (_, c, name) in &self.figures {
            let s = c.to_svg();
            crate::io::write_atomic(&dir.join(name), |w| w.write_all(s.as_bytes()))?;
        }
        Ok(())
    }

    /// HTML of the section; file links are relative to the report folder (`prefix/…`).
    pub fn html(&self, prefix: &str) -> String {
        let mut s = format!("<h2>{}</h2>\n", esc(&self.title));
        for p in &self.text {
            s += &format!("<p>{}</p>\n", esc(p));
        }
        for (cap, t, stem) in &self.tables {
            s += &format!(
                "<h3>{}</h3>\n{}\n<p class=\"files\"><a href=\"{prefix}{stem}.csv\">CSV</a> · <a href=\"{prefix}{stem}.md\">Markdown</a></p>\n",
                esc(cap),
                t.html()
            );
        }
        for (cap, _, name) in &self.figures {
            s += &format!(
                "<figure><img src=\"{prefix}{name}\" alt=\"{0}\"><figcaption>{0}</figcaption></figure>\n",
                esc(cap)
            );
        }
        s
    }
}

/// Writes `index.html` of sections (each in its own subfolder `folder/`).
pub fn write_index(
    dir: &Path,
    title: &str,
    intro: &[String],
    sections: &[(String, Section)],
) -> Result<()> {
    let mut s = format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{0}</title><style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}}table{{border-collapse:collapse;margin:0.5em 0}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}th{{background:#f3f3f3}}figure{{display:inline-block;margin:0.5em}}img{{max-width:100%}}.files{{font-size:90%}}</style></head><body><h1>{0}</h1>\n",
        esc(title)
    );
    for p in intro {
        s += &format!("<p>{}</p>\n", esc(p));
    }
    for (folder, sec) in sections {
        s += &sec.html(&format!("{folder}/"));
    }
    s += "</body></html>\n";
    crate::io::write_atomic(&dir.join("index.html"), |w| w.write_all(s.as_bytes()))
}
