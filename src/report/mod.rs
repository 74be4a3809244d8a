//! Reports: tables (Markdown, CSV, HTML), SVG charts, and the `index.html` of an output
//! folder. Each part of a report (an experiment) lives in its own subfolder with its tables,
//! figures and a `section.json` that describes them; the index is rebuilt from every
//! `section.json` present, so parts run one by one into one folder, in any order, all show.

mod escape;
pub mod svg;
pub mod table;
pub mod tornado;

pub use escape::esc;

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;
use svg::Figure;
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
    pub figures: Vec<(String, Figure, String)>,
}

/// What `section.json` holds: the section without its drawings (the SVG files are beside it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SavedSection {
    /// Heading.
    pub title: String,
    /// Paragraphs.
    pub text: Vec<String>,
    /// Tables: caption, table, file stem.
    pub tables: Vec<(String, Table, String)>,
    /// Figures: caption, file name.
    pub figures: Vec<(String, String)>,
    /// Links to pages beside the section (text, file name), such as the viewer.
    #[serde(default)]
    pub links: Vec<(String, String)>,
}

/// File that describes a section in its folder.
pub const SECTION_FILE: &str = "section.json";

impl Section {
    /// Writes the section's tables, figures and `section.json` into `dir`.
    pub fn write_files(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
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
        let saved = SavedSection {
            title: self.title.clone(),
            text: self.text.clone(),
            tables: self.tables.clone(),
            figures: self
                .figures
                .iter()
                .map(|(cap, _, name)| (cap.clone(), name.clone()))
                .collect(),
            links: Vec::new(),
        };
        saved.write(dir)
    }
}

impl SavedSection {
    /// Writes `dir/section.json` (the tables and figures it names are the caller's).
    pub fn write(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let json = crate::io::to_json_pretty(self, &dir.join(SECTION_FILE))?;
        crate::io::write_atomic(&dir.join(SECTION_FILE), |w| w.write_all(json.as_bytes()))
    }

    /// Reads `dir/section.json`; `None` when the folder holds no section.
    pub fn read(dir: &Path) -> Result<Option<Self>> {
        let path = dir.join(SECTION_FILE);
        if !path.exists() {
            return Ok(None);
        }
        let text = crate::io::read_text(&path)?;
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| Error::Parse {
                file: path,
                message: e.to_string(),
            })
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
        for (cap, name) in &self.figures {
            s += &format!(
                "<figure><img src=\"{prefix}{name}\" alt=\"{0}\"><figcaption>{0}</figcaption></figure>\n",
                esc(cap)
            );
        }
        for (text, name) in &self.links {
            s += &format!(
                "<p><a href=\"{prefix}{name}\"><strong>{}</strong></a></p>\n",
                esc(text)
            );
        }
        s
    }
}

/// Writes `dir/index.html` from the sections saved in the subfolders `folders` (in that
/// order; folders without a `section.json` are left out). Returns the folders shown.
pub fn write_index(
    dir: &Path,
    title: &str,
    intro: &[String],
    folders: &[&str],
) -> Result<Vec<String>> {
    let mut s = format!(
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{0}</title><style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}}table{{border-collapse:collapse;margin:0.5em 0}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}th{{background:#f3f3f3}}figure{{margin:1em 0}}img{{max-width:100%}}.files{{font-size:90%}}nav a{{margin-right:1em}}</style></head><body><h1>{0}</h1>\n",
        esc(title)
    );
    for p in intro {
        s += &format!("<p>{}</p>\n", esc(p));
    }
    let mut shown = Vec::new();
    let mut body = String::new();
    for folder in folders {
        if let Some(sec) = SavedSection::read(&dir.join(folder))? {
            body += &format!("<section id=\"{folder}\">\n");
            body += &sec.html(&format!("{folder}/"));
            body += "</section>\n";
            shown.push((folder.to_string(), sec.title));
        }
    }
    if shown.len() > 1 {
        s += "<nav>";
        for (folder, t) in &shown {
            s += &format!("<a href=\"#{folder}\">{}</a>", esc(t));
        }
        s += "</nav>\n";
    }
    s += &body;
    s += "</body></html>\n";
    crate::io::write_atomic(&dir.join("index.html"), |w| w.write_all(s.as_bytes()))?;
    Ok(shown.into_iter().map(|f| f.0).collect())
}
