//! Every input file parses or says why, never panics: valid files are mutated —
//! truncated, bytes flipped, numbers replaced by NaN, ±inf, huge and negative values or a
//! string, lines deleted or duplicated (duplicate keys) — and each loader must return either
//! a value or an error that names the file; a panic fails the test. A bounded number of cases
//! per file (seeded, so a failure reproduces).

use crate::common;

use std::path::{Path, PathBuf};

const CASES: usize = 40;

/// A small seeded generator (SplitMix64): the cases are the same on every run.
pub(crate) struct Gen(pub u64);

impl Gen {
    pub(crate) fn random_range(&mut self, r: std::ops::Range<usize>) -> usize {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        r.start + (z % (r.end - r.start).max(1) as u64) as usize
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub(crate) fn mutate(text: &str, rng: &mut Gen) -> Vec<u8> {
    let bytes = text.as_bytes();
    match rng.random_range(0..5) {
        0 => bytes[..rng.random_range(0..bytes.len())].to_vec(),
        1 => {
            let mut b = bytes.to_vec();
            let i = rng.random_range(0..b.len());
            b[i] ^= 1 << rng.random_range(0..8);
            b
        }
        2 => {
            // Replace one number with something hostile.
            let nums: Vec<(usize, usize)> = {
                let mut v = Vec::new();
                let mut i = 0;
                while i < bytes.len() {
                    if bytes[i].is_ascii_digit() {
                        let s = i;
                        while i < bytes.len()
                            && (bytes[i].is_ascii_digit() || b".eE-+".contains(&bytes[i]))
                        {
                            i += 1;
                        }
                        v.push((s, i));
                    }
                    i += 1;
                }
                v
            };
            if nums.is_empty() {
                return bytes.to_vec();
            }
            let (s, e) = nums[rng.random_range(0..nums.len())];
            let hostile = [
                "nan",
                "inf",
                "-inf",
                "1e308",
                "-1e308",
                "-5",
                "0",
                "\"x\"",
                "18446744073709551615",
            ];
            let mut out = bytes[..s].to_vec();
            out.extend_from_slice(hostile[rng.random_range(0..hostile.len())].as_bytes());
            out.extend_from_slice(&bytes[e..]);
            out
        }
        3 => {
            let lines: Vec<&str> = text.lines().collect();
            let k = rng.random_range(0..lines.len());
            lines
                .iter()
                .enumerate()
                .filter(|(i, _)| *i != k)
                .map(|(_, l)| *l)
                .collect::<Vec<_>>()
                .join("\n")
                .into_bytes()
        }
        _ => {
            let lines: Vec<&str> = text.lines().collect();
            let k = rng.random_range(0..lines.len());
            let mut out: Vec<&str> = lines.clone();
            out.insert(k, lines[k]);
            out.join("\n").into_bytes()
        }
    }
}

/// Mutates `name` (copied with its `siblings` into a scratch folder) `CASES` times and hands
/// the mutated file's path to `load`.
fn fuzz<T>(
    tag: &str,
    source: &Path,
    siblings: &[&Path],
    load: impl Fn(&Path) -> railforce::Result<T> + std::panic::RefUnwindSafe,
) {
    let dir = std::env::temp_dir().join(format!("railforce-mut-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for s in siblings {
        std::fs::copy(s, dir.join(s.file_name().unwrap())).unwrap();
    }
    let text = std::fs::read_to_string(source).unwrap();
    let target = dir.join(source.file_name().unwrap());
    let name = target.file_name().unwrap().to_string_lossy().into_owned();
    let mut rng = Gen(17);
    for case in 0..CASES {
        let bytes = mutate(&text, &mut rng);
        std::fs::write(&target, &bytes).unwrap();
        let result = std::panic::catch_unwind(|| load(&target).map(|_| ()));
        match result {
            Err(_) => panic!(
                "{tag} case {case}: the loader panicked on\n{}",
                String::from_utf8_lossy(&bytes)
            ),
            Ok(Err(e)) => {
                let msg = e.to_string();
                assert!(
                    msg.contains(&name)
                        || siblings
                            .iter()
                            .any(|s| msg.contains(&*s.file_name().unwrap().to_string_lossy())),
                    "{tag} case {case}: the error does not name the file: {msg}"
                );
            }
            Ok(Ok(())) => {}
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn vehicle_files_parse_or_say_why() {
    let v = root().join("vehicles");
    fuzz(
        "vehicle",
        &v.join("c80.toml"),
        &[&v.join("c80.urdf")],
        railforce::vehicle::Vehicle::load,
    );
    fuzz("urdf", &v.join("c80.urdf"), &[&v.join("c80.toml")], |p| {
        railforce::vehicle::Vehicle::load(&p.with_file_name("c80.toml"))
    });
}

#[test]
fn track_files_parse_or_say_why() {
    fuzz("track", &root().join("tracks/grade20_L50.toml"), &[], |p| {
        let spec = railforce::track::TrackSpec::load(p)?;
        let t = railforce::track::Track::new(spec, None);
        let r = t.at(0.5 * t.length()).rails;
        assert!(r.left_y.is_finite() && r.left_z.is_finite());
        Ok(())
    });
}

#[test]
fn criteria_files_parse_or_say_why() {
    fuzz(
        "criteria",
        &root().join("vehicles/assessment.toml"),
        &[],
        railforce::assess::Criteria::load,
    );
}

#[test]
fn plan_files_parse_or_say_why() {
    fuzz("plan", &root().join("tracks/demo.plan.toml"), &[], |p| {
        railforce::plan::Plan::load(p)
    });
}

#[test]
fn profile_files_parse_or_say_why() {
    use railforce::contact::profile::{LoadOptions, load};
    fuzz(
        "profile-csv",
        &root().join("vehicles/profiles/cone_1_40.csv"),
        &[],
        |p| load(p, LoadOptions::default()),
    );
    fuzz(
        "profile-prw",
        &root().join("assets/reference/profiles/MBench_S1002_v3.prw"),
        &[],
        |p| load(p, LoadOptions::default()),
    );
    fuzz(
        "profile-whl",
        &root().join("assets/reference/profiles/Car7216_0001r.whl"),
        &[],
        |p| load(p, LoadOptions::default()),
    );
    fuzz(
        "profile-ban",
        &root().join("assets/reference/profiles/MBench_UIC60_v3.ban"),
        &[],
        |p| load(p, LoadOptions { mirror_y: true }),
    );
}

#[test]
fn sensor_files_parse_or_say_why() {
    let dir = std::env::temp_dir().join(format!("railforce-mut-src-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("sensors.csv");
    let mut text = String::from("time_s,ws1_acc_y,ws1_acc_z\n");
    for i in 0..50 {
        text += &format!(
            "{:.3},{:.4},{:.4}\n",
            i as f64 * 0.005,
            (i as f64).sin(),
            9.81 + 0.1 * (i as f64).cos()
        );
    }
    std::fs::write(&csv, text).unwrap();
    fuzz("sensors", &csv, &[], |p| {
        let t = railforce::identify::SensorTable::read(p)?;
        assert!(t.time.iter().all(|v| v.is_finite()));
        Ok(())
    });
    let _ = std::fs::remove_dir_all(&dir);
}

/// Weight files: a count that cannot fit, truncation, garbage — errors, never a panic.
#[test]
fn weight_files_parse_or_say_why() {
    let dir = std::env::temp_dir().join(format!("railforce-mut-w-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("weights.bin");
    railforce::learn::model::write_weights(&p, &[1.0, 2.0, 3.0]).unwrap();
    let good = std::fs::read(&p).unwrap();
    assert_eq!(
        railforce::learn::model::read_weights(&p).unwrap(),
        vec![1.0, 2.0, 3.0]
    );
    let mut huge = good.clone();
    huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
    for bytes in [huge, good[..20].to_vec(), b"garbage".to_vec(), Vec::new()] {
        std::fs::write(&p, &bytes).unwrap();
        let e = railforce::learn::model::read_weights(&p).unwrap_err();
        assert!(e.to_string().contains("weights.bin"), "{e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A shard manifest without its runs is refused by name.
#[test]
fn shard_manifest_without_runs_is_an_error() {
    let dir = std::env::temp_dir().join(format!("railforce-mut-m-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("manifest.shard-1-of-2.json"),
        "{\"format\": \"npz\"}",
    )
    .unwrap();
    let e = railforce::dataset::merge(&dir).unwrap_err();
    assert!(e.to_string().contains("manifest.shard-1-of-2.json"), "{e}");
    std::fs::write(dir.join("manifest.shard-1-of-2.json"), "[1, 2]").unwrap();
    assert!(railforce::dataset::merge(&dir).is_err());
    let _ = std::fs::remove_dir_all(&dir);
}

/// A tiny data set and model, made with the binary, then its files mutated: the model
/// directory's `model.json`, the data set's `manifest.json` and a run file (NPZ, bytes
/// truncated or flipped) load or say why, never panic.
#[test]
fn model_and_data_set_files_parse_or_say_why() {
    let dir = std::env::temp_dir().join(format!("railforce-mut-md-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let (plan, data, model) = common::tiny_data_and_tree_model(&dir);
    let run = |args: &[&str]| {
        common::succeed(std::process::Command::new(env!("CARGO_BIN_EXE_railforce")).args(args));
    };
    fuzz(
        "model",
        &model.join("model.json"),
        &[&model.join("model.bin")],
        |p| railforce::learn::model::Model::load(p.parent().unwrap()),
    );
    // A standard deviation of zero would divide every input into infinities (identify wrote
    // NaN in every column), a negative one flip its sign: both refused at load, by field.
    let json = model.join("model.json");
    let good = std::fs::read_to_string(&json).unwrap();
    for (field, bad) in [
        ("input_stats", 0.0),
        ("input_stats", -1.0),
        ("target_stats", 0.0),
    ] {
        let mut v: serde_json::Value = serde_json::from_str(&good).unwrap();
        v[field]["std"][0] = serde_json::json!(bad);
        std::fs::write(&json, serde_json::to_string(&v).unwrap()).unwrap();
        let err = railforce::learn::model::Model::load(&model)
            .err()
            .unwrap_or_else(|| panic!("{field}.std = {bad} was accepted"))
            .to_string();
        assert!(
            err.contains("model.json") && err.contains(&format!("{field}.std")),
            "{err}"
        );
    }
    std::fs::write(&json, &good).unwrap();
    let files: Vec<PathBuf> = std::fs::read_dir(&data)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "npz"))
        .collect();
    let siblings: Vec<&Path> = files.iter().map(|p| p.as_path()).collect();
    fuzz("manifest", &data.join("manifest.json"), &siblings, |p| {
        railforce::dataset::DataSet::load(p.parent().unwrap())
    });
    // Run files, as bytes (NPZ, and Parquet from a second data set): truncated or a bit flipped.
    let pq = dir.join("pq");
    run(&[
        "generate",
        "--plan",
        plan.to_str().unwrap(),
        "--out",
        pq.to_str().unwrap(),
        "--settle",
        "0.1",
        "--format",
        "parquet",
    ]);
    let parquet = std::fs::read_dir(&pq)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "parquet"))
        .unwrap();
    for file in [&files[0], &parquet] {
        let bytes = std::fs::read(file).unwrap();
        let mut g = Gen(5);
        for case in 0..CASES {
            let mut b = bytes.clone();
            if case % 2 == 0 {
                b.truncate(g.random_range(0..b.len()));
            } else {
                let i = g.random_range(0..b.len());
                b[i] ^= 1 << g.random_range(0..8);
            }
            std::fs::write(file, &b).unwrap();
            let r = std::panic::catch_unwind(|| railforce::dataset::read_table(file).map(|_| ()));
            match r {
                Err(_) => panic!("{} case {case}: the reader panicked", file.display()),
                Ok(Err(e)) => assert!(
                    e.to_string()
                        .contains(&*file.file_name().unwrap().to_string_lossy()),
                    "{} case {case}: {e}",
                    file.display()
                ),
                Ok(Ok(())) => {}
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A run cut short, or with a row of other length, is refused in every run format, naming the
/// file and the row or column: `view` and `assess` index any column by row and panicked on a
/// CSV truncated inside its last row.
#[test]
fn run_files_cut_short_are_refused_in_every_format() {
    use railforce::dataset::read_table;
    use railforce::dataset::{npz, parquet_file};
    let dir = std::env::temp_dir().join(format!("railforce-cut-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n = 50;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
    let a: Vec<f64> = (0..n).map(|i| (i as f64 * 0.3).sin() * 1e4).collect();
    let b = vec![2.5; n];
    // CSV: the header and n rows; cut inside the last row, and a row with a field too many.
    let mut csv = String::from("time_s,a,b\n");
    for i in 0..n {
        csv += &format!("{},{},{}\n", t[i], a[i], b[i]);
    }
    let cut = dir.join("cut.csv");
    let last = csv.trim_end().rfind('\n').unwrap();
    std::fs::write(&cut, &csv[..last + 6]).unwrap();
    let e = read_table(&cut).unwrap_err().to_string();
    assert!(
        e.contains("cut.csv") && e.contains(&format!("row {n}")) && e.contains("cut short"),
        "{e}"
    );
    let long = dir.join("long.csv");
    std::fs::write(&long, csv.replacen("\n0.05,", "\n0.05,7,", 1)).unwrap();
    let e = read_table(&long).unwrap_err().to_string();
    assert!(
        e.contains("long.csv") && e.contains("row 11 has 4 field(s)"),
        "{e}"
    );
    // NPZ and Parquet: one array shorter than the others; and every cut of the bytes.
    let short = &a[..n - 1];
    let cols: [(&str, &[f64]); 3] = [("time_s", &t), ("a", short), ("b", &b)];
    let mut bytes = Vec::new();
    npz::write_npz(&mut bytes, &cols, false).unwrap();
    let p = dir.join("short.npz");
    std::fs::write(&p, &bytes).unwrap();
    let e = read_table(&p).unwrap_err().to_string();
    assert!(
        e.contains("short.npz") && e.contains("column a has 49 rows"),
        "{e}"
    );
    let pq = parquet_file::write_parquet(&[("time_s", &t), ("a", &a), ("b", &b)], false).unwrap();
    for (name, whole) in [("cut.npz", bytes), ("cut.parquet", pq)] {
        let p = dir.join(name);
        for k in (1..whole.len()).step_by((whole.len() / 37).max(1)) {
            std::fs::write(&p, &whole[..k]).unwrap();
            match read_table(&p) {
                Ok(table) => {
                    let len = table[0].1.len();
                    assert!(
                        table.iter().all(|(_, c)| c.len() == len),
                        "{name} cut at {k}"
                    );
                }
                Err(e) => assert!(e.to_string().contains(name), "{name} cut at {k}: {e}"),
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The C80 file with `edit` applied, loaded from a temporary copy beside its URDF.
/// One point for both bodies is refused with what to write; a point off its body, or the two
/// points more than a metre apart, name the element and the field.
#[test]
fn one_point_and_misplaced_attachments_are_refused() {
    assert_eq!(crate::common::load_c80_edited(|t| t), "loaded");
    let one = crate::common::load_c80_edited(|t| {
        t.replacen(
            "upper_at = [5.015, 0.978, 0.580]",
            "at = [5.015, 0.978, 0.42]",
            1,
        )
        .replacen("lower_at = [5.015, 0.978, 0.555]", "", 1)
    });
    assert!(
        one.contains("shear_pad[0].at") && one.contains("upper_at") && one.contains("lower_at"),
        "{one}"
    );
    let off = crate::common::load_c80_edited(|t| {
        t.replacen(
            "lower_at = [5.015, 0.978, 0.555]",
            "lower_at = [5.015, 0.978, 1.555]",
            1,
        )
    });
    assert!(
        off.contains("shear_pad[0].lower_at") && off.contains("does not lie on \"wheelset1\""),
        "{off}"
    );
    let apart = crate::common::load_c80_edited(|t| {
        t.replacen(
            "upper_at = [4.100, 0.000, 0.700]",
            "upper_at = [4.100, 0.000, 1.900]",
            1,
        )
    });
    assert!(
        apart.contains("centre_plate[0].lower_at") && apart.contains("at most 1 m apart"),
        "{apart}"
    );
    let missing =
        crate::common::load_c80_edited(|t| t.replacen("lower_at = [4.100, 0.978, 0.300]", "", 1));
    assert!(
        missing.contains("spring_nest[0].lower_at") && missing.contains("missing"),
        "{missing}"
    );
}

/// A data set whose manifest names an unknown noise reference is refused naming the field; it
/// used to fall back to the default silently . Without the field (older data sets)
/// the rms reference they were made with is read.
#[test]
fn an_unknown_noise_reference_in_a_manifest_is_refused() {
    use railforce::dataset::DataSet;
    let dir = std::env::temp_dir().join(format!("railforce-snrref-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("r.csv"), "time_s,a\n0,1\n0.005,2\n").unwrap();
    // The manifests of today and of the first writer (no reference recorded), their runs
    // pointed at one small file.
    let fixture = |name: &str| {
        std::fs::read_to_string(
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("tests/fixtures/manifests")
                .join(name),
        )
        .unwrap()
        .replace("curve_r400_v60_seed1.npz", "r.csv")
        .replace("curve_r400_v60_seed4.npz", "r.csv")
    };
    let today = fixture("format4.json");
    assert!(today.contains(r#""snr_reference": "std""#));
    std::fs::write(
        dir.join("manifest.json"),
        today.replace(r#""snr_reference": "std""#, r#""snr_reference": "bogus""#),
    )
    .unwrap();
    let e = DataSet::load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("manifest.json") && e.contains("snr_reference") && e.contains("std or rms"),
        "{e}"
    );
    std::fs::write(
        dir.join("manifest.json"),
        fixture("format1-first-writer.json"),
    )
    .unwrap();
    let ds = DataSet::load(&dir).unwrap();
    assert_eq!(
        ds.noise.map(|n| n.reference),
        Some(railforce::sensors::SnrReference::Rms)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
