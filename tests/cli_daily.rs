//! The command line for daily use: identification of both wheels, streaming against batch,
//! the contact command's rolling, sweeps and warnings, and every `--help` example.

use crate::cli::{railforce, tiny_data, tmp};
use std::process::Command;

/// On-board identification of both wheels of the leading wheelset: a list of targets gives
/// Y/Q of each wheel and the wheelset's H; streaming and batch write the same file, with the
/// track position carried through and ASCII column names.
#[test]
fn identify_both_wheels_streaming_equals_batch() {
    let data = tiny_data("wheels", "curve_r400", 0.5, "csv");
    let model = tmp("wheels_model");
    let train = |target: &str| {
        railforce(&[
            "train",
            "--data",
            data.to_str().unwrap(),
            "--model",
            "gru",
            "--epochs",
            "1",
            "--target",
            target,
            "--out",
            model.to_str().unwrap(),
        ])
    };
    let (ok, _, err) = train("w1l,1R");
    assert!(ok, "{err}");
    let (ok, _, err) = train("FX");
    assert!(
        !ok && err.contains("unknown target FX") && err.contains("w1l"),
        "{err}"
    );
    // A finished model is not trained over by a repeated command.
    let before = std::fs::read(model.join("weights.bin")).unwrap();
    let (ok, _, err) = train("w1l,1R");
    assert!(
        !ok && err.contains("--force") && err.contains("--resume"),
        "{err}"
    );
    assert_eq!(std::fs::read(model.join("weights.bin")).unwrap(), before);
    let input = data.join("curve_r400_seed3.csv");
    let batch = tmp("wheels_batch.csv");
    let (ok, _, err) = railforce(&[
        "identify",
        "--model",
        model.to_str().unwrap(),
        "--input",
        input.to_str().unwrap(),
        "--out",
        batch.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("H wheelset 1 (kN)"), "{err}");
    let streamed = tmp("wheels_stream.csv");
    let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args([
            "identify",
            "--model",
            model.to_str().unwrap(),
            "--input",
            "-",
            "--out",
        ])
        .arg(&streamed)
        .stdin(std::fs::File::open(&input).unwrap())
        .output()
        .unwrap();
    let serr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{serr}");
    assert!(
        serr.contains("H wheelset 1 (kN)"),
        "the exceedance report: {serr}"
    );
    let (a, b) = (
        std::fs::read_to_string(&batch).unwrap(),
        std::fs::read_to_string(&streamed).unwrap(),
    );
    assert_eq!(
        a.lines().next().unwrap(),
        "time_s,s_m,w1l_force_y_N,w1l_force_y_lo_N,w1l_force_y_hi_N,\
         w1l_force_z_N,w1l_force_z_lo_N,w1l_force_z_hi_N,\
         w1r_force_y_N,w1r_force_y_lo_N,w1r_force_y_hi_N,\
         w1r_force_z_N,w1r_force_z_lo_N,w1r_force_z_hi_N,\
         y_over_q_w1l,unloading_w1l,y_over_q_w1r,unloading_w1r,h_wheelset1_kn,ood_channels"
    );
    assert!(a.is_ascii());
    assert_eq!(a, b, "streaming and batch write the same file");
    assert!(batch.with_extension("safety.json").exists());
    assert!(streamed.with_extension("safety.json").exists());
    // One error format: a NaN in the stream is named by column and row like the batch reader.
    let text = std::fs::read_to_string(&input).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let k = lines[0]
        .split(',')
        .position(|c| c == "frame_l_acc_y_noisy")
        .unwrap();
    let mut f: Vec<String> = lines[5].split(',').map(str::to_string).collect();
    f[k] = "NaN".into();
    lines[5] = f.join(",");
    let bad = tmp("wheels_nan.csv");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    let (ok, _, err_batch) = railforce(&[
        "identify",
        "--model",
        model.to_str().unwrap(),
        "--input",
        bad.to_str().unwrap(),
    ]);
    assert!(!ok);
    let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args([
            "identify",
            "--model",
            model.to_str().unwrap(),
            "--input",
            "-",
        ])
        .stdin(std::fs::File::open(&bad).unwrap())
        .output()
        .unwrap();
    let err_stream = String::from_utf8_lossy(&out.stderr);
    for e in [&err_batch, &err_stream.to_string()] {
        assert!(e.contains("column frame_l_acc_y_noisy, row 5"), "{e}");
    }
    // …and so is an empty field, which the CSV reader itself refuses.
    f[k] = String::new();
    lines[5] = f.join(",");
    std::fs::write(&bad, lines.join("\n") + "\n").unwrap();
    let (ok, _, err) = railforce(&[
        "identify",
        "--model",
        model.to_str().unwrap(),
        "--input",
        bad.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("column frame_l_acc_y_noisy, row 5: \"\" is not a number"),
        "{err}"
    );
}

/// `contact` rolls by default (no longitudinal force when centred), prints Y/Q, warns past
/// Nadal's limit, and a sweep's row at y = 0 is the single state's.
#[test]
fn contact_rolls_sweeps_and_warns() {
    let (ok, out, err) = railforce(&["contact", "--vehicle", "vehicles/c80.toml"]);
    assert!(ok, "{err}");
    assert!(out.contains("rolling at the mean rolling radius"), "{out}");
    let fx: Vec<f64> = out
        .lines()
        .filter(|l| l.starts_with("left ") || l.starts_with("right "))
        .map(|l| l.split_whitespace().nth(12).unwrap().parse().unwrap())
        .collect();
    assert_eq!(fx.len(), 2);
    assert!(
        fx.iter().all(|f| f.abs() < 0.01),
        "Fx {fx:?} kN when centred"
    );
    let yq_single: Vec<String> = out
        .lines()
        .filter_map(|l| l.split("|Y|/Q ").nth(1))
        .map(|r| r.split_whitespace().next().unwrap().to_string())
        .collect();
    let sweep = tmp("sweep.csv");
    let (ok, _, err) = railforce(&[
        "contact",
        "--vehicle",
        "vehicles/c80.toml",
        "--sweep-y",
        "-10:10:5",
        "--out",
        sweep.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(err.contains("beyond Nadal's flange-climb limit"), "{err}");
    let text = std::fs::read_to_string(&sweep).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 10);
    let at0: Vec<String> = rows
        .iter()
        .filter(|r| r[0] == "0")
        .map(|r| format!("{:.3}", r[8].parse::<f64>().unwrap()))
        .collect();
    assert_eq!(at0, yq_single, "the sweep's y = 0 is the single state");
    let (ok, _, err) = railforce(&["contact", "--vehicle", "vehicles/c80.toml", "--y-mm", "10"]);
    assert!(ok && err.contains("would climb its flange"), "{err}");
    let (ok, _, err) = railforce(&["contact", "--sweep-y", "5:1:1"]);
    assert!(!ok && err.contains("FROM ≤ TO"), "{err}");
}

/// Every example in every subcommand's `--help` runs, in a fresh folder, in the order a user
/// would type them (data before training, a model before identifying).
#[test]
#[ignore = "runs every --help example (generation, training, a closed loop): release, CI"]
fn every_help_example_runs() {
    let dir = std::env::temp_dir().join(format!("railforce-examples-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let exe = env!("CARGO_BIN_EXE_railforce");
    let mut ran = 0;
    for cmd in [
        "init",
        "track",
        "contact",
        "simulate",
        "generate",
        "select",
        "train",
        "evaluate",
        "calibrate",
        "identify",
        "export",
        "assess",
        "view",
        "validate",
        "experiment",
    ] {
        let (ok, help, _) = railforce(&[cmd, "--help"]);
        assert!(
            ok && help.contains("Examples:"),
            "{cmd} --help has no examples"
        );
        let examples: Vec<&str> = help
            .split("Examples:")
            .nth(1)
            .unwrap()
            .lines()
            .filter_map(|l| l.strip_prefix("  railforce "))
            .collect();
        assert!(!examples.is_empty(), "{cmd}");
        for e in examples {
            let out = Command::new("sh")
                .arg("-c")
                .arg(format!("'{exe}' {e}"))
                .current_dir(&dir)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "`railforce {e}` failed:\n{}",
                String::from_utf8_lossy(&out.stderr)
            );
            ran += 1;
        }
    }
    assert!(ran >= 20, "{ran} examples");
    let _ = std::fs::remove_dir_all(&dir);
}
