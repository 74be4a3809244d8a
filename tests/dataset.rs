//! Data set generation: formats, resume, shards, noise, and loading from Python.

use crate::common;

use railforce::dataset::{self, Event, Format, GenerateOptions, Manifest, npz};
use railforce::plan::Plan;
use railforce::sensors::{NoiseModel, SnrReference};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("railforce-ds-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A tiny plan: three short runs on the paper's tangent and R 400 m tracks.
fn tiny_plan(dir: &Path) -> Plan {
    let r = root();
    let text = format!(
        "name = \"tiny\"\nvehicle = \"{}\"\nduration_s = 0.3\nseeds = [1]\n\
         [[condition]]\nname = \"tangent_v80\"\ntrack = \"{}\"\nspeed_kmh = 80.0\nseeds = [1, 2]\n\
         [[condition]]\nname = \"curve_v60\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        r.join("vehicles/c80.toml").display(),
        r.join("tracks/tangent.toml").display(),
        r.join("tracks/curve_r400.toml").display()
    );
    let p = dir.join("tiny.plan.toml");
    std::fs::write(&p, text).unwrap();
    Plan::load(&p).unwrap()
}

fn opts(out: &Path, format: Format, shard: Option<(usize, usize)>) -> GenerateOptions {
    GenerateOptions {
        out: out.to_path_buf(),
        format,
        jobs: 2,
        shard,
        noise: Some(NoiseModel::new(6.0, SnrReference::Std)),
        settle: 0.2,
        stepping: Default::default(),
    }
}

fn run_events(plan: &Plan, o: &GenerateOptions) -> (serde_json::Value, Vec<Event>) {
    let events = Mutex::new(Vec::new());
    let m = dataset::generate(plan, o, &|e| events.lock().unwrap().push(e)).unwrap();
    // The typed manifest as it is on disk.
    (
        serde_json::to_value(&m).unwrap(),
        events.into_inner().unwrap(),
    )
}

fn started(events: &[Event]) -> usize {
    events
        .iter()
        .filter(|e| matches!(e, Event::Started(_)))
        .count()
}

#[test]
fn generate_resume_shard_merge_and_formats() {
    let dir = temp("main");
    let plan = tiny_plan(&dir);
    assert_eq!(dataset::runs(&plan).len(), 3);

    // Full generation, NPZ.
    let a = dir.join("a");
    let (m, ev) = run_events(&plan, &opts(&a, Format::Npz, None));
    assert_eq!(started(&ev), 3);
    let runs = m["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 3);
    let channels = m["channels"].as_array().unwrap();
    let kind = |n: &str| {
        channels
            .iter()
            .find(|c| c["name"] == n)
            .map(|c| c["kind"].as_str().unwrap().to_string())
    };
    assert_eq!(kind("w1l_force_z").as_deref(), Some("label"));
    assert_eq!(kind("frame_l_acc_y").as_deref(), Some("input"));
    assert_eq!(kind("frame_l_acc_y_noisy").as_deref(), Some("input_noisy"));
    assert_eq!(kind("w3r_force_y").as_deref(), Some("wheel"));
    assert!(channels.iter().all(|c| c["unit"].is_string()));
    // The manifest says how the runs were made: the integration step and settling time.
    assert_eq!(m["integration"]["dt_s"], 5e-3 / 6.0);
    assert!(m["integration"]["settle_s"].is_number());
    assert!(m["integration"]["integrator"].is_string());
    let file = a.join("tangent_v80_seed1.npz");
    let bytes = std::fs::read(&file).unwrap();
    let cols = npz::read_npz(&bytes).unwrap();
    assert_eq!(cols.len(), channels.len());
    assert!(cols.iter().all(|(_, v)| v.len() == 61), "0.3 s at 200 Hz");
    // Labels are never noised; inputs get a noised copy that differs.
    let col = |n: &str| &cols.iter().find(|(c, _)| c == n).unwrap().1;
    assert!(cols.iter().all(|(c, _)| c != "w1l_force_z_noisy"));
    assert_ne!(col("frame_l_acc_y"), col("frame_l_acc_y_noisy"));

    // A rerun skips everything and changes no byte.
    let identity = dataset::data_identity(&a).unwrap();
    let (_, ev) = run_events(&plan, &opts(&a, Format::Npz, None));
    assert_eq!(started(&ev), 0);
    assert_eq!(std::fs::read(&file).unwrap(), bytes);
    assert_eq!(dataset::data_identity(&a).unwrap(), identity);
    // A run file cut short since is simulated again, to the same bytes.
    std::fs::write(&file, &bytes[..bytes.len() / 2]).unwrap();
    let (_, ev) = run_events(&plan, &opts(&a, Format::Npz, None));
    assert_eq!(started(&ev), 1);
    assert_eq!(std::fs::read(&file).unwrap(), bytes);
    assert_eq!(dataset::data_identity(&a).unwrap(), identity);

    // Another integrator is another data set: a folder made at one is refused at another,
    // naming both (the default's step has changed, so a run's key alone cannot tell);
    // elsewhere it runs everything, the manifest says which, and the forces differ; a step
    // outside (0, 1 ms] is refused before any run.
    let li = dir.join("li");
    let stepping = railforce::sim::Stepping {
        integrator: railforce::sim::Integrator::SemiImplicit,
        dt: 2e-4,
        given: true,
    };
    std::fs::create_dir_all(&li).unwrap();
    for f in ["manifest.json", "tangent_v80_seed1.npz"] {
        std::fs::copy(a.join(f), li.join(f)).unwrap();
    }
    let o = GenerateOptions {
        stepping,
        ..opts(&li, Format::Npz, None)
    };
    let e = dataset::generate(&plan, &o, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("integration at 0.833") && e.contains("now 0.2 ms, semi-implicit"),
        "{e}"
    );
    std::fs::remove_dir_all(&li).unwrap();
    let (m_li, ev) = run_events(&plan, &o);
    assert_eq!(started(&ev), 3, "another integrator resumes nothing");
    assert_eq!(m_li["integration"]["dt_s"], 2e-4);
    assert!(
        m_li["integration"]["integrator"]
            .as_str()
            .unwrap()
            .starts_with("semi-implicit")
    );
    let li_cols = npz::read_npz(&std::fs::read(li.join("tangent_v80_seed1.npz")).unwrap()).unwrap();
    let q = |c: &[(String, Vec<f64>)]| {
        c.iter()
            .find(|(n, _)| n == "w1l_force_z")
            .unwrap()
            .1
            .clone()
    };
    assert_ne!(q(&li_cols), q(&cols));
    let bad = GenerateOptions {
        stepping: railforce::sim::Stepping {
            dt: 2e-3,
            ..stepping
        },
        ..opts(&dir.join("bad"), Format::Npz, None)
    };
    let e = dataset::generate(&plan, &bad, &|_| {})
        .unwrap_err()
        .to_string();
    assert!(e.contains("integration step") && e.contains("1 ms"), "{e}");
    assert!(!dir.join("bad/manifest.json").exists());

    // Interruption: one file lost and the manifest written before it finished.
    let manifest_path = a.join("manifest.json");
    let mut man: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest_path).unwrap()).unwrap();
    man["runs"]
        .as_array_mut()
        .unwrap()
        .retain(|r| r["file"] != "tangent_v80_seed1.npz");
    std::fs::write(&manifest_path, serde_json::to_string(&man).unwrap()).unwrap();
    std::fs::write(&file, b"half a file").unwrap();
    let (m2, ev) = run_events(&plan, &opts(&a, Format::Npz, None));
    assert_eq!(started(&ev), 1, "only the unfinished run is redone");
    assert_eq!(
        std::fs::read(&file).unwrap(),
        bytes,
        "same seed, same bytes"
    );
    assert_eq!(m2["runs"].as_array().unwrap().len(), 3);
    // The redone run has the same bytes, and so has the manifest (it holds no wall time):
    // the data identity (what reports and models quote) is unchanged.
    assert_eq!(dataset::data_identity(&a).unwrap(), identity);
    let manifest_a = std::fs::read(a.join("manifest.json")).unwrap();

    // Two shards and a merge give the same files and runs.
    let b = dir.join("b");
    run_events(&plan, &opts(&b, Format::Npz, Some((1, 2))));
    run_events(&plan, &opts(&b, Format::Npz, Some((2, 2))));
    let merged = serde_json::to_value(dataset::merge(&b).unwrap()).unwrap();
    let strip = |m: &serde_json::Value| {
        m["runs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| {
                (
                    r["file"].clone(),
                    r["bytes_hash_fnv1a"].clone(),
                    r["key"].clone(),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(strip(&merged), strip(&m2));
    assert_eq!(
        std::fs::read(b.join("manifest.json")).unwrap(),
        manifest_a,
        "shards and a merge write the manifest of one process, byte for byte"
    );
    for r in m2["runs"].as_array().unwrap() {
        let f = r["file"].as_str().unwrap();
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap()
        );
    }

    // CSV of the same run holds the same numbers (7 significant digits).
    let c = dir.join("c");
    run_events(&plan, &opts(&c, Format::Csv, Some((1, 3))));
    let text = std::fs::read_to_string(c.join("tangent_v80_seed1.csv")).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let names: Vec<&str> = cols.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(header, names);
    for (r, line) in text.lines().skip(1).enumerate() {
        for (k, v) in line.split(',').enumerate() {
            let x: f64 = v.parse().unwrap();
            let y = cols[k].1[r];
            assert!(
                (x - y).abs() <= 1e-6 * y.abs().max(1e-12),
                "{} row {r}",
                names[k]
            );
        }
    }

    // Parquet of the same run holds exactly the same numbers.
    let d = dir.join("d");
    run_events(&plan, &opts(&d, Format::Parquet, Some((1, 3))));
    let pq = d.join("tangent_v80_seed1.parquet");
    let back = dataset::parquet_file::read_parquet(std::fs::read(&pq).unwrap()).unwrap();
    assert_eq!(back, cols);

    // Python users load the NPZ and the Parquet file in one line.
    python_loads(&file, &pq, channels.len());
}

fn python_loads(npz_file: &Path, parquet_file: &Path, n_channels: usize) {
    if !common::python_with("numpy, pyarrow") {
        return;
    }
    let script = [
        "import numpy as np, pyarrow.parquet as pq".to_string(),
        format!("d = np.load(r'{}')", npz_file.display()),
        format!("assert len(d.files) == {n_channels}, len(d.files)"),
        "assert d['w1l_force_z'].shape == (61,)".into(),
        "assert d['frame_l_acc_y_noisy'].dtype == np.float64".into(),
        "assert 60e3 < d['w1l_force_z'].mean() < 200e3".into(),
        format!("t = pq.read_table(r'{}')", parquet_file.display()),
        format!("assert t.num_rows == 61 and t.num_columns == {n_channels}"),
        "assert t.column_names == d.files".into(),
        "assert np.array_equal(t.column('w1l_force_z').to_numpy(), d['w1l_force_z'])".into(),
        "print('ok')".into(),
    ]
    .join("\n");
    common::succeed(std::process::Command::new("python3").args(["-c", &script]));
}

#[test]
fn noise_has_the_stated_variance_and_is_seeded() {
    // An offset, as gravity in a vertical accelerometer: the rms reference sees it, the std
    // reference (the default) does not.
    let clean: Vec<f64> = (0..40_000)
        .map(|i| (i as f64 * 0.01).sin() * 3.0 + 9.81)
        .collect();
    let rms = (clean.iter().map(|x| x * x).sum::<f64>() / clean.len() as f64).sqrt();
    let std = 3.0 / 2f64.sqrt();
    for (snr, reference, scale) in [
        (0.0, SnrReference::Std, std),
        (6.0, SnrReference::Std, std),
        (20.0, SnrReference::Std, std),
        (6.0, SnrReference::Rms, rms),
    ] {
        let m = NoiseModel::new(snr, reference);
        let noisy = m.apply(&clean, 7, "ws1_acc_z");
        let var = noisy
            .iter()
            .zip(&clean)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / clean.len() as f64;
        let want = (scale * 10f64.powf(-snr / 20.0)).powi(2);
        assert!(
            (var / want - 1.0).abs() < 0.03,
            "SNR {snr}: {var} vs {want}"
        );
        assert_eq!(noisy, m.apply(&clean, 7, "ws1_acc_z"));
        assert_ne!(noisy, m.apply(&clean, 8, "ws1_acc_z"));
    }
}

#[test]
fn bad_shard_is_refused() {
    let dir = temp("shard");
    let plan = tiny_plan(&dir);
    let e = dataset::generate(
        &plan,
        &opts(&dir.join("x"), Format::Csv, Some((3, 2))),
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("shard 3/2") && e.contains("1 ≤ i ≤ N"), "{e}");
}

/// Every per-condition key of a plan is read, and a bad one is refused with the file and key.
#[test]
fn plan_keys_are_read_and_bad_ones_named() {
    let dir = temp("plankeys");
    let r = root();
    let write = |text: &str| {
        let p = dir.join("k.plan.toml");
        std::fs::write(&p, text).unwrap();
        p
    };
    let head = format!(
        "vehicle = \"{}\"\nduration_s = 1.0\nseeds = \"2-4\"\n",
        r.join("vehicles/c80.toml").display()
    );
    let cond = format!(
        "[[condition]]\nname = \"c\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        r.join("tracks/curve_r400.toml").display()
    );
    let good = format!(
        "{head}[dataset]\nchannels = [\"input\", \"carbody_acc_y\"]\nfloat32 = true\n{cond}\
         vehicle = \"{}\"\nclass = 4\nstart_m = 120.0\nseeds = [7, 9]\n{cond}",
        r.join("vehicles/c80_empty.toml").display()
    )
    .replacen("name = \"c\"", "name = \"d\"", 1);
    let plan = Plan::load(&write(&good)).unwrap();
    let (d, c) = (&plan.conditions[0], &plan.conditions[1]);
    assert_eq!(d.seeds, vec![7, 9]);
    assert_eq!(d.class, Some(4));
    assert_eq!(d.start_m, Some(120.0));
    assert!(d.vehicle.ends_with("c80_empty.toml"));
    assert_eq!(c.seeds, vec![2, 3, 4], "the plan's range");
    assert!(c.vehicle.ends_with("c80.toml") && c.class.is_none());
    assert!(plan.dataset.float32);
    assert_eq!(plan.dataset.channels, ["input", "carbody_acc_y"]);
    for (bad, expect) in [
        (format!("{head}{cond}class = 7\n"), "condition[0].class"),
        (
            format!("{head}{cond}start_m = -1.0\n"),
            "condition[0].start_m",
        ),
        (
            format!("{head}{cond}seeds = \"5-1\"\n"),
            "condition[0].seeds",
        ),
        (
            format!("{head}{cond}seeds = \"a-b\"\n"),
            "condition[0].seeds",
        ),
        (format!("{head}{cond}colour = \"red\"\n"), "colour"),
        (head.replace("\"2-4\"", "[3, 3]") + &cond, "seeds"),
        (
            format!("{head}[dataset]\nchannels = [\"\"]\n{cond}"),
            "dataset.channels",
        ),
        // Files that are not there are named with the key that names them.
        (
            format!(
                "{head}{}",
                cond.replace("curve_r400.toml", "curve_r401.toml")
            ),
            "condition[0].track: ",
        ),
        (head.replace("c80.toml", "c81.toml") + &cond, "vehicle: "),
        (
            format!("{head}{cond}vehicle = \"nowhere.toml\"\n"),
            "condition[0].vehicle: ",
        ),
    ] {
        let err = Plan::load(&write(&bad)).unwrap_err().to_string();
        assert!(
            err.contains(expect) && err.contains("k.plan.toml"),
            "{expect}: {err}"
        );
    }
}

/// A float32 data set with a channel subset: only the kept channels, values equal to the
/// float64 data set's to float32 precision, time still exact; and numpy reads it.
#[test]
fn float32_subset_keeps_values_to_float32_precision() {
    let dir = temp("f32");
    let r = root();
    let text = |extra: &str| {
        format!(
            "name = \"f\"\nvehicle = \"{}\"\nduration_s = 0.3\nseeds = [1]\n{extra}\
             [[condition]]\nname = \"t\"\ntrack = \"{}\"\nspeed_kmh = 80.0\nclass = 4\nstart_m = 15.0\n",
            r.join("vehicles/c80.toml").display(),
            r.join("tracks/tangent.toml").display()
        )
    };
    let p64 = dir.join("a.plan.toml");
    let p32 = dir.join("b.plan.toml");
    std::fs::write(&p64, text("")).unwrap();
    std::fs::write(
        &p32,
        text("[dataset]\nchannels = [\"input\", \"deflection\"]\nfloat32 = true\n"),
    )
    .unwrap();
    let (a, b) = (dir.join("a"), dir.join("b"));
    run_events(&Plan::load(&p64).unwrap(), &opts(&a, Format::Npz, None));
    let (m, _) = run_events(&Plan::load(&p32).unwrap(), &opts(&b, Format::Npz, None));
    assert_eq!(m["dataset"]["float32"], true);
    assert_eq!(m["runs"][0]["class"], 4);
    let (da, db) = (
        railforce::dataset::DataSet::load(&a).unwrap(),
        railforce::dataset::DataSet::load(&b).unwrap(),
    );
    assert!(db.names.len() < da.names.len());
    for n in [
        "time_s",
        "s_m",
        "w1l_force_z",
        "frame_l_acc_y",
        "frame_l_acc_y_noisy",
        "pad_sideframe1l_wheelset1_z",
    ] {
        assert!(db.channel(n).is_ok(), "{n} kept");
    }
    assert!(db.channel("w2r_force_y").is_err(), "wheel forces dropped");
    for n in [
        "time_s",
        "w1l_force_z",
        "frame_l_acc_y_noisy",
        "pad_sideframe1l_wheelset1_z",
    ] {
        let x = &da.runs[0].columns[da.channel(n).unwrap()];
        let y = &db.runs[0].columns[db.channel(n).unwrap()];
        for (u, v) in x.iter().zip(y) {
            if n == "time_s" {
                assert_eq!(u, v);
            } else {
                assert_eq!(*u as f32 as f64, *v, "{n}");
            }
        }
    }
    let size = |d: &Path| std::fs::metadata(d.join("t_seed1.npz")).unwrap().len();
    assert!(size(&b) < size(&a) / 2, "{} vs {}", size(&b), size(&a));
    if common::python_with("numpy") {
        let script = format!(
            "import numpy as np\nd = np.load(r'{}')\nassert d['w1l_force_z'].dtype == np.float32\nassert d['time_s'].dtype == np.float64\nprint('ok')",
            b.join("t_seed1.npz").display()
        );
        common::succeed(std::process::Command::new("python3").args(["-c", &script]));
    }
    // The folder now holds a float32 data set: the float64 plan is refused there.
    let err = dataset::generate(
        &Plan::load(&p64).unwrap(),
        &opts(&b, Format::Npz, None),
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("data-set options") && err.contains("another folder"),
        "{err}"
    );
}

/// The typed manifest reads every manifest format railforce has written: format 4 (written
/// back byte for byte), format 3 with each run's wall time (read and dropped), format 2
/// without `integration`, and the first writer's format 1 without the data-set options, the
/// noise reference, the accelerometer setting, the label wheel and each run's vehicle, class
/// and start.
#[test]
fn typed_manifest_reads_every_format() {
    let dir = root().join("tests/fixtures/manifests");
    let current = dir.join("format4.json");
    let m = Manifest::read(&current).unwrap().unwrap();
    let integration = m.integration.as_ref().unwrap();
    assert_eq!(integration.dt_s, 2e-4);
    assert_eq!(m.labels(), ["w1l_force_y", "w1l_force_z"]);
    assert_eq!(
        m.conventions.labels.as_ref().unwrap().wheel.as_deref(),
        Some("1L")
    );
    let noise = m.noise_model(&current).unwrap().unwrap();
    assert_eq!((noise.snr_db, noise.reference), (6.0, SnrReference::Std));
    assert_eq!(m.runs.len(), 2);
    assert_eq!(m.runs[0].vehicle.as_deref(), Some("C80 loaded (100 t)"));
    let tmp = temp("manifest_round_trip");
    let back = tmp.join("manifest.json");
    m.write(&back).unwrap();
    assert_eq!(
        std::fs::read_to_string(&back).unwrap(),
        std::fs::read_to_string(&current).unwrap(),
        "the typed manifest writes the untyped writer's bytes"
    );

    let format3 = Manifest::read(&dir.join("format3-run-wall-times.json"))
        .unwrap()
        .unwrap();
    assert_eq!(
        format3, m,
        "the wall times of format 3 are read and dropped"
    );

    let format2 = Manifest::read(&dir.join("format2-no-integration.json"))
        .unwrap()
        .unwrap();
    assert!(format2.integration.is_none());
    assert_eq!(format2.runs, m.runs);

    let first = dir.join("format1-first-writer.json");
    let old = Manifest::read(&first).unwrap().unwrap();
    assert_eq!(old.dataset, railforce::plan::DatasetOptions::default());
    assert_eq!(old.labels(), ["w1l_force_y", "w1l_force_z"]);
    assert!(old.conventions.accelerometers.is_none());
    assert!(
        old.runs
            .iter()
            .all(|r| r.vehicle.is_none() && r.class.is_none())
    );
    // No reference recorded with an SNR: the rms, as that writer's noise said.
    let noise = old.noise_model(&first).unwrap().unwrap();
    assert_eq!(noise.reference, SnrReference::Rms);
}

/// A manifest field that is there but cannot be read is an error naming the file and the
/// field, never a silent default.
#[test]
fn unreadable_manifest_field_is_named() {
    let text =
        std::fs::read_to_string(root().join("tests/fixtures/manifests/format4.json")).unwrap();
    let tmp = temp("manifest_bad_field");
    for (from, to, field) in [
        ("\"snr_db\": 6.0", "\"snr_db\": \"six\"", "snr_db"),
        ("\"seed\": 4", "\"seed\": -4", "seed"),
        ("\"dt_s\": 0.0002", "\"dt_s\": [0.0002]", "dt_s"),
    ] {
        assert!(text.contains(from), "{from}");
        let path = tmp.join("manifest.json");
        std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
        let e = Manifest::read(&path).unwrap_err().to_string();
        assert!(e.contains("manifest.json"), "{e}");
        assert!(e.contains(&format!("field \"{field}\"")), "{e}");
    }
    let path = tmp.join("manifest.json");
    std::fs::write(
        &path,
        text.replacen(
            "\"snr_reference\": \"std\"",
            "\"snr_reference\": \"peak\"",
            1,
        ),
    )
    .unwrap();
    let m = Manifest::read(&path).unwrap().unwrap();
    let e = m.noise_model(&path).unwrap_err().to_string();
    assert!(e.contains("snr_reference") && e.contains("peak"), "{e}");
}

/// Every condition draws its own irregularities and noise at a seed; (condition, seed) repeats.
#[test]
fn conditions_draw_their_own_realisation() {
    use railforce::track::{Track, TrackSpec};
    let r = root();
    // Two conditions of one track and speed: only their names differ.
    let spec = TrackSpec::load(&r.join("tracks/tangent.toml")).unwrap();
    let rails = |name: &str, seed: u64| {
        let t = Track::new(spec.clone(), Some(dataset::realisation_seed(name, seed)));
        let irr = t.irregularities().expect("tangent.toml has irregularities");
        (0..50)
            .map(|i| irr.raw_rails_at(300.0 + 7.3 * i as f64).left_y)
            .collect::<Vec<f64>>()
    };
    assert_eq!(
        rails("a", 4),
        rails("a", 4),
        "same condition and seed, same rails"
    );
    assert_ne!(
        rails("a", 4),
        rails("b", 4),
        "two conditions, two realisations"
    );
    assert_ne!(rails("a", 4), rails("a", 5), "two seeds, two realisations");

    let dir = temp("realisation");
    let text = format!(
        "name = \"twins\"\nvehicle = \"{}\"\nduration_s = 0.3\nseeds = [4]\n\
         [[condition]]\nname = \"a\"\ntrack = \"{t}\"\nspeed_kmh = 80.0\n\
         [[condition]]\nname = \"b\"\ntrack = \"{t}\"\nspeed_kmh = 80.0\n",
        r.join("vehicles/c80.toml").display(),
        t = r.join("tracks/tangent.toml").display()
    );
    let p = dir.join("twins.plan.toml");
    std::fs::write(&p, text).unwrap();
    let plan = Plan::load(&p).unwrap();
    let out = dir.join("out");
    let (m, _) = run_events(&plan, &opts(&out, Format::Csv, None));
    for run in m["runs"].as_array().unwrap() {
        let name = run["condition"].as_str().unwrap();
        assert_eq!(
            run["realisation_seed"].as_u64(),
            Some(dataset::realisation_seed(name, 4)),
            "the manifest records the realisation of {name}"
        );
    }
    // The clean channels differ (their own rails), and so does the noise: the two runs'
    // noise sequences (noisy − clean, each scaled by its own run's std) are uncorrelated.
    let table = |name: &str| {
        railforce::dataset::read_table(&out.join(format!("{name}_seed4.csv"))).unwrap()
    };
    let (a, b) = (table("a"), table("b"));
    let col = |t: &[(String, Vec<f64>)], n: &str| {
        t.iter()
            .find(|(c, _)| c == n)
            .map(|(_, v)| v.clone())
            .unwrap()
    };
    let noisy = a
        .iter()
        .find(|(n, _)| n.ends_with("_noisy"))
        .unwrap()
        .0
        .clone();
    let clean = noisy.trim_end_matches("_noisy").to_string();
    assert_ne!(
        col(&a, &clean),
        col(&b, &clean),
        "each condition its own rails"
    );
    let noise = |t: &[(String, Vec<f64>)]| {
        let (y, x) = (col(t, &noisy), col(t, &clean));
        y.iter().zip(&x).map(|(y, x)| y - x).collect::<Vec<f64>>()
    };
    let (na, nb) = (noise(&a), noise(&b));
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    let corr = dot(&na, &nb) / (dot(&na, &na) * dot(&nb, &nb)).sqrt();
    assert!(
        corr.abs() < 0.3,
        "each condition its own noise: correlation {corr:.3}"
    );
}

/// Tables written by NumPy and pyarrow (tests/fixtures/foreign/README.md) are read as users
/// write them: ZIP64 and deflated NPZ entries, integer, boolean and big-endian columns, and
/// Parquet with each common codec; a 2-D or a text array is refused naming its entry.
#[test]
fn foreign_files_are_read() {
    let dir = root().join("tests/fixtures/foreign");
    let want: [(&str, [f64; 4]); 3] = [
        ("a", [0.5, -1.25, 3.0, 1e6]),
        ("b", [1.0, -2.0, 3.0, 40000.0]),
        ("c", [0.25, 2.0, -8.0, 0.125]),
    ];
    for f in [
        "numpy_savez.npz",
        "numpy_savez_compressed.npz",
        "pyarrow_snappy.parquet",
        "pyarrow_zstd.parquet",
        "pyarrow_gzip.parquet",
        "pyarrow_lz4.parquet",
    ] {
        let t = dataset::read_table(&dir.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        for (name, values) in &want {
            let (_, got) = t.iter().find(|(n, _)| n == name).expect(name);
            assert_eq!(got, values, "{f}: {name}");
        }
        if f.ends_with(".npz") {
            let (_, flag) = t.iter().find(|(n, _)| n == "flag").unwrap();
            assert_eq!(flag, &[1.0, 0.0, 1.0, 1.0]);
        }
    }
    for (f, says) in [
        ("numpy_2d.npz", "entry 'm': shape (2, 3)"),
        (
            "numpy_text.npz",
            "entry 's': data type '<U1' is not a number",
        ),
    ] {
        let e = dataset::read_table(&dir.join(f)).unwrap_err().to_string();
        assert!(e.contains(f) && e.contains(says), "{e}");
    }
}

/// A CSV header that names a column twice, or a file separated by semicolons, is refused
/// saying so (the first read as a missing channel, the second as one 6 kB column name).
#[test]
fn csv_headers_that_cannot_be_columns_are_refused() {
    let p = Path::new("rec.csv");
    let e = dataset::read_csv(b"time_s,a,b,a\n0,1,2,3\n", p)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("rec.csv") && e.contains("column a appears twice (columns 2 and 4"),
        "{e}"
    );
    let e = dataset::read_csv(b"time_s;a;b\n0;1;2\n", p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("comma-separated") && e.contains("';'"), "{e}");
}
