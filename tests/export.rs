//! `railforce export`: the safetensors file of each network, read back and run with numpy
//! alone (assets/python/numpy_forward.py, PyTorch's names and layouts), gives the forces
//! `railforce identify` gives.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("railforce-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn railforce(args: &[&str]) -> String {
    let out = common::succeed(common::railforce_in(root()).args(args));
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// The safetensors header: names, dtypes, shapes and byte ranges that tile the data.
#[test]
fn the_file_is_safetensors_with_pytorch_names() {
    let data = tiny_data();
    let model = tmp("gru_header");
    railforce(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "gru",
        "--epochs",
        "1",
        "--windows-per-epoch",
        "200",
        "--target",
        "both",
        "--out",
        model.to_str().unwrap(),
    ]);
    let said = railforce(&["export", "--model", model.to_str().unwrap()]);
    assert!(said.contains("model.safetensors"), "{said}");
    let bytes = std::fs::read(model.join("model.safetensors")).unwrap();
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!((8 + n) % 8, 0, "data 8-byte aligned");
    let header: serde_json::Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    let meta = &header["__metadata__"];
    assert_eq!(meta["architecture"], "gru");
    assert_eq!(meta["targets"], "w1l_force_y,w1l_force_z");
    // Quantile heads (train's default): three blocks of two outputs, and their coverage.
    assert_eq!(meta["outputs"], "6");
    assert_eq!(meta["quantile_coverage"], "0.9");
    assert_eq!(header["out.weight"]["shape"], serde_json::json!([6, 8]));
    let mut ranges: Vec<(u64, u64)> = header
        .as_object()
        .unwrap()
        .iter()
        .filter(|(k, _)| *k != "__metadata__")
        .map(|(k, t)| {
            assert_eq!(t["dtype"], "F32", "{k}");
            let o = t["data_offsets"].as_array().unwrap();
            let shape: u64 = t["shape"]
                .as_array()
                .unwrap()
                .iter()
                .map(|d| d.as_u64().unwrap())
                .product();
            let r = (o[0].as_u64().unwrap(), o[1].as_u64().unwrap());
            assert_eq!(r.1 - r.0, 4 * shape, "{k}: bytes match its shape");
            r
        })
        .collect();
    ranges.sort();
    assert_eq!(ranges[0].0, 0);
    for w in ranges.windows(2) {
        assert_eq!(w[0].1, w[1].0, "the tensors tile the data");
    }
    assert_eq!(ranges.last().unwrap().1 as usize, bytes.len() - 8 - n);
    for name in [
        "gru.weight_ih_l0",
        "gru.weight_hh_l0",
        "fc1.weight",
        "out.bias",
        "input_mean",
        "target_std",
    ] {
        assert!(header.get(name).is_some(), "{name}");
    }
    assert_eq!(
        header["gru.weight_hh_l0"]["shape"],
        serde_json::json!([60, 20])
    );
    // A classical model has no network to export: said plainly.
    let tree = tmp("tree_header");
    railforce(&[
        "train",
        "--data",
        data.to_str().unwrap(),
        "--model",
        "tree",
        "--target",
        "FL",
        "--out",
        tree.to_str().unwrap(),
    ]);
    let out = Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args(["export", "--model", tree.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("classical"));
}

/// One clean condition, seeds 1–3, 3 s each (shared by the tests of this file).
fn tiny_data() -> PathBuf {
    static DATA: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DATA.get_or_init(|| {
        let plan = tmp("export.plan.toml");
        let r = root().display();
        std::fs::write(
            &plan,
            format!(
                "name = \"export\"\nvehicle = \"{r}/vehicles/c80.toml\"\nduration_s = 3.0\nseeds = [1, 2, 3]\n\
                 [[condition]]\nname = \"curve_r400\"\ntrack = \"{r}/tracks/curve_r400.toml\"\nspeed_kmh = 60.0\n"
            ),
        )
        .unwrap();
        let data = tmp("export_data");
        railforce(&[
            "generate", "--plan", plan.to_str().unwrap(), "--out", data.to_str().unwrap(),
            "--settle", "0.2",
        ]);
        data
    })
    .clone()
}

/// For each of the four networks: export, run the file's network with numpy alone on a run,
/// and compare with `railforce identify` on the same run (which equals `evaluate`, tested in
/// tests/identify.rs). CI requires numpy (RAILFORCE_PYTHON_TESTS=1).
#[test]
fn numpy_forward_of_the_export_equals_identify_for_all_four_networks() {
    if !common::python_with("numpy") {
        return;
    }
    let data = tiny_data();
    let run = data.join("curve_r400_seed3.npz");
    assert!(run.exists(), "{}", run.display());
    for arch in ["gru", "bilstm", "cnn", "cnn-bilstm"] {
        let model = tmp(&format!("{arch}_model"));
        // Two epochs move the batch-norm statistics off their initial values.
        railforce(&[
            "train",
            "--data",
            data.to_str().unwrap(),
            "--model",
            arch,
            "--epochs",
            "2",
            "--windows-per-epoch",
            "300",
            "--target",
            "both",
            "--centre-label",
            "--out",
            model.to_str().unwrap(),
        ]);
        railforce(&["export", "--model", model.to_str().unwrap()]);
        let ours = tmp(&format!("{arch}_identify.csv"));
        railforce(&[
            "identify",
            "--model",
            model.to_str().unwrap(),
            "--input",
            run.to_str().unwrap(),
            "--out",
            ours.to_str().unwrap(),
        ]);
        let theirs = tmp(&format!("{arch}_numpy.csv"));
        common::succeed(
            Command::new("python3")
                .arg(root().join("assets/python/numpy_forward.py"))
                .arg(model.join("model.safetensors"))
                .arg(&run)
                .arg(&theirs),
        );
        let (h1, a) = read_csv(&ours);
        let (h2, b) = read_csv(&theirs);
        assert_eq!(a.len(), b.len(), "{arch}: one estimate per window");
        // train's default quantile heads: the export says so and numpy un-scales their
        // lower and upper quantiles as well (6 outputs for the two targets).
        for q in ["w1l_force_y_lower_N", "w1l_force_z_upper_N"] {
            let j = h2.iter().position(|c| c == q);
            let j = j.unwrap_or_else(|| panic!("{arch}: no {q} in {h2:?}"));
            assert!(b.iter().all(|r| r[j].is_finite()), "{arch} {q}");
        }
        let col = |h: &[String], name: &str| h.iter().position(|c| c == name).unwrap();
        let mut worst: f64 = 0.0;
        for target in ["w1l_force_y_N", "w1l_force_z_N"] {
            let (i, j) = (col(&h1, target), col(&h2, target));
            for (ra, rb) in a.iter().zip(&b) {
                assert!((ra[0] - rb[0]).abs() < 1e-6, "{arch}: label times");
                // identify prints 0.1 N; the engine computes in f32.
                let tol = 0.1 + 2e-5 * rb[j].abs();
                let err = (ra[i] - rb[j]).abs();
                worst = worst.max(err);
                assert!(
                    err < tol,
                    "{arch} {target}: identify {} vs numpy {}",
                    ra[i],
                    rb[j]
                );
            }
        }
        eprintln!(
            "{arch}: largest difference {worst:.3} N over {} windows",
            a.len()
        );
    }
}
