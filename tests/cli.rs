//! The command line as a user runs it.

use crate::common;

use std::process::Command;

pub(crate) fn railforce(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

pub(crate) fn tmp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("railforce-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A small noised data set (6 dB, seeds 1–3, one condition) generated through the CLI.
pub(crate) fn tiny_data(
    name: &str,
    track: &str,
    duration: f64,
    format: &str,
) -> std::path::PathBuf {
    let plan = tmp(&format!("{name}.plan.toml"));
    let root = env!("CARGO_MANIFEST_DIR");
    std::fs::write(
        &plan,
        format!(
            "name = \"{name}\"\nvehicle = \"{root}/vehicles/c80.toml\"\nduration_s = {duration}\nseeds = [1, 2, 3]\n\
             [[condition]]\nname = \"{track}\"\ntrack = \"{root}/tracks/{track}.toml\"\nspeed_kmh = 60.0\n"
        ),
    )
    .unwrap();
    let data = tmp(&format!("{name}_data"));
    let (ok, _, err) = railforce(&[
        "generate",
        "--plan",
        plan.to_str().unwrap(),
        "--out",
        data.to_str().unwrap(),
        "--format",
        format,
        "--snr-db",
        "6",
        "--settle",
        "0.1",
    ]);
    assert!(ok, "{err}");
    data
}

#[test]
fn help_explains_each_subcommand() {
    let (ok, out, _) = railforce(&["--help"]);
    assert!(ok);
    assert!(out.contains("track"), "{out}");
    let (ok, out, _) = railforce(&["track", "--help"]);
    assert!(
        ok && out.contains("--psd") && out.contains("--step"),
        "{out}"
    );
}

#[test]
fn track_summary_export_and_psd() {
    let csv = tmp("r400.csv");
    let psd = tmp("r400_psd.csv");
    let (ok, out, err) = railforce(&[
        "track",
        "tracks/curve_r400.toml",
        "--out",
        csv.to_str().unwrap(),
        "--step",
        "1",
        "--psd",
        "--psd-out",
        psd.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("balance speed 71.3 km/h"), "{out}");
    assert!(out.contains("formula RMS"), "{out}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header[0], "s_m");
    assert!(header.contains(&"left_z_m") && header.contains(&"cant_angle_rad"));
    assert_eq!(lines.count(), 2201, "0..=2200 m every 1 m");
    let psd_text = std::fs::read_to_string(&psd).unwrap();
    assert!(psd_text.starts_with("omega_rad_per_m,wavelength_m,vertical_welch"));
    // Same seed, same bytes.
    let csv2 = tmp("r400b.csv");
    let (ok, _, _) = railforce(&[
        "track",
        "tracks/curve_r400.toml",
        "--out",
        csv2.to_str().unwrap(),
        "--step",
        "1",
    ]);
    assert!(ok);
    assert_eq!(std::fs::read(&csv).unwrap(), std::fs::read(&csv2).unwrap());
}

#[test]
fn bad_track_file_fails_with_file_and_field() {
    let bad = tmp("bad.toml");
    std::fs::write(
        &bad,
        "[[section]]\nkind = \"curve\"\nlength_m = 100\nradius_m = 400\ncant_mm = 300\ndirection = \"right\"\n",
    )
    .unwrap();
    let (ok, _, err) = railforce(&["track", bad.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        err.contains("bad.toml") && err.contains("section[0].cant_mm"),
        "{err}"
    );
    let (ok, _, err) = railforce(&["track", "no/such/file.toml"]);
    assert!(!ok && err.contains("no/such/file.toml"), "{err}");
    // A bare name that is neither a file nor a built-in says which names are built in.
    let (ok, _, err) = railforce(&["track", "curve_r401"]);
    assert!(
        !ok && err.contains("curve_r401") && err.contains("curve_r400, "),
        "{err}"
    );
}

#[test]
fn contact_prints_both_wheels_and_flags_flange_contact() {
    let (ok, out, err) = railforce(&["contact", "--y-mm", "2", "--yaw-mrad", "0.5"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("left") && out.contains("right") && out.contains("xi_x"),
        "{out}"
    );
    // Far to the left the left wheel runs on its flange: contact angle above 45°.
    let (ok, out, _) = railforce(&["contact", "--y-mm", "12"]);
    assert!(ok);
    let left = out.lines().find(|l| l.starts_with("left ")).unwrap();
    let angle: f64 = left.split_whitespace().nth(4).unwrap().parse().unwrap();
    assert!(angle > 45.0, "{left}");
    let (ok, _, err) = railforce(&["contact", "--law", "magic"]);
    assert!(!ok && err.contains("--law"), "{err}");
    let (ok, _, err) = railforce(&["contact", "--wheel", "nowhere.prw"]);
    assert!(!ok && err.contains("nowhere.prw"), "{err}");
}

#[test]
fn bench_simulate_needs_at_least_one_measurement() {
    let (ok, _, err) = railforce(&["bench", "simulate", "--repeat", "0"]);
    assert!(!ok && err.contains("--repeat"), "{err}");
    let (ok, out, _) = railforce(&["bench", "simulate", "--help"]);
    assert!(ok && out.contains("fastest counts"), "{out}");
}

/// `--against` times another binary in alternate rounds (here the same one: a ratio near 1 is
/// printed), and names the file when what it is given is not a railforce binary.
#[test]
fn bench_simulate_against_another_binary() {
    let me = env!("CARGO_BIN_EXE_railforce");
    let short = ["--repeat", "2", "--seconds", "0.05"];
    let (ok, out, err) = railforce(
        &["bench", "simulate", "--against", me]
            .into_iter()
            .chain(short)
            .collect::<Vec<_>>(),
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("round 2:") && out.contains("median: physics") && out.contains("build:"),
        "{out}"
    );
    let (ok, _, err) = railforce(
        &["bench", "simulate", "--against", "no-such-railforce"]
            .into_iter()
            .chain(short)
            .collect::<Vec<_>>(),
    );
    assert!(!ok && err.contains("--against no-such-railforce"), "{err}");
}

/// `bench learn --against-torch` checks PyTorch before it times anything: an interpreter that
/// does not start, or one that cannot run the benchmark, is named with the install line.
#[test]
fn bench_learn_against_torch_names_a_missing_pytorch() {
    let base = [
        "bench",
        "learn",
        "--rows",
        "0",
        "--seconds",
        "0.01",
        "--against-torch",
    ];
    let run = |python: &str| {
        railforce(
            &base
                .into_iter()
                .chain(["--python", python])
                .collect::<Vec<_>>(),
        )
    };
    let (ok, out, err) = run("no-such-python");
    assert!(!ok && err.contains("starting no-such-python"), "{err}");
    assert!(
        !out.contains("train win/s"),
        "timed before the check: {out}"
    );
    let (ok, _, err) = run("false");
    assert!(
        !ok && err.contains("false could not run the PyTorch benchmark")
            && err.contains("--index-url https://download.pytorch.org/whl/cpu"),
        "{err}"
    );
}

#[test]
fn validate_contact_passes_on_the_built_in_reference_data_from_any_folder() {
    // Run from an empty folder: the reference data are built into the binary.
    let dir = std::env::temp_dir().join(format!("railforce-vc-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args(["validate", "contact"])
        .current_dir(&dir)
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("all gated comparisons within tolerance") && stdout.contains("built-in"),
        "{stdout}"
    );
    // A folder given on the command line is read instead; a missing one is a clear error.
    let (ok, _, err) = railforce(&["validate", "contact", "--reference-dir", "/no/such/dir"]);
    assert!(!ok && err.contains("/no/such/dir"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn learning_commands_explain_bad_input() {
    let (ok, _, err) = railforce(&[
        "train",
        "--data",
        "tracks",
        "--model",
        "transformer",
        "--out",
        "x",
    ]);
    assert!(
        !ok && err.contains("unknown model `transformer`") && err.contains("cnn-bilstm"),
        "{err}"
    );
    let missing = tmp("no_model");
    let (ok, _, err) = railforce(&[
        "identify",
        "--model",
        missing.to_str().unwrap(),
        "--input",
        "x.csv",
    ]);
    assert!(!ok && err.contains("model.json"), "{err}");
    let (ok, out, _) = railforce(&["--help"]);
    for cmd in ["train", "evaluate", "identify", "experiment", "demo"] {
        assert!(ok && out.contains(cmd), "{cmd} missing from --help: {out}");
    }
    let (ok, out, _) = railforce(&["validate", "identify", "--help"]);
    assert!(ok && out.contains("never used in training"), "{out}");
}

/// On-board selection on a noised data set, then training on the selection: the copies the
/// data set lacks are drawn with its noise, and the model records that noise and the split.
#[test]
fn select_onboard_then_train_on_noisy_inputs() {
    let data = tiny_data("onboard", "tangent", 0.4, "npz");
    let sel = tmp("onboard_sel.json");
    let (ok, out, err) = railforce(&[
        "select",
        "--data",
        data.to_str().unwrap(),
        "--candidates",
        "onboard",
        "--noisy",
        "--out",
        sel.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("drawing the noisy copies"), "{err}");
    assert!(out.contains("split by seed"), "{out}");
    // A misspelt condition is named, with the ones the data set has.
    let (ok, _, err) = railforce(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "tree",
        "--test-conditions",
        "tangnet",
        "--out",
        tmp("nowhere").to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("unknown condition tangnet") && err.contains("has: tangent"),
        "{err}"
    );
    // A missing folder: the OS's reason said once, in words.
    let (ok, _, err) = railforce(&["train", "--data", "/no/such/data", "--out", "x"]);
    assert!(
        !ok && err.matches("no such file or directory").count() == 1,
        "{err}"
    );
    assert!(!err.contains("os error"), "{err}");
    let model = tmp("onboard_model");
    let (ok, out_train, err) = railforce(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--selection",
        sel.to_str().unwrap(),
        "--model",
        "tree",
        "--target",
        "FQ",
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    // train speaks to people: the target by name, the settings that apply, a summary line.
    assert!(
        out_train.contains("→ FQ") && out_train.contains("validation R² FQ "),
        "{out_train}"
    );
    assert!(
        out_train.contains("fitted on at most") && !out_train.contains("Adam"),
        "{out_train}"
    );
    assert!(
        !out_train.contains("Blocks {") && !out_train.contains("Matched"),
        "{out_train}"
    );
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(model.join("model.json")).unwrap()).unwrap();
    assert!(
        meta["training"]["options"]["epochs"].is_null(),
        "a tree has no epochs"
    );
    // evaluate: per condition beside the pooled figure, the worst condition in the summary.
    let (ok, out, err) = railforce(&[
        "evaluate",
        "--model",
        model.to_str().unwrap(),
        "--data",
        data.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("all (pooled)") && out.contains(", worst "),
        "{out}"
    );
    let per = std::fs::read_to_string(model.join("metrics_per_condition.csv")).unwrap();
    assert!(
        per.starts_with("condition,target,n,mse,r2,var_y,rmse_kn,mae_kn\n"),
        "{per}"
    );
    assert!(per.lines().any(|l| l.starts_with("all,")), "{per}");
    // Every model is calibrated: the coverage of its intervals, per condition then pooled.
    assert!(
        out.contains("intervals at 90 % nominal coverage: FQ "),
        "{out}"
    );
    let cov = std::fs::read_to_string(model.join("coverage_per_condition.csv")).unwrap();
    assert!(
        cov.starts_with("condition,target,coverage,coverage_se,mean_width_kn\n")
            && cov.lines().last().unwrap().starts_with("all (pooled),FQ,"),
        "{cov}"
    );
    assert_eq!(meta["data"]["noise"], "Matched");
    assert_eq!(meta["data"]["noise_model"]["snr_db"], 6.0);
    assert_eq!(meta["data"]["noise_model"]["reference"], "std");
    assert!(
        meta["data"]["split"]["seeds"].is_object(),
        "{}",
        meta["data"]["split"]
    );
}

/// After `cargo install` the repository's files are not beside the binary: from an empty
/// folder, the default vehicle and a named track come from the built-in copies, and
/// `railforce init` writes them out to edit (refusing to overwrite without --force).
#[test]
fn built_in_vehicles_and_tracks_work_from_an_empty_folder() {
    let dir = std::env::temp_dir().join(format!("railforce-empty-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
            .args(args)
            .current_dir(&dir)
            .output()
            .unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (ok, out, err) = run(&[
        "simulate",
        "--track",
        "tracks/tangent.toml",
        "--duration",
        "0.2",
        "--settle",
        "0.1",
        "--out",
        "run.csv",
    ]);
    assert!(ok, "{out}\n{err}");
    assert!(err.contains("built-in"), "{err}");
    assert!(dir.join("run.csv").exists());
    // The extension picks the format: the same run in Parquet holds the CSV's numbers; an
    // unknown extension is refused before anything runs or is written.
    let (ok, out, err) = run(&[
        "simulate",
        "--track",
        "tangent",
        "--duration",
        "0.2",
        "--settle",
        "0.1",
        "--out",
        "run.parquet",
    ]);
    assert!(ok, "{out}\n{err}");
    let cols = railforce::dataset::parquet_file::read_parquet(
        std::fs::read(dir.join("run.parquet")).unwrap(),
    )
    .unwrap();
    let csv = std::fs::read_to_string(dir.join("run.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let q = header.iter().position(|h| *h == "w1l_force_z").unwrap();
    let last: f64 = csv
        .lines()
        .last()
        .unwrap()
        .split(',')
        .nth(q)
        .unwrap()
        .parse()
        .unwrap();
    let (name, values) = &cols[q];
    assert_eq!(name, "w1l_force_z");
    assert_eq!(values.len(), csv.lines().count() - 1);
    assert!(
        (values.last().unwrap() - last).abs() <= 1e-6 * last.abs(),
        "{last}"
    );
    assert!(dir.join("run.meta.json").exists());
    let (ok, _, err) = run(&["simulate", "--track", "tangent", "--out", "run.txt"]);
    assert!(
        !ok && err.contains("run.txt") && err.contains(".parquet"),
        "{err}"
    );
    assert!(!dir.join("run.txt").exists());
    // A bare name stands for a built-in track, vehicle or plan.
    let (ok, out, err) = run(&["track", "curve_r400"]);
    assert!(ok && out.contains("R 400 m"), "{out}\n{err}");
    // …also beside a folder of that name (`railforce demo` writes `demo/`).
    std::fs::create_dir_all(dir.join("curve_r400")).unwrap();
    let (ok, out, err) = run(&["track", "curve_r400"]);
    assert!(ok && out.contains("R 400 m"), "{out}\n{err}");
    let (ok, out, err) = run(&["init", "mine"]);
    assert!(ok, "{err}");
    assert!(out.contains("wrote"), "{out}");
    for f in [
        "vehicles/c80.toml",
        "vehicles/c80.urdf",
        "tracks/paper34.plan.toml",
    ] {
        let a = std::fs::read_to_string(dir.join("mine").join(f)).unwrap();
        let b = std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(f))
            .unwrap();
        assert_eq!(a, b, "{f}");
    }
    let (ok, _, err) = run(&["init", "mine"]);
    assert!(!ok && err.contains("--force"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The installed binary runs the demo from an empty folder: plan, vehicle and tracks come
/// from the built-in copies (release: the demo trains for about a minute and a half).
#[test]
#[ignore = "long: the whole demo, run in release"]
fn demo_runs_from_an_empty_folder() {
    let dir = std::env::temp_dir().join(format!("railforce-demo-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    common::succeed(common::railforce_in(&dir).arg("demo"));
    // Every link of the report resolves.
    let html = std::fs::read_to_string(dir.join("demo/index.html")).unwrap();
    let mut links = 0;
    for attr in ["href=\"", "src=\""] {
        for part in html.split(attr).skip(1) {
            let target = part.split('"').next().unwrap();
            if !target.starts_with('#') {
                assert!(dir.join("demo").join(target).is_file(), "{target}");
                links += 1;
            }
        }
    }
    assert!(links >= 20, "{links} links");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A step too coarse for the vehicle's stiffest coupling is refused before the run starts,
/// naming the longest step that holds it; and a step given coarser than short waves allow is
/// refused with the step that follows them.
#[test]
fn a_burst_is_named_and_a_step_too_coarse_for_short_waves_refused() {
    let out = std::env::temp_dir().join(format!("railforce-burst-{}.csv", std::process::id()));
    let out = out.to_str().unwrap();
    let run = |extra: &[&str]| {
        let base = [
            "simulate",
            "--track",
            "tangent",
            "--speed-kmh",
            "80",
            "--duration",
            "1",
        ];
        railforce(
            &base
                .iter()
                .chain(extra)
                .chain(&["--out", out])
                .copied()
                .collect::<Vec<_>>(),
        )
    };
    let (ok, _, err) = run(&["--dt", "1e-3"]);
    assert!(
        !ok && err.contains("cannot follow") && err.contains("--dt below"),
        "{err}"
    );
    let (ok, _, err) = run(&["--dt", "5e-4", "--roughness", "cnossos_m"]);
    assert!(
        !ok && err.contains("too coarse") && err.contains("0.0625 ms"),
        "{err}"
    );
    assert!(!std::path::Path::new(out).exists(), "nothing written");
}
