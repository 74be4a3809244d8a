//! The sensor contract end to end: the label wheel of a vehicle file reaches the labels, the
//! on-board candidate channels (suspension deflections) exist, are finite, read zero in the
//! static loaded position and show the outer spring nests compressed more in a curve with cant
//! deficiency; seed splits never share a seed; the shuffled protocol says it leaks.

use railforce::dataset::DataSet;
use railforce::dataset::{self, Format, GenerateOptions};
use railforce::features::{LabelAt, Samples, Split};
use railforce::plan::Plan;
use railforce::sensors::{Candidates, ChannelKind, NoiseModel, SnrReference};
use railforce::sim::output::{self, Recorder};
use railforce::sim::{SimConfig, Simulation, checks};
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::Vehicle;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("railforce-sensors-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const DEFLECTIONS: [&str; 8] = [
    "nest_sideframe1l_z",
    "nest_sideframe1r_y",
    "pad_sideframe1l_wheelset1_x",
    "pad_sideframe2r_wheelset4_z",
    "sidebearer_bolster1_l_z",
    "sidebearer_bolster2_r_z",
    "centreplate_bolster1_z",
    "centreplate_bolster2_z",
];

#[test]
fn deflection_channels_exist_and_read_the_static_compression_at_rest() {
    let v = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = Track::new(
        TrackSpec::load(&root().join("tracks/tangent.toml")).unwrap(),
        None,
    );
    let mut sim = Simulation::new(&v, &track, SimConfig::default()).unwrap();
    let mut rec = Recorder::new(&sim);
    let names = rec.names().to_vec();
    let row = rec.sample(&mut sim).unwrap().to_vec();
    let labels = railforce::sensors::label_channels("1L");
    let defl: Vec<usize> = (0..names.len())
        .filter(|&i| ChannelKind::of(&names[i], &labels) == ChannelKind::Deflection)
        .collect();
    // 4 nests × 2 + 8 pads × 3 + 4 side bearers + 2 centre plates.
    assert_eq!(
        defl.len(),
        38,
        "{:?}",
        defl.iter().map(|&i| &names[i]).collect::<Vec<_>>()
    );
    for n in DEFLECTIONS {
        let i = names
            .iter()
            .position(|c| c == n)
            .unwrap_or_else(|| panic!("no {n}"));
        assert!(row[i].is_finite());
    }
    // Gauges read from the free element: in the static loaded position, each reads its
    // element's static compression on its axis (vertical: load / stiffness, > 0 for the
    // supports that carry load; the other axes 0).
    let mut vertical = 0;
    for e in &v.elements {
        for (n, axis) in e.gauges(&v.bodies) {
            let i = names.iter().position(|c| *c == n).unwrap();
            let want = e.static_deflection()[axis];
            assert!(
                (row[i] - want).abs() < 1e-9,
                "{n} reads {} m at rest, not {want} m",
                row[i]
            );
            if axis == 2 {
                assert!(want > 0.0, "{n}: a support carries load");
                vertical += 1;
            }
        }
    }
    assert_eq!(vertical, 4 + 8 + 4 + 2);
    let cands = Candidates::Onboard.among(&names, &labels);
    assert!(cands.len() > 100, "{}", cands.len());
    assert!(
        cands
            .iter()
            .all(|c| !c.contains("force") && !c.contains("_xi_"))
    );
}

#[test]
fn the_label_wheel_of_the_vehicle_file_reaches_the_labels() {
    let dir = temp("label");
    let toml = std::fs::read_to_string(root().join("vehicles/c80.toml"))
        .unwrap()
        .replace("label_wheel = \"1L\"", "label_wheel = \"2R\"");
    std::fs::copy(root().join("vehicles/c80.urdf"), dir.join("c80.urdf")).unwrap();
    std::fs::write(dir.join("c80.toml"), toml).unwrap();
    let plan_text = format!(
        "name = \"label\"\nvehicle = \"c80.toml\"\nduration_s = 0.2\nseeds = [1, 2, 3]\n\
         [[condition]]\nname = \"tangent\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        root().join("tracks/tangent.toml").display()
    );
    std::fs::write(dir.join("p.plan.toml"), plan_text).unwrap();
    let plan = Plan::load(&dir.join("p.plan.toml")).unwrap();
    let out = dir.join("data");
    let opts = GenerateOptions {
        out: out.clone(),
        format: Format::Npz,
        jobs: 2,
        shard: None,
        noise: Some(NoiseModel::new(6.0, SnrReference::Std)),
        settle: 0.1,
        stepping: Default::default(),
    };
    let m = dataset::generate(&plan, &opts, &|_| {}).unwrap();
    assert_eq!(m.labels()[0], "w2r_force_y");
    assert_eq!(m.snr_reference.as_deref(), Some("std"));
    let ds = DataSet::load(&out).unwrap();
    assert_eq!(ds.labels, ["w2r_force_y", "w2r_force_z"]);
    assert_eq!(ds.target_channel("FQ"), "w2r_force_z");
    assert_eq!(ds.noise, Some(NoiseModel::new(6.0, SnrReference::Std)));
    // The paper's creepage inputs are those of the label wheel.
    let (a, b) = (
        ds.channel("w1l_creep_y").unwrap(),
        ds.channel("w2r_xi_y").unwrap(),
    );
    assert_eq!(ds.runs[0].columns[a], ds.runs[0].columns[b]);
    // Three seeds: the standard split tests on the last, validates on the one before.
    assert_eq!(
        Split::standard(&ds),
        Split::Seeds {
            train: vec![1],
            val: vec![2],
            test: vec![3]
        }
    );
}

fn seeded(seeds: &[u64]) -> DataSet {
    let runs = seeds
        .iter()
        .map(|&s| railforce::dataset::Run {
            condition: "c".into(),
            seed: s,
            columns: vec![(0..200).map(|i| i as f64).collect()],
        })
        .collect();
    DataSet::in_memory(&PathBuf::from("mem"), vec!["x".into()], runs)
}

#[test]
fn a_seed_never_serves_two_parts() {
    let ds = seeded(&[1, 2, 3, 4, 1]);
    let split = Split::standard(&ds);
    let s = Samples::build(&ds, &split, 20, 1, LabelAt::Centre).unwrap();
    let seeds = |w: &[railforce::features::Window]| -> std::collections::BTreeSet<u64> {
        w.iter().map(|w| ds.runs[w.run as usize].seed).collect()
    };
    assert_eq!(seeds(&s.train), [1, 2].into());
    assert_eq!(seeds(&s.val), [3].into());
    assert_eq!(seeds(&s.test), [4].into());
    let bad = Split::Seeds {
        train: vec![1, 2],
        val: vec![2],
        test: vec![4],
    };
    let e = Samples::build(&ds, &bad, 20, 1, LabelAt::Centre)
        .unwrap_err()
        .to_string();
    assert!(e.contains("seed 2") && e.contains("two parts"), "{e}");
    // Fewer than three seeds: blocks, and it says so.
    assert_eq!(Split::standard(&seeded(&[1, 2])).name(), "blocks");
}

#[test]
fn the_shuffled_protocol_says_it_leaks() {
    let ds = seeded(&[1, 2]);
    let sh = Split::Shuffled {
        train: 0.7,
        val: 0.15,
        seed: 1,
    };
    assert!(sh.describe().contains("SHUFFLED (leaky)"));
    let s = Samples::build(&ds, &sh, 20, 1, LabelAt::Centre).unwrap();
    assert_eq!(s.train.len() + s.val.len() + s.test.len(), 2 * 181);
    // Neighbouring windows end up in train and test: the leak it exists to show.
    let starts = |w: &[railforce::features::Window]| -> std::collections::BTreeSet<(u32, u32)> {
        w.iter().map(|w| (w.run, w.start)).collect()
    };
    let (tr, te) = (starts(&s.train), starts(&s.test));
    assert!(te.iter().any(|&(r, st)| tr.contains(&(r, st + 1))));
    let json = serde_json::to_string(&sh).unwrap();
    assert!(json.contains("shuffled"), "{json}");
}

/// In a curve run above its balancing speed (cant deficiency), the outer (left, for a
/// right-hand curve) spring nests carry more than the inner ones: they are compressed more.
#[test]
#[ignore = "long simulation: run in release"]
fn outer_spring_nests_compress_more_with_cant_deficiency() {
    let v = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = checks::with_class(&root().join("tracks/curve_r400.toml"), 6).unwrap();
    let kmh = 95.0;
    let a_nc = (kmh / 3.6f64).powi(2) / 400.0 - railforce::GRAVITY * (0.188f64 / 1.5).asin().tan();
    assert!(a_nc > 0.3, "cant deficiency {a_nc}");
    let cfg = SimConfig {
        speed: kmh / 3.6,
        duration: 14.0,
        settle: 1.0,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(&v, &track, cfg).unwrap();
    let rec = output::record(&mut sim, |_| {}).unwrap();
    let col = |n: &str| rec.names.iter().position(|c| c == n).unwrap();
    let tail = |c: usize| {
        let rows = &rec.rows[rec.rows.len() - 300..];
        rows.iter().map(|r| r[c]).sum::<f64>() / rows.len() as f64
    };
    for bogie in [1, 2] {
        let outer = tail(col(&format!("nest_sideframe{bogie}l_z")));
        let inner = tail(col(&format!("nest_sideframe{bogie}r_z")));
        assert!(
            outer > inner + 1e-3,
            "bogie {bogie}: outer nest {outer} m, inner {inner} m"
        );
    }
    for c in 0..rec.names.len() {
        assert!(
            rec.rows.iter().all(|r| r[c].is_finite()),
            "{}",
            rec.names[c]
        );
    }
}

/// A model trained at 6 dB records its noise, and the closed loop tests it on inputs noised
/// the same way (not on clean ones).
#[test]
fn a_model_trained_at_6_db_is_validated_on_noisy_inputs() {
    use railforce::features::NoiseProtocol;
    use railforce::identify::closed_loop;
    use railforce::identify::safety::Limits;
    use railforce::learn::model::ModelKind;
    use railforce::learn::train::{TrainOptions, train};
    use railforce::learn::windows::DataSpec;
    let dir = temp("closed");
    let plan_text = format!(
        "name = \"closed\"\nvehicle = \"{}\"\nduration_s = 0.6\nseeds = [1, 2, 3]\n\
         [[condition]]\nname = \"tangent\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        root().join("vehicles/c80.toml").display(),
        root().join("tracks/tangent.toml").display()
    );
    std::fs::write(dir.join("p.plan.toml"), plan_text).unwrap();
    let plan = Plan::load(&dir.join("p.plan.toml")).unwrap();
    let noise = NoiseModel::new(6.0, SnrReference::Std);
    let opts = GenerateOptions {
        out: dir.join("data"),
        format: Format::Npz,
        jobs: 2,
        shard: None,
        noise: Some(noise),
        settle: 0.1,
        stepping: Default::default(),
    };
    dataset::generate(&plan, &opts, &|_| {}).unwrap();
    let ds = DataSet::load(&dir.join("data")).unwrap();
    let spec = DataSpec {
        channels: railforce::sensors::PAPER_CHANNELS
            .iter()
            .map(|c| c.to_string())
            .collect(),
        targets: ds.labels.to_vec(),
        window: 20,
        label_at: LabelAt::Last,
        stride: 1,
        split: Split::standard(&ds),
        noise: NoiseProtocol::Matched,
        noise_model: None,
    };
    let mut model = train(
        &ds,
        &spec,
        ModelKind::Tree,
        &TrainOptions::default(),
        &dir.join("model"),
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(
        model.meta.data.noise_model,
        Some(noise),
        "the model records its SNR"
    );
    model.meta.calibration =
        Some(railforce::learn::uncertainty::calibrate(&mut model, &ds).unwrap());
    let work = dir.join("closed_loop");
    let limits = Limits::default();
    let checks =
        closed_loop::validate(&mut model, &plan, 1001, &work, 1, &limits, 0.2, None).unwrap();
    assert_eq!(checks.len(), 1);
    // The same loop through a field recorder's conventions (its own column, g, the axis
    // flipped, time in ms): written as RUN.field.csv, read back through the map, the same
    // identification.
    let first = model.meta.data.channels[0].clone();
    let map_path = dir.join("map.toml");
    std::fs::write(
        &map_path,
        format!(
            "time = {{ column = \"Time\", unit = \"ms\" }}\n[channels]\n{first} = {{ column = \"ACC_1\", unit = \"g\", sign = -1 }}\n"
        ),
    )
    .unwrap();
    let map = railforce::identify::ChannelMap::load(&map_path).unwrap();
    let field_work = dir.join("closed_loop_field");
    let through = closed_loop::validate(
        &mut model,
        &plan,
        1001,
        &field_work,
        1,
        &limits,
        0.2,
        Some(&map),
    )
    .unwrap();
    let rec = std::fs::read_to_string(field_work.join("tangent_seed1001.field.csv")).unwrap();
    assert!(rec.starts_with("Time,") && rec.lines().next().unwrap().contains("ACC_1"));
    assert!(!rec.lines().next().unwrap().contains(first.as_str()));
    for (a, b) in checks[0].targets.iter().zip(&through[0].targets) {
        assert!((a.r2 - b.r2).abs() < 1e-6 && (a.rmse_kn - b.rmse_kn).abs() < 1e-6);
    }
    // The calibrated interval's coverage and width on the fresh run, per target.
    for t in &checks[0].targets {
        let (c, w) = (t.coverage.unwrap(), t.width_kn.unwrap());
        assert!(
            (0.0..=1.0).contains(&c) && w > 0.0 && w.is_finite(),
            "{c} {w}"
        );
    }
    // The report: labelled JSON, tidy traces, a page whose every link resolves.
    let report = dir.join("report");
    let settings = railforce::identify::check_report::CheckSettings {
        model: "tree",
        plan: "closed",
        seed: 1001,
        margin: 0.2,
        limits: &limits,
        noise: noise.describe(),
    };
    let index = railforce::identify::check_report::write(&report, &checks, &settings).unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report.join("closed_loop.json")).unwrap())
            .unwrap();
    let first = &json["runs"][0]["safety"][0];
    assert_eq!(first["index"], "Y/Q");
    assert_eq!(first["place"], "w1l");
    assert!(first["true_p99_85"].is_number() && first["verdicts_agree"].is_boolean());
    // The acceptance statistics of the identified forces against the true ones.
    let stat = &json["runs"][0]["assessment"][0];
    assert!(
        stat["true_value"].is_number() && stat["identified_value"].is_number(),
        "{stat}"
    );
    assert!(
        json["runs"][0]["assessment"]
            .as_array()
            .unwrap()
            .iter()
            .any(|s| s["quantity"] == "(Y/Q)2m")
    );
    let traces = std::fs::read_to_string(report.join("traces.csv")).unwrap();
    assert!(traces.starts_with(
        "condition,seed,time_s,w1l_force_y_true_n,w1l_force_y_identified_n,w1l_force_z_true_n"
    ));
    assert_eq!(traces.lines().count(), 1 + checks[0].truth.time.len());
    let html = std::fs::read_to_string(&index).unwrap();
    for part in html.split("src=\"").skip(1) {
        let target = part.split('"').next().unwrap();
        assert!(report.join(target).is_file(), "{target}");
    }
    assert!(html.contains("trace_000_w1l_force_z.svg") && html.contains("p99_85_ratio.svg"));
    assert!(checks[0].targets.iter().all(|t| t.rmse_kn.is_finite()));
    let fresh = DataSet::load(&work).unwrap();
    assert_eq!(
        fresh.noise,
        Some(noise),
        "fresh runs noised at the model's SNR"
    );
    assert!(fresh.channel("ws1_acc_z_noisy").is_ok());
}

/// One signal under two names is one candidate: the second name is dropped.
#[test]
fn a_signal_recorded_twice_is_one_candidate() {
    let a: Vec<f64> = (0..50).map(|i| (i as f64).sin()).collect();
    let c: Vec<f64> = (0..50).map(|i| (i as f64).cos()).collect();
    let run = railforce::dataset::Run {
        condition: "c".into(),
        seed: 1,
        columns: vec![a.clone(), a, c],
    };
    let names: Vec<String> = ["ws1_acc_y", "wheelset1_acc_y", "carbody_acc_y"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let ds = DataSet::in_memory(&PathBuf::from("mem"), names.clone(), vec![run]);
    assert_eq!(ds.distinct_channels(&names), ["ws1_acc_y", "carbody_acc_y"]);
}
