//! Training and inference throughput of the networks (windows per second, one thread), with
//! this machine's sustained GEMM rate measured in the same run (the hardware reference), and
//! PyTorch's in alternating rounds where it is installed (`torch.rs`).

use railforce::learn::linalg::gemm;
use railforce::learn::neural::{Adam, Architecture, NetConfig, Network};
use railforce::learn::train::{GradientEngine, Stepper};
use std::time::Instant;

/// One architecture's figures.
#[derive(Debug, Clone)]
pub struct NetBench {
    /// Training windows per second (forward + backward + Adam) at the batch size.
    pub train_windows_per_s: f64,
    /// Inference windows per second in batches of 1024.
    pub infer_windows_per_s: f64,
    /// Inference latency of one window, ms.
    pub single_ms: f64,
}

/// Sustained single-thread GEMM rate, GFLOP/s, on the LSTM input projection's shape.
pub fn gemm_gflops() -> f64 {
    let (m, k, n) = (64 * 19, 128, 160);
    let a = vec![0.5f32; m * k];
    let b = vec![0.25f32; k * n];
    let mut c = vec![0.0f32; m * n];
    let mut reps = 0;
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < 0.5 {
        gemm(m, k, n, &a, false, &b, false, &mut c, 0.0);
        reps += 1;
    }
    2.0 * (m * k * n * reps) as f64 / t0.elapsed().as_secs_f64() / 1e9
}

fn bench_config(architecture: Architecture) -> NetConfig {
    NetConfig {
        quantiles: None,
        architecture,
        window: 20,
        channels: 21,
        outputs: 1,
        dropout: 0.2,
        seed: 1,
    }
}

fn windows(batch: usize) -> Vec<f32> {
    (0..batch * 20 * 21)
        .map(|i| ((i as f32) * 0.618).sin())
        .collect()
}

/// Training windows per second (forward + backward + Adam, what `train` runs) of one
/// architecture on 21-channel, 20-step windows with gradients by `engine`, for about
/// `seconds` after three warm-up steps (a GPU backend compiles its kernels then).
pub fn train_rate(
    architecture: Architecture,
    engine: GradientEngine,
    batch: usize,
    seconds: f64,
) -> railforce::Result<f64> {
    let config = bench_config(architecture);
    let mut stepper = Stepper::new(engine, &config)?;
    let mut net = Network::new(config);
    let mut adam = Adam::new(net.params.value.len(), 1e-3);
    let x = windows(batch);
    let y: Vec<f32> = (0..batch).map(|i| ((i as f32) * 0.1).cos()).collect();
    let mut dout = Vec::new();
    for _ in 0..3 {
        stepper.step(&mut net, &x, &y, batch, &mut dout)?;
        adam.step(&mut net.params);
    }
    let mut done = 0usize;
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < seconds || done == 0 {
        stepper.step(&mut net, &x, &y, batch, &mut dout)?;
        adam.step(&mut net.params);
        done += batch;
    }
    Ok(done as f64 / t0.elapsed().as_secs_f64())
}

/// Measures one architecture with the fused engine on 21-channel, 20-step windows for about
/// `seconds` per figure.
pub fn run(architecture: Architecture, batch: usize, seconds: f64) -> NetBench {
    let train = train_rate(architecture, GradientEngine::Fused, batch, seconds)
        .expect("the fused engine is always built");
    let infer = infer_rate(architecture, seconds);
    let mut net = Network::new(bench_config(architecture));
    let per = 20 * 21;
    let big = windows(1);
    let mut k = 0usize;
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < seconds / 2.0 || k == 0 {
        std::hint::black_box(net.predict(&big[..per], 1));
        k += 1;
    }
    NetBench {
        train_windows_per_s: train,
        infer_windows_per_s: infer,
        single_ms: t0.elapsed().as_secs_f64() * 1e3 / k as f64,
    }
}

/// Inference windows per second of one architecture in batches of 1 024 for about `seconds`.
pub fn infer_rate(architecture: Architecture, seconds: f64) -> f64 {
    let mut net = Network::new(bench_config(architecture));
    let big = windows(1024);
    let mut n = 0usize;
    std::hint::black_box(net.predict(&big, 1024));
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < seconds || n == 0 {
        std::hint::black_box(net.predict(&big, 1024));
        n += 1024;
    }
    n as f64 / t0.elapsed().as_secs_f64()
}

/// Inference windows per second of the CNN-BiLSTM on `threads` threads (the evaluation path
/// of `evaluate`, `experiment` and `identify`: [`Network::predict_all_on`]) and on one, in
/// alternating rounds of 8 192 windows for about `seconds` in all: `(one, threads)`.
pub fn infer_rate_on(threads: usize, seconds: f64) -> (f64, f64) {
    let mut net = Network::new(bench_config(Architecture::CnnBiLstm));
    let n = 8 * 1024;
    let big = windows(n);
    let (mut one, mut many) = (0.0, 0.0);
    let t0 = Instant::now();
    let mut rounds = 0usize;
    while t0.elapsed().as_secs_f64() < seconds || rounds == 0 {
        let t = Instant::now();
        std::hint::black_box(net.predict_all(&big, n));
        one += t.elapsed().as_secs_f64();
        let t = Instant::now();
        std::hint::black_box(net.predict_all_on(&big, n, threads));
        many += t.elapsed().as_secs_f64();
        rounds += 1;
    }
    let done = (rounds * n) as f64;
    (done / one, done / many)
}

/// Training rates with gradients by burn (`engines`: `burn-cpu`, `burn-gpu`) for the four
/// networks at each batch size, each beside the fused engine at the same batch measured in the
/// same run (the reference the ratio is read against).
pub fn burn_table(engines: &[String], batches: &[usize], seconds: f64) -> anyhow::Result<()> {
    use Architecture as A;
    let engines: Vec<GradientEngine> = engines
        .iter()
        .filter_map(|e| GradientEngine::from_name(e))
        .collect();
    println!(
        "training with gradients by burn 0.22 (21 channels × 20 steps; weights upload and gradients read back every step, Adam in the engine)"
    );
    println!(
        "{:<11} {:>6} {:<10} {:>12} {:>15} {:>10}",
        "network", "batch", "engine", "train win/s", "fused win/s", "vs fused"
    );
    for a in [A::CnnBiLstm, A::Cnn, A::BiLstm, A::Gru] {
        for &batch in batches {
            let fused = train_rate(a, GradientEngine::Fused, batch, seconds)?;
            for &engine in &engines {
                let rate = train_rate(a, engine, batch, seconds)?;
                println!(
                    "{:<11} {:>6} {:<10} {:>12.0} {:>15.0} {:>9.2}×",
                    a.name(),
                    batch,
                    engine.name(),
                    rate,
                    fused,
                    rate / fused
                );
            }
        }
    }
    Ok(())
}

/// Seconds to fit `params` on `n` synthetic windows of `f` features (one output), and the
/// test R² reached (a smooth nonlinear function of a few features, so the fit is real work).
pub fn classical_fit(
    params: railforce::learn::classical::ClassicalParams,
    n: usize,
    f: usize,
) -> (f64, f64) {
    use railforce::learn::classical::Classical;
    let make = |n: usize, seed: u64| -> (Vec<f32>, Vec<f32>) {
        let mut s = seed;
        let x: Vec<f32> = (0..n * f)
            .map(|_| {
                s = s
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                ((s >> 40) as f32 / (1u64 << 24) as f32) * 3.0 - 1.5
            })
            .collect();
        let y = (0..n)
            .map(|r| {
                let v = &x[r * f..];
                (2.0 * v[0]).sin() * v[1] + v[2] * v[2] + 0.5 * v[f / 2] * v[f - 1]
            })
            .collect();
        (x, y)
    };
    let (x, y) = make(n, 1);
    let t0 = Instant::now();
    let m = Classical::fit(params, &x, f, &y, 1, &mut |_, _| {});
    let secs = t0.elapsed().as_secs_f64();
    let (xt, yt) = make(2000, 2);
    let p = m.predict(&xt, 2000);
    let mean = yt.iter().sum::<f32>() / yt.len() as f32;
    let sst: f32 = yt.iter().map(|v| (v - mean).powi(2)).sum();
    let sse: f32 = yt.iter().zip(&p).map(|(a, b)| (a - b).powi(2)).sum();
    (secs, (1.0 - sse / sst) as f64)
}

/// Streaming latency of the CNN-BiLSTM, µs per new sample ([`railforce::identify::Streamer::push`]:
/// standardise, shift the window, one forward pass), over `samples` pushes.
pub fn streaming_latency_us(samples: usize) -> f64 {
    use railforce::features::{LabelAt, NoiseProtocol, Split, ZScore};
    use railforce::learn::model::{Engine, Model, ModelKind, ModelMeta};
    use railforce::learn::windows::DataSpec;
    let channels: Vec<String> = railforce::sensors::PAPER_CHANNELS
        .iter()
        .map(|c| c.to_string())
        .collect();
    let config = NetConfig {
        quantiles: None,
        architecture: Architecture::CnnBiLstm,
        window: 20,
        channels: 21,
        outputs: 2,
        dropout: 0.2,
        seed: 1,
    };
    let net = Network::new(config.clone());
    let stats = |names: Vec<String>| ZScore {
        mean: vec![0.0; names.len()],
        std: vec![1.0; names.len()],
        names,
    };
    let mut model = Model {
        meta: ModelMeta {
            kind: ModelKind::CnnBiLstm,
            data: DataSpec {
                channels: channels.clone(),
                targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
                window: 20,
                label_at: LabelAt::Last,
                stride: 1,
                split: Split::default(),
                noise: NoiseProtocol::Clean,
                noise_model: None,
            },
            input_stats: stats(channels),
            target_stats: stats(vec!["w1l_force_y".into(), "w1l_force_z".into()]),
            net: Some(config),
            slots: Some(net.params.slots.clone()),
            data_identity: serde_json::Value::Null,
            training: serde_json::Value::Null,
            version: String::new(),
            members: 1,
            calibration: None,
        },
        engine: Engine::Net(Box::new(net)),
        members: Vec::new(),
    };
    let mut st = railforce::identify::Streamer::new(&mut model);
    let row: Vec<f64> = (0..21).map(|k| (k as f64 * 0.3).sin()).collect();
    for i in 0..20 {
        st.push(i as f64 * 0.005, &row);
    }
    let t0 = Instant::now();
    for i in 0..samples {
        std::hint::black_box(st.push((20 + i) as f64 * 0.005, &row));
    }
    t0.elapsed().as_secs_f64() * 1e6 / samples as f64
}
