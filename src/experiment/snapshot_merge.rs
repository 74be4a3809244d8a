//! A results snapshot updated part by part: when a change of the code touches one part's data
//! (the track on sleepers, say) that part alone is run again into a fresh folder, and its
//! snapshot replaces that part's sections, headline rows and wall time in the snapshot of
//! the earlier run, while every other part stays as it was measured, under its own commit.
//! The Run line then names each part's commit.

use super::Which;
use super::snapshot::{HEADLINE_BEGIN, HEADLINE_END, minutes, wall_cells};

/// The part each headline row comes from, by the start of its first cell (the rows
/// [`super::snapshot`] writes).
const ROW_PARTS: [(&str, &str); 8] = [
    ("All conditions", "generalization"),
    ("the same network per condition", "generalization"),
    ("Selected on-board sensors", "sensors"),
    ("The CNN-BiLSTM split by", "protocols"),
    ("One condition (", "comparison"),
    ("One condition at", "robustness"),
    ("Wagons never trained on", "mismatch"),
    ("Trained on the", "model_form"),
];

/// A snapshot cut at its `## ` headings.
struct Doc {
    /// Lines before the first heading.
    preamble: Vec<String>,
    /// Each heading's title and the lines under it.
    sections: Vec<(String, Vec<String>)>,
}

impl Doc {
    fn parse(text: &str) -> Doc {
        let mut doc = Doc {
            preamble: Vec::new(),
            sections: Vec::new(),
        };
        for line in text.lines() {
            if let Some(title) = line.strip_prefix("## ") {
                doc.sections.push((title.to_string(), Vec::new()));
            } else if let Some((_, body)) = doc.sections.last_mut() {
                body.push(line.to_string());
            } else {
                doc.preamble.push(line.to_string());
            }
        }
        doc
    }

    fn section(&self, title: &str) -> Option<&Vec<String>> {
        self.sections.iter().find(|s| s.0 == title).map(|s| &s.1)
    }

    /// The rows of the first table under `title` (header and rule left out).
    fn rows(&self, title: &str) -> Vec<String> {
        (self.section(title).into_iter().flatten())
            .filter(|l| l.starts_with("| "))
            .skip(1)
            .cloned()
            .collect()
    }

    /// The Run line's commit of each part (`` `c` (a, b), `d` (e) ``, or one `` `c` `` for
    /// every part of the wall-time table).
    fn commits(&self) -> Vec<(String, String)> {
        let line = self.preamble.iter().find(|l| l.starts_with("- **Run:**"));
        let Some(text) = line.and_then(|l| l.split(", commit ").nth(1)) else {
            return Vec::new();
        };
        let text = text.split(", its parts").next().unwrap_or(text);
        let mut out = Vec::new();
        let mut rest = text;
        while let Some(a) = rest.find('`') {
            let Some(b) = rest[a + 1..].find('`') else {
                break;
            };
            let commit = &rest[a + 1..a + 1 + b];
            rest = &rest[a + b + 2..];
            match rest.strip_prefix(" (") {
                Some(r) => {
                    let end = r.find(')').unwrap_or(r.len());
                    for part in r[..end].split(", ") {
                        out.push((part.to_string(), commit.to_string()));
                    }
                    rest = &r[end..];
                }
                None => {
                    for part in self.wall_parts() {
                        out.push((part, commit.to_string()));
                    }
                    break;
                }
            }
        }
        out
    }

    /// The parts in the wall-time table, in its order.
    fn wall_parts(&self) -> Vec<String> {
        (self.rows(WALL).iter())
            .filter_map(|r| first_cell(r))
            .filter(|p| Which::FOLDERS.contains(&p.as_str()))
            .collect()
    }
}

const HEADLINE: &str = "Headline";
const WALL: &str = "Wall time of each part";

/// The first cell of a Markdown table row.
fn first_cell(row: &str) -> Option<String> {
    row.trim_start_matches('|')
        .split('|')
        .next()
        .map(|c| c.trim().to_string())
}

/// The cells of a Markdown table row.
fn cells(row: &str) -> Vec<String> {
    let inner = row.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(|c| c.trim().to_string()).collect()
}

/// Seconds of "12.3 min" or "45 s".
fn seconds(text: &str) -> Option<f64> {
    if let Some(m) = text.strip_suffix(" min") {
        m.parse::<f64>().ok().map(|m| m * 60.0)
    } else {
        text.strip_suffix(" s")?.parse().ok()
    }
}

/// A section's key: its title to the first colon and the word after it (the parts' titles
/// keep these while their figures in brackets change).
fn key(title: &str) -> String {
    match title.split_once(": ") {
        Some((a, b)) => format!("{a}: {}", b.split(' ').next().unwrap_or("")),
        None => title.to_string(),
    }
}

/// The snapshot `old` with the parts `new` holds replaced by `new`'s: their sections (by
/// title), headline rows and wall times; the Run line names each part's commit and the
/// latest finish. Everything else of `old` stays as written.
pub fn merge(old: &str, new: &str) -> String {
    let (o, n) = (Doc::parse(old), Doc::parse(new));
    let parts = n.wall_parts();
    let mut commits = o.commits();
    let new_commits = n.commits();
    commits.retain(|(p, _)| !parts.contains(p));
    commits.extend(
        new_commits
            .iter()
            .filter(|(p, _)| parts.contains(p))
            .cloned(),
    );
    // The wall-time rows, each part's from the snapshot that ran it.
    let mut wall: Vec<(String, String)> = Vec::new();
    for f in Which::FOLDERS {
        let from = if parts.iter().any(|p| p == f) { &n } else { &o };
        if let Some(r) = (from.rows(WALL).into_iter()).find(|r| first_cell(r).as_deref() == Some(f))
        {
            wall.push((f.to_string(), r));
        }
    }
    let total: f64 = (wall.iter())
        .filter_map(|(_, r)| cells(r).get(2).and_then(|c| seconds(c)))
        .sum();
    // CPU time added while every part's row has one (rows from before the column have none).
    let total_cpu: Option<f64> = (wall.iter())
        .map(|(_, r)| cells(r).get(3).and_then(|c| seconds(c)))
        .sum();
    let mut out = String::new();
    for line in &o.preamble {
        if line.starts_with("- **Run:**") {
            out += &run_line(&o, &n, &commits, total);
        } else {
            out += line;
        }
        out.push('\n');
    }
    // Each replaced part's new rows where its old rows stood (the others in their order);
    // a part the old snapshot had no row of, at the end.
    let headline_rows = {
        let part_of = |r: &String| {
            let what = first_cell(r).unwrap_or_default();
            (ROW_PARTS.iter())
                .find(|(pre, part)| what.starts_with(pre) && parts.iter().any(|p| p == part))
                .map(|(_, part)| *part)
        };
        let new_rows = n.rows(HEADLINE);
        let mut rows = Vec::new();
        let mut placed: Vec<&str> = Vec::new();
        for r in o.rows(HEADLINE) {
            match part_of(&r) {
                None => rows.push(r),
                Some(p) if !placed.contains(&p) => {
                    placed.push(p);
                    rows.extend(new_rows.iter().filter(|x| part_of(x) == Some(p)).cloned());
                }
                Some(_) => {}
            }
        }
        rows.extend(
            (new_rows.iter())
                .filter(|x| part_of(x).is_none_or(|p| !placed.contains(&p)))
                .cloned(),
        );
        rows
    };
    for (title, body) in &o.sections {
        match title.as_str() {
            HEADLINE => {
                out += &format!("## {title}\n");
                let table: Vec<&String> = body.iter().filter(|l| l.starts_with("| ")).collect();
                out += &format!("\n{HEADLINE_BEGIN}\n");
                for l in table.iter().take(1) {
                    out += &format!("{l}\n{}\n", rule(l));
                }
                for r in &headline_rows {
                    out += &format!("{r}\n");
                }
                out += &format!("{HEADLINE_END}\n\n");
            }
            WALL => {
                // The wider table's words and columns (the newer's where both are as wide),
                // each part's row from its own run.
                let width_of = |b: &Vec<String>| {
                    (b.iter().find(|l| l.starts_with("| "))).map_or(0, |h| cells(h).len())
                };
                let body = match n.section(WALL) {
                    Some(nb) if width_of(nb) >= width_of(body) => nb,
                    _ => body,
                };
                out += &format!("## {title}\n");
                for l in body.iter().take_while(|l| !l.starts_with("| ")) {
                    out += &format!("{l}\n");
                }
                let head = body.iter().find(|l| l.starts_with("| "));
                let width = head.map_or(3, |h| cells(h).len());
                if let Some(h) = head {
                    out += &format!("{h}\n{}\n", rule(h));
                }
                let pad = |mut c: Vec<String>| {
                    c.resize(width.max(c.len()), "—".into());
                    c.truncate(width);
                    format!("| {} |\n", c.join(" | "))
                };
                for (_, r) in &wall {
                    out += &pad(cells(r));
                }
                let mut last = vec!["the parts above, added".to_string(), String::new()];
                last.extend(wall_cells(total, total_cpu));
                last.push(String::new());
                out += &pad(last);
                out.push('\n');
            }
            _ => {
                let replaced = (n.sections.iter()).find(|(t, _)| key(t) == key(title));
                let (t, b) = replaced.map_or((title, body), |(t, b)| (t, b));
                out += &format!("## {t}\n");
                for l in b {
                    out += l;
                    out.push('\n');
                }
            }
        }
    }
    // A part the earlier snapshot lacked: at the end.
    for (t, b) in &n.sections {
        let known = o.sections.iter().any(|(s, _)| key(s) == key(t));
        if !known && t != HEADLINE && t != WALL {
            out += &format!("## {t}\n");
            for l in b {
                out += l;
                out.push('\n');
            }
        }
    }
    out
}

/// The rule line under a table's header.
fn rule(header: &str) -> String {
    let n = cells(header).len();
    format!("|{}", "---|".repeat(n))
}

/// The Run line of a merged snapshot: the later finish, the newer version, each part's commit.
fn run_line(o: &Doc, n: &Doc, commits: &[(String, String)], total: f64) -> String {
    let finished = |d: &Doc| {
        let l = d.preamble.iter().find(|l| l.starts_with("- **Run:**"))?;
        let date = l.split("finished ").nth(1)?.split(" (UTC)").next()?;
        let date = date.trim_start_matches("by ").to_string();
        let version = l.split("railforce ").nth(1)?.split(',').next()?.to_string();
        Some((date, version))
    };
    let (date, version) = match (finished(o), finished(n)) {
        (Some(a), Some(b)) => a.max(b),
        (a, b) => a.or(b).unwrap_or_else(|| ("?".into(), "?".into())),
    };
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for f in Which::FOLDERS {
        if let Some((_, c)) = commits.iter().find(|(p, _)| p == f) {
            match groups.iter_mut().find(|(k, _)| k == c) {
                Some((_, ps)) => ps.push(f.to_string()),
                None => groups.push((c.clone(), vec![f.to_string()])),
            }
        }
    }
    let commit = (groups.iter())
        .map(|(c, ps)| format!("`{c}` ({})", ps.join(", ")))
        .collect::<Vec<_>>()
        .join(", ");
    format!(
        "- **Run:** finished {date} (UTC), railforce {version}, commit {commit}, its parts run at different times and merged part by part (experiment snapshot --merge), {} of wall time added.",
        minutes(total)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The test's instants, written apart so that no date stands in the source.
    const OLD: [&str; 3] = ["2026", "12", "01 10:00"];
    const NEW: [&str; 3] = ["2026", "12", "06 20:00"];

    fn date(d: [&str; 3]) -> String {
        d.join("-")
    }

    fn snapshot(run: &str, headline: &[&str], wall: &[&str], sections: &[(&str, &str)]) -> String {
        let run = run
            .replace("{OLD}", &date(OLD))
            .replace("{NEW}", &date(NEW));
        let mut s = format!(
            "# Results\n\nWritten by.\n\n{run}\n- protocol line\n\n## Headline\n\n{HEADLINE_BEGIN}\n| what | FL R² |\n|---|---|\n"
        );
        for r in headline {
            s += &format!("{r}\n");
        }
        s += &format!(
            "{HEADLINE_END}\n\n## Wall time of each part\n\n| part | commit | wall time |\n|---|---|---|\n"
        );
        for r in wall {
            s += &format!("{r}\n");
        }
        s += "| the parts above, added |  | 1.0 min |\n";
        for (t, b) in sections {
            s += &format!("\n## {t}\n\n{b}\n");
        }
        s
    }

    /// One part run again replaces its rows, section and wall time and its commit; the other
    /// parts stay as they were, with theirs.
    #[test]
    fn a_part_run_again_replaces_its_own_and_nothing_else() {
        let old = snapshot(
            "- **Run:** finished {OLD} (UTC), railforce 0.1.0, commit `aaaa` (comparison, generalization), `bbbb` (model_form), its parts run into one folder at different times, 30.0 min of wall time added.",
            &[
                "| All conditions, x | 0.9 |",
                "| Trained on the lumped track, tested on y | 0.8 |",
                "| One condition (c), cnn | 0.7 |",
            ],
            &[
                "| comparison | aaaa | 2.0 min |",
                "| generalization | aaaa | 20.0 min |",
                "| model_form | bbbb | 8.0 min |",
            ],
            &[
                ("1. Model comparison: c at 6 dB", "cmp body"),
                ("2. Generalisation over conditions (paper)", "gen body"),
                (
                    "7. The simulator's form: lumped track (old)",
                    "old form body",
                ),
            ],
        );
        let new = snapshot(
            "- **Run:** not finished: the parts below are those that had finished by {NEW} (UTC), railforce 0.1.0, commit `cccc`; **not in this snapshot: comparison**.",
            &["| Trained on the lumped track, tested on z | 0.75 |"],
            &["| model_form | cccc | 9.0 min |"],
            &[(
                "7. The simulator's form: lumped track (new)",
                "new form body",
            )],
        );
        let m = merge(&old, &new);
        assert!(m.contains(&format!("finished {} (UTC)", date(NEW))), "{m}");
        assert!(
            m.contains("commit `aaaa` (comparison, generalization), `cccc` (model_form)"),
            "{m}"
        );
        assert!(
            m.contains("31.0 min of wall time added")
                && m.contains("| the parts above, added |  | 31.0 min |"),
            "{m}"
        );
        assert!(
            m.contains("| Trained on the lumped track, tested on z | 0.75 |")
                && !m.contains("tested on y"),
            "{m}"
        );
        // The replaced row keeps its place among the others.
        let (a, b, c) = (
            m.find("All conditions").unwrap(),
            m.find("tested on z").unwrap(),
            m.find("One condition (c)").unwrap(),
        );
        assert!(a < b && b < c, "{m}");
        assert!(
            m.contains("| model_form | cccc | 9.0 min |")
                && m.contains("| generalization | aaaa | 20.0 min |"),
            "{m}"
        );
        assert!(
            m.contains("## 7. The simulator's form: lumped track (new)\n\nnew form body")
                && !m.contains("old form body"),
            "{m}"
        );
        assert!(
            m.contains("cmp body") && m.contains("gen body") && m.contains("- protocol line"),
            "{m}"
        );
        // Merging the same again changes nothing.
        assert_eq!(merge(&m, &new), m);
    }

    /// A part run with the CPU column merged into a snapshot from before it: the newer
    /// columns, the older rows padded with "—", and the total's CPU time unknown until every
    /// part has one.
    #[test]
    fn the_cpu_column_pads_rows_from_before_it() {
        let wall = |rows: &[&str]| {
            snapshot(
                "- **Run:** finished {OLD} (UTC), railforce 0.1.0, commit `aaaa` (comparison, model_form), its parts run into one folder at different times, 10.0 min of wall time added.",
                &[],
                rows,
                &[],
            )
        };
        let old = wall(&[
            "| comparison | aaaa | 2.0 min |",
            "| model_form | aaaa | 8.0 min |",
        ]);
        let new = wall(&["| model_form | cccc | 6.0 min | 11.4 min | 1.90 |"]).replace(
            "| part | commit | wall time |\n|---|---|---|",
            "CPU time: words.\n\n| part | commit | wall time | CPU time | cores busy |\n|---|---|---|---|---|",
        );
        let m = merge(&old, &new);
        assert!(m.contains("CPU time: words."), "{m}");
        assert!(
            m.contains("| comparison | aaaa | 2.0 min | — | — |")
                && m.contains("| model_form | cccc | 6.0 min | 11.4 min | 1.90 |")
                && m.contains("| the parts above, added |  | 8.0 min | — | — |"),
            "{m}"
        );
        // A snapshot from before the column merged into one with it keeps the column.
        let back = merge(&m, &old);
        assert!(
            back.contains("CPU time: words.")
                && back.contains("| part | commit | wall time | CPU time | cores busy |")
                && back.contains("| model_form | aaaa | 8.0 min | — | — |"),
            "{back}"
        );
        let both = wall(&[
            "| comparison | cccc | 2.0 min | 3.0 min | 1.50 |",
            "| model_form | cccc | 6.0 min | 11.4 min | 1.90 |",
        ])
        .replace(
            "| part | commit | wall time |\n|---|---|---|",
            "| part | commit | wall time | CPU time | cores busy |\n|---|---|---|---|---|",
        );
        let m = merge(&m, &both);
        assert!(
            m.contains("| the parts above, added |  | 8.0 min | 14.4 min | 1.80 |"),
            "{m}"
        );
    }

    /// Two parts run again with another part's rows between theirs: each part's new rows
    /// stand where its old ones stood, and the rows between stay between.
    #[test]
    fn merged_rows_keep_the_order_of_the_parts() {
        let old = snapshot(
            "- **Run:** finished {OLD} (UTC), railforce 0.1.0, commit `aaaa`, 3.0 min wall time in all.",
            &[
                "| All conditions, x | 0.9 |",
                "| Selected on-board sensors, s | 0.8 |",
                "| The CNN-BiLSTM split by blocks | 0.7 |",
                "| One condition (c), cnn | 0.6 |",
            ],
            &[
                "| generalization | aaaa | 1.0 min |",
                "| sensors | aaaa | 1.0 min |",
                "| protocols | aaaa | 1.0 min |",
            ],
            &[],
        );
        let new = snapshot(
            "- **Run:** finished {NEW} (UTC), railforce 0.1.0, commit `cccc`, 2.0 min wall time in all.",
            &[
                "| All conditions, y | 0.91 |",
                "| The CNN-BiLSTM split by blocks | 0.71 |",
            ],
            &[
                "| generalization | cccc | 1.0 min |",
                "| protocols | cccc | 1.0 min |",
            ],
            &[],
        );
        let m = merge(&old, &new);
        let at = |t: &str| m.find(t).unwrap_or_else(|| panic!("{t} missing: {m}"));
        assert!(
            at("All conditions, y") < at("Selected on-board sensors, s")
                && at("Selected on-board sensors, s") < at("split by blocks | 0.71")
                && at("split by blocks | 0.71") < at("One condition (c)"),
            "{m}"
        );
        assert!(
            !m.contains("All conditions, x") && !m.contains("| 0.7 |"),
            "{m}"
        );
    }
}
