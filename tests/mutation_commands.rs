//! Mutated inputs run through the commands that read them: the vehicle and the track through
//! `simulate`, the criteria through `assess`, the model's `model.json` and a channel map
//! through `identify`, sensor rows streamed into `identify --input -`, the plan through
//! `generate`. Each command must end without a panic (exit status 101) or a signal; a
//! refused file is named in the error; an accepted one leaves no non-finite number in any
//! output. The mutations are the loaders' (`mutation.rs`), seeded: a failure reproduces.
//! `cargo test` runs a few cases of each; the ignored `..._long_pass` runs many, in release.

use crate::common;
use crate::mutation::{Gen, mutate};

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn scratch(tag: &str) -> PathBuf {
    common::scratch(&format!("mutcmd-{tag}"))
}

fn railforce(dir: &Path) -> Command {
    let mut c = common::railforce_in(dir);
    // A cache of the contact tables private to the test run: the mutated vehicles' tables
    // never reach the user's cache.
    c.env(
        "RAILFORCE_CACHE_DIR",
        std::env::temp_dir().join("railforce-mutcmd-cache"),
    );
    c
}

/// Every number of an output is finite: a JSON file parses (JSON has no NaN or infinity, so
/// one written as a bare token fails), and every unquoted cell of a CSV file that reads as a
/// number is finite.
fn assert_finite_output(path: &Path, what: &str) {
    let Ok(text) = std::fs::read_to_string(path) else {
        return;
    };
    if path.extension().is_some_and(|e| e == "json") {
        if let Err(e) = serde_json::from_str::<serde_json::Value>(&text) {
            panic!("{what}: {} is not JSON: {e}", path.display());
        }
        return;
    }
    for (row, line) in text.lines().enumerate() {
        for cell in line.split(',') {
            let c = cell.trim();
            if c.starts_with('"') {
                continue;
            }
            if c.eq_ignore_ascii_case("nan") || c.to_ascii_lowercase().ends_with("inf") {
                panic!("{what}: {} row {} holds `{c}`", path.display(), row + 1);
            }
            if let Ok(v) = c.parse::<f64>() {
                assert!(
                    v.is_finite(),
                    "{what}: {} row {}: {c}",
                    path.display(),
                    row + 1
                );
            }
        }
    }
}

/// The outcome of one command on one mutated file: no panic, no signal; an error names the
/// file; a success leaves finite outputs.
fn judge(what: &str, out: &Output, file: &str, outputs: &[PathBuf], input: &[u8]) {
    let err = String::from_utf8_lossy(&out.stderr);
    match out.status.code() {
        None => panic!(
            "{what}: killed by a signal on\n{}",
            String::from_utf8_lossy(input)
        ),
        Some(101) => panic!(
            "{what}: panicked:\n{err}\non\n{}",
            String::from_utf8_lossy(input)
        ),
        Some(0) => {
            for o in outputs {
                assert_finite_output(o, what);
            }
        }
        Some(_) => assert!(
            err.contains(file),
            "{what}: the error does not name {file}:\n{err}"
        ),
    }
}

/// Runs `run(case, bytes)` over `cases` mutations of `text`, seeded by `seed`.
fn each_mutation(text: &str, seed: u64, cases: usize, mut run: impl FnMut(usize, &[u8])) {
    let mut rng = Gen(seed);
    for case in 0..cases {
        let bytes = mutate(text, &mut rng);
        run(case, &bytes);
    }
}

fn simulate_pass(cases: usize) {
    let dir = scratch("sim");
    for f in ["c80.toml", "c80.urdf"] {
        std::fs::copy(root().join("vehicles").join(f), dir.join(f)).unwrap();
    }
    std::fs::copy(root().join("tracks/tangent.toml"), dir.join("tangent.toml")).unwrap();
    let good_vehicle = std::fs::read_to_string(dir.join("c80.toml")).unwrap();
    let good_track = std::fs::read_to_string(dir.join("tangent.toml")).unwrap();
    let sim = |dir: &Path, vehicle: &str, track: &str| {
        railforce(dir)
            .args(["simulate", "--vehicle", vehicle, "--track", track])
            .args(["--duration", "0.2", "--settle", "0.05", "--out", "out.csv"])
            .output()
            .unwrap()
    };
    let out_csv = dir.join("out.csv");
    each_mutation(&good_vehicle, 3, cases, |case, bytes| {
        let v = dir.join("mutant.toml");
        std::fs::write(&v, bytes).unwrap();
        let _ = std::fs::remove_file(&out_csv);
        let out = sim(&dir, "mutant.toml", "tangent.toml");
        judge(
            &format!("simulate, vehicle case {case}"),
            &out,
            "mutant.toml",
            std::slice::from_ref(&out_csv),
            bytes,
        );
    });
    each_mutation(&good_track, 4, cases, |case, bytes| {
        std::fs::write(dir.join("track.toml"), bytes).unwrap();
        let _ = std::fs::remove_file(&out_csv);
        let out = sim(&dir, "c80.toml", "track.toml");
        judge(
            &format!("simulate, track case {case}"),
            &out,
            "track.toml",
            std::slice::from_ref(&out_csv),
            bytes,
        );
    });
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_on_mutated_vehicles_and_tracks_never_panics_nor_writes_nan() {
    simulate_pass(6);
}

/// A run, a tiny data set and a tree model made once for the `assess` and `identify` passes.
struct Made {
    dir: PathBuf,
    run_csv: PathBuf,
    model: PathBuf,
}

fn made() -> &'static Made {
    static MADE: OnceLock<Made> = OnceLock::new();
    MADE.get_or_init(|| {
        let dir = scratch("made");
        let r = root();
        let run_csv = dir.join("run.csv");
        common::succeed(railforce(&dir).args([
            "simulate",
            "--vehicle",
            r.join("vehicles/c80.toml").to_str().unwrap(),
            "--track",
            r.join("tracks/curve_r800.toml").to_str().unwrap(),
            "--duration",
            "2",
            "--out",
            run_csv.to_str().unwrap(),
        ]));
        let (_, _, model) = common::tiny_data_and_tree_model(&dir);
        Made {
            dir,
            run_csv,
            model,
        }
    })
}

fn assess_pass(cases: usize) {
    let m = made();
    let dir = scratch("assess");
    let good = std::fs::read_to_string(root().join("vehicles/assessment.toml")).unwrap();
    let out_dir = dir.join("out");
    each_mutation(&good, 5, cases, |case, bytes| {
        std::fs::write(dir.join("criteria.toml"), bytes).unwrap();
        let _ = std::fs::remove_dir_all(&out_dir);
        let out = railforce(&dir)
            .args(["assess", m.run_csv.to_str().unwrap()])
            .args(["--criteria", "criteria.toml", "--out", "out"])
            .output()
            .unwrap();
        judge(
            &format!("assess, criteria case {case}"),
            &out,
            "criteria.toml",
            &[
                out_dir.join("assessment.csv"),
                out_dir.join("assessment.json"),
            ],
            bytes,
        );
    });
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn assess_on_mutated_criteria_never_panics_nor_writes_nan() {
    assess_pass(6);
}

fn identify_pass(cases: usize) {
    let m = made();
    let dir = scratch("identify");
    let model = dir.join("model");
    std::fs::create_dir_all(&model).unwrap();
    for e in std::fs::read_dir(&m.model).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, model.join(p.file_name().unwrap())).unwrap();
    }
    let out_csv = dir.join("identified.csv");
    let identify = |extra: &[&str]| {
        railforce(&dir)
            .args(["identify", "--model", "model", "--input"])
            .arg(&m.run_csv)
            .args(["--out", "identified.csv"])
            .args(extra)
            .output()
            .unwrap()
    };
    // model.json
    let good = std::fs::read_to_string(m.model.join("model.json")).unwrap();
    each_mutation(&good, 6, cases, |case, bytes| {
        std::fs::write(model.join("model.json"), bytes).unwrap();
        let _ = std::fs::remove_file(&out_csv);
        let out = identify(&[]);
        judge(
            &format!("identify, model.json case {case}"),
            &out,
            "model.json",
            std::slice::from_ref(&out_csv),
            bytes,
        );
    });
    std::fs::write(model.join("model.json"), &good).unwrap();
    // A channel map naming each of the model's channels by its own column.
    let meta: serde_json::Value = serde_json::from_str(&good).unwrap();
    let mut map = String::from("time = { column = \"time_s\", unit = \"s\" }\n[channels]\n");
    for c in meta["data"]["channels"].as_array().unwrap() {
        let c = c.as_str().unwrap();
        map += &format!("{c} = {{ column = \"{c}\", sign = 1 }}\n");
    }
    each_mutation(&map, 7, cases, |case, bytes| {
        std::fs::write(dir.join("map.toml"), bytes).unwrap();
        let _ = std::fs::remove_file(&out_csv);
        let out = identify(&["--channel-map", "map.toml"]);
        judge(
            &format!("identify, channel map case {case}"),
            &out,
            "map.toml",
            std::slice::from_ref(&out_csv),
            bytes,
        );
    });
    // Streamed rows: the run's CSV, mutated, on standard input.
    let rows = std::fs::read_to_string(&m.run_csv).unwrap();
    let rows: String = rows.lines().take(200).collect::<Vec<_>>().join("\n") + "\n";
    each_mutation(&rows, 8, cases, |case, bytes| {
        let _ = std::fs::remove_file(&out_csv);
        let mut child = railforce(&dir)
            .args(["identify", "--model", "model", "--input", "-"])
            .args(["--out", "identified.csv"])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        {
            use std::io::Write;
            let mut stdin = child.stdin.take().unwrap();
            let _ = stdin.write_all(bytes);
        }
        let out = child.wait_with_output().unwrap();
        judge(
            &format!("identify --input -, streamed rows case {case}"),
            &out,
            "stdin",
            std::slice::from_ref(&out_csv),
            bytes,
        );
    });
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn identify_on_mutated_models_maps_and_streams_never_panics_nor_writes_nan() {
    identify_pass(6);
}

fn generate_pass(cases: usize) {
    let dir = scratch("generate");
    let r = root();
    let plan = format!(
        "name = \"p\"\nvehicle = \"{}\"\nduration_s = 0.3\nseeds = [1]\n\
         [vary]\n\"vehicle.contact.friction\" = {{ uniform = [0.2, 0.4] }}\n\
         [[condition]]\nname = \"tangent\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        r.join("vehicles/c80.toml").display(),
        r.join("tracks/tangent.toml").display()
    );
    each_mutation(&plan, 9, cases, |case, bytes| {
        std::fs::write(dir.join("p.plan.toml"), bytes).unwrap();
        let data = dir.join("data");
        let _ = std::fs::remove_dir_all(&data);
        let out = railforce(&dir)
            .args(["generate", "--plan", "p.plan.toml", "--out", "data"])
            .args(["--settle", "0.05", "--format", "csv"])
            .output()
            .unwrap();
        let outputs: Vec<PathBuf> = std::fs::read_dir(&data)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
            .unwrap_or_default();
        judge(
            &format!("generate, plan case {case}"),
            &out,
            "p.plan.toml",
            &outputs,
            bytes,
        );
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// Values no judgement can use are refused, not judged: identify's non-positive limits and a
/// stream that ends before one window (it printed "within limit" on no data); assess on a
/// wheel with one of its two forces (it left the wheel out unnoticed).
#[test]
fn identify_and_assess_refuse_what_they_cannot_judge() {
    let m = made();
    let dir = scratch("refuse");
    let fail = |cmd: &mut std::process::Command, says: &str| {
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.contains(says), "{err}");
    };
    for (flag, says) in [
        ("--static-wheel-load-kn=-100", "static wheel load"),
        ("--limit-yq=-1", "Y/Q limit"),
        ("--limit-unloading=0", "ΔQ/Q̄ limit"),
    ] {
        fail(
            railforce(&dir)
                .args(["identify", "--model"])
                .arg(&m.model)
                .arg("--input")
                .arg(&m.run_csv)
                .args(["--out", "o.csv", flag]),
            says,
        );
        assert!(!dir.join("o.csv").exists(), "{flag}");
    }
    let rows = std::fs::read_to_string(&m.run_csv).unwrap();
    let short: String = rows.lines().take(4).collect::<Vec<_>>().join("\n") + "\n";
    let mut child = railforce(&dir)
        .args(["identify", "--model"])
        .arg(&m.model)
        .args(["--input", "-", "--out", "s.csv"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    {
        use std::io::Write;
        child
            .stdin
            .take()
            .unwrap()
            .write_all(short.as_bytes())
            .unwrap();
    }
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("stdin") && err.contains("after 3 row(s)"),
        "{err}"
    );
    assert!(!dir.join("s.csv").exists());
    // One wheel's vertical force dropped from the run: refused, naming the column.
    let mut lines = rows.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let drop = header.iter().position(|h| *h == "w1l_force_z").unwrap();
    let keep = |l: &str| {
        l.split(',')
            .enumerate()
            .filter(|(i, _)| *i != drop)
            .map(|(_, c)| c)
            .collect::<Vec<_>>()
            .join(",")
    };
    let cut: String = rows.lines().map(|l| keep(l) + "\n").collect();
    std::fs::write(dir.join("cut.csv"), cut).unwrap();
    fail(
        railforce(&dir).args(["assess", "cut.csv", "--out", "a"]),
        "w1l_force_y has no w1l_force_z",
    );
    // The run's own track, from its .meta.json; another one is warned of.
    let out = railforce(&dir)
        .arg("assess")
        .arg(&m.run_csv)
        .args(["--out", "own"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && err.contains("sections from") && err.contains("curve_r800.toml"),
        "{err}"
    );
    let tangent = root().join("tracks/tangent.toml");
    let out = railforce(&dir)
        .arg("assess")
        .arg(&m.run_csv)
        .arg("--track")
        .arg(&tangent)
        .args(["--out", "other"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("was simulated on track 'curve_r800'"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn generate_on_mutated_plans_never_panics_nor_writes_nan() {
    generate_pass(4);
}

/// The long pass: many more cases of every command (release CI).
#[test]
#[ignore = "long: many mutations through every command; run in release"]
fn mutated_inputs_through_the_commands_long_pass() {
    simulate_pass(60);
    assess_pass(60);
    identify_pass(60);
    generate_pass(30);
    let _ = &made().dir;
}
