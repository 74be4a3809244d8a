//! Trainer, model directories and classical regressors on small synthetic problems.

use railforce::dataset::{DataSet, Run};
use railforce::features::{LabelAt, NoiseProtocol, Split};
use railforce::learn::classical::{Classical, ClassicalParams};
use railforce::learn::evaluate::{EvalPart, evaluate};
use railforce::learn::metrics::metrics;
use railforce::learn::model::{Model, ModelKind};
use railforce::learn::train::{TrainOptions, train};
use railforce::learn::windows::DataSpec;
use railforce::sensors::{NoiseModel, SnrReference};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("railforce-learn-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Three inputs and a target that depends nonlinearly on lagged inputs.
fn synthetic(runs: usize, rows: usize) -> DataSet {
    let names: Vec<String> = ["a", "b", "c", "w1l_force_y", "time_s"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let runs = (0..runs)
        .map(|r| {
            let ph = r as f64 * 0.7;
            let a: Vec<f64> = (0..rows)
                .map(|t| (0.05 * t as f64 + ph).sin() + 0.3 * (0.31 * t as f64).sin())
                .collect();
            let b: Vec<f64> = (0..rows)
                .map(|t| (0.021 * t as f64 + 2.0 * ph).cos())
                .collect();
            let c: Vec<f64> = (0..rows)
                .map(|t| (0.13 * t as f64 + ph).sin() * (0.007 * t as f64).cos())
                .collect();
            let y: Vec<f64> = (0..rows)
                .map(|t| {
                    let l = t.saturating_sub(3);
                    1000.0 * (a[t] * b[l] + 0.5 * (2.0 * c[t.saturating_sub(1)]).tanh())
                })
                .collect();
            let time: Vec<f64> = (0..rows).map(|t| t as f64 / 200.0).collect();
            Run {
                condition: format!("cond{r}"),
                seed: 1,
                columns: vec![a, b, c, y, time],
            }
        })
        .collect();
    DataSet::in_memory(&PathBuf::from("synthetic"), names, runs)
}

fn spec() -> DataSpec {
    DataSpec {
        channels: vec!["a".into(), "b".into(), "c".into()],
        targets: vec!["w1l_force_y".into()],
        window: 8,
        label_at: LabelAt::Last,
        stride: 1,
        split: Split::default(),
        noise: NoiseProtocol::Clean,
        noise_model: None,
    }
}

fn quick(epochs: usize) -> TrainOptions {
    TrainOptions {
        epochs,
        patience: 1000,
        batch: 32,
        seed: 3,
        ..TrainOptions::default()
    }
}

#[test]
fn network_overfits_a_tiny_data_set() {
    let ds = synthetic(1, 300);
    let out = tmp("overfit");
    let mut log = Vec::new();
    let opts = TrainOptions {
        dropout: 0.0,
        ..quick(60)
    };
    train(&ds, &spec(), ModelKind::CnnBiLstm, &opts, &out, &mut |p| {
        if let railforce::learn::train::Progress::Epoch(e) = p {
            log.push(e.train_loss)
        }
    })
    .unwrap();
    let (first, last) = (log[0], *log.last().unwrap());
    assert!(last < first / 10.0, "training loss {first} → {last}");
    assert!(out.join("train_log.jsonl").exists() && out.join("checkpoint.json").exists());
}

#[test]
fn saved_models_predict_the_same_after_loading() {
    let ds = synthetic(2, 400);
    for kind in [ModelKind::Gru, ModelKind::Gbdt] {
        let out = tmp(&format!("roundtrip-{}", kind.name()));
        let mut m = train(&ds, &spec(), kind, &quick(3), &out, &mut |_| {}).unwrap();
        let mut back = Model::load(&out).unwrap();
        let a = evaluate(&mut m, &ds, EvalPart::Test).unwrap();
        let b = evaluate(&mut back, &ds, EvalPart::Test).unwrap();
        assert_eq!(a.rows, b.rows, "{}", kind.name());
        assert_eq!(a.metrics, b.metrics);
    }
}

/// Predictions shared out between threads, each on its own copy of the networks, are the
/// single thread's bit for bit: for one network, for one with quantile heads, and for an
/// ensemble (its spread too), whatever the number of windows and threads.
#[test]
fn predictions_on_several_threads_are_the_single_threads() {
    let ds = synthetic(1, 300);
    let q = TrainOptions {
        quantile_heads: Some(0.9),
        ..quick(1)
    };
    let gru = |seed: u64, dir: &str| {
        let opts = TrainOptions { seed, ..quick(1) };
        train(&ds, &spec(), ModelKind::Gru, &opts, &tmp(dir), &mut |_| {}).unwrap()
    };
    let members = vec![gru(3, "member1"), gru(4, "member2")];
    let nets = [
        train(
            &ds,
            &spec(),
            ModelKind::CnnBiLstm,
            &quick(1),
            &tmp("one"),
            &mut |_| {},
        )
        .unwrap(),
        train(
            &ds,
            &spec(),
            ModelKind::CnnBiLstm,
            &q,
            &tmp("quantiles"),
            &mut |_| {},
        )
        .unwrap(),
        railforce::learn::uncertainty::join(members, &ds, &tmp("ensemble")).unwrap(),
    ];
    let (w, c) = (8, 3);
    let n = 2 * 1024 + 77;
    let x: Vec<f32> = (0..n * w * c).map(|i| ((i as f32) * 0.37).sin()).collect();
    for mut m in nets {
        let one = m.predict_spread(&x, n);
        for threads in [2, 3, 8] {
            let (p, s) = m.predict_spread_on(&x, n, threads);
            assert!(
                p.iter()
                    .zip(&one.0)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            assert_eq!(p.len(), one.0.len());
            assert_eq!(s.is_some(), one.1.is_some(), "{threads} threads");
            if let (Some(s), Some(o)) = (s, &one.1) {
                assert!(s.iter().zip(o).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
    }
}

#[test]
fn same_seed_same_weights_and_resume_continues_exactly() {
    let ds = synthetic(2, 300);
    let (a, b, c) = (tmp("seed-a"), tmp("seed-b"), tmp("seed-c"));
    train(
        &ds,
        &spec(),
        ModelKind::CnnBiLstm,
        &quick(4),
        &a,
        &mut |_| {},
    )
    .unwrap();
    train(
        &ds,
        &spec(),
        ModelKind::CnnBiLstm,
        &quick(4),
        &b,
        &mut |_| {},
    )
    .unwrap();
    let wa = std::fs::read(a.join("weights.bin")).unwrap();
    assert_eq!(wa, std::fs::read(b.join("weights.bin")).unwrap());
    // Interrupted after 2 epochs, resumed to 4: the same weights as 4 epochs in one go.
    train(
        &ds,
        &spec(),
        ModelKind::CnnBiLstm,
        &quick(2),
        &c,
        &mut |_| {},
    )
    .unwrap();
    let resumed = TrainOptions {
        resume: true,
        ..quick(4)
    };
    train(
        &ds,
        &spec(),
        ModelKind::CnnBiLstm,
        &resumed,
        &c,
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(wa, std::fs::read(c.join("weights.bin")).unwrap());
    let other = TrainOptions {
        seed: 4,
        ..quick(4)
    };
    train(&ds, &spec(), ModelKind::CnnBiLstm, &other, &b, &mut |_| {}).unwrap();
    assert_ne!(wa, std::fs::read(b.join("weights.bin")).unwrap());
    // A checkpoint of other settings is refused, not silently mixed.
    let wrong = TrainOptions {
        resume: true,
        batch: 16,
        ..quick(5)
    };
    let err = train(&ds, &spec(), ModelKind::CnnBiLstm, &wrong, &c, &mut |_| {})
        .err()
        .unwrap();
    assert!(err.to_string().contains("fingerprint"), "{err}");
}

#[test]
fn learning_rate_halves_on_a_plateau_and_resumes_halved() {
    let ds = synthetic(2, 300);
    let (a, b) = (tmp("plateau-a"), tmp("plateau-b"));
    // A rate high enough that the validation loss does not fall every epoch.
    let opts = |epochs, resume| TrainOptions {
        lr: 0.02,
        lr_plateau: 1,
        resume,
        ..quick(epochs)
    };
    let mut log = Vec::new();
    train(
        &ds,
        &spec(),
        ModelKind::Gru,
        &opts(12, false),
        &a,
        &mut |p| {
            if let railforce::learn::train::Progress::Epoch(e) = p {
                log.push(e)
            }
        },
    )
    .unwrap();
    // Each epoch that did not improve halves the next epoch's rate; one that did keeps it.
    assert_eq!(log[0].lr, 0.02);
    for w in log.windows(2) {
        let want = if w[0].best_epoch == w[0].epoch {
            w[0].lr
        } else {
            w[0].lr / 2.0
        };
        assert_eq!(w[1].lr, want, "epoch {}", w[1].epoch);
    }
    assert!(log.last().unwrap().lr < 0.02, "no plateau in 12 epochs");
    // Interrupted after 6 epochs and resumed: the halved rate comes back with the checkpoint.
    for (epochs, resume) in [(6, false), (12, true)] {
        train(
            &ds,
            &spec(),
            ModelKind::Gru,
            &opts(epochs, resume),
            &b,
            &mut |_| {},
        )
        .unwrap();
    }
    assert_eq!(
        std::fs::read(a.join("weights.bin")).unwrap(),
        std::fs::read(b.join("weights.bin")).unwrap()
    );
}

#[test]
fn missing_noisy_columns_are_named() {
    let ds = synthetic(1, 200);
    let s = DataSpec {
        noise: NoiseProtocol::Matched,
        ..spec()
    };
    let err = train(
        &ds,
        &s,
        ModelKind::Tree,
        &quick(1),
        &tmp("noisy"),
        &mut |_| {},
    )
    .err()
    .unwrap();
    assert!(err.to_string().contains("a_noisy"), "{err}");
}

/// y = sin(2x₀)·x₁ + x₂² on 8 features, 3 of them informative.
fn regression(n: usize, seed: u64) -> (Vec<f32>, Vec<f32>) {
    let f = 8;
    let mut s = seed;
    let mut u = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((s >> 33) as f64 / (1u64 << 31) as f64) * 2.0 - 1.0
    };
    let x: Vec<f32> = (0..n * f).map(|_| (u() * 1.5) as f32).collect();
    let y = (0..n)
        .map(|r| {
            let v = &x[r * f..];
            (2.0 * v[0]).sin() * v[1] + v[2] * v[2] - 0.75
        })
        .collect();
    (x, y)
}

#[test]
fn classical_models_learn_a_nonlinear_function() {
    let (x, y) = regression(3000, 1);
    let (xt, yt) = regression(1000, 2);
    let stats = railforce::features::ZScore {
        names: vec!["y".into()],
        mean: vec![0.0],
        std: vec![1000.0],
    };
    for (params, bound) in [
        (ClassicalParams::gbdt(), 0.75),
        (ClassicalParams::xgboost(), 0.9),
        // One tree is piecewise constant in 8 dimensions: about 0.5 on this problem.
        (ClassicalParams::tree(), 0.4),
        (ClassicalParams::svr(), 0.8),
    ] {
        let m = Classical::fit(params, &x, 8, &y, 1, &mut |_, _| {});
        let p = m.predict(&xt, 1000);
        let r2 = metrics(&yt, &p, &stats)[0].r2;
        assert!(r2 > bound, "{params:?}: test R² {r2:.3} ≤ {bound}");
        // Predicting the mean scores R² ≈ 0: every model beats it by a wide margin.
        let again = Classical::fit(params, &x, 8, &y, 1, &mut |_, _| {});
        assert_eq!(m, again, "deterministic fit");
        assert_eq!(
            Classical::from_bytes(&m.to_bytes()).unwrap(),
            m,
            "round trip"
        );
    }
}

/// The synthetic set with `_noisy` copies of its inputs at `snr` dB (the data set's noise).
fn with_noisy(ds: DataSet, snr: f64) -> DataSet {
    let inputs: Vec<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    ds.with_noise(NoiseModel::new(snr, SnrReference::Std), &inputs)
        .unwrap()
}

#[test]
fn fresh_noise_has_the_data_sets_level_and_changes_with_the_seed() {
    use railforce::learn::windows::{NoiseRefresher, prepare};
    let ds = with_noisy(synthetic(2, 3000), 6.0);
    let s = DataSpec {
        noise: NoiseProtocol::Matched,
        ..spec()
    };
    let prep = prepare(&ds, &s, None).unwrap();
    let at = |snr| NoiseModel::new(snr, SnrReference::Std);
    let clean = NoiseRefresher::new(&ds, &s, &prep.input_stats, &at(1000.0)).unwrap();
    let fresh = NoiseRefresher::new(&ds, &s, &prep.input_stats, &at(6.0)).unwrap();
    let (base, a, a2, b) = (clean.draw(1), fresh.draw(1), fresh.draw(1), fresh.draw(2));
    assert_eq!(a, a2, "same seed, same draw");
    assert_ne!(a, b, "another seed, another draw");
    // Per channel, the noise of the draw and of the data set's fixed copy have the same
    // spread (the draw is in the training view's standardisation).
    for r in 0..2 {
        for (k, name) in ["a", "b", "c"].iter().enumerate() {
            let col = |m: &[f32]| m.iter().skip(k).step_by(3).copied().collect::<Vec<f32>>();
            let (x0, xa) = (col(&base[r]), col(&a[r]));
            let run = &ds.runs[r];
            let ci = ds.names.iter().position(|n| n == name).unwrap();
            let ni = ds.names.len() - 3 + k;
            let std = |v: &[f64]| {
                let m = v.iter().sum::<f64>() / v.len() as f64;
                (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
            };
            let fixed_noise: Vec<f64> = run.columns[ni]
                .iter()
                .zip(&run.columns[ci])
                .map(|(n, c)| n - c)
                .collect();
            let drawn: Vec<f64> = xa
                .iter()
                .zip(&x0)
                .map(|(n, c)| ((n - c) as f64) * prep.input_stats.std[k])
                .collect();
            let ratio = std(&drawn) / std(&fixed_noise);
            assert!(
                (ratio - 1.0).abs() < 0.06,
                "run {r} channel {k}: drawn σ / data set σ = {ratio}"
            );
        }
    }
}

#[test]
fn fresh_noise_needs_the_matched_protocol() {
    let ds = with_noisy(synthetic(1, 400), 6.0);
    let opts = TrainOptions {
        fresh_noise: Some(NoiseModel::new(6.0, SnrReference::Std)),
        ..quick(1)
    };
    let err = train(
        &ds,
        &spec(),
        ModelKind::CnnBiLstm,
        &opts,
        &tmp("fresh"),
        &mut |_| {},
    )
    .err()
    .unwrap();
    assert!(err.to_string().contains("matched"), "{err}");
}

/// `--engine burn-cpu` trains the same model as the fused engine (the same files, loaded and
/// evaluated by the engine), and a checkpoint of one engine resumes in the other. Plain
/// networks on both sides: quantile heads train with the fused engine only, so burn leaves
/// them out (`TrainOptions::heads_for`) and the fused run must too to be the same model.
#[cfg(feature = "burn")]
#[test]
fn burn_trains_the_engines_model_and_resumes_its_checkpoints() {
    use railforce::learn::train::GradientEngine;
    let ds = synthetic(2, 300);
    let plain = |epochs| TrainOptions {
        quantile_heads: None,
        ..quick(epochs)
    };
    for kind in [ModelKind::CnnBiLstm, ModelKind::Gru] {
        let fused_dir = tmp(&format!("fused-{}", kind.name()));
        let burn_dir = tmp(&format!("burn-{}", kind.name()));
        let mut fused = train(&ds, &spec(), kind, &plain(3), &fused_dir, &mut |_| {}).unwrap();
        let burn_opts = TrainOptions {
            engine: GradientEngine::BurnCpu,
            ..plain(3)
        };
        train(&ds, &spec(), kind, &burn_opts, &burn_dir, &mut |_| {}).unwrap();
        // The burn-trained directory is an ordinary model: the engine loads and evaluates it.
        let mut by_burn = Model::load(&burn_dir).unwrap();
        let a = evaluate(&mut fused, &ds, EvalPart::Test).unwrap();
        let b = evaluate(&mut by_burn, &ds, EvalPart::Test).unwrap();
        let (la, lb) = (a.metrics[0].mse, b.metrics[0].mse);
        assert!(
            (la - lb).abs() <= 0.02 * la,
            "{}: test MSE fused {la} vs burn {lb}",
            kind.name()
        );
        // And the other way: burn loads the model directory and predicts the same numbers.
        let railforce::learn::model::Engine::Net(net) = &mut by_burn.engine else {
            unreachable!("a network")
        };
        let device = burn::tensor::Device::flex();
        let mut module = railforce::learn::burn::BurnNet::new(&net.config, &device);
        module.load(net, &device);
        let x: Vec<f32> = (0..10 * 8 * 3).map(|i| (i as f32 * 0.37).sin()).collect();
        let by_engine = net.predict(&x, 10);
        let in_burn = module.predict(&x, 10, 8, &device).unwrap();
        for (e, b) in by_engine.iter().zip(&in_burn) {
            assert!((e - b).abs() <= 1e-5 * e.abs().max(1.0), "{e} vs {b}");
        }
        // Resume the burn run with the fused engine for two more epochs: it continues.
        let more = TrainOptions {
            resume: true,
            ..plain(5)
        };
        let resumed = train(&ds, &spec(), kind, &more, &burn_dir, &mut |_| {}).unwrap();
        assert_eq!(resumed.meta.training["epochs_run"], 5, "{}", kind.name());
    }
}

#[cfg(not(feature = "burn"))]
#[test]
fn the_burn_engine_without_burn_says_how_to_build_it() {
    use railforce::learn::train::GradientEngine;
    let ds = synthetic(1, 200);
    let opts = TrainOptions {
        engine: GradientEngine::BurnCpu,
        ..quick(1)
    };
    let err = train(
        &ds,
        &spec(),
        ModelKind::Gru,
        &opts,
        &tmp("noburn"),
        &mut |_| {},
    )
    .err()
    .expect("refused")
    .to_string();
    assert!(err.contains("--features burn"), "{err}");
}

/// Quantile heads learn a noise that depends on the inputs: on a planted problem
/// `y = 1000·a + σ·ε` with σ four times larger where the slow input `b` is positive, the
/// heads' interval is wider there by about that factor (measured 3.1×), and the raw 90 %
/// quantile interval covers close to 90 % of held-out windows (measured 91.3 %) before any
/// conformal correction. Two of them joined into an ensemble spread by their total variance.
#[test]
fn quantile_heads_learn_where_the_noise_is_larger() {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    let rows = 4000;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let a: Vec<f64> = (0..rows).map(|t| (0.05 * t as f64).sin()).collect();
    let b: Vec<f64> = (0..rows).map(|t| (0.004 * t as f64).cos()).collect();
    let c: Vec<f64> = (0..rows).map(|t| (0.13 * t as f64).sin()).collect();
    let sigma = |t: usize| if b[t] > 0.0 { 400.0 } else { 100.0 };
    let y: Vec<f64> = (0..rows)
        .map(|t| {
            let e: f64 = StandardNormal.sample(&mut rng);
            1000.0 * a[t] + sigma(t) * e
        })
        .collect();
    let time: Vec<f64> = (0..rows).map(|t| t as f64 / 200.0).collect();
    let names = ["a", "b", "c", "w1l_force_y", "time_s"]
        .map(String::from)
        .to_vec();
    let ds = DataSet::in_memory(
        &PathBuf::from("planted"),
        names,
        vec![Run {
            condition: "planted".into(),
            seed: 1,
            columns: vec![a, b.clone(), c, y, time],
        }],
    );
    // Blocks 60/20/20: the test block holds both noise levels (b changes sign at t ≈ 1178,
    // 2749 and 3927).
    let spec = DataSpec {
        split: Split::Blocks {
            train: 0.6,
            val: 0.2,
        },
        ..spec()
    };
    let opts = TrainOptions {
        quantile_heads: Some(0.9),
        lr: 3e-3,
        // Without head dropout: dropout's own noise widens every quantile alike and hides
        // part of the planted contrast (measured: ratio 1.4 with 0.2, 3.1 without).
        dropout: 0.0,
        ..quick(40)
    };
    let out = tmp("quantile_heads");
    let mut model = train(&ds, &spec, ModelKind::Cnn, &opts, &out, &mut |_| {}).unwrap();
    let prep = railforce::learn::windows::prepare(&ds, &spec, None).unwrap();
    let (x, y) = prep.test.all();
    let (mean, spread) = model.predict_spread(&x, prep.test.len());
    let spread = spread.expect("quantile heads give a spread");
    let z = 1.6449; // the normal quantile of 0.95: spread · z is the heads' half-width
    let (mut wide, mut narrow, mut covered) = (Vec::new(), Vec::new(), 0usize);
    for i in 0..prep.test.len() {
        let (_, row) = prep.test.label_row(i);
        let half = spread[i] * z;
        if (y[i] - mean[i]).abs() <= half {
            covered += 1;
        }
        if b[row] > 0.1 {
            wide.push(half);
        } else if b[row] < -0.1 {
            narrow.push(half);
        }
    }
    let med = |v: &mut Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v[v.len() / 2]
    };
    assert!(
        wide.len() > 100 && narrow.len() > 100,
        "{} {}",
        wide.len(),
        narrow.len()
    );
    let ratio = med(&mut wide) / med(&mut narrow);
    assert!(
        ratio > 2.5,
        "interval width ratio {ratio} (planted σ ratio 4)"
    );
    let coverage = covered as f64 / prep.test.len() as f64;
    assert!((0.8..0.97).contains(&coverage), "raw coverage {coverage}");
    // Two such networks joined (seeds 1 and 2, each with its heads): the ensemble's mean is
    // the members' mean and its spread their total variance, Var_k(ŷ_k) + E_k(σ_k²), and the
    // joined model reads back from disk predicting the same.
    let second_out = tmp("quantile_heads_member2");
    let mut second = train(
        &ds,
        &spec,
        ModelKind::Cnn,
        &TrainOptions {
            seed: 2,
            ..opts.clone()
        },
        &second_out,
        &mut |_| {},
    )
    .unwrap();
    let (mean2, spread2) = second.predict_spread(&x, prep.test.len());
    let spread2 = spread2.expect("the second member's heads");
    let mut joined = railforce::learn::uncertainty::join(vec![model, second], &ds, &out).unwrap();
    assert_eq!(joined.meta.members, 2);
    let (m, s) = joined.predict_spread(&x, prep.test.len());
    let s = s.expect("an ensemble's spread");
    for i in 0..m.len() {
        let mu = 0.5 * (mean[i] + mean2[i]);
        let var = 0.5 * ((mean[i] - mu).powi(2) + (mean2[i] - mu).powi(2))
            + 0.5 * (spread[i].powi(2) + spread2[i].powi(2));
        assert!((m[i] - mu).abs() < 1e-5, "mean {} against {mu}", m[i]);
        assert!(
            (s[i] - var.sqrt()).abs() < 1e-4 * (1.0 + s[i]),
            "spread {} against {}",
            s[i],
            var.sqrt()
        );
    }
    let mut back = railforce::learn::model::Model::load(&out).unwrap();
    assert_eq!(back.predict_spread(&x, prep.test.len()), (m, Some(s)));
    // `train --ensemble` keeps heads for one network only: its members' spread is their
    // disagreement; classical models and the burn engine train without heads.
    assert_eq!(opts.heads_for(ModelKind::Cnn, 1), Some(0.9));
    assert_eq!(opts.heads_for(ModelKind::Cnn, 2), None);
    assert_eq!(opts.heads_for(ModelKind::Gbdt, 1), None);
}

/// A window shorter than the convolutional stem reads is refused before training (it was an
/// index panic), for both stemmed networks; the recurrent ones take one step. A hand-edited
/// `model.json` with a channel named twice, a coverage outside (0, 1) or such a window is
/// refused naming the field.
#[test]
fn short_windows_and_edited_model_files_are_refused() {
    let ds = synthetic(2, 200);
    let one = DataSpec {
        window: 1,
        ..spec()
    };
    for kind in [ModelKind::Cnn, ModelKind::CnnBiLstm] {
        let out = tmp(&format!("short-{}", kind.name()));
        let e = train(&ds, &one, kind, &quick(1), &out, &mut |_| {})
            .err()
            .expect("refused")
            .to_string();
        assert!(
            e.contains("window of 1 step") && e.contains("at least 2"),
            "{e}"
        );
    }
    train(
        &ds,
        &one,
        ModelKind::Gru,
        &quick(1),
        &tmp("short-gru"),
        &mut |_| {},
    )
    .unwrap();

    let out = tmp("edited");
    train(&ds, &spec(), ModelKind::Cnn, &quick(1), &out, &mut |_| {}).unwrap();
    let text = std::fs::read_to_string(out.join("model.json")).unwrap();
    let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
    for (edit, field) in [
        ("channels", "data.channels[1]"),
        ("quantiles", "net.quantiles"),
        ("window", "net.window"),
    ] {
        let mut j = json.clone();
        match edit {
            "channels" => j["data"]["channels"][1] = "a".into(),
            "quantiles" => j["net"]["quantiles"] = 1.5.into(),
            _ => j["net"]["window"] = 1.into(),
        }
        std::fs::write(out.join("model.json"), j.to_string()).unwrap();
        let e = Model::load(&out).err().expect("refused").to_string();
        assert!(e.contains("model.json") && e.contains(field), "{edit}: {e}");
    }
    json["net"]["window"] = 8.into();
    std::fs::write(out.join("model.json"), json.to_string()).unwrap();
    Model::load(&out).unwrap();
}
