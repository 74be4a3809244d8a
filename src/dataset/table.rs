//! Run files as tables of named columns: NPZ, Parquet or CSV by extension. Every reader
//! refuses a row or column of the wrong length, naming the file and the row.

use super::{npz, parquet_file};
use crate::error::{Error, Result};
use std::path::Path;

/// Reads a table of named f64 columns from an `.npz`, `.parquet` or CSV file (by extension).
/// Every column has the same length (a run cut short, or one array of another length, is
/// refused naming the file and the column), so readers may index any column by row.
pub fn read_table(file: &Path) -> Result<Vec<(String, Vec<f64>)>> {
    let bytes = std::fs::read(file).map_err(|e| Error::io(file, e))?;
    let ext = file.extension().map(|e| e.to_string_lossy().into_owned());
    let table = match ext.as_deref() {
        Some("npz") => npz::read_npz(&bytes).map_err(|e| Error::io(file, e))?,
        Some("parquet") => parquet_file::read_parquet(bytes).map_err(|e| Error::Parse {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?,
        _ => read_csv(&bytes, file)?,
    };
    let Some((first, x)) = table.first() else {
        return Err(Error::Parse {
            file: file.to_path_buf(),
            message: "holds no columns (empty, or cut short)".into(),
        });
    };
    if let Some((name, y)) = table.iter().find(|(_, y)| y.len() != x.len()) {
        return Err(Error::Parse {
            file: file.to_path_buf(),
            message: format!(
                "column {name} has {} rows but column {first} has {}: the file is cut short or mixes runs",
                y.len(),
                x.len()
            ),
        });
    }
    Ok(table)
}

/// Parses CSV text with a header of column names (as [`read_table`] does for `.csv`). Every
/// row must have as many fields as the header: a row cut short (a file truncated mid-row) or
/// one with extra fields is refused, naming the row counted from 1 after the header.
pub fn read_csv(bytes: &[u8], file: &Path) -> Result<Vec<(String, Vec<f64>)>> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or_default()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let mut cols = vec![Vec::new(); header.len()];
    let parse_err = |message: String| Error::Parse {
        file: file.to_path_buf(),
        message,
    };
    if header.len() == 1 && header[0].contains([';', '\t']) {
        return Err(parse_err(
            "the header has no comma: railforce reads comma-separated CSV (this file looks separated by ';' or tabs)".into(),
        ));
    }
    if let Some(k) = (1..header.len()).find(|&k| header[..k].contains(&header[k])) {
        let first = header.iter().position(|h| *h == header[k]).unwrap_or(0);
        return Err(parse_err(format!(
            "column {} appears twice (columns {} and {} of the header)",
            header[k],
            first + 1,
            k + 1
        )));
    }
    for (ln, line) in lines.enumerate() {
        let fields = line.split(',').count();
        if fields != header.len() {
            return Err(parse_err(row_length(ln + 1, fields, header.len())));
        }
        for (k, v) in line.split(',').enumerate() {
            let x: f64 = v.parse().map_err(|_| {
                // The same wording as the identify checks: column, row from 1 after the header.
                parse_err(not_a_number(&header[k], ln + 1, v))
            })?;
            cols[k].push(x);
        }
    }
    Ok(header.into_iter().zip(cols).collect())
}

/// What a CSV row of the wrong length is told, for every CSV reader (batch and stream): row
/// counted from 1 after the header.
pub fn row_length(row: usize, fields: usize, columns: usize) -> String {
    format!(
        "row {row} has {fields} field(s) but the header names {columns} columns{}",
        if fields < columns {
            " (the file may be cut short)"
        } else {
            ""
        }
    )
}

/// What a field that is not a number is told, for every CSV reader: column and row (from 1
/// after the header).
pub fn not_a_number(column: &str, row: usize, field: &str) -> String {
    format!("column {column}, row {row}: \"{field}\" is not a number")
}
