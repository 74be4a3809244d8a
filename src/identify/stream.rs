//! The sensor stream: CSV rows on a reader (stdin on board), checked one at a time with the
//! batch check's rules and wording — the model's channels present in the header, every field a
//! finite number, one 200 Hz step between rows — for streaming identification.

use super::{TIME_COLUMNS, irregular_step, is_regular_step, not_finite, resolve_channels};
use crate::dataset::{not_a_number, row_length};
use crate::error::{Error, Result};
use crate::learn::model::Model;
use std::io::BufRead;

/// A checked CSV stream of sensor rows.
pub struct SensorRows<R: BufRead> {
    source: String,
    lines: std::io::Lines<R>,
    names: Vec<String>,
    time: usize,
    position: Option<usize>,
    pick: Vec<usize>,
    row: usize,
    last_time: Option<f64>,
}

impl<R: BufRead> SensorRows<R> {
    /// Reads the header from `reader` and finds the time column, `s_m` and the model's
    /// channels (their `_noisy` copies where the model was tested on them).
    pub fn new(reader: R, source: &str, model: &Model) -> Result<Self> {
        let mut lines = reader.lines();
        let header = lines
            .next()
            .ok_or_else(|| Error::Domain(format!("{source}: empty input: expected a CSV header")))?
            .map_err(|e| Error::Domain(format!("{source}: {e}")))?;
        let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
        let time = names
            .iter()
            .position(|n| TIME_COLUMNS.contains(&n.as_str()))
            .ok_or_else(|| {
                Error::Domain(format!(
                    "{source}: no time column (expected one of {})",
                    TIME_COLUMNS.join(", ")
                ))
            })?;
        let head: Vec<&str> = names.iter().map(String::as_str).collect();
        let pick = resolve_channels(&head, model, source)?;
        Ok(SensorRows {
            source: source.to_string(),
            lines,
            position: names.iter().position(|n| n == "s_m"),
            names,
            time,
            pick,
            row: 0,
            last_time: None,
        })
    }

    /// Whether the stream carries the track position `s_m`.
    pub fn has_position(&self) -> bool {
        self.position.is_some()
    }

    /// The next row: its time, the model's channels written into `values` (model order) and
    /// `s_m` where the stream has it; `None` at the end.
    pub fn next_row(&mut self, values: &mut [f64]) -> Result<Option<(f64, Option<f64>)>> {
        let Some(line) = self.lines.next() else {
            return Ok(None);
        };
        let line = line.map_err(|e| Error::Domain(format!("{}: {e}", self.source)))?;
        self.row += 1;
        let row = self.row;
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != self.names.len() {
            return Err(Error::Domain(format!(
                "{}: {}",
                self.source,
                row_length(row, fields.len(), self.names.len())
            )));
        }
        let num = |k: usize| -> Result<f64> {
            let field = fields[k].trim();
            let v: f64 = field.parse().map_err(|_| {
                Error::Domain(format!(
                    "{}: {}",
                    self.source,
                    not_a_number(&self.names[k], row, field)
                ))
            })?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(not_finite(&self.source, &self.names[k], row, v))
            }
        };
        let t = num(self.time)?;
        if let Some(p) = self.last_time
            && !is_regular_step(t - p)
        {
            return Err(irregular_step(&self.source, row - 1, t - p, ""));
        }
        self.last_time = Some(t);
        for (v, &k) in values.iter_mut().zip(&self.pick) {
            *v = num(k)?;
        }
        let s = self.position.map(num).transpose()?;
        Ok(Some((t, s)))
    }
}
