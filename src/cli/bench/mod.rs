//! `railforce bench …`: built-in benchmarks.

mod against;
mod contact;
mod learn;
mod simulate;
mod step;
mod torch;

use anyhow::Result;
use clap::{Args, Subcommand};

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(Debug, Subcommand)]
enum What {
    /// Training and inference throughput of the four networks (windows/s, one thread, batch
    /// 64, 21 channels × 20 steps) beside this machine's GEMM rate, and with --against-torch
    /// PyTorch's CNN-BiLSTM measured in the same run; then the fit time of XGBoost-style and
    /// GBDT boosting on synthetic windows.
    Learn {
        /// Seconds per network figure.
        #[arg(long, default_value_t = 3.0)]
        seconds: f64,
        /// Rows of the boosting fit (0 skips it).
        #[arg(long, default_value_t = 40_000)]
        rows: usize,
        /// Also time training with gradients by burn: `burn-cpu` (Flex backend, needs
        /// `--features burn`) and/or `burn-gpu` (needs `--features burn-gpu` and a GPU),
        /// comma separated, each beside the fused engine at the same batch.
        #[arg(long, value_delimiter = ',', value_parser = ["burn-cpu", "burn-gpu"])]
        burn: Vec<String>,
        /// Batch sizes of the burn figures.
        #[arg(long, value_delimiter = ',', default_value = "64")]
        batches: Vec<usize>,
        /// Only the burn figures (skip the fused table, inference and boosting).
        #[arg(long)]
        burn_only: bool,
        /// Also measure PyTorch's CNN-BiLSTM (assets/python/bench_torch.py, the module
        /// `export` targets) against the engine in alternating rounds: the same windows,
        /// batch and thread count, training and inference, both windows/s and their ratio.
        /// Needs PyTorch for `--python` (CPU build: `pip install torch --index-url
        /// https://download.pytorch.org/whl/cpu`).
        #[arg(long)]
        against_torch: bool,
        /// Python interpreter with PyTorch, for --against-torch.
        #[arg(long, default_value = "python3")]
        python: String,
        /// Alternating rounds of --against-torch (each times both, in turn first).
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
        rounds: u32,
    },
    /// One wheel's contact evaluation during a simulation step (table lookup + Hertz +
    /// creepages + Polach), against FASTSIM and a full rigid solve measured in the same run.
    /// Build with --release for meaningful numbers.
    Contact {
        /// Vehicle file whose wheel–rail pair is timed.
        #[arg(long, default_value = "vehicles/c80.toml")]
        vehicle: std::path::PathBuf,
        /// Evaluations timed.
        #[arg(long, default_value_t = 2_000_000)]
        iterations: usize,
    },
    /// The full C80 on tangent track with FRA class 5 irregularities and profile contact: wall
    /// time per integration step and real-time factor, physics only and with every channel
    /// filtered and sampled (one thread).
    Simulate {
        /// Vehicle file.
        #[arg(long, default_value = "vehicles/c80.toml")]
        vehicle: std::path::PathBuf,
        /// Track file.
        #[arg(long, default_value = "tracks/tangent.toml")]
        track: std::path::PathBuf,
        /// Speed, km/h.
        #[arg(long, default_value_t = 80.0)]
        speed_kmh: f64,
        /// Simulated seconds per measurement.
        #[arg(long, default_value_t = 20.0)]
        seconds: f64,
        /// Measurements of each kind, taken in turn; the fastest counts and the slowest is
        /// shown beside it (on a shared machine other work only ever slows a run down).
        #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u64).range(1..))]
        repeat: u64,
        /// Integrator (default: the default; `bench step` measures what each costs in accuracy).
        #[arg(long, value_parser = railforce::sim::Integrator::NAMES)]
        integrator: Option<String>,
        /// Integration step, s (default: the integrator's own; on rails on sleepers 0.1 ms, faster
        /// than 60 km/h 1.67 mm of travel a step).
        #[arg(long)]
        dt: Option<f64>,
        /// The rails' support over the track file's (`rigid`, `lumped`, `discrete`, as
        /// `simulate --rail-support`); when it changes the file's, the file's own is timed in
        /// the same run and the ratio printed (what the track costs).
        #[arg(long, value_parser = railforce::track::RAIL_SUPPORT_MODELS, conflicts_with = "against")]
        rail_support: Option<String>,
        /// Another railforce binary (an older build, say) to time against this one: `--repeat`
        /// rounds, each measuring both, in alternating order; prints each round's real-time
        /// factors and the ratio of the medians (this build's speed-up). Each binary steps at
        /// its own default unless --integrator or --dt is given. A shared machine's load then
        /// falls on both alike.
        #[arg(long, value_name = "BINARY")]
        against: Option<std::path::PathBuf>,
    },
    /// Accuracy and speed against the integration step: the same run (default R 400 m, FRA
    /// class 5, 60 km/h, 15 s) at each step and at a finer reference step; every wheel's Y/Q
    /// rms and Q standard deviation, the label wheel's FL standard deviation and the labels'
    /// power above 40 Hz, and the wall time. A step that diverges or derails says so.
    Step(step::StepArgs),
}

pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        What::Learn {
            seconds,
            rows,
            burn,
            batches,
            burn_only,
            against_torch,
            python,
            rounds,
        } => {
            use learn;
            use railforce::learn::neural::Architecture as A;
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench learn`");
            }
            if burn_only && against_torch {
                anyhow::bail!(
                    "--against-torch times the fused engine, which --burn-only skips: give one of them"
                );
            }
            if burn_only {
                return learn::burn_table(&burn, &batches, seconds);
            }
            // PyTorch first: a missing one stops the bench before it has timed anything.
            let torch = if against_torch {
                Some(torch::Torch::start(&python, 64)?)
            } else {
                None
            };
            let gf = learn::gemm_gflops();
            println!("GEMM [1216×128]·[128×160], one thread: {gf:.1} GFLOP/s (hardware reference)");
            println!(
                "{:<11} {:>14} {:>12} {:>14} {:>12}",
                "network", "train win/s", "infer win/s", "single window", "train/GFLOP"
            );
            for a in [A::CnnBiLstm, A::Cnn, A::BiLstm, A::Gru] {
                let b = learn::run(a, 64, seconds);
                println!(
                    "{:<11} {:>14.0} {:>12.0} {:>11.3} ms {:>12.1}",
                    a.name(),
                    b.train_windows_per_s,
                    b.infer_windows_per_s,
                    b.single_ms,
                    b.train_windows_per_s / gf
                );
            }
            if let Some(torch) = torch {
                torch::compare(torch, A::CnnBiLstm, 64, rounds as usize, seconds)?;
            } else {
                println!(
                    "(against PyTorch in the same run, alternating rounds: --against-torch; needs PyTorch)"
                );
            }
            let cores = railforce::dataset::default_jobs();
            if cores > 1 {
                let (one, many) = learn::infer_rate_on(cores, 2.0 * seconds);
                println!(
                    "evaluation path (cnn-bilstm, 8 192 windows, alternating rounds): {many:.0} win/s on {cores} threads against {one:.0} on one, {:.2}×",
                    many / one
                );
            }
            let lat = learn::streaming_latency_us(5000);
            println!(
                "streaming identification (cnn-bilstm, FL + FQ): {lat:.1} µs per new sample, {:.0}× inside the 5 ms sampling interval",
                5000.0 / lat
            );
            if !burn.is_empty() {
                learn::burn_table(&burn, &batches, seconds)?;
            }
            if rows > 0 {
                use railforce::learn::classical::ClassicalParams;
                for (name, p, reference) in [
                    (
                        "xgboost (300 trees, depth 6)",
                        ClassicalParams::xgboost(),
                        Some(34.0),
                    ),
                    ("gbdt (100 trees, depth 3)", ClassicalParams::gbdt(), None),
                ] {
                    let (s, r2) = learn::classical_fit(p, rows, 420);
                    let refs = reference
                        .map(|r| format!(", XGBoost reference {r:.0} s: {:.2}×", r / s))
                        .unwrap_or_default();
                    println!("{name}: fit {rows} × 420 in {s:.1} s (test R² {r2:.3}{refs})");
                }
            }
            Ok(())
        }
        What::Simulate {
            vehicle,
            track,
            speed_kmh,
            seconds,
            repeat,
            integrator,
            dt,
            rail_support,
            against,
        } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench simulate`");
            }
            let (vehicle, track) = (
                super::builtin::resolve(&vehicle)?,
                super::builtin::resolve(&track)?,
            );
            let v = railforce::vehicle::Vehicle::load(&vehicle)?;
            let t0 = std::time::Instant::now();
            v.contact.table();
            let table_s = t0.elapsed().as_secs_f64();
            let file_track = railforce::track::Track::load(&track)?;
            let mut spec = file_track.spec().clone();
            if let Some(m) = &rail_support {
                spec.set_rail_model(m)?;
            }
            let tr = railforce::track::Track::new(spec, None);
            let default = railforce::sim::SimConfig::default();
            let stepping = railforce::sim::Stepping::chosen(integrator.as_deref(), dt);
            let base = railforce::sim::SimConfig {
                integrator: stepping.integrator,
                dt: stepping.step_on(tr.spec(), &v, speed_kmh / 3.6)?,
                ..default.clone()
            };
            if let Some(other) = against {
                let mut args: Vec<String> = vec![
                    "--vehicle".into(),
                    vehicle.display().to_string(),
                    "--track".into(),
                    track.display().to_string(),
                    "--speed-kmh".into(),
                    speed_kmh.to_string(),
                    "--seconds".into(),
                    seconds.to_string(),
                ];
                if let Some(i) = &integrator {
                    args.extend(["--integrator".into(), i.clone()]);
                }
                if let Some(dt) = dt {
                    args.extend(["--dt".into(), dt.to_string()]);
                }
                return ab_rounds(&v, &tr, speed_kmh, seconds, repeat, &base, &other, &args);
            }
            let repeat = repeat as usize;
            let b = simulate::run(&v, &tr, speed_kmh / 3.6, seconds, repeat, &base)?;
            println!(
                "simulation benchmark: {} on {} ({} rails), {speed_kmh} km/h, {seconds} s, {} step {} ms, one thread, fastest of {repeat}",
                v.name,
                tr.spec().name,
                tr.spec().rail_model(),
                base.integrator.name(),
                b.dt * 1e3
            );
            let own = file_track.spec().rail_model();
            if tr.spec().rail_model() != own {
                let file_cfg = railforce::sim::SimConfig {
                    dt: stepping.step_on(file_track.spec(), &v, speed_kmh / 3.6)?,
                    ..base.clone()
                };
                let r =
                    simulate::run(&v, &file_track, speed_kmh / 3.6, seconds, repeat, &file_cfg)?;
                println!(
                    "  against the file's {own} rails ({} ms) in the same run: physics {:.2}× ({:.1}× real time), all channels {:.2}× ({:.1}× real time)",
                    file_cfg.dt * 1e3,
                    b.real_time_factor / r.real_time_factor,
                    r.real_time_factor,
                    b.real_time_factor_recorded / r.real_time_factor_recorded,
                    r.real_time_factor_recorded
                );
            } else if base.integrator != default.integrator || base.dt != default.dt {
                let r = simulate::run(&v, &tr, speed_kmh / 3.6, seconds, repeat, &default)?;
                println!(
                    "  against the default ({} at {} ms) in the same run: physics {:.2}× ({:.1}× real time), all channels {:.2}× ({:.1}× real time)",
                    default.integrator.name(),
                    default.dt * 1e3,
                    b.real_time_factor / r.real_time_factor,
                    r.real_time_factor,
                    b.real_time_factor_recorded / r.real_time_factor_recorded,
                    r.real_time_factor_recorded
                );
            }
            let slowest = |us: f64| {
                if repeat > 1 {
                    format!(" (slowest {us:.2})")
                } else {
                    String::new()
                }
            };
            println!(
                "  physics only:       {:>6.2} µs per step{}, {:>5.1}× real time",
                b.step_us,
                slowest(b.slowest_us.0),
                b.real_time_factor
            );
            println!(
                "  with all channels:  {:>6.2} µs per step{}, {:>5.1}× real time (recording costs {:.0} % of the physics)",
                b.step_recorded_us,
                slowest(b.slowest_us.1),
                b.real_time_factor_recorded,
                100.0 * (b.step_recorded_us / b.step_us - 1.0)
            );
            println!(
                "  contact table (once per wheelset geometry in a process, all cores): {table_s:.2} s"
            );
            println!("  build: {}", railforce::sim::profile::vector_build());
            println!(
                "where a recorded step's time goes (a profiled run: {:.2} µs per step with the clock read around every part; the clock's own cost taken off):",
                b.profiled_step_us
            );
            // Parts nested in another ("  of which …") are not added to the total.
            let total: f64 = b
                .profile
                .iter()
                .filter(|p| !p.0.starts_with("  "))
                .map(|p| p.1)
                .sum();
            for (part, us, calls) in &b.profile {
                println!(
                    "  {part:<58} {us:>6.3} µs  {:>5.1} %  ({calls:.0} per step)",
                    100.0 * us / total.max(1e-12)
                );
                if part == "force elements" {
                    for (kind, n, ns) in &b.elements {
                        println!(
                            "    {:<56} {:>6.3} µs  ({n} × {ns:.0} ns, measured apart)",
                            format!("of which {kind}"),
                            *n as f64 * ns * 1e-3
                        );
                    }
                }
            }
            Ok(())
        }
        What::Step(args) => step::run(&args),
        What::Contact {
            vehicle,
            iterations,
        } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench contact`");
            }
            let v = railforce::vehicle::Vehicle::load(&super::builtin::resolve(&vehicle)?)?;
            let b = contact::run(&v, iterations);
            println!(
                "contact benchmark ({}: {} on {}, one thread, 122.6 kN, 60 km/h)",
                v.name,
                v.contact.geometry.wheel().name,
                v.contact.geometry.rail().name
            );
            println!(
                "  one wheel, strips + Hertz + Polach (what a run executes): {:>10.1} ns  ({:.2}× the 1 µs budget)",
                b.wheel_polach_ns,
                b.wheel_polach_ns / 1000.0
            );
            println!(
                "  one wheel, strips + Hertz + FASTSIM 60×60: {:>10.1} ns  (Polach is {:.0}× faster)",
                b.wheel_fastsim_ns,
                b.wheel_fastsim_ns / b.wheel_polach_ns
            );
            println!(
                "  rigid contact solve, both wheels:  {:>10.0} ns  (the table lookup path is {:.0}× faster)",
                b.rigid_solve_ns,
                b.rigid_solve_ns / b.wheel_polach_ns
            );
            println!(
                "  contact table with strips (±40 mm every 0.1 mm, all cores): {:>6.2} s",
                b.table_build_s
            );
            Ok(())
        }
    }
}

/// `bench simulate --against`: `rounds` alternating measurements of this build and `other`
/// (run with `args`: the same vehicle, track, speed, duration and stepping).
#[allow(clippy::too_many_arguments)]
fn ab_rounds(
    v: &railforce::vehicle::Vehicle,
    tr: &railforce::track::Track,
    speed_kmh: f64,
    seconds: f64,
    rounds: u64,
    base: &railforce::sim::SimConfig,
    other: &std::path::Path,
    args: &[String],
) -> Result<()> {
    println!(
        "simulation benchmark against {}: {} on {}, {speed_kmh} km/h, {seconds} s, {} step {} ms, {rounds} rounds alternating (× real time, physics / all channels; each binary at its own default step unless --integrator or --dt is given)",
        other.display(),
        v.name,
        tr.spec().name,
        base.integrator.name(),
        base.dt * 1e3
    );
    let (mut this, mut that) = (Vec::new(), Vec::new());
    for round in 0..rounds {
        // Alternate which goes first, so neither always follows the other's warm-up.
        let mine = || simulate::once(v, tr, speed_kmh / 3.6, seconds, base);
        if round % 2 == 0 {
            this.push(mine()?);
            that.push(against::other_once(other, args)?);
        } else {
            that.push(against::other_once(other, args)?);
            this.push(mine()?);
        }
        let (a, b) = (this[this.len() - 1], that[that.len() - 1]);
        println!(
            "  round {}: this {:.1} / {:.1}, the other {:.1} / {:.1}",
            round + 1,
            a.0,
            a.1,
            b.0,
            b.1
        );
    }
    // Physics-only and recorded real-time factors of each side, then the two summaries of each.
    let column = |v: &[(f64, f64)], k: usize| -> Vec<f64> {
        v.iter().map(|x| if k == 0 { x.0 } else { x.1 }).collect()
    };
    let fastest = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    for (name, stat) in [
        ("median", against::median as fn(&[f64]) -> f64),
        ("fastest", fastest),
    ] {
        let [p, q, r, s] =
            [(&this, 0), (&that, 0), (&this, 1), (&that, 1)].map(|(v, k)| stat(&column(v, k)));
        println!(
            "  {name}: physics {p:.1}× against {q:.1}× real time ({:.3}× the other's speed), all channels {r:.1}× against {s:.1}× ({:.3}×)",
            p / q,
            r / s
        );
    }
    println!("  build: {}", railforce::sim::profile::vector_build());
    Ok(())
}
