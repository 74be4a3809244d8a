//! The documents as a reader meets them: every relative link and anchor resolves, no dated or
//! relative-time phrase outside CHANGELOG.md and the results snapshot, every `railforce …`
//! command they quote parses, the README quotes the snapshot's headline table, the channel
//! table is the recorder's, every repository file they quote exists, and the label position is one default in every front end.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every Markdown file of the project: not in hidden folders, not in the top-level folders
/// .gitignore names (outputs such as experiments/), never through a symbolic link.
fn markdown_files() -> Vec<PathBuf> {
    let ignored: Vec<String> = std::fs::read_to_string(root().join(".gitignore"))
        .unwrap_or_default()
        .lines()
        .filter_map(|l| {
            l.trim()
                .strip_prefix('/')
                .map(|l| l.trim_end_matches('/').to_string())
        })
        .collect();
    fn walk(dir: &Path, top: bool, ignored: &[String], out: &mut Vec<PathBuf>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            return;
        };
        for e in entries.flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().to_string();
            let Ok(kind) = e.file_type() else { continue };
            if name.starts_with('.') || kind.is_symlink() || (top && ignored.contains(&name)) {
                continue;
            }
            if kind.is_dir() {
                walk(&p, false, ignored, out);
            } else if name.ends_with(".md") {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    walk(&root(), true, &ignored, &mut out);
    out.sort();
    out
}

/// The spans a Markdown line quotes in backticks.
fn quoted_spans(line: &str) -> Vec<&str> {
    line.split('`').skip(1).step_by(2).collect()
}

/// A quoted span that names one file the repository carries: a path under a tracked top-level
/// folder, with an extension, and nothing a reader fills in (`<…>`, `*`, `{…}`, `NAME`, spaces).
fn repository_path(span: &str) -> Option<&str> {
    const TRACKED: [&str; 9] = [
        "examples/",
        "src/",
        "tests/",
        "vehicles/",
        "tracks/",
        "python/",
        "assets/",
        "benches/",
        ".ci/",
    ];
    let span = span.trim();
    let plain = !span.contains(|c: char| c.is_whitespace() || "<>*{}[]$:".contains(c))
        && !["NAME", "FILE", "DIR"].iter().any(|p| span.contains(p));
    let file = span.rsplit('/').next().is_some_and(|n| n.contains('.'));
    (plain && file && TRACKED.iter().any(|t| span.starts_with(t))).then_some(span)
}

#[test]
fn every_repository_file_the_documents_quote_exists() {
    let mut missing = Vec::new();
    for f in markdown_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in prose_lines(&text) {
            for span in quoted_spans(line) {
                if let Some(path) = repository_path(span)
                    && !root().join(path).exists()
                {
                    missing.push(format!("{}:{n}: `{path}`", rel(&f)));
                }
            }
        }
    }
    assert!(
        missing.is_empty(),
        "quoted files that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn the_quoted_path_check_catches_what_it_should() {
    assert_eq!(
        repository_path("examples/python/train_windows.py"),
        Some("examples/python/train_windows.py")
    );
    assert_eq!(repository_path("src/track/"), None);
    assert_eq!(repository_path("vehicles/<name>.toml"), None);
    assert_eq!(repository_path("vehicles/NAME.consist.toml"), None);
    assert_eq!(repository_path("railforce simulate"), None);
    assert!(quoted_spans("see `a/b.rs` and `c`").contains(&"a/b.rs"));
}

/// The path from the project's root, with `/` between its parts on every platform.
fn rel(p: &Path) -> String {
    p.strip_prefix(root())
        .unwrap_or(p)
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// The lines of a Markdown text outside fenced code blocks, with their numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, l) in text.lines().enumerate() {
        if l.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced {
            out.push((i + 1, l));
        }
    }
    out
}

/// A line without its inline code spans.
fn without_code(line: &str) -> String {
    let mut out = String::new();
    let mut inside = false;
    for c in line.chars() {
        if c == '`' {
            inside = !inside;
        } else if !inside {
            out.push(c);
        }
    }
    out
}

/// GitHub's anchor of a heading: markdown removed, lower case, letters, digits, `-` and `_`
/// kept, spaces to `-`, everything else dropped.
fn slug(heading: &str) -> String {
    // Links [text](url) keep their text.
    let mut text = String::new();
    let mut rest = heading;
    while let Some(a) = rest.find('[') {
        text += &rest[..a];
        let after = &rest[a + 1..];
        match (after.find("]("), after.find(')')) {
            (Some(b), Some(c)) if b < c => {
                text += &after[..b];
                rest = &after[c + 1..];
            }
            _ => {
                text.push('[');
                rest = after;
            }
        }
    }
    text += rest;
    text.chars()
        .filter_map(|c| {
            if c.is_alphanumeric() {
                Some(c.to_lowercase().next().unwrap_or(c))
            } else if c == ' ' || c == '-' {
                Some('-')
            } else if c == '_' {
                Some('_')
            } else {
                None
            }
        })
        .collect()
}

/// The anchors of a Markdown file: its headings' (duplicates numbered as GitHub does) and
/// explicit `<a id=…>` / `<a name=…>`.
fn anchors(text: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    for (_, l) in prose_lines(text) {
        let t = l.trim_start();
        if t.starts_with('#') {
            let h = t.trim_start_matches('#');
            if h.starts_with(' ') {
                let s = slug(h.trim());
                let n = seen.entry(s.clone()).or_insert(0);
                out.insert(if *n == 0 {
                    s.clone()
                } else {
                    format!("{s}-{n}")
                });
                *n += 1;
            }
        }
        for key in ["<a id=\"", "<a name=\""] {
            let mut r = l;
            while let Some(i) = r.find(key) {
                let after = &r[i + key.len()..];
                if let Some(j) = after.find('"') {
                    out.insert(after[..j].to_string());
                }
                r = after;
            }
        }
    }
    out
}

/// The link targets of a line (`[text](target)` and `![alt](target)`), code spans removed.
fn link_targets(line: &str) -> Vec<String> {
    let l = without_code(line);
    let mut out = Vec::new();
    let mut rest = l.as_str();
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        let Some(j) = after.find(')') else { break };
        let target = after[..j]
            .split_whitespace()
            .next()
            .unwrap_or("")
            .to_string();
        out.push(target);
        rest = &after[j..];
    }
    out
}

#[test]
fn every_relative_link_and_anchor_resolves() {
    let files = markdown_files();
    assert!(files.len() > 10, "found only {files:?}");
    let mut cache: BTreeMap<PathBuf, BTreeSet<String>> = BTreeMap::new();
    let mut broken = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let dir = f.parent().unwrap();
        for (n, line) in prose_lines(&text) {
            for t in link_targets(line) {
                if t.is_empty()
                    || t.contains("://")
                    || t.starts_with("mailto:")
                    || t.starts_with('<')
                {
                    continue;
                }
                let (path, anchor) = match t.split_once('#') {
                    Some((p, a)) => (p, Some(a)),
                    None => (t.as_str(), None),
                };
                let target = if path.is_empty() {
                    f.clone()
                } else {
                    dir.join(path)
                };
                if !target.exists() {
                    broken.push(format!("{}:{n}: {t}: no such file", rel(f)));
                    continue;
                }
                if let Some(a) = anchor
                    && target.extension().is_some_and(|e| e == "md")
                {
                    let key = target.canonicalize().unwrap();
                    let set = cache.entry(key).or_insert_with(|| {
                        anchors(&std::fs::read_to_string(&target).unwrap_or_default())
                    });
                    if !set.contains(a) {
                        broken.push(format!("{}:{n}: {t}: no such anchor", rel(f)));
                    }
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

/// What marks history in prose: an ISO date, an issue number, a relative time of day.
fn dated_phrase(line: &str) -> Option<String> {
    let l = line.to_lowercase();
    let b = l.as_bytes();
    let word_edge = |i: usize| i >= b.len() || !(b[i] as char).is_ascii_alphanumeric();
    let before_edge = |i: usize| i == 0 || !(b[i - 1] as char).is_ascii_alphanumeric();
    for i in 0..b.len().saturating_sub(9) {
        let d = |k: usize| b[i + k].is_ascii_digit();
        if b[i] == b'2'
            && b[i + 1] == b'0'
            && d(2)
            && d(3)
            && b[i + 4] == b'-'
            && d(5)
            && d(6)
            && b[i + 7] == b'-'
            && d(8)
            && d(9)
            && before_edge(i)
        {
            return Some(l[i..i + 10].to_string());
        }
    }
    let mut phrases: Vec<String> = vec![
        "tonight".into(),
        "yesterday".into(),
        "earlier today".into(),
        "later that".into(),
    ];
    for w in ["morning", "evening", "night", "afternoon", "session"] {
        phrases.push(format!("{w}'s"));
    }
    for a in [
        "that",
        "this",
        "the same",
        "one",
        "last",
        "next",
        "a later",
        "an earlier",
    ] {
        for w in ["morning", "evening", "night", "afternoon", "day", "session"] {
            phrases.push(format!("{a} {w}"));
        }
    }
    for p in &phrases {
        let mut from = 0;
        while let Some(k) = l[from..].find(p.as_str()) {
            let i = from + k;
            if before_edge(i) && word_edge(i + p.len()) {
                return Some(p.clone());
            }
            from = i + 1;
        }
    }
    let mut from = 0;
    while let Some(k) = l[from..].find("issue ") {
        let i = from + k;
        if before_edge(i) && b.get(i + 6).is_some_and(|c| c.is_ascii_digit()) {
            return Some(l[i..].chars().take(9).collect());
        }
        from = i + 1;
    }
    None
}

#[test]
fn no_dated_phrase_outside_the_changelog_and_the_results_snapshot() {
    let mut found = Vec::new();
    for f in markdown_files() {
        let r = rel(&f);
        if r == "CHANGELOG.md" || r == "assets/docs/results.md" {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            if let Some(p) = dated_phrase(line) {
                found.push(format!("{r}:{}: \"{p}\" in: {}", n + 1, line.trim()));
            }
        }
    }
    // Code comments say why, not when.
    fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                rust_files(&p, out);
            } else if p.extension().is_some_and(|e| e == "rs") {
                out.push(p);
            }
        }
    }
    let mut code = Vec::new();
    rust_files(&root().join("src"), &mut code);
    for f in code {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let Some(c) = line.find("//") else { continue };
            if let Some(p) = dated_phrase(&line[c..]) {
                found.push(format!(
                    "{}:{}: \"{p}\" in: {}",
                    rel(&f),
                    n + 1,
                    line.trim()
                ));
            }
        }
    }
    assert!(
        found.is_empty(),
        "history belongs in CHANGELOG.md:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_dated_phrase_check_catches_what_it_should() {
    assert!(dated_phrase("measured on 2026-12-04 idle").is_some());
    assert!(dated_phrase("That night the default moved").is_some());
    assert!(dated_phrase("the evening's run").is_some());
    assert!(dated_phrase("(issue 37)").is_some());
    assert!(dated_phrase("the default step is 5/6 ms").is_none());
    assert!(dated_phrase("the nightly build; a dayless oneday").is_none());
    assert!(dated_phrase("an issue of the tracker").is_none());
}

/// The `railforce …` commands a Markdown text quotes: lines of code blocks, continued
/// lines joined, and inline code spans.
fn quoted_commands(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    let mut pending: Option<(usize, String)> = None;
    for (i, l) in text.lines().enumerate() {
        let t = l.trim();
        if t.starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            let t = t.trim_start_matches("$ ");
            if let Some((n, mut acc)) = pending.take() {
                acc.push(' ');
                acc += t.trim_end_matches('\\');
                if t.ends_with('\\') {
                    pending = Some((n, acc));
                } else {
                    out.push((n, acc));
                }
                continue;
            }
            let t = t
                .strip_prefix("cargo run --release -- ")
                .map(|r| format!("railforce {r}"))
                .unwrap_or_else(|| t.to_string());
            if t.starts_with("railforce ") || t.starts_with("\"$R\" ") {
                let t = t.replacen("\"$R\" ", "railforce ", 1);
                if t.ends_with('\\') {
                    pending = Some((i + 1, t.trim_end_matches('\\').to_string()));
                } else {
                    out.push((i + 1, t));
                }
            }
        } else {
            let mut inside = false;
            for (k, part) in l.split('`').enumerate() {
                if k > 0 {
                    inside = !inside;
                }
                if inside && part.starts_with("railforce ") {
                    out.push((i + 1, part.to_string()));
                }
            }
        }
    }
    out
}

/// The long flags a subcommand's `--help` lists, and its own subcommands.
type Help = Option<(BTreeSet<String>, BTreeSet<String>)>;

/// [`Help`] of `railforce PATH… --help`; `None` when it is no subcommand.
fn help_of(path: &[String]) -> Help {
    let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args(path)
        .arg("--help")
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let mut flags = BTreeSet::new();
    for w in text.split(|c: char| c.is_whitespace() || c == ',' || c == '[' || c == ']') {
        if let Some(f) = w.strip_prefix("--") {
            let f: String = f
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                .collect();
            if !f.is_empty() {
                flags.insert(f);
            }
        }
    }
    let mut subs = BTreeSet::new();
    if let Some(i) = text.find("Commands:") {
        for l in text[i..].lines().skip(1) {
            if l.trim().is_empty() {
                break;
            }
            if let Some(w) = l.split_whitespace().next() {
                subs.insert(w.to_string());
            }
        }
    }
    Some((flags, subs))
}

#[test]
fn every_quoted_railforce_command_parses() {
    let mut cache: BTreeMap<Vec<String>, Help> = BTreeMap::new();
    let mut bad = Vec::new();
    let mut checked = 0;
    for f in markdown_files() {
        let r = rel(&f);
        // The changelog keeps the commands of their day.
        if r == "CHANGELOG.md" {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, cmd) in quoted_commands(&text) {
            // The command ends where the shell takes over.
            let cmd = cmd
                .split(" #")
                .next()
                .unwrap_or("")
                .split(['|', ';', '>'])
                .next()
                .unwrap_or("")
                .split("&&")
                .next()
                .unwrap_or("")
                .to_string();
            let words: Vec<&str> = cmd.split_whitespace().collect();
            let Some(sub) = words.get(1) else { continue };
            if !sub.chars().all(|c| c.is_ascii_lowercase() || c == '-') {
                continue;
            }
            let mut path = vec![sub.to_string()];
            let help = cache
                .entry(path.clone())
                .or_insert_with(|| help_of(&[sub.to_string()]))
                .clone();
            let Some((mut flags, subs)) = help else {
                bad.push(format!("{r}:{n}: `{cmd}`: no subcommand {sub}"));
                continue;
            };
            if !subs.is_empty()
                && let Some(s2) = words.get(2)
                && subs.contains(*s2)
            {
                path.push(s2.to_string());
                match cache
                    .entry(path.clone())
                    .or_insert_with(|| help_of(&path))
                    .clone()
                {
                    Some((f2, _)) => flags = f2,
                    None => {
                        bad.push(format!("{r}:{n}: `{cmd}`: no subcommand {s2}"));
                        continue;
                    }
                }
            }
            for w in &words[path.len() + 1..] {
                let w = w.trim_start_matches(['[', '(', '"', '\'']);
                let Some(flag) = w.strip_prefix("--") else {
                    continue;
                };
                let flag: String = flag
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '-')
                    .collect();
                if flag.is_empty() {
                    continue;
                }
                if !flags.contains(&flag) {
                    bad.push(format!(
                        "{r}:{n}: `{cmd}`: railforce {} has no --{flag}",
                        path.join(" ")
                    ));
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 50, "only {checked} commands found");
    assert!(
        bad.is_empty(),
        "commands that do not parse:\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_readme_is_a_front_door_and_quotes_the_results_snapshot() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let lines = readme.lines().count();
    assert!(lines <= 200, "README.md has {lines} lines (at most 200)");
    let snapshot = std::fs::read_to_string(root().join("assets/docs/results.md")).unwrap();
    let quoted = railforce::experiment::quoted_headline(&readme)
        .expect("README.md quotes the headline table between its markers");
    let written = railforce::experiment::quoted_headline(&snapshot)
        .expect("results.md carries the headline table between its markers");
    assert_eq!(
        quoted, written,
        "README.md's headline table differs from results.md's: `railforce experiment snapshot --out experiments --results assets/docs/results.md --readme README.md` copies it"
    );
    assert!(
        written.lines().count() > 5,
        "the headline table has rows:\n{written}"
    );
}

#[test]
fn the_channel_table_is_the_recorders() {
    let v = railforce::vehicle::Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let list = railforce::sim::channels::channels(&v);
    let table = railforce::sim::channels::markdown(
        &list,
        &railforce::sensors::label_channels(&v.label_wheel_name()),
    );
    let doc = std::fs::read_to_string(root().join("assets/docs/channels.md")).unwrap();
    assert!(
        doc.contains(&table),
        "assets/docs/channels.md is not `railforce channels --markdown`: regenerate its table"
    );
    // The recorder records this list (`Recorder::new` builds its columns from it).
    assert_eq!(list.len(), 244, "time_s and 243 channels");
    // A run in a train adds the couplers' channels, listed in their own table.
    let train = railforce::sim::channels::channels_of(&v, true);
    let full = railforce::sim::channels::markdown(
        &train,
        &railforce::sensors::label_channels(&v.label_wheel_name()),
    );
    for row in full.lines().skip(2 + list.len()) {
        assert!(
            doc.contains(row),
            "assets/docs/channels.md lacks the in-train row of `railforce channels --markdown --in-train`: {row}"
        );
    }
}

#[test]
fn the_label_position_is_one_default_in_every_front_end() {
    use railforce::features::LabelAt;
    assert_eq!(LabelAt::default(), LabelAt::Centre);
    let default = LabelAt::default().name();
    for (file, def) in [
        ("python/railforce/__init__.py", "def windows("),
        ("python/railforce/torch.py", "def __init__("),
    ] {
        let text = std::fs::read_to_string(root().join(file)).unwrap();
        let at = text.find(def).unwrap_or_else(|| panic!("{file}: no {def}"));
        let sig = &text[at..at + text[at..].find("):").unwrap_or(600)];
        assert!(
            sig.contains(&format!("label: str = \"{default}\"")),
            "{file}: {def}…) does not default its label to \"{default}\":\n{sig}"
        );
    }
    for sub in ["select", "experiment"] {
        let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
            .args([sub, "--help"])
            .output()
            .unwrap();
        let help = String::from_utf8_lossy(&out.stdout);
        let at = help.find("--label").expect("a --label flag");
        assert!(
            help[at..].contains(&format!("[default: {default}]")),
            "railforce {sub} --label does not default to {default}"
        );
    }
    assert_eq!(LabelAt::parse("last").unwrap(), LabelAt::Last);
    let err = LabelAt::parse("middle").unwrap_err().to_string();
    assert!(err.contains("centre") && err.contains("last"), "{err}");
}

#[test]
fn the_minimal_vehicle_file_loads_and_its_page_explains_every_key() {
    let path = root().join("vehicles/minimal.toml");
    let v = railforce::vehicle::Vehicle::load(&path).unwrap();
    assert_eq!(v.bodies.len(), 11);
    let count = |k: &str| v.elements.iter().filter(|e| e.kind() == k).count();
    assert_eq!(
        [
            count("shear_pad"),
            count("spring_nest"),
            count("wedge_damper"),
            count("centre_plate")
        ],
        [8, 4, 4, 2]
    );
    let file = std::fs::read_to_string(&path).unwrap();
    let page = std::fs::read_to_string(root().join("assets/docs/vehicle-file.md")).unwrap();
    let mut missing = BTreeSet::new();
    for line in file.lines() {
        let t = line.trim();
        if t.starts_with('#') || t.is_empty() {
            continue;
        }
        let key = if t.starts_with('[') {
            t.trim_matches(|c| c == '[' || c == ']').to_string()
        } else if let Some((k, _)) = t.split_once('=') {
            k.trim().to_string()
        } else {
            continue;
        };
        if !page.contains(&format!("`{key}")) && !page.contains(&format!("[{key}]")) {
            missing.insert(key);
        }
    }
    assert!(
        missing.is_empty(),
        "vehicle-file.md does not explain {missing:?}"
    );
}
