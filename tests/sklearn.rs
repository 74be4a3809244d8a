//! The classical baselines against scikit-learn on the same windows (CI runs it with
//! RAILFORCE_PYTHON_TESTS=1 and scikit-learn installed): SVR, GBDT and the decision tree must
//! score within 0.03 test R² of scikit-learn's with the same settings.

use crate::common;

use railforce::learn::classical::{Classical, ClassicalParams};
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use std::process::Command;

/// Windows of a nonlinear, noisy response: 4 000 training and 1 000 test rows of 20 features.
fn data(n: usize, rng: &mut ChaCha8Rng) -> (Vec<f32>, Vec<f32>) {
    let f = 20;
    let mut x = Vec::with_capacity(n * f);
    let mut y = Vec::with_capacity(n);
    for _ in 0..n {
        let row: Vec<f32> = (0..f).map(|_| rng.random_range(-2.0f32..2.0)).collect();
        let t = (1.5 * row[0]).sin() + 0.4 * row[1] * row[2] + 0.3 * row[3] - 0.2 * row[4].powi(2)
            + 0.5
            + 0.1 * rng.random_range(-1.0f32..1.0);
        x.extend_from_slice(&row);
        y.push(t);
    }
    (x, y)
}

fn write_csv(path: &std::path::Path, v: &[f32], cols: usize) {
    let s: String = v
        .chunks(cols)
        .map(|r| {
            r.iter()
                .map(|x| format!("{x:.7e}"))
                .collect::<Vec<_>>()
                .join(",")
                + "\n"
        })
        .collect();
    std::fs::write(path, s).unwrap();
}

fn r2(y: &[f32], p: &[f32]) -> f64 {
    let m = y.iter().map(|&v| v as f64).sum::<f64>() / y.len() as f64;
    let sst: f64 = y.iter().map(|&v| (v as f64 - m).powi(2)).sum();
    let sse: f64 = y
        .iter()
        .zip(p)
        .map(|(&a, &b)| (a as f64 - b as f64).powi(2))
        .sum();
    1.0 - sse / sst
}

#[test]
fn classical_models_match_scikit_learn() {
    if !common::python_with("sklearn, numpy") {
        return;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (xtr, ytr) = data(4000, &mut rng);
    let (xte, yte) = data(1000, &mut rng);
    let dir = std::env::temp_dir().join(format!("railforce_sklearn_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    write_csv(&dir.join("train_x.csv"), &xtr, 20);
    write_csv(&dir.join("train_y.csv"), &ytr, 1);
    write_csv(&dir.join("test_x.csv"), &xte, 20);
    write_csv(&dir.join("test_y.csv"), &yte, 1);
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/analysis/sklearn_check.py"
    );
    let out = common::succeed(Command::new("python3").arg(script).arg(&dir));
    let sk: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let mut failures = Vec::new();
    for (name, params) in [
        ("svr", ClassicalParams::svr()),
        ("gbdt", ClassicalParams::gbdt()),
        ("tree", ClassicalParams::tree()),
    ] {
        let m = Classical::fit(params, &xtr, 20, &ytr, 1, &mut |_, _| {});
        let ours = r2(&yte, &m.predict(&xte, 1000));
        let theirs = sk[name].as_f64().unwrap();
        eprintln!("{name}: railforce R² {ours:.4}, scikit-learn {theirs:.4}");
        if (ours - theirs).abs() >= 0.03 {
            failures.push(format!(
                "{name}: railforce R² {ours:.4} vs scikit-learn {theirs:.4}"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
