//! `railforce identify` and `railforce validate identify`: forces and safety indices from
//! sensor recordings with a trained model.

use anyhow::{Context, Result, bail};
use clap::Args;
use railforce::identify::safety::{IndexReport, Limits, indices};
use railforce::identify::{SensorTable, Streamer, check, identify};
use railforce::learn::model::Model;
use std::fmt::Write as _;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

/// Limits of the safety indices (defaults: commonly quoted Chinese values, secondary sources).
#[derive(Debug, Args, Clone)]
pub struct LimitArgs {
    /// Derailment coefficient |Y|/Q limit (1.2 allowable, 1.0 preferred).
    #[arg(long, default_value_t = 1.2)]
    pub limit_yq: f64,
    /// Wheel unloading ΔQ/Q̄ limit (0.65 allowable, 0.60 preferred).
    #[arg(long, default_value_t = 0.65)]
    pub limit_unloading: f64,
    /// Static wheel load Q̄, kN [default: the --vehicle's weight over its wheels]; H's limit
    /// 0.85·(10 + P_st/3) follows from it.
    #[arg(long)]
    pub static_wheel_load_kn: Option<f64>,
    /// Vehicle whose weight gives the static wheel load (C80 loaded: 100 t on 8 wheels →
    /// 122.6 kN).
    #[arg(long, default_value = "vehicles/c80.toml")]
    pub vehicle: PathBuf,
}

impl LimitArgs {
    pub fn limits(&self) -> Result<Limits> {
        let static_wheel_load_kn = match self.static_wheel_load_kn {
            Some(q) => q,
            None => {
                let v =
                    railforce::vehicle::Vehicle::load(&super::builtin::resolve(&self.vehicle)?)?;
                v.mass() * railforce::GRAVITY / (2 * v.contact.wheelsets.len()) as f64 * 1e-3
            }
        };
        Ok(Limits {
            y_over_q: self.limit_yq,
            unloading: self.limit_unloading,
            static_wheel_load_kn,
        })
    }
}

#[derive(Debug, Args)]
pub struct IdentifyArgs {
    /// Model directory written by `railforce train`.
    #[arg(long)]
    model: PathBuf,
    /// Sensor file (CSV, NPZ or Parquet, named channels and a time column `time_s`), or `-`
    /// to stream CSV lines from standard input (header first).
    #[arg(long)]
    input: PathBuf,
    /// Output CSV of identified forces (N) and safety indices; `-` for standard output.
    #[arg(long, default_value = "-")]
    out: PathBuf,
    /// Interpolate the input linearly onto 200 Hz instead of refusing another rate.
    #[arg(long)]
    resample: bool,
    #[command(flatten)]
    limits: LimitArgs,
}

pub fn run(args: IdentifyArgs) -> Result<()> {
    let mut model = Model::load(&args.model)?;
    if args.input.as_os_str() == "-" {
        return stream(&mut model, &args.out);
    }
    let table = SensorTable::read(&args.input)?;
    let input = check(&table, &model, args.resample)?;
    let t0 = std::time::Instant::now();
    let id = identify(&mut model, &input);
    let secs = t0.elapsed().as_secs_f64();
    let reports = indices(&id, &args.limits.limits()?);
    let mut s = String::from("time_s");
    for t in &id.targets {
        let _ = write!(s, ",{t}_N");
    }
    for r in &reports {
        let _ = write!(s, ",{}", r.name.replace(' ', "_"));
    }
    s.push('\n');
    for (i, t) in id.time.iter().enumerate() {
        let _ = write!(s, "{t:.3}");
        for v in &id.values[i] {
            let _ = write!(s, ",{v:.1}");
        }
        for r in &reports {
            let _ = write!(s, ",{:.4}", r.series[i]);
        }
        s.push('\n');
    }
    if args.out.as_os_str() == "-" {
        std::io::stdout().write_all(s.as_bytes())?;
    } else {
        railforce::io::write_atomic(&args.out, |w| w.write_all(s.as_bytes()))?;
        let json = serde_json::to_string_pretty(&reports)?;
        let sp = args.out.with_extension("safety.json");
        railforce::io::write_atomic(&sp, |w| w.write_all(json.as_bytes()))?;
        eprintln!(
            "identified {} estimates of {} from {} ({} channels: {}) in {:.3} s; wrote {} and {}",
            id.time.len(),
            id.targets.join(", "),
            args.input.display(),
            input.used.len(),
            if input.used.iter().any(|u| u.ends_with("_noisy")) {
                "the _noisy copies"
            } else {
                "clean names"
            },
            secs,
            args.out.display(),
            sp.display()
        );
        if let Some(n) = model.meta.data.noise_model {
            eprintln!(
                "the model was trained on inputs at {} dB (σ from each channel's {}): it expects sensor signals about that noisy; `validate identify` checks it at that SNR",
                n.snr_db,
                n.reference.name()
            );
        }
    }
    print_safety(&reports);
    Ok(())
}

/// Prints the exceedance report to standard error.
pub fn print_safety(reports: &[IndexReport]) {
    if reports.is_empty() {
        eprintln!(
            "safety: no index available (Y/Q needs Y and Q of one wheel: train with --target both)"
        );
    }
    for r in reports {
        let verdict = if r.exceedances.is_empty() {
            "within limit"
        } else {
            "EXCEEDED"
        };
        eprintln!(
            "safety {:<22} max {:>8.3} at {:>8.3} s, limit {:.3} (secondary-source value): {verdict}",
            r.name, r.max, r.max_time_s, r.limit
        );
        for (a, b, peak) in &r.exceedances {
            eprintln!(
                "    above the limit from {a:.3} s to {b:.3} s ({:.0} ms), peak {peak:.3}",
                (b - a) * 1000.0 + 5.0
            );
        }
    }
}

/// Streams CSV lines from standard input; writes each estimate as soon as its window is full.
fn stream(model: &mut Model, out: &Path) -> Result<()> {
    let stdin = std::io::stdin();
    let mut lines = stdin.lock().lines();
    let header = lines
        .next()
        .context("empty input: expected a CSV header")??;
    let names: Vec<String> = header.split(',').map(|s| s.trim().to_string()).collect();
    let time_k = names
        .iter()
        .position(|n| railforce::identify::TIME_COLUMNS.contains(&n.as_str()))
        .context("stdin: no time column (time_s, time or t)")?;
    let spec = model.meta.data.clone();
    let header: Vec<&str> = names.iter().map(String::as_str).collect();
    let pick = railforce::identify::resolve_channels(&header, model, "stdin")?;
    let mut w: Box<dyn Write> = if out.as_os_str() == "-" {
        Box::new(std::io::stdout().lock())
    } else {
        Box::new(std::io::BufWriter::new(std::fs::File::create(out)?))
    };
    let mut head = String::from("time_s");
    for t in &spec.targets {
        let _ = write!(head, ",{t}_N");
    }
    writeln!(w, "{head}")?;
    let mut st = Streamer::new(model);
    let mut values = vec![0.0; pick.len()];
    let mut last_t: Option<f64> = None;
    for (row, line) in lines.enumerate() {
        let line = line?;
        let fields: Vec<&str> = line.split(',').collect();
        let num = |k: usize, name: &str| -> Result<f64> {
            let v: f64 = fields
                .get(k)
                .and_then(|s| s.trim().parse().ok())
                .with_context(|| format!("stdin row {}: column {name} is not a number", row + 1))?;
            if !v.is_finite() {
                bail!("stdin row {}: column {name} is {v}", row + 1);
            }
            Ok(v)
        };
        let t = num(time_k, "time")?;
        if let Some(p) = last_t
            && !railforce::identify::is_regular_step(t - p)
        {
            bail!(
                "stdin rows {}–{}: step {:.6} s; streaming needs 200 Hz without gaps",
                row,
                row + 1,
                t - p
            );
        }
        last_t = Some(t);
        for (v, &k) in values.iter_mut().zip(&pick) {
            *v = num(k, &names[k])?;
        }
        if let Some((tl, f)) = st.push(t, &values) {
            let mut s = format!("{tl:.3}");
            for v in f {
                let _ = write!(s, ",{v:.1}");
            }
            writeln!(w, "{s}")?;
            w.flush()?;
        }
    }
    Ok(())
}

/// `validate identify`: closed loop on fresh simulations.
pub fn validate(
    model_dir: &Path,
    plan: &Path,
    seed: Option<u64>,
    jobs: usize,
    limits: &Limits,
    margin: f64,
) -> Result<()> {
    if !(0.0..1.0).contains(&margin) {
        bail!("--margin {margin}: expected a fraction between 0 and 1 (0.2 = 20 %)");
    }
    let mut model = Model::load(model_dir)?;
    let plan = railforce::plan::Plan::load(&super::builtin::resolve(plan)?)?;
    let seed = seed.unwrap_or_else(|| railforce::identify::closed_loop::fresh_seed(&model));
    let work = model_dir.join(format!("closed_loop_seed{seed}"));
    let noise = match model.meta.data.noise {
        railforce::features::NoiseProtocol::Clean => None,
        _ => model.meta.data.noise_model,
    };
    eprintln!(
        "simulating {} condition(s) of {} with seed {seed} into {}, inputs {} (as the model was trained) …",
        plan.conditions.len(),
        plan.name,
        work.display(),
        noise
            .map(|n| format!(
                "noised at {} dB, σ from the {}",
                n.snr_db,
                n.reference.name()
            ))
            .unwrap_or_else(|| "clean".into())
    );
    let runs = railforce::identify::closed_loop::validate(
        &mut model, &plan, seed, &work, jobs, limits, margin,
    )?;
    println!(
        "{:<22} {:<14} {:>7} {:>9} {:>12}",
        "condition", "target", "R²", "RMSE kN", "peak err kN"
    );
    for r in &runs {
        for t in &r.targets {
            println!(
                "{:<22} {:<14} {:>7.3} {:>9.2} {:>12.2}",
                r.condition, t.target, t.r2, t.rmse_kn, t.peak_error_kn
            );
        }
    }
    println!(
        "\n{:<22} {:<16} {:>8} {:>10} {:>11} {:>10} {:>11}  verdicts",
        "condition", "index", "limit", "true peak", "id ÷ true", "true 99.85", "id ÷ true"
    );
    let ratio = |r: Option<f64>| r.map_or("—".to_string(), |r| format!("{r:.2}"));
    let (mut differ, mut under, mut reached) = (0, Vec::new(), 0);
    for r in &runs {
        for c in &r.safety {
            let exceeds = |b: bool| if b { "over" } else { "within" };
            println!(
                "{:<22} {:<16} {:>8.3} {:>10.3} {:>11} {:>10.3} {:>11}  true {}, identified {}{}",
                r.condition,
                format!("{} {}", c.index, c.place),
                c.limit,
                c.true_peak,
                ratio(c.peak_ratio),
                c.true_p99_85,
                ratio(c.p99_85_ratio),
                exceeds(c.true_exceeds),
                exceeds(c.identified_exceeds),
                if c.verdicts_agree { "" } else { "  DISAGREE" }
            );
            differ += usize::from(!c.verdicts_agree);
            reached += usize::from(c.true_exceeds || c.identified_exceeds);
            if c.underestimated {
                under.push(format!(
                    "warning: {} {} {}: identified peak {} × and 99.85 % percentile {} × the true (more than {:.0} % low)",
                    r.condition,
                    c.index,
                    c.place,
                    ratio(c.peak_ratio),
                    ratio(c.p99_85_ratio),
                    100.0 * margin
                ));
            }
        }
    }
    for w in &under {
        eprintln!("{w}");
    }
    let checks: usize = runs.iter().map(|r| r.safety.len()).sum();
    let verdicts = if reached == 0 {
        "no limit was reached by the truth or the identification, so the verdicts test nothing here"
            .to_string()
    } else if differ == 0 {
        format!("safety verdicts agree on all {checks} (a limit was reached in {reached})")
    } else {
        format!("safety verdicts DIFFER on {differ} of {checks}")
    };
    let dir = model_dir.join(format!("closed_loop_seed{seed}_report"));
    let settings = railforce::identify::check_report::CheckSettings {
        model: &format!("{} ({})", model.meta.kind.name(), model_dir.display()),
        plan: &plan.name,
        seed,
        margin,
        limits,
        noise: noise
            .map(|n| n.describe())
            .unwrap_or_else(|| "clean".into()),
    };
    let index = railforce::identify::check_report::write(&dir, &runs, &settings)?;
    println!(
        "{verdicts}; {} of {checks} statistics under-identified by more than {:.0} %.\nreport: {} (closed_loop.json, traces.csv beside it)",
        under.len(),
        100.0 * margin,
        index.display()
    );
    Ok(())
}
