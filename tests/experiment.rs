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
        robustness_models: vec![ModelKind::Tree, ModelKind::Gru],
        snrs: vec![40.0, 1.0],
        loco: vec!["curve_r400_v60".into()],
        window: 12,
        train: TrainOptions {
            epochs: 2,
            patience: 2,
            ..TrainOptions::default()
        },
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
        "model,train MSE,train R²,test MSE,test R²,Var(y_test),test RMSE kN,fit s,paper train MSE / R²,paper test MSE / R²"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("comparison/comparison_fq.csv"))
            .unwrap()
            .lines()
            .count(),
        4
    );
    assert!(
        header("generalization/per_condition.csv")
            .starts_with("condition,FL MSE,FL R²,FQ MSE,FQ R²")
    );
    assert!(header("generalization/leave_one_out.csv").starts_with("held-out condition,"));
    assert_eq!(
        header("robustness/robustness.csv"),
        "protocol,SNR dB,model,FL MSE,FL R²,FQ MSE,FQ R²,paper R² at 1 dB"
    );
    // 2 protocols × 2 models × 2 SNRs.
    assert_eq!(
        std::fs::read_to_string(out.join("robustness/robustness.csv"))
            .unwrap()
            .lines()
            .count(),
        9
    );
    let html = std::fs::read_to_string(&index).unwrap();
    let mut links = 0;
    for attr in ["href=\"", "src=\""] {
        for part in html.split(attr).skip(1) {
            let target = part.split('"').next().unwrap();
            assert!(
                out.join(target).is_file(),
                "index.html links {target}, which does not exist"
            );
            links += 1;
        }
    }
    assert!(links >= 12, "{links} links");
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
    assert!(
        meta["data_manifest_fnv1a"].is_string() && meta["wall_seconds"].as_f64().unwrap() > 0.0
    );
    assert_eq!(meta["window"], 12);
    assert_eq!(meta["label_at"], "Centre");
    assert_eq!(meta["noise"]["reference"], "std");
    let protocols = std::fs::read_to_string(out.join("protocols/protocols.csv")).unwrap();
    assert!(protocols.starts_with("protocol,"), "{protocols}");
    assert!(protocols.contains("shuffled (leaky)") && protocols.contains("SHUFFLED (leaky)"));
    assert_eq!(protocols.lines().count(), 5);
    let sensors = std::fs::read_to_string(out.join("sensors/sensors.csv")).unwrap();
    assert!(sensors.contains("selected on-board") && sensors.contains("paper's 21"));
    assert!(header("sensors/selection_fq.csv").starts_with("channel,MI nats"));
    assert!(html.contains("label at the centre step"));
    assert!(html.contains("windows of 12 steps"));
}
