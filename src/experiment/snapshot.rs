//! The results snapshot: `results.md` written from a finished run's own files (`meta.json`
//! and each part's `section.json`), so the figures a reader quotes are the ones the run
//! measured. It carries the date, the commit and the binary's version, every protocol line,
//! the wall and CPU time of each part, a headline table picked from the parts' tables, and every
//! table and figure of every part. The README quotes the headline table between
//! [`HEADLINE_BEGIN`] and [`HEADLINE_END`] (a test holds the two equal).

use super::Which;
use super::index::{protocol_lines, read_json};
use crate::error::{Error, Result};
use crate::report::SavedSection;
use crate::report::table::{MISSING, Table};
use std::path::{Path, PathBuf};

/// The line before the headline table, in the snapshot and in the README.
pub const HEADLINE_BEGIN: &str =
    "<!-- results:headline:begin (written by railforce experiment; do not edit) -->";
/// The line after it.
pub const HEADLINE_END: &str = "<!-- results:headline:end -->";

/// The folders of a sensitivity study in an experiment's output folder, shown after its parts.
const SENSITIVITY: [&str; 2] = ["sensitivity/morris", "sensitivity/sobol"];

/// Writes the snapshot of the run in `out` to `dest` (atomically), copying the parts'
/// figures into `dest`'s folder under `results/<part>/` unless `dest` lies in `out`. A run
/// that has not finished (no `meta.json` of the whole run) is written from the parts that
/// have, and the snapshot says which are missing; a folder without any part is refused.
pub fn write_snapshot(out: &Path, dest: &Path) -> Result<PathBuf> {
    let md = render(out, dest)?;
    crate::io::write_atomic(dest, |w| w.write_all(md.as_bytes()))?;
    Ok(dest.to_path_buf())
}

/// The snapshot of the run in `out` as [`write_snapshot`] writes it to `dest` (the figures
/// copied beside `dest` already).
pub(super) fn render(out: &Path, dest: &Path) -> Result<String> {
    let meta_path = out.join("meta.json");
    let (meta, missing) = match read_json(&meta_path) {
        Some(m) if m["wall_seconds"].as_f64().is_some() => (m, Vec::new()),
        _ => partial_meta(out).ok_or_else(|| Error::Parse {
            file: meta_path.clone(),
            message: "no finished part of a run here (run `railforce experiment all` first)".into(),
        })?,
    };
    let dest_dir = dest
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let same = same_dir(&dest_dir, out);
    // Beside the project's other documents, link them; anywhere else, name them.
    let docs = dest_dir.ends_with("assets/docs");
    let doc = |name: &str| {
        if docs {
            format!("[{name}]({name})")
        } else {
            format!("railforce's assets/docs/{name}")
        }
    };
    let mut md = String::new();
    md += "# Results\n\n";
    md += &format!(
        "Written by `railforce experiment` from its own tables when the run finished: do not edit; rerun and this file is rewritten (`railforce experiment all --plan {} --out {} --results {}`, or `railforce experiment snapshot --out {} --results {}` for a finished folder). The protocol behind every number: {}; the words: {}.\n\n",
        meta["plan_name"].as_str().unwrap_or("?"),
        out.display(),
        dest.display(),
        out.display(),
        dest.display(),
        doc("learning.md"),
        doc("glossary.md"),
    );
    // Each part's own provenance (parts may run into one folder at different times).
    let parts: Vec<(&str, serde_json::Value)> = Which::FOLDERS
        .iter()
        .filter(|f| !missing.iter().any(|m| m == *f))
        .filter_map(|f| read_json(&out.join(f).join("meta.json")).map(|m| (*f, m)))
        .collect();
    let mut commits: Vec<(String, Vec<&str>)> = Vec::new();
    for (f, m) in &parts {
        let c = m["commit"]
            .as_str()
            .or(meta["commit"].as_str())
            .unwrap_or("unknown")
            .to_string();
        match commits.iter_mut().find(|(k, _)| *k == c) {
            Some((_, fs)) => fs.push(f),
            None => commits.push((c, vec![f])),
        }
    }
    let commit = match commits.as_slice() {
        [] => format!("`{}`", meta["commit"].as_str().unwrap_or("unknown")),
        [(c, _)] => format!("`{c}`"),
        many => many
            .iter()
            .map(|(c, fs)| format!("`{c}` ({})", fs.join(", ")))
            .collect::<Vec<_>>()
            .join(", "),
    };
    let one_run = commits.len() <= 1
        && parts
            .iter()
            .all(|(f, _)| meta["timings"][format!("{f}_s")].is_number());
    let parts_wall: f64 = parts
        .iter()
        .filter_map(|(_, m)| m["wall_seconds"].as_f64())
        .sum();
    if missing.is_empty() {
        md += &format!(
            "- **Run:** finished {} (UTC), railforce {}, commit {}, {}.\n",
            meta["finished_unix"]
                .as_u64()
                .map_or("?".into(), utc_date_time),
            meta["railforce_version"].as_str().unwrap_or("?"),
            commit,
            if one_run {
                format!(
                    "{} wall time in all",
                    minutes(meta["wall_seconds"].as_f64().unwrap_or(0.0))
                )
            } else {
                format!(
                    "its parts run into one folder at different times, {} of wall time added",
                    minutes(parts_wall)
                )
            },
        );
    } else {
        md += &format!(
            "- **Run:** not finished: the parts below are those that had finished by {} (UTC), railforce {}, commit {}; **not in this snapshot: {}** (no figure of theirs is quoted from another run).\n",
            meta["finished_unix"]
                .as_u64()
                .map_or("?".into(), utc_date_time),
            meta["railforce_version"].as_str().unwrap_or("?"),
            commit,
            missing.join(", "),
        );
    }
    for line in protocol_lines(&meta) {
        md += &format!("- {}\n", line.trim_start_matches("Latest run: "));
    }
    md += "- Paper numbers come from another simulator and an unstated (apparently shuffled) split: a bar, not a target to match digit for digit.\n\n";
    md += "## Headline\n\n";
    md += &headline_block(out)?;
    md += "\n## Wall time of each part\n\n";
    md += "CPU time: every thread's user and system time while the part ran; cores busy: CPU time over wall time, of the cores its machine had (last column). A part that keeps every core busy is bound by its work, not by the order of its jobs.\n\n";
    let mut wt = Table::new(&WALL_HEADER);
    for (f, m) in &parts {
        if let Some(s) = m["wall_seconds"].as_f64() {
            let c = m["commit"].as_str().unwrap_or("unknown");
            let mut row = vec![f.to_string(), c.chars().take(7).collect()];
            row.extend(wall_cells(s, m["cpu_seconds"].as_f64()));
            row.push(m["machine"].as_str().unwrap_or("—").to_string());
            wt.push(row);
        }
    }
    let (total, total_cpu) = if one_run {
        (
            meta["wall_seconds"].as_f64().unwrap_or(0.0),
            meta["cpu_seconds"].as_f64(),
        )
    } else {
        let cpu: Option<f64> = (parts.iter())
            .filter(|(_, m)| m["wall_seconds"].is_number())
            .map(|(_, m)| m["cpu_seconds"].as_f64())
            .sum();
        (parts_wall, cpu)
    };
    let mut row = vec![
        if missing.is_empty() && one_run {
            "all, with the simulation of the data".into()
        } else {
            "the parts above, added".into()
        },
        String::new(),
    ];
    row.extend(wall_cells(total, total_cpu));
    row.push(String::new());
    wt.push(row);
    md += &wt.markdown();
    // The experiments' parts, then a sensitivity study run into the same folder
    // (`railforce sensitivity --out OUT/sensitivity`): the labels' own uncertainty beside the
    // networks' R² (its long table of every measure stays in its CSV).
    for f in Which::FOLDERS.into_iter().chain(SENSITIVITY) {
        let Some(sec) = SavedSection::read(&out.join(f))? else {
            continue;
        };
        md += &format!("\n## {}\n\n", sec.title);
        for p in &sec.text {
            md += &format!("{p}\n\n");
        }
        for (cap, t, _) in sec.tables.iter().filter(|t| t.2 != "measures") {
            md += &format!("**{cap}**\n\n{}\n", t.markdown());
        }
        for (cap, name) in &sec.figures {
            let link = if same {
                format!("{f}/{name}")
            } else {
                let rel = format!("results/{f}/{name}");
                let to = dest_dir.join(&rel);
                if let Some(d) = to.parent() {
                    std::fs::create_dir_all(d).map_err(|e| Error::io(d, e))?;
                }
                let svg = crate::io::read_text(&out.join(f).join(name))?;
                crate::io::write_atomic(&to, |w| w.write_all(svg.as_bytes()))?;
                rel
            };
            md += &format!("![{cap}]({link})\n\n*{cap}*\n\n");
        }
    }
    Ok(md)
}

/// The run's description from the parts that finished (each part's `meta.json` carries the
/// run's protocol and its own wall time), and the parts missing; `None` without any part.
fn partial_meta(out: &Path) -> Option<(serde_json::Value, Vec<String>)> {
    let mut meta: Option<serde_json::Value> = None;
    let (mut timings, mut missing) = (serde_json::Map::new(), Vec::new());
    // The parts' CPU time added, while every part recorded one.
    let mut cpu = Some(0.0);
    let mut last = 0u64;
    for f in Which::FOLDERS {
        let p = out.join(f).join("meta.json");
        match (
            read_json(&p),
            SavedSection::read(&out.join(f)).ok().flatten(),
        ) {
            (Some(m), Some(_)) => {
                if let Some(s) = m["wall_seconds"].as_f64() {
                    timings.insert(format!("{f}_s"), serde_json::json!(s));
                    cpu = cpu.zip(m["cpu_seconds"].as_f64()).map(|(a, b)| a + b);
                }
                let modified = std::fs::metadata(&p)
                    .and_then(|md| md.modified())
                    .ok()
                    .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                    .map_or(0, |d| d.as_secs());
                last = last.max(modified);
                meta.get_or_insert(m);
            }
            _ => missing.push(f.to_string()),
        }
    }
    let mut meta = meta?;
    let total: f64 = timings.values().filter_map(|v| v.as_f64()).sum();
    meta["cpu_seconds"] = serde_json::json!(cpu);
    meta["timings"] = serde_json::Value::Object(timings);
    meta["wall_seconds"] = serde_json::json!(total);
    meta["finished_unix"] = serde_json::json!(last);
    Some((meta, missing))
}

/// Whether two folders are the same on disk.
fn same_dir(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// The headline table of the run in `out` between its markers, as the README quotes it.
pub fn headline_block(out: &Path) -> Result<String> {
    Ok(format!(
        "{HEADLINE_BEGIN}\n{}{HEADLINE_END}\n",
        headline(out)?.markdown()
    ))
}

/// The text between the markers (markers included) of a snapshot or README, if any.
pub fn quoted_headline(text: &str) -> Option<&str> {
    let a = text.find(HEADLINE_BEGIN)?;
    let b = text[a..].find(HEADLINE_END)? + a + HEADLINE_END.len();
    Some(&text[a..b])
}

/// `readme` with its quoted headline replaced by `snapshot`'s; an error names the file that
/// lacks the markers.
pub fn requote(readme: &str, snapshot: &str, readme_path: &Path) -> Result<String> {
    let new = quoted_headline(snapshot).ok_or_else(|| Error::Parse {
        file: readme_path.to_path_buf(),
        message: "the snapshot has no headline table".into(),
    })?;
    let old = quoted_headline(readme).ok_or_else(|| Error::Parse {
        file: readme_path.to_path_buf(),
        message: format!("no headline markers ({HEADLINE_BEGIN} … {HEADLINE_END})"),
    })?;
    Ok(readme.replacen(old, new, 1))
}

/// The headline: the figures a reader asks first, each row picked from a part's own table.
fn headline(out: &Path) -> Result<Table> {
    let mut h = Table::new(&[
        "what",
        "FL R²",
        "FQ R²",
        "FL RMSE kN",
        "FQ RMSE kN",
        "protocol",
    ]);
    let tables = |f: &str| -> Result<Vec<(String, Table, String)>> {
        Ok(SavedSection::read(&out.join(f))?
            .map(|s| s.tables)
            .unwrap_or_default())
    };
    let find = |ts: &[(String, Table, String)], stem: &str| -> Option<Table> {
        ts.iter().find(|t| t.2 == stem).map(|t| t.1.clone())
    };
    let general = tables("generalization")?;
    if let Some(t) = find(&general, "seed_spread")
        && let Some(r) = t.rows.last()
    {
        h.push(metric_row(
            &t,
            r,
            "All conditions, the paper's 21 (two training seeds: mean ± half range)".into(),
            "one CNN-BiLSTM, FL and FQ as two outputs, the test runs of the split above".into(),
        ));
    }
    if let Some(t) = find(&general, "per_condition") {
        let rows: Vec<&Vec<String>> = t
            .rows
            .iter()
            .filter(|r| r.first().is_some_and(|c| !c.starts_with("all")))
            .collect();
        h.push(vec![
            "the same network per condition, lowest – highest".into(),
            range(&t, &rows, "FL R²"),
            range(&t, &rows, "FQ R²"),
            MISSING.into(),
            MISSING.into(),
            "each condition's own test variance (first seed)".into(),
        ]);
    }
    if let Some(t) = find(&tables("sensors")?, "sensors") {
        for r in t
            .rows
            .iter()
            .filter(|r| cell(&t, r, "inputs") != "paper's 21")
        {
            h.push(metric_row(
                &t,
                r,
                format!(
                    "Selected on-board sensors ({} channels) at {} dB",
                    cell(&t, r, "channels"),
                    cell(&t, r, "SNR dB")
                ),
                "Filter–Wrapper over the on-board candidates, CNN-BiLSTM, the same test runs"
                    .into(),
            ));
        }
    }
    if let Some(t) = find(&tables("protocols")?, "protocols") {
        // The seed split is the generalisation's own row.
        for r in t.rows.iter().filter(|r| cell(&t, r, "protocol") != "seeds") {
            h.push(metric_row(
                &t,
                r,
                format!("The CNN-BiLSTM split by {}", cell(&t, r, "protocol")),
                cell(&t, r, "what the test part is"),
            ));
        }
    }
    let cmp = tables("comparison")?;
    if let (Some(fl), Some(fq)) = (find(&cmp, "comparison_fl"), find(&cmp, "comparison_fq")) {
        let fq_r2 = |model: &str| {
            fq.rows
                .iter()
                .find(|q| cell(&fq, q, "model") == model)
                .and_then(|q| cell(&fq, q, "test R²").parse::<f64>().ok())
                .unwrap_or(f64::NEG_INFINITY)
        };
        // The CNN-BiLSTM, and the model that identifies FQ best if it is another.
        let mut shown = vec!["cnn-bilstm".to_string()];
        if let Some(best) = fl
            .rows
            .iter()
            .map(|r| cell(&fl, r, "model"))
            .max_by(|a, b| fq_r2(a).total_cmp(&fq_r2(b)))
            && best != "cnn-bilstm"
        {
            shown.push(best);
        }
        for model in shown {
            let (Some(r), Some(q)) = (
                fl.rows.iter().find(|r| cell(&fl, r, "model") == model),
                fq.rows.iter().find(|q| cell(&fq, q, "model") == model),
            ) else {
                continue;
            };
            h.push(vec![
                format!("One condition ({}), {model}", condition_of(out)),
                cell(&fl, r, "test R²"),
                cell(&fq, q, "test R²"),
                cell(&fl, r, "test RMSE kN"),
                cell(&fq, q, "test RMSE kN"),
                "one model per target, trained on that condition alone".into(),
            ]);
        }
    }
    if let Some(t) = find(&tables("robustness")?, "robustness") {
        for r in &t.rows {
            let snr: f64 = cell(&t, r, "SNR dB").parse().unwrap_or(f64::NAN);
            if snr == 1.0
                && cell(&t, r, "protocol").starts_with("train and test")
                && cell(&t, r, "model") == "cnn-bilstm"
            {
                h.push(vec![
                    format!("One condition at 1 dB, {}", cell(&t, r, "model")),
                    cell(&t, r, "FL R²"),
                    cell(&t, r, "FQ R²"),
                    MISSING.into(),
                    MISSING.into(),
                    "trained and tested at 1 dB".into(),
                ]);
            }
        }
    }
    if let Some(t) = find(&tables("mismatch")?, "mismatch") {
        // The part reads its own window (the other parts' protocol above says 20).
        let window = read_json(&out.join("mismatch/meta.json")).map_or(String::new(), |m| {
            let label = m["label_at"].as_str().unwrap_or("?").to_lowercase();
            m["mismatch_window"].as_u64().map_or(String::new(), |w| {
                let seconds = w as f64 / crate::sensors::RATE_HZ;
                format!("; windows of {w} steps ({seconds} s), label at the {label} step")
            })
        });
        // The deployable models: fleet-trained with the weighed mass, on the fleet's test wagons.
        for r in &t.rows {
            if cell(&t, r, "tested on") == "fleet" && cell(&t, r, "inputs").contains("mass") {
                h.push(metric_row(
                    &t,
                    r,
                    format!(
                        "Wagons never trained on: {}, trained on the {}",
                        cell(&t, r, "inputs"),
                        cell(&t, r, "trained on")
                    ),
                    format!("the fleet's wagons drawn for the test seeds{window}"),
                ));
            }
        }
    }
    if let Some(t) = find(&tables("model_form")?, "model_form") {
        // The lumped track's network (the one every other part trains) on what it never saw:
        // the other track model, and short waves.
        for r in &t.rows {
            let (trained, tested) = (cell(&t, r, "trained on"), cell(&t, r, "tested on"));
            if trained == "lumped rail masses" && tested != trained {
                let protocol = if tested.contains("roughness") {
                    "the paper's 21, the test runs again with CNOSSOS rail roughness below 1 m (short waves no training run had)"
                } else {
                    "the paper's 21, the test runs simulated again on rails on sleepers"
                };
                h.push(metric_row(
                    &t,
                    r,
                    format!("Trained on the lumped track, tested on {tested}"),
                    protocol.into(),
                ));
            }
        }
    }
    Ok(h)
}

/// The condition of the run's one-condition parts.
fn condition_of(out: &Path) -> String {
    ["meta.json", "comparison/meta.json", "robustness/meta.json"]
        .iter()
        .find_map(|f| {
            read_json(&out.join(f))?["condition"]
                .as_str()
                .map(String::from)
        })
        .unwrap_or_else(|| "?".into())
}

/// A headline row: what it is, the row's FL and FQ R² and RMSE in kN, and its protocol.
fn metric_row(t: &Table, r: &[String], what: String, protocol: String) -> Vec<String> {
    let mut row = vec![what];
    row.extend(
        ["FL R²", "FQ R²", "FL RMSE kN", "FQ RMSE kN"]
            .iter()
            .map(|c| cell(t, r, c)),
    );
    row.push(protocol);
    row
}

/// The cell of row `r` under `column`, or [`MISSING`].
fn cell(t: &Table, r: &[String], column: &str) -> String {
    t.header
        .iter()
        .position(|c| c == column)
        .and_then(|i| r.get(i))
        .cloned()
        .unwrap_or_else(|| MISSING.into())
}

/// "lowest – highest" of a numeric column over `rows`.
fn range(t: &Table, rows: &[&Vec<String>], column: &str) -> String {
    let v: Vec<f64> = rows
        .iter()
        .filter_map(|r| cell(t, r, column).parse::<f64>().ok())
        .filter(|v| v.is_finite())
        .collect();
    if v.is_empty() {
        return MISSING.into();
    }
    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    format!("{lo:.3} – {hi:.3}")
}

/// The wall-time table's columns (`experiment snapshot --merge` keeps them).
pub(super) const WALL_HEADER: [&str; 6] = [
    "part",
    "commit",
    "wall time",
    "CPU time",
    "cores busy",
    "machine",
];

/// A part's wall time, CPU time and cores busy as table cells ("—" where the CPU time was
/// not recorded).
pub(super) fn wall_cells(wall: f64, cpu: Option<f64>) -> [String; 3] {
    match cpu {
        Some(c) if wall > 0.0 => [minutes(wall), minutes(c), format!("{:.2}", c / wall)],
        _ => [minutes(wall), "—".into(), "—".into()],
    }
}

/// "12.3 min, CPU 23.1 min (1.88 cores busy)" for the log.
pub(super) fn busy(wall: f64, cpu: Option<f64>) -> String {
    match wall_cells(wall, cpu) {
        [w, c, b] if c != "—" => format!("{w}, CPU {c} ({b} cores busy)"),
        [w, ..] => w,
    }
}

/// "12.3 min" (or seconds below a minute).
pub(super) fn minutes(s: f64) -> String {
    if s < 60.0 {
        format!("{s:.0} s")
    } else {
        format!("{:.1} min", s / 60.0)
    }
}

/// `YYYY-MM-DD HH:MM` of seconds since 1970-01-01 UTC (the civil calendar from the day
/// count, Howard Hinnant's `civil_from_days`).
pub fn utc_date_time(unix: u64) -> String {
    let days = (unix / 86_400) as i64;
    let secs = unix % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}",
        secs / 3_600,
        (secs % 3_600) / 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_calendar_reads_known_instants() {
        assert_eq!(utc_date_time(0), "1970-01-01 00:00");
        // A leap day of a century leap year, at 12:34.
        assert_eq!(
            utc_date_time(951_827_640),
            ["2000", "02", "29 12:34"].join("-")
        );
        assert_eq!(
            utc_date_time(1_796_493_600),
            ["2026", "12", "05 18:00"].join("-")
        );
    }

    #[test]
    fn the_readme_quote_is_replaced_between_its_markers() {
        let snap = format!("x\n{HEADLINE_BEGIN}\n| a |\n{HEADLINE_END}\ny");
        let readme = format!("head\n{HEADLINE_BEGIN}\n| old |\n{HEADLINE_END}\ntail");
        let new = requote(&readme, &snap, Path::new("README.md")).unwrap();
        assert_eq!(
            new,
            format!("head\n{HEADLINE_BEGIN}\n| a |\n{HEADLINE_END}\ntail")
        );
        let err = requote("no markers", &snap, Path::new("README.md")).unwrap_err();
        assert!(err.to_string().contains("README.md"), "{err}");
    }
}
