//! MiniProf profile files (`.whl` wheels, `.ban` rails), as CONTACT documents and reads them
//! (`matlab/read_miniprof.m`, Vollebregt, Apache-2.0): three header styles — the old one
//! (`MINIPROF` in the first lines, data after the first empty line), the regular one
//! (`key=value` lines, then the data) and the multi-part one (`[FileInfo]`, data in
//! `[Profile…Points]` sections, the first read) — comments after `"`, `!` or `%`, and a
//! `ColumnDef` naming the columns (`X` lateral, `Y` vertical; default `X,Y`).
//!
//! Orientation, as CONTACT's automatic mode: a rail whose lowest point lies at an end of the
//! data has z up and is turned to z down (depth below the top); a wheel whose highest point
//! lies at an end likewise (its side faces read upside down). A wheel's y is measured from the
//! back of its flange: it is shifted by [`WHEEL_TAPE_LINE`] so that y = 0 is the tape line, as
//! railforce reads wheels. The back face, the outer chamfer and the under-turned corners of a
//! rail head, where the measured y turns back or stands vertical, are left out: from a wheel's
//! flange tip or a rail's top the points are kept both ways while y advances (a glitch that
//! steps back less than 1 mm is passed over), and they must cover at least 50 or 30 mm of y,
//! without a jump, in millimetres.

use crate::error::{Error, Result};
use std::path::Path;

/// Distance of the tape line from the back of the flange, mm (EN 13715; the MiniProf wheel's
/// y origin is the flange back).
pub const WHEEL_TAPE_LINE: f64 = 70.0;

/// Largest distance between neighbouring points, mm: beyond it the data has a gap.
const MAX_STEP: f64 = 10.0;

/// Whether a file is MiniProf by its extension.
pub fn is_miniprof(ext: &str) -> bool {
    matches!(ext, "whl" | "ban" | "mpt")
}

/// Points `(y, z)` in metres of a MiniProf file, oriented and trimmed (module docs).
pub fn parse(text: &str, path: &Path, wheel: bool) -> Result<Vec<(f64, f64)>> {
    let err = |m: String| Error::Parse {
        file: path.to_path_buf(),
        message: m,
    };
    let lines: Vec<&str> = text.lines().collect();
    let old = lines.iter().take(3).any(|l| l.contains("MINIPROF"));
    let multi = lines.iter().take(3).any(|l| l.contains("[FileInfo]"));
    let (mut cols, mut in_data, mut section) = ("X,Y".to_string(), false, 0);
    // (file line, y, z) in mm
    let mut raw: Vec<(usize, f64, f64)> = Vec::new();
    for (ln, full) in lines.iter().enumerate() {
        if multi && full.contains("Points]") {
            section += 1;
            in_data = section == 1;
            continue;
        }
        if !multi && full.trim().is_empty() {
            in_data = true; // the old format's data follow its first empty line
            continue;
        }
        let line = full.split(['"', '!', '%']).next().unwrap_or("").trim();
        if let Some((key, value)) = line.split_once('=') {
            if key.trim().eq_ignore_ascii_case("ColumnDef") {
                cols = value.trim().to_string();
            }
            continue;
        }
        if line.is_empty() || line.starts_with('[') || (old && !in_data) || (multi && !in_data) {
            continue;
        }
        let names: Vec<&str> = cols.split(',').map(str::trim).collect();
        let pos = |c: &str| names.iter().position(|n| n.eq_ignore_ascii_case(c));
        let (Some(ix), Some(iz)) = (pos("X"), pos("Y")) else {
            return Err(err(format!(
                "ColumnDef \"{cols}\" names no X and Y columns (lateral, vertical)"
            )));
        };
        // The leading numbers of the line (a remark may follow them, as CONTACT reads it).
        let nums: Vec<f64> = line
            .split([',', ' ', '\t', ';'])
            .filter(|s| !s.is_empty())
            .map_while(|t| t.parse().ok())
            .collect();
        if nums.is_empty() {
            return Err(err(format!(
                "line {}: \"{line}\" is not a row of numbers",
                ln + 1
            )));
        }
        if nums.len() <= ix.max(iz) {
            // A header line of the old format before its data (e.g. `32.58 37.11 14.71`).
            if raw.is_empty() {
                continue;
            }
            return Err(err(format!(
                "line {}: {} column(s), ColumnDef \"{cols}\" needs {}",
                ln + 1,
                nums.len(),
                ix.max(iz) + 1
            )));
        }
        raw.push((ln + 1, nums[ix], nums[iz]));
    }
    if raw.len() < 10 {
        return Err(err(format!("{} profile points: too few", raw.len())));
    }
    if raw.iter().all(|p| p.1.abs() < 1.0 && p.2.abs() < 1.0) {
        return Err(err(
            "every coordinate is below 1: MiniProf files are in millimetres (metres given?)".into(),
        ));
    }
    // z down: turn the data over where its extreme lies at an end (CONTACT's automatic mode).
    let n = raw.len();
    let at_end = |i: usize| i < n / 20 || i > n - 1 - n / 20;
    let argmin = (0..n)
        .min_by(|&a, &b| raw[a].2.total_cmp(&raw[b].2))
        .unwrap_or(0);
    let argmax = (0..n)
        .max_by(|&a, &b| raw[a].2.total_cmp(&raw[b].2))
        .unwrap_or(0);
    let flip = if wheel {
        !at_end(argmin) && at_end(argmax)
    } else {
        at_end(argmin) && !at_end(argmax)
    };
    let mut pts: Vec<(usize, f64, f64)> = raw
        .into_iter()
        .map(|(l, y, z)| {
            let y = if wheel { y - WHEEL_TAPE_LINE } else { y };
            (l, y, if flip { -z } else { z })
        })
        .collect();
    // Increasing y from the flange tip (wheel) or the top (rail) both ways, past measurement
    // glitches that step back less than 1 mm, until the data turns back for good or turns
    // vertical (the back face, the chamfer, the corners of a rail head): those are left out.
    if pts[0].1 > pts[n - 1].1 {
        pts.reverse();
    }
    let key = if wheel {
        (0..n).max_by(|&a, &b| pts[a].2.total_cmp(&pts[b].2))
    } else {
        (0..n).min_by(|&a, &b| pts[a].2.total_cmp(&pts[b].2))
    }
    .unwrap_or(0);
    // A wheel's back face stands vertical; a rail's gauge face is steep by design (1:20).
    let face = |a: &(usize, f64, f64), b: &(usize, f64, f64)| {
        let (dy, dz) = ((b.1 - a.1).abs(), (b.2 - a.2).abs());
        wheel && dz > 10.0 * dy && dz > 0.05
    };
    let mut forward = vec![pts[key]];
    for p in &pts[key + 1..] {
        let last = forward[forward.len() - 1];
        if p.1 < last.1 - 1.0 || (p.1 > last.1 && face(&last, p)) {
            break;
        }
        if p.1 > last.1 {
            forward.push(*p);
        }
    }
    let mut backward = Vec::new();
    let mut last = pts[key];
    for p in pts[..key].iter().rev() {
        if p.1 > last.1 + 1.0 || (p.1 < last.1 && face(p, &last)) {
            break;
        }
        if p.1 < last.1 {
            backward.push(*p);
            last = *p;
        }
    }
    backward.reverse();
    let kept: Vec<(usize, f64, f64)> = backward.into_iter().chain(forward).collect();
    let span = kept.last().map_or(0.0, |l| l.1) - kept.first().map_or(0.0, |f| f.1);
    if span < if wheel { 50.0 } else { 30.0 } {
        let at = kept.last().map_or(0, |l| l.0);
        return Err(err(format!(
            "line {at}: the profile turns back or stands vertical {span:.1} mm from the {} (it must advance over {} mm around it)",
            if wheel { "flange tip" } else { "rail top" },
            if wheel { 50 } else { 30 }
        )));
    }
    if let Some(w) = kept
        .windows(2)
        .find(|w| ((w[1].1 - w[0].1).powi(2) + (w[1].2 - w[0].2).powi(2)).sqrt() > MAX_STEP)
    {
        return Err(err(format!(
            "line {}: a jump of more than {MAX_STEP} mm from the point before (missing data?)",
            w[1].0
        )));
    }
    Ok(kept.iter().map(|&(_, y, z)| (y * 1e-3, z * 1e-3)).collect())
}
