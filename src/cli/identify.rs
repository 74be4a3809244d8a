//! `railforce identify` and `railforce validate identify`: forces and safety indices from
//! sensor recordings with a trained model.

use anyhow::{Context, Result, bail};
use clap::Args;
use railforce::identify::safety::{IndexReport, Limits, Monitor};
use railforce::identify::{SensorRows, SensorTable, Streamer, check};
use railforce::learn::model::Model;
use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Limits of the safety indices: by default the `[chinese]` table of the assessment criteria
/// (`vehicles/assessment.toml`: commonly quoted Chinese values, secondary sources), so
/// `identify`, `validate identify` and `assess` judge with the same numbers.
#[derive(Debug, Args, Clone)]
pub struct LimitArgs {
    /// Derailment coefficient |Y|/Q limit [default: the criteria's, 1.2 allowable; 1.0 is
    /// the preferred value].
    #[arg(long)]
    pub limit_yq: Option<f64>,
    /// Wheel unloading ΔQ/Q̄ limit [default: the criteria's, 0.65 allowable; 0.60 preferred].
    #[arg(long)]
    pub limit_unloading: Option<f64>,
    /// Static wheel load Q̄, kN [default: the --vehicle's weight over its wheels]; H's limit
    /// α·(10 + P_st/3) follows from it.
    #[arg(long)]
    pub static_wheel_load_kn: Option<f64>,
    /// Vehicle whose weight gives the static wheel load (C80 loaded: 100 t on 8 wheels →
    /// 122.6 kN).
    #[arg(long, default_value = "vehicles/c80.toml")]
    pub vehicle: PathBuf,
    /// Time criterion, ms: an excursion above a limit counts as an exceedance when it lasts
    /// at least this long (shorter ones are reported as brief) [default: the criteria's,
    /// 50 ms]; 0 counts every sample.
    #[arg(long)]
    pub min_duration_ms: Option<f64>,
    /// Criteria file whose `[chinese]` table gives the defaults above [default: the built-in
    /// vehicles/assessment.toml].
    #[arg(long)]
    pub criteria: Option<PathBuf>,
}

impl LimitArgs {
    pub fn limits(&self) -> Result<Limits> {
        let static_wheel_load_kn = match self.static_wheel_load_kn {
            Some(q) => q,
            None => {
                let v =
                    railforce::vehicle::Vehicle::load(&super::builtin::resolve(&self.vehicle)?)?;
                v.static_wheel_load_kn()
            }
        };
        let criteria = match &self.criteria {
            Some(p) => railforce::assess::Criteria::load(&super::builtin::resolve(p)?)?,
            None => railforce::assess::Criteria::builtin(),
        };
        let base = Limits::from_criteria(&criteria, static_wheel_load_kn);
        let min_ms = self.min_duration_ms.unwrap_or(base.min_duration_s * 1000.0);
        if !(min_ms.is_finite() && min_ms >= 0.0) {
            bail!("--min-duration-ms {min_ms}: give a duration ≥ 0");
        }
        let limits = Limits {
            y_over_q: self.limit_yq.unwrap_or(base.y_over_q),
            unloading: self.limit_unloading.unwrap_or(base.unloading),
            min_duration_s: min_ms / 1000.0,
            ..base
        };
        limits.check().context(
            "the limits (--limit-yq, --limit-unloading, --static-wheel-load-kn, --criteria)",
        )?;
        Ok(limits)
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
    /// Coverage of the interval written around every identified force (`<target>_lo_N`,
    /// `<target>_hi_N`): split conformal on the model's validation runs, widened where an
    /// ensemble's members disagree (`train --ensemble N`); streamed input gets them too. Not
    /// for a model trained before calibration existed.
    #[arg(long, default_value_t = 0.9)]
    coverage: f64,
    /// Channel map (TOML) for a recording with its own column names, units (g, mm, deg,
    /// mrad/s …) and axis signs: each model channel's column, unit and sign, and the time
    /// column (assets/docs/file-formats.md, "Channel maps"). Recorded in OUT.safety.json.
    #[arg(long)]
    channel_map: Option<PathBuf>,
    #[command(flatten)]
    limits: LimitArgs,
}

pub fn run(args: IdentifyArgs) -> Result<()> {
    let mut model = Model::load(&args.model)?;
    let limits = args.limits.limits()?;
    if !(args.coverage > 0.0 && args.coverage < 1.0) {
        bail!(
            "--coverage {}: give a fraction between 0 and 1, e.g. 0.9",
            args.coverage
        );
    }
    let map = args
        .channel_map
        .as_deref()
        .map(railforce::identify::ChannelMap::load)
        .transpose()?;
    if args.input.as_os_str() == "-" {
        if map.is_some() {
            bail!("--channel-map reads a file: give --input a recording, not - (a stream)");
        }
        return stream(&mut model, &args.out, &limits, args.coverage);
    }
    let table = match &map {
        Some(m) => m.read(&args.input, &model.meta.data.channels)?,
        None => SensorTable::read(&args.input)?,
    };
    let input = check(&table, &model, args.resample).map_err(|e| {
        // The hint only where the rate is what is wrong.
        let m = e.to_string();
        if args.resample || !m.contains(" Hz without gaps") {
            anyhow::anyhow!(e)
        } else {
            anyhow::anyhow!("{m}; --resample interpolates a record onto the model's rate")
        }
    })?;
    let t0 = std::time::Instant::now();
    let out = railforce::identify::output::run(&mut model, &input, &limits, args.coverage);
    let secs = t0.elapsed().as_secs_f64();
    if out.bands.is_none() {
        eprintln!(
            "note: {} has no calibration (trained by a version without intervals): no intervals; `railforce calibrate` adds them",
            args.model.display()
        );
    }
    let id = &out.identified;
    let names: Vec<&str> = out.index_names.iter().map(String::as_str).collect();
    let mut s = header(
        &id.targets,
        out.position.is_some(),
        out.bands.is_some(),
        &names,
        out.ood_counts.is_some(),
    );
    for (i, t) in id.time.iter().enumerate() {
        s += &row(
            *t,
            out.position.as_ref().map(|p| p[i]),
            &id.values[i],
            out.bands.as_ref().map(|b| b.bounds[i].as_slice()),
            &out.indices[i],
            out.ood_counts.as_ref().map(|o| o[i]),
        );
    }
    let (spans, reports) = (&out.ood_spans, &out.reports);
    railforce::io::check_csv_finite(&s, &args.out)?;
    if args.out.as_os_str() == "-" {
        std::io::stdout().write_all(s.as_bytes())?;
    } else {
        railforce::io::write_atomic(&args.out, |w| w.write_all(s.as_bytes()))?;
        let sp = write_safety_json(&args.out, reports, &limits, map.as_ref(), spans.as_ref())?;
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
        if args.input.as_os_str() != "-" {
            eprintln!(
                "to see it over the true forces (for a run with all channels): {}",
                super::view::hint(&args.input, Some(&args.out))
            );
        }
    }
    print_safety(reports, &limits);
    print_ood(spans.as_ref());
    Ok(())
}

/// The out-of-distribution report on standard error.
fn print_ood(spans: Option<&(f64, Vec<railforce::identify::OodSpan>)>) {
    let Some((share, spans)) = spans else {
        return;
    };
    if spans.is_empty() {
        eprintln!(
            "inputs within what the model was trained on throughout (training envelope ± 25 %)"
        );
        return;
    }
    eprintln!(
        "OUT OF DISTRIBUTION: {:.1} % of the estimates read inputs beyond the training envelope (± 25 %); their forces are extrapolated:",
        share * 100.0
    );
    for s in spans.iter().take(20) {
        eprintln!(
            "    {:.3} s to {:.3} s: {}",
            s.from_s,
            s.to_s,
            s.channels.join(", ")
        );
    }
    if spans.len() > 20 {
        eprintln!(
            "    … {} more stretches in the .safety.json",
            spans.len() - 20
        );
    }
}

/// Header of identify's output: time, the track position when the input has it, each target's
/// force in N (with its interval's bounds when `bands`), then each safety index (ASCII names).
fn header(targets: &[String], position: bool, bands: bool, indices: &[&str], ood: bool) -> String {
    let mut s = String::from("time_s");
    if position {
        s.push_str(",s_m");
    }
    for t in targets {
        let _ = write!(s, ",{t}_N");
        if bands {
            let _ = write!(s, ",{t}_lo_N,{t}_hi_N");
        }
    }
    for c in indices {
        let _ = write!(s, ",{c}");
    }
    if ood {
        s.push_str(",ood_channels");
    }
    s.push('\n');
    s
}

/// One output row: the same text whether identified in one go or streamed.
fn row(
    t: f64,
    position: Option<f64>,
    forces: &[f64],
    bounds: Option<&[(f64, f64)]>,
    indices: &[f64],
    ood: Option<usize>,
) -> String {
    let mut s = format!("{:.3}", railforce::identify::safety::on_grid(t));
    if let Some(p) = position {
        let _ = write!(s, ",{p:.3}");
    }
    for (k, v) in forces.iter().enumerate() {
        let _ = write!(s, ",{v:.1}");
        if let Some(b) = bounds {
            let _ = write!(s, ",{:.1},{:.1}", b[k].0, b[k].1);
        }
    }
    for v in indices {
        let _ = write!(s, ",{v:.4}");
    }
    if let Some(n) = ood {
        let _ = write!(s, ",{n}");
    }
    s.push('\n');
    s
}

/// Writes `OUT.safety.json` (limits and every index's report) beside the output.
fn write_safety_json(
    out: &Path,
    reports: &[IndexReport],
    limits: &Limits,
    map: Option<&railforce::identify::ChannelMap>,
    ood: Option<&(f64, Vec<railforce::identify::OodSpan>)>,
) -> Result<PathBuf> {
    let mut doc = serde_json::json!({
        "limits": limits,
        "limits_source": "commonly quoted Chinese values (secondary sources, assets/docs/physics.md §7)",
        "indices": reports,
    });
    if let Some(m) = map {
        doc["channel_map"] = m.describe();
    }
    if let Some((share, spans)) = ood {
        doc["out_of_distribution"] = serde_json::json!({
            "rule": "an estimate whose window holds an input beyond the 0.1–99.9 % range of the training part widened by 25 % on each side",
            "share": share,
            "spans": spans,
        });
    }
    let json = serde_json::to_string_pretty(&doc)?;
    let sp = out.with_extension("safety.json");
    railforce::io::write_atomic(&sp, |w| w.write_all(json.as_bytes()))?;
    Ok(sp)
}

/// Prints the exceedance report to standard error.
pub fn print_safety(reports: &[IndexReport], limits: &Limits) {
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
        let brief = if r.brief_excursions > 0 {
            format!(
                " ({} excursion(s) shorter than {:.0} ms not counted)",
                r.brief_excursions,
                limits.min_duration_s * 1000.0
            )
        } else {
            String::new()
        };
        eprintln!(
            "safety {:<22} max {:>8.3} at {:>8.3} s, limit {:.3} (secondary-source value): {verdict}{brief}",
            r.name, r.max, r.max_time_s, r.limit
        );
        for (a, b, peak) in &r.exceedances {
            eprintln!(
                "    above the limit from {a:.3} s to {b:.3} s ({:.0} ms), peak {peak:.3}",
                (b - a) * 1000.0 + 1000.0 / railforce::identify::RATE_HZ
            );
        }
    }
}

/// Streams CSV lines from standard input; writes each estimate, with the track position and
/// the safety indices, as soon as its window is full (the same row text as a batch run), and
/// the exceedance report at the end of the stream.
fn stream(model: &mut Model, out: &Path, limits: &Limits, coverage: f64) -> Result<()> {
    let mut rows = SensorRows::new(std::io::stdin().lock(), "stdin", model)?;
    let has_position = rows.has_position();
    let spec = model.meta.data.clone();
    let mut w: Box<dyn Write> = if out.as_os_str() == "-" {
        Box::new(std::io::stdout().lock())
    } else {
        Box::new(std::io::BufWriter::new(
            std::fs::File::create(out).with_context(|| format!("creating {}", out.display()))?,
        ))
    };
    let mut monitor = Monitor::new(&spec.targets, limits, false);
    let banded = model.meta.calibration.is_some();
    let enveloped = model
        .meta
        .calibration
        .as_ref()
        .is_some_and(|c| !c.envelope.is_empty());
    let head = header(
        &spec.targets,
        has_position,
        banded,
        &monitor.columns(),
        enveloped,
    );
    w.write_all(head.as_bytes())?;
    let (mut times, mut flagged) = (Vec::new(), Vec::new());
    let off = railforce::learn::windows::label_offset(spec.window, spec.label_at);
    let mut positions = std::collections::VecDeque::with_capacity(spec.window);
    let mut st = Streamer::new(model);
    let mut values = vec![0.0; spec.channels.len()];
    let mut read = 0usize;
    while let Some((t, s)) = rows.next_row(&mut values)? {
        read += 1;
        if let Some(s) = s {
            positions.push_back(s);
            if positions.len() > spec.window {
                positions.pop_front();
            }
        }
        if let Some(e) = st.push_with_bands(t, &values, Some(coverage)) {
            let idx = monitor.push(e.time, &e.forces);
            let p = has_position.then(|| positions[off]);
            let n_out = e.outside.as_ref().map(|o| o.len());
            let line = row(e.time, p, &e.forces, e.bounds.as_deref(), &idx, n_out);
            // The same check as a batch run's, row by row: a streamed estimate that is not a
            // number ends the stream instead of being written.
            railforce::io::check_csv_finite(&format!("{head}{line}"), out)?;
            w.write_all(line.as_bytes())?;
            times.push(e.time);
            flagged.push(e.outside.unwrap_or_default());
            w.flush()?;
        }
    }
    if times.is_empty() {
        // Nothing identified: no safety verdict on no data, and no header-only file left.
        drop(w);
        if out.as_os_str() != "-" {
            let _ = std::fs::remove_file(out);
        }
        bail!(
            "stdin: the stream ended after {read} row(s), fewer than one window of {} steps: nothing identified",
            spec.window
        );
    }
    let reports = monitor.finish();
    let spans = enveloped.then(|| {
        let o = railforce::identify::OutOfDistribution { channels: flagged };
        (o.share(), o.spans(&times, &spec.channels))
    });
    if out.as_os_str() != "-" {
        let sp = write_safety_json(out, &reports, limits, None, spans.as_ref())?;
        eprintln!("wrote {} and {}", out.display(), sp.display());
    }
    print_safety(&reports, limits);
    print_ood(spans.as_ref());
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
    channel_map: Option<&Path>,
) -> Result<()> {
    let map = channel_map
        .map(railforce::identify::channel_map::ChannelMap::load)
        .transpose()?;
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
        &mut model,
        &plan,
        seed,
        &work,
        jobs,
        limits,
        margin,
        map.as_ref(),
    )?;
    println!(
        "{:<22} {:<14} {:>7} {:>9} {:>12} {:>13} {:>13}",
        "condition", "target", "R²", "RMSE kN", "peak err kN", "90 % covers", "width kN"
    );
    for r in &runs {
        for t in &r.targets {
            println!(
                "{:<22} {:<14} {:>7.3} {:>9.2} {:>12.2} {:>13} {:>13}",
                r.condition,
                t.target,
                t.r2,
                t.rmse_kn,
                t.peak_error_kn,
                t.coverage
                    .map_or("—".into(), |c| format!("{:.1} %", c * 100.0)),
                t.width_kn.map_or("—".into(), |w| format!("{w:.2}"))
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
    // The acceptance statistics, true against identified.
    let stats: Vec<&railforce::assess::StatCheck> =
        runs.iter().flat_map(|r| &r.assessment).collect();
    let stat_differ = stats.iter().filter(|c| !c.verdicts_agree).count();
    for q in ["(Y/Q)2m", "Q", "Yqst", "Qqst"] {
        let ratios: Vec<f64> = stats
            .iter()
            .filter(|c| c.quantity == q)
            .filter_map(|c| c.ratio)
            .collect();
        if !ratios.is_empty() {
            println!(
                "assessment {q:<8} identified ÷ true over {} section(s): median {:.3}, range {:.3}–{:.3}",
                ratios.len(),
                railforce::dsp::percentile(&ratios, 50.0),
                railforce::dsp::percentile(&ratios, 0.0),
                railforce::dsp::percentile(&ratios, 100.0)
            );
        }
    }
    println!(
        "assessment verdicts (within the limit or not) agree on {} of {} statistics",
        stats.len() - stat_differ,
        stats.len()
    );
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
