//! A tiny configuration of every experiment, end to end: data, training, tables, figures and
//! an index.html whose links all exist.

use railforce::experiment::{ExperimentOptions, Which, run};
use railforce::learn::model::ModelKind;
use railforce::learn::train::TrainOptions;
use std::path::{Path, PathBuf};

fn tiny_plan(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let plan = format!(
        r#"name = "tiny"
vehicle = "{v}"
duration_s = 4.0
seeds = [1, 2, 3]

[[condition]]
name = "tangent_v80"
track = "{t}/tangent.toml"
speed_kmh = 80.0

[[condition]]
name = "curve_r400_v60"
track = "{t}/curve_r400.toml"
speed_kmh = 60.0

[[condition]]
name = "grade20_L50_v60"
track = "{t}/grade20_L50.toml"
speed_kmh = 60.0
consist = "daqin_20kt"
position = 0.02
"#,
        v = root.join("vehicles/c80.toml").display(),
        t = root.join("tracks").display()
    );
    let p = dir.join("tiny.plan.toml");
    std::fs::write(&p, plan).unwrap();
    p
}

#[test]
#[ignore = "simulates three short runs and trains 16 small models: run in release (CI does)"]
fn every_experiment_runs_end_to_end() {
    let dir = std::env::temp_dir().join(format!("railforce-experiment-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let opts = ExperimentOptions {
        models: vec![ModelKind::CnnBiLstm, ModelKind::Gru, ModelKind::Tree],
        robustness_models: vec![ModelKind::Tree, ModelKind::Cnn],
        snrs: vec![40.0, 1.0],
        loco: vec!["curve_r400_v60".into()],
        window: 12,
        mismatch_window: 16,
        mismatch_members: 2,
        train: TrainOptions {
            epochs: 2,
            patience: 2,
            ..TrainOptions::default()
        },
        fleet: Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("tracks/paper34_varied.plan.toml")),
        ..ExperimentOptions::full(tiny_plan(&dir), dir.join("out"))
    };
    let index = run(&[Which::All], &opts, &|_| {}).unwrap();
    let out = dir.join("out");
    let header = |p: &str| {
        std::fs::read_to_string(out.join(p))
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_string()
    };
    assert_eq!(
        header("comparison/comparison_fl.csv"),
        "model,train_mse,train_r2,test_mse,test_r2,var_y_test,test_rmse_kn,fit_s,paper_train_mse,paper_train_r2,paper_test_mse,paper_test_r2"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("comparison/comparison_fq.csv"))
            .unwrap()
            .lines()
            .count(),
        4
    );
    assert!(header("generalization/per_condition.csv").starts_with(
        "condition,n,fl_mse,fl_r2,var_fl_test,fq_mse,fq_r2,var_fq_test,paper_fq_mse,paper_fq_r2"
    ));
    assert!(header("generalization/leave_one_out.csv").starts_with("held_out_condition,"));
    // The test runs judged by the acceptance statistics, identified against true.
    assert!(
        header("generalization/assessment.csv")
            .starts_with("condition,y_q_2m_true,y_q_2m_identified_true,q_true,q_identified_true"),
        "{}",
        header("generalization/assessment.csv")
    );
    let assessed = std::fs::read_to_string(out.join("generalization/assessment.csv")).unwrap();
    assert_eq!(assessed.lines().count(), 4, "three conditions: {assessed}");
    assert_eq!(
        header("robustness/robustness.csv"),
        "protocol,snr_db,model,fl_mse,fl_r2,fq_mse,fq_r2,paper_r2_at_1_db"
    );
    // 2 protocols × 2 models × 2 SNRs.
    assert_eq!(
        std::fs::read_to_string(out.join("robustness/robustness.csv"))
            .unwrap()
            .lines()
            .count(),
        9
    );
    check_links(&index, &out, 12);
    // Charts a reader reads at a glance: names on the axis, the paper's values beside ours.
    let bars = std::fs::read_to_string(out.join("generalization/r2_per_condition.svg")).unwrap();
    for name in ["tangent_v80", "curve_r400_v60", "grade20_L50_v60"] {
        assert!(
            bars.contains(name),
            "{name} missing from the per-condition chart"
        );
    }
    // The paper's FQ R² of curve_r400_v60 (Table 4: 0.9301).
    assert!(bars.contains("FQ (paper): 0.93<"), "paper's value missing");
    let models = std::fs::read_to_string(out.join("comparison/r2_per_model_fl.svg")).unwrap();
    assert!(models.contains("cnn-bilstm") && models.contains("paper: 0.813<"));
    let snr = std::fs::read_to_string(out.join("robustness/r2_vs_snr_fl_matched.svg")).unwrap();
    assert!(
        snr.contains("paper cnn (1 dB): 1, 0.657"),
        "the paper's point"
    );
    let html = std::fs::read_to_string(&index).unwrap();
    for svg in [
        "comparison/training_curves_fl.svg",
        "comparison/trace_fq.svg",
        "robustness/r2_vs_snr_fq_matched.svg",
    ] {
        let s = std::fs::read_to_string(out.join(svg)).unwrap();
        assert!(s.starts_with("<svg") && s.contains("polyline"), "{svg}");
    }
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    assert!(meta["data_fnv1a"].is_string() && meta["wall_seconds"].as_f64().unwrap() > 0.0);
    assert_eq!(meta["window"], 12);
    assert_eq!(meta["label_at"], "Centre");
    assert_eq!(meta["noise"]["reference"], "std");
    // CPU time: the process's, so here it counts the other tests' threads too (no bound
    // from this run's wall time holds); it grew while the parts trained.
    let cpu = meta["cpu_seconds"].as_f64().unwrap();
    assert!(
        cpu > 0.0 && meta["cores"].as_u64().unwrap() >= 1,
        "{cpu} s CPU"
    );
    assert!(meta["machine"].as_str().unwrap().ends_with(" cores"));
    let snapshot = std::fs::read_to_string(out.join("results.md")).unwrap();
    assert!(
        snapshot.contains("| part | commit | wall time | CPU time | cores busy | machine |"),
        "{snapshot}"
    );
    let part: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("generalization/meta.json")).unwrap(),
    )
    .unwrap();
    assert!(part["cpu_seconds"].as_f64().unwrap() > 0.0);
    let protocols = std::fs::read_to_string(out.join("protocols/protocols.csv")).unwrap();
    assert!(protocols.starts_with("protocol,"), "{protocols}");
    assert!(protocols.contains("shuffled (leaky)") && protocols.contains("SHUFFLED (leaky)"));
    assert_eq!(protocols.lines().count(), 5);
    let sensors = std::fs::read_to_string(out.join("sensors/sensors.csv")).unwrap();
    assert!(sensors.contains("selected on-board") && sensors.contains("paper's 21"));
    assert!(header("sensors/selection_fq.csv").starts_with("channel,mi_nats"));
    // Mismatch: 5 models × (nominal, fleet, 4 extremes), each
    // with its coverage and out-of-distribution share (every experiment model is calibrated).
    let mismatch = std::fs::read_to_string(out.join("mismatch/mismatch.csv")).unwrap();
    assert!(
        header("mismatch/mismatch.csv").starts_with(
            "inputs,trained_on,tested_on,windows,fl_r2,fl_rmse_kn,fq_r2,fq_rmse_kn,fl_covered,fq_covered"
        ),
        "{mismatch}"
    );
    // Paper's 21 and on-board, nominal- and fleet-trained, and both fleet-trained with the
    // weighed mass: 6 models on 6 test sets.
    assert_eq!(mismatch.lines().count(), 1 + 6 * 6, "{mismatch}");
    assert!(mismatch.contains("paper's 21 + weighed mass"), "{mismatch}");
    assert!(
        mismatch.contains("selected on-board + weighed mass"),
        "{mismatch}"
    );
    for case in [
        "half_payload",
        "wet_rail",
        "high_conicity",
        "class4",
        "fleet",
    ] {
        assert!(mismatch.contains(case), "{case} missing: {mismatch}");
    }
    for line in mismatch.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        // fl_covered, fq_covered, fl/fq width, flagged: every model is calibrated.
        assert!(f[8..13].iter().all(|v| !v.is_empty()), "{line}");
    }
    // The fleet's test runs drew their own wagons: the manifest records the draws.
    let manifest = std::fs::read_to_string(out.join("mismatch/data/fleet/manifest.json")).unwrap();
    assert!(manifest.contains("vehicle.contact.friction"));
    let half =
        std::fs::read_to_string(out.join("mismatch/data/half_payload/manifest.json")).unwrap();
    let half: serde_json::Value = serde_json::from_str(&half).unwrap();
    let runs = half["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 3, "the test seed of three conditions");
    for r in runs {
        assert_eq!(r["seed"], 3);
        assert_eq!(r["draws"]["vehicle.body.carbody.mass"]["scale"], 0.565);
    }
    assert!(html.contains("label at the centre step"));
    assert!(html.contains("windows of 12 steps"));
    // The mismatch part reads its own window, its nominal models trained again at it.
    assert!(html.contains("windows of 16 steps"));
    assert_eq!(meta["mismatch_window"], 16);
    for m in ["nominal_paper21", "nominal_selected"] {
        let model: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(out.join(format!("mismatch/models/{m}/model.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(model["data"]["window"], 16, "{m}");
    }
    // The fleet models with the weighed mass are ensembles of two networks with heads (seeds
    // 1 and 2, the second in member2/), the ones without it single networks.
    for (m, members) in [
        ("fleet_paper21_weighed", 2),
        ("fleet_selected_weighed", 2),
        ("fleet_paper21", 1),
    ] {
        let dir = out.join(format!("mismatch/models/{m}"));
        let model: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap())
                .unwrap();
        assert_eq!(model["members"].as_u64().unwrap_or(1), members, "{m}");
        assert_eq!(
            dir.join("weights_member2.bin").exists(),
            members == 2,
            "{m}"
        );
        if members == 2 {
            let second: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(dir.join("member2/model.json")).unwrap(),
            )
            .unwrap();
            assert_eq!(second["net"]["seed"], 2, "{m}");
            assert_eq!(
                second["net"]["quantiles"], 0.9,
                "{m}: each member keeps its heads"
            );
            assert_eq!(
                model["training"]["ensemble"].as_array().map(|a| a.len()),
                Some(2)
            );
        }
    }
    assert!(html.contains("fleet, ensemble of 2"));
    // Model form: each track model's network on both tracks; the labels on both per condition.
    let form = std::fs::read_to_string(out.join("model_form/model_form.csv")).unwrap();
    assert!(
        header("model_form/model_form.csv")
            .starts_with("trained_on,tested_on,windows,fl_r2,fl_rmse_kn,fq_r2,fq_rmse_kn"),
        "{form}"
    );
    // Two networks from each of two training seeds on three test sets: each track model, and
    // short waves on the lumped one; each pair's spread over the seeds.
    assert_eq!(form.lines().count(), 1 + 12, "{form}");
    assert!(form.contains("rails on sleepers, training seed"), "{form}");
    let spread = std::fs::read_to_string(out.join("model_form/model_form_spread.csv")).unwrap();
    assert_eq!(spread.lines().count(), 1 + 6, "{spread}");
    assert!(spread.contains(" ± "), "{spread}");
    assert!(form.contains("lumped, cnossos_m roughness"), "{form}");
    assert!(
        form.contains("lumped rail masses,rails on sleepers"),
        "{form}"
    );
    assert!(
        form.contains("rails on sleepers,lumped rail masses"),
        "{form}"
    );
    let labels = std::fs::read_to_string(out.join("model_form/labels.csv")).unwrap();
    assert_eq!(labels.lines().count(), 1 + 3, "{labels}");
    let sleepers =
        std::fs::read_to_string(out.join("model_form/data/on_sleepers/manifest.json")).unwrap();
    assert!(sleepers.contains("discrete"), "the runs on sleepers say so");
    let rough =
        std::fs::read_to_string(out.join("model_form/data/cnossos_m/manifest.json")).unwrap();
    assert!(
        rough.contains("\"roughness\": \"cnossos_m\""),
        "the rough runs say so"
    );
    assert!(
        header("model_form/labels.csv").contains("fq_20_50_hz_kn_rough"),
        "{labels}"
    );
    // The lumped network is the generalisation part's, not trained again.
    assert!(!out.join("model_form/models/lumped").exists());
    assert!(!out.join("model_form/models/lumped_seed2").exists());
    assert!(out.join("model_form/models/on_sleepers_seed2").exists());
    assert!(html.contains("lumped track against rails on sleepers"));
    let data = meta["data_fnv1a"].clone();

    // One part run again on its own into the same folder: the report still shows all seven,
    // and the data identity is unchanged (nothing was regenerated).
    let again = ExperimentOptions {
        robustness_models: vec![ModelKind::Tree],
        ..opts.clone()
    };
    run(&[Which::Robustness], &again, &|_| {}).unwrap();
    let html = check_links(&index, &out, 12);
    for part in [
        "comparison",
        "generalization",
        "robustness",
        "protocols",
        "sensors",
        "mismatch",
        "model_form",
    ] {
        assert!(
            html.contains(&format!("id=\"{part}\"")),
            "{part} missing after a rerun"
        );
    }
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["data_fnv1a"], data);
    assert!(!html.contains("computed on different data"));
}

/// Every link of an index resolves to a file; returns the page.
fn check_links(index: &Path, out: &Path, at_least: usize) -> String {
    let html = std::fs::read_to_string(index).unwrap();
    let mut links = 0;
    for attr in ["href=\"", "src=\""] {
        for part in html.split(attr).skip(1) {
            let target = part.split('"').next().unwrap();
            if target.starts_with('#') {
                continue;
            }
            assert!(
                out.join(target).is_file(),
                "index.html links {target}, which does not exist"
            );
            links += 1;
        }
    }
    assert!(links >= at_least, "{links} links");
    html
}

#[test]
fn a_missing_fleet_plan_is_refused_before_any_simulation() {
    let dir = std::env::temp_dir().join(format!("railforce-fleet-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let opts = ExperimentOptions {
        fleet: Some(dir.join("no_such_fleet.plan.toml")),
        ..ExperimentOptions::full(tiny_plan(&dir), dir.join("out"))
    };
    let err = run(&[Which::All], &opts, &|_| {}).unwrap_err().to_string();
    assert!(err.contains("no_such_fleet.plan.toml"), "{err}");
    assert!(
        !dir.join("out/data").exists(),
        "nothing simulated before the fleet plan was checked"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
