//! Data set generation: formats, resume, shards, noise, and loading from Python.

use railforce::dataset::{self, Event, Format, GenerateOptions, npz};
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
    }
}

fn run_events(plan: &Plan, o: &GenerateOptions) -> (serde_json::Value, Vec<Event>) {
    let events = Mutex::new(Vec::new());
    let m = dataset::generate(plan, o, &|e| events.lock().unwrap().push(e)).unwrap();
    (m, events.into_inner().unwrap())
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
    // The redone run has a new wall time in the manifest but the same bytes: the data
    // identity (what reports and models quote) is unchanged.
    assert_eq!(dataset::data_identity(&a).unwrap(), identity);

    // Two shards and a merge give the same files and runs.
    let b = dir.join("b");
    run_events(&plan, &opts(&b, Format::Npz, Some((1, 2))));
    run_events(&plan, &opts(&b, Format::Npz, Some((2, 2))));
    let merged = dataset::merge(&b).unwrap();
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
    let required = std::env::var_os("RAILFORCE_PYTHON_TESTS").is_some();
    let check = std::process::Command::new("python3")
        .args(["-c", "import numpy, pyarrow"])
        .output();
    if !matches!(&check, Ok(o) if o.status.success()) {
        assert!(
            !required,
            "python3 with numpy and pyarrow is required (RAILFORCE_PYTHON_TESTS is set)"
        );
        eprintln!("skipping the Python check: no python3 with numpy and pyarrow");
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
    let out = std::process::Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
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
    assert!(e.contains("--shard"), "{e}");
}
