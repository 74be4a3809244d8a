//! The estimates file: every parameter of the vehicle and track files that is an estimate,
//! with the range a sensitivity study samples and where that range comes from.
//!
//! ```toml
//! name = "c80"
//! [estimate."vehicle.wedge_damper.stick_stiffness"]
//! uniform = [0.25, 4.0]      # the range: a factor on the file's value with scale = true
//! scale = true
//! source = "estimate ×/÷ 4 about 20 MN/m: no published loop test of the K6 wedge"
//! ```
//!
//! A key is a `[vary]` key (assets/docs/file-formats.md, "Variation"); `with` works as there.
//! Every estimate needs a range (`uniform = [lo, hi]`, lo < hi) and a `source`.

use crate::error::{Error, Result};
use crate::plan::Plan;
use crate::vary::{Draw, Vary};
use std::path::{Path, PathBuf};

/// One estimated parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The key, its `with` keys and whether the range scales the file's value.
    pub variation: crate::vary::Variation,
    /// The range's ends (a factor when `variation.scale`).
    pub range: (f64, f64),
    /// Where the range comes from.
    pub source: String,
}

impl Estimate {
    /// The value at `x` ∈ [0, 1] of the range.
    pub fn at(&self, x: f64) -> f64 {
        self.range.0 + x * (self.range.1 - self.range.0)
    }

    /// The range as a report prints it: `0.25–4 ×` or `0.15–0.5`.
    pub fn describe_range(&self) -> String {
        let (lo, hi) = self.range;
        if self.variation.scale {
            format!("{lo}–{hi} ×")
        } else {
            format!("{lo}–{hi}")
        }
    }
}

/// An estimates file.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimates {
    /// The file it came from.
    pub path: PathBuf,
    /// Its name.
    pub name: String,
    /// The estimates, in key order.
    pub estimates: Vec<Estimate>,
}

impl Estimates {
    /// Reads an estimates file; every error names the file and the key.
    pub fn load(path: &Path) -> Result<Self> {
        let raw: toml::Table = crate::io::read_toml(path)?;
        let mut name = None;
        let mut table = None;
        for (k, v) in &raw {
            match k.as_str() {
                "name" => {
                    name = Some(
                        v.as_str()
                            .map(str::to_string)
                            .ok_or_else(|| Error::config(path, "name", "must be a string"))?,
                    )
                }
                "estimate" => {
                    table = Some(v.as_table().cloned().ok_or_else(|| {
                        Error::config(
                            path,
                            "estimate",
                            "must be a table of keys: [estimate.\"vehicle.contact.friction\"]",
                        )
                    })?)
                }
                other => {
                    return Err(Error::config(
                        path,
                        other,
                        "unknown key: an estimates file has name and [estimate.\"<key>\"] tables",
                    ));
                }
            }
        }
        let table = table
            .filter(|t| !t.is_empty())
            .ok_or_else(|| Error::config(path, "estimate", "no estimate given"))?;
        let mut estimates = Vec::new();
        for (key, spec) in &table {
            let field = format!("estimate.\"{key}\"");
            let bad = |m: String| Error::config(path, &field, m);
            let mut spec = spec
                .as_table()
                .cloned()
                .ok_or_else(|| bad("give a table: uniform = [lo, hi], source = \"…\"".into()))?;
            let source = match spec.remove("source") {
                Some(toml::Value::String(s)) if !s.trim().is_empty() => s,
                Some(_) => return Err(bad("source must be a non-empty string".into())),
                None => {
                    return Err(bad(
                        "no source: say where the range comes from, or \"estimate ±x %\"".into(),
                    ));
                }
            };
            let one: toml::Table = [(key.clone(), toml::Value::Table(spec))]
                .into_iter()
                .collect();
            let vary = Vary::parse(&one, path, "estimate")?;
            let variation = vary.variations.into_iter().next().expect("one key parsed");
            let range = match variation.draw {
                Draw::Uniform(lo, hi) if lo < hi => (lo, hi),
                Draw::Uniform(lo, hi) => {
                    return Err(bad(format!(
                        "uniform = [{lo}, {hi}] is no range: a study samples lo < hi"
                    )));
                }
                _ => {
                    return Err(bad(
                        "no range: a study samples uniform = [lo, hi] (normal and one_of are draws, not ranges)"
                            .into(),
                    ));
                }
            };
            estimates.push(Estimate {
                variation,
                range,
                source,
            });
        }
        Ok(Estimates {
            path: path.to_path_buf(),
            name: name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            estimates,
        })
    }

    /// The index of the estimate of `key`, or an error naming this file.
    pub fn index_of(&self, key: &str) -> Result<usize> {
        self.estimates
            .iter()
            .position(|e| e.variation.key == key)
            .ok_or_else(|| {
                Error::Domain(format!(
                    "{key} is not an estimate of {}",
                    self.path.display()
                ))
            })
    }

    /// The estimates as one `[vary]` set over their whole ranges.
    pub fn vary(&self) -> Vary {
        Vary {
            variations: self.estimates.iter().map(|e| e.variation.clone()).collect(),
        }
    }

    /// Tries every range's ends on every condition of `plan` through the files' own loaders,
    /// before any run: a range outside an element's physical bounds is refused, naming this
    /// file and the key ([`crate::vary::check`]).
    pub fn check(&self, plan: &Plan) -> Result<()> {
        let vary = self.vary();
        let mut tried = Vec::new();
        for (index, c) in plan.conditions.iter().enumerate() {
            crate::vary::check(&self.path, c.subject(index), &vary, &mut tried)?;
        }
        Ok(())
    }
}
