//! Identification: input checks, agreement with evaluation, streaming equals batch.

use railforce::dataset::{DataSet, Run};
use railforce::features::{LabelAt, NoiseProtocol, Split};
use railforce::identify::{SensorTable, Streamer, check, identify};
use railforce::learn::evaluate::{EvalPart, evaluate};
use railforce::learn::model::{Model, ModelKind};
use railforce::learn::train::{TrainOptions, train};
use railforce::learn::windows::DataSpec;
use std::path::PathBuf;

fn synthetic(rows: usize) -> DataSet {
    let names: Vec<String> = ["time_s", "a", "b", "w1l_force_y"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let a: Vec<f64> = (0..rows).map(|t| (0.05 * t as f64).sin()).collect();
    let b: Vec<f64> = (0..rows).map(|t| (0.021 * t as f64).cos()).collect();
    let y: Vec<f64> = (0..rows)
        .map(|t| 1000.0 * a[t] * b[t.saturating_sub(2)])
        .collect();
    let time: Vec<f64> = (0..rows).map(|t| t as f64 * 0.005).collect();
    let run = Run {
        condition: "c".into(),
        seed: 1,
        columns: vec![time, a, b, y],
    };
    DataSet::in_memory(&PathBuf::from("synthetic"), names, vec![run])
}

/// The synthetic data set's windows: channels a and b, 6 steps, the label at `label_at`.
fn spec_of(label_at: LabelAt) -> DataSpec {
    DataSpec {
        channels: vec!["a".into(), "b".into()],
        targets: vec!["w1l_force_y".into()],
        window: 6,
        label_at,
        stride: 1,
        split: Split::default(),
        noise: NoiseProtocol::Clean,
        noise_model: None,
    }
}

fn model(label_at: LabelAt, test: &str) -> (DataSet, Model) {
    let ds = synthetic(600);
    let spec = spec_of(label_at);
    let out = std::env::temp_dir().join(format!(
        "railforce-identify-{}-{test}-{label_at:?}",
        std::process::id()
    ));
    let opts = TrainOptions {
        epochs: 3,
        batch: 32,
        ..TrainOptions::default()
    };
    let m = train(&ds, &spec, ModelKind::Gru, &opts, &out, &mut |_| {}).unwrap();
    (ds, m)
}

fn table(ds: &DataSet) -> SensorTable {
    let cols = ds
        .names
        .iter()
        .cloned()
        .zip(ds.runs[0].columns.iter().cloned())
        .collect();
    SensorTable::from_columns("test input".into(), cols).unwrap()
}

#[test]
fn bad_input_gets_a_clear_error() {
    let (ds, m) = model(LabelAt::Last, "errors");
    let good = table(&ds);
    let mut missing = good.clone();
    missing.columns.retain(|(n, _)| n != "b");
    let e = check(&missing, &m, false).unwrap_err().to_string();
    assert!(e.contains("missing channel(s) b"), "{e}");
    let mut nan = good.clone();
    nan.columns[0].1[41] = f64::NAN;
    let e = check(&nan, &m, false).unwrap_err().to_string();
    assert!(e.contains("column a, row 42"), "{e}");
    // A value no sensor gives (it overflowed the network into NaN, blamed on the output).
    let mut huge = good.clone();
    huge.columns[0].1[9] = 1e300;
    let e = check(&huge, &m, false).unwrap_err().to_string();
    assert!(
        e.contains("column a, row 10") && e.contains("standard deviations"),
        "{e}"
    );
    // Time running backwards is told as such, not as an infinite rate.
    let mut back = good.clone();
    back.time[51] = back.time[49];
    let e = check(&back, &m, false).unwrap_err().to_string();
    assert!(e.contains("time does not increase"), "{e}");
    let mut slow = good.clone();
    slow.time = (0..slow.time.len()).map(|i| i as f64 * 0.01).collect();
    let e = check(&slow, &m, false).unwrap_err().to_string();
    assert!(e.contains("100.0 Hz") && e.contains("resampling"), "{e}");
    // Resampling a 100 Hz record gives a 200 Hz one of the same span.
    let r = check(&slow, &m, true).unwrap();
    assert_eq!(r.time.len(), 2 * slow.time.len() - 1);
    let mut gap = good.clone();
    gap.time[300..].iter_mut().for_each(|t| *t += 0.5);
    let e = check(&gap, &m, false).unwrap_err().to_string();
    assert!(e.contains("rows 300–301"), "{e}");
    let e = SensorTable::from_columns("x".into(), vec![("a".into(), vec![1.0])])
        .unwrap_err()
        .to_string();
    assert!(e.contains("no time column"), "{e}");
}

#[test]
fn identify_reproduces_the_evaluation_and_streaming_equals_batch() {
    for label_at in [LabelAt::Last, LabelAt::Centre] {
        let (ds, mut m) = model(label_at, "agree");
        let ev = evaluate(&mut m, &ds, EvalPart::All).unwrap();
        let input = check(&table(&ds), &m, false).unwrap();
        let id = identify(&mut m, &input);
        assert_eq!(id.time.len(), ev.rows.len());
        for (i, row) in ev.rows.iter().enumerate() {
            assert!((row.2 - id.time[i]).abs() < 1e-9, "label times align");
            let (truth, pred) = row.3[0];
            assert!(
                (pred - id.values[i][0]).abs() < 1e-6 * truth.abs().max(1.0) + 1e-3,
                "same numbers as evaluate"
            );
        }
        let mut st = Streamer::new(&mut m);
        let mut streamed = Vec::new();
        for (i, t) in input.time.iter().enumerate() {
            let v: Vec<f64> = input.columns.iter().map(|c| c[i]).collect();
            if let Some(e) = st.push(*t, &v) {
                streamed.push(e);
            }
        }
        assert_eq!(streamed.len(), id.time.len());
        for (s, (t, v)) in streamed.iter().enumerate() {
            assert_eq!(*t, id.time[s]);
            assert!(
                (v[0] - id.values[s][0]).abs() <= 1e-6 * v[0].abs().max(1.0),
                "{} vs {}",
                v[0],
                id.values[s][0]
            );
        }
    }
}

/// A deep ensemble of three GRUs (`train --ensemble 3`): saved and loaded back it predicts the
/// same, its bands at 90 % are ordered (lo ≤ value ≤ hi) and finite, wider at 95 % than at
/// 50 %, and a model without calibration gives none.
#[test]
fn ensemble_bands_are_ordered_finite_and_survive_a_round_trip() {
    use railforce::identify::identify_with_bands;
    use railforce::learn::uncertainty::train_ensemble;
    let ds = synthetic(600);
    let spec = spec_of(LabelAt::Centre);
    let out = std::env::temp_dir().join(format!("railforce-ensemble-{}", std::process::id()));
    let opts = TrainOptions {
        epochs: 3,
        batch: 32,
        ..TrainOptions::default()
    };
    let mut m = train_ensemble(&ds, &spec, ModelKind::Gru, &opts, 3, &out, &mut |_, _| {}).unwrap();
    assert_eq!((m.meta.members, m.members.len()), (3, 2));
    let cal = m.meta.calibration.clone().expect("calibrated");
    assert_eq!(cal.score, railforce::learn::uncertainty::Score::Normalised);
    let input = check(&table(&ds), &m, false).unwrap();
    let (id, bands) = identify_with_bands(&mut m, &input, Some(0.9));
    let bands = bands.expect("bands");
    assert_eq!(bands.bounds.len(), id.values.len());
    for (b, v) in bands.bounds.iter().zip(&id.values) {
        let (lo, hi) = b[0];
        assert!(
            lo.is_finite() && hi.is_finite() && lo <= v[0] && v[0] <= hi,
            "{lo} {} {hi}",
            v[0]
        );
    }
    let width = |c: f64, m: &mut Model| {
        let b = identify_with_bands(m, &input, Some(c)).1.unwrap();
        b.bounds.iter().map(|r| r[0].1 - r[0].0).sum::<f64>()
    };
    assert!(width(0.95, &mut m) > width(0.5, &mut m));
    let mut back = Model::load(&out).unwrap();
    let (id2, bands2) = identify_with_bands(&mut back, &input, Some(0.9));
    assert_eq!(id2.values, id.values);
    assert_eq!(bands2.unwrap(), bands);
    let (_, mut single) = model(LabelAt::Centre, "nocal");
    assert!(
        identify_with_bands(&mut single, &input, Some(0.9))
            .1
            .is_none()
    );
    let _ = std::fs::remove_dir_all(&out);
}

/// Every channel the recorder writes for the C80 has the unit `sim::output::unit_of` gives its
/// name (the channel map converts to it).
#[test]
fn unit_of_agrees_with_the_recorder() {
    let v = railforce::vehicle::Vehicle::load(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("vehicles/c80.toml"),
    )
    .unwrap();
    let track = railforce::sim::checks::smooth_tangent(300.0);
    let sim = railforce::sim::Simulation::new(&v, &track, Default::default()).unwrap();
    let rec = railforce::sim::Recorder::new(&sim);
    assert!(rec.names().len() > 200);
    for (n, u) in rec.names().iter().zip(rec.units()) {
        assert_eq!(railforce::sim::output::unit_of(n), Some(*u), "{n}");
        assert_eq!(
            railforce::sim::output::unit_of(&format!("{n}_noisy")),
            Some(*u)
        );
    }
    assert_eq!(railforce::sim::output::unit_of("wagon_speed"), None);
}

/// A field recording with its own names, units (g, deg/s), signs and a time column in ms,
/// read through a channel map, identifies the same forces as the recording in railforce's
/// names and units; a missing column, a unit that does not convert, an unknown unit and a
/// channel the model does not read are errors naming the map, the channel and the column.
#[test]
fn channel_map_reads_a_field_recording() {
    use railforce::identify::ChannelMap;
    let rows = 600;
    let names: Vec<String> = ["time_s", "ws1_acc_y", "body_yaw_rate", "w1l_force_y"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let a: Vec<f64> = (0..rows).map(|t| 2.0 * (0.05 * t as f64).sin()).collect();
    let b: Vec<f64> = (0..rows).map(|t| 0.01 * (0.021 * t as f64).cos()).collect();
    let y: Vec<f64> = (0..rows)
        .map(|t| 1000.0 * a[t] * b[t.saturating_sub(2)] * 50.0)
        .collect();
    let time: Vec<f64> = (0..rows).map(|t| t as f64 * 0.005).collect();
    let ds = DataSet::in_memory(
        &PathBuf::from("synthetic"),
        names.clone(),
        vec![Run {
            condition: "c".into(),
            seed: 1,
            columns: vec![time.clone(), a.clone(), b.clone(), y],
        }],
    );
    let spec = DataSpec {
        channels: vec!["ws1_acc_y".into(), "body_yaw_rate".into()],
        targets: vec!["w1l_force_y".into()],
        window: 6,
        label_at: LabelAt::Centre,
        stride: 1,
        split: Split::default(),
        noise: NoiseProtocol::Clean,
        noise_model: None,
    };
    let dir = std::env::temp_dir().join(format!("railforce-chmap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let opts = TrainOptions {
        epochs: 2,
        batch: 32,
        ..TrainOptions::default()
    };
    let mut m = train(
        &ds,
        &spec,
        ModelKind::Gru,
        &opts,
        &dir.join("m"),
        &mut |_| {},
    )
    .unwrap();
    let plain = check(&table(&ds), &m, false).unwrap();
    let want = identify(&mut m, &plain);
    // The field recording: other names, g and deg/s, the lateral axis flipped, time in ms.
    let mut csv = String::from("Time,LAT_ACC,GYRO_Z\n");
    for t in 0..rows {
        csv += &format!(
            "{},{},{}\n",
            time[t] * 1000.0,
            -a[t] / 9.80665,
            b[t].to_degrees()
        );
    }
    let rec = dir.join("field.csv");
    std::fs::write(&rec, csv).unwrap();
    let map_text = "time = { column = \"Time\", unit = \"ms\" }\n[channels]\nws1_acc_y = { column = \"LAT_ACC\", unit = \"g\", sign = -1 }\nbody_yaw_rate = { column = \"GYRO_Z\", unit = \"deg/s\" }\n";
    let map_path = dir.join("map.toml");
    std::fs::write(&map_path, map_text).unwrap();
    let map = ChannelMap::load(&map_path).unwrap();
    let field = map.read(&rec, &m.meta.data.channels).unwrap();
    let input = check(&field, &m, false).unwrap();
    let got = identify(&mut m, &input);
    assert_eq!(got.time.len(), want.time.len());
    for (g, w) in got.values.iter().zip(&want.values) {
        assert!(
            (g[0] - w[0]).abs() < 1e-3 * w[0].abs().max(1.0),
            "{} vs {}",
            g[0],
            w[0]
        );
    }
    // Errors name the map, the channel and the column.
    for (text, says) in [
        (
            map_text.replace("GYRO_Z", "GYRO_X"),
            "channels.body_yaw_rate",
        ),
        (
            map_text.replace("unit = \"deg/s\"", "unit = \"g\""),
            "does not convert to the channel's rad/s",
        ),
        (
            map_text.replace("unit = \"deg/s\"", "unit = \"furlong\""),
            "unknown unit \"furlong\"",
        ),
        (
            map_text.replace(
                "[channels]\n",
                "[channels]\nws2_acc_y = { column = \"Time\" }\n",
            ),
            "does not read this channel",
        ),
        (
            map_text.replace(
                "[channels]\n",
                "[channels]\nws2_acc_y = { column = \"LAT_ACC\" }\n",
            ),
            "\"LAT_ACC\" is already channels.ws1_acc_y's",
        ),
    ] {
        std::fs::write(&map_path, &text).unwrap();
        let e = ChannelMap::load(&map_path)
            .and_then(|m2| m2.read(&rec, &m.meta.data.channels))
            .err()
            .unwrap_or_else(|| panic!("accepted: {text}"))
            .to_string();
        assert!(e.contains("map.toml") && e.contains(says), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The out-of-distribution flag stays quiet on inputs like the training runs and fires where a
/// channel is planted off its range, naming that channel and only that stretch.
#[test]
fn ood_flag_fires_on_a_planted_offset_and_stays_quiet_otherwise() {
    use railforce::identify::out_of_distribution;
    use railforce::learn::uncertainty::train_ensemble;
    let ds = synthetic(600);
    let spec = spec_of(LabelAt::Centre);
    let out = std::env::temp_dir().join(format!("railforce-ood-{}", std::process::id()));
    let opts = TrainOptions {
        epochs: 2,
        batch: 32,
        ..TrainOptions::default()
    };
    let m = train_ensemble(&ds, &spec, ModelKind::Gru, &opts, 1, &out, &mut |_, _| {}).unwrap();
    assert_eq!(m.meta.calibration.as_ref().unwrap().envelope.len(), 2);
    let quiet = out_of_distribution(&m, &check(&table(&ds), &m, false).unwrap()).unwrap();
    assert_eq!(quiet.share(), 0.0, "in distribution: no flag");
    // Channel a (a sine of amplitude 1) shifted by 3 from row 300 to 349.
    let mut t = table(&ds);
    let a = t.columns.iter_mut().find(|(n, _)| n == "a").unwrap();
    for v in &mut a.1[300..350] {
        *v += 3.0;
    }
    let input = check(&t, &m, false).unwrap();
    let ood = out_of_distribution(&m, &input).unwrap();
    let time: Vec<f64> = (0..ood.channels.len()).map(|i| i as f64).collect();
    let spans = ood.spans(&time, &m.meta.data.channels);
    assert_eq!(spans.len(), 1, "{spans:?}");
    assert_eq!(spans[0].channels, vec!["a".to_string()]);
    // Windows of 6 that hold any of rows 300–349 start at 295–349.
    assert_eq!((spans[0].from_s, spans[0].to_s), (295.0, 349.0));
    let _ = std::fs::remove_dir_all(&out);
}
