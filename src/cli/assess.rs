//! `railforce assess`: a thin shell over `assess`.

use anyhow::{Context, Result};
use clap::Args;
use railforce::assess::{Criteria, assess_columns, spans};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct AssessArgs {
    /// Run file: a `simulate` CSV, a `generate` run (npz, parquet, csv) or `identify` output
    /// (identified forces `w1l_force_y_N` with `s_m`).
    file: PathBuf,
    /// Track of the run, to assess each section (tangent, transition, curve by radius) apart
    /// [default: the track the data set's manifest or the run's own `.meta.json` names, else
    /// the whole run as one section]; another file than the run's is warned of.
    #[arg(long)]
    track: Option<PathBuf>,
    /// Criteria file (filters, windows, percentiles, limits, each with its source) [default:
    /// the built-in vehicles/assessment.toml].
    #[arg(long)]
    criteria: Option<PathBuf>,
    /// Static wheel load Q0, kN [default: the --vehicle's weight over its wheels].
    #[arg(long)]
    static_wheel_load_kn: Option<f64>,
    /// Vehicle whose weight gives Q0.
    #[arg(long, default_value = "vehicles/c80.toml")]
    vehicle: PathBuf,
    /// Output folder for assessment.md, .csv and .json [default: FILE's name + _assessment].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Coverage of the intervals in FILE (`identify --coverage`, 0.9 by default): where the
    /// identified forces carry bounds (`w1l_force_y_lo_N`, `_hi_N`), each statistic gets its
    /// interval and the probability its limit is exceeded.
    #[arg(long, default_value_t = 0.9)]
    coverage: f64,
}

pub fn run(args: AssessArgs) -> Result<()> {
    let criteria = match &args.criteria {
        Some(p) => Criteria::load(&super::builtin::resolve(p)?)?,
        None => Criteria::builtin(),
    };
    let q0 = match args.static_wheel_load_kn {
        Some(q) if q.is_finite() && q > 0.0 => q,
        Some(q) => anyhow::bail!("--static-wheel-load-kn must be positive, got {q}"),
        None => {
            let v = railforce::vehicle::Vehicle::load(&super::builtin::resolve(&args.vehicle)?)?;
            v.static_wheel_load_kn()
        }
    };
    let cols = railforce::dataset::read_table(&args.file)?;
    let recorded = railforce::dataset::recorded_run(&args.file).track;
    let track = match &args.track {
        Some(t) => {
            let t = super::builtin::resolve(t)?;
            // A track other than the run's own cuts the run into sections it never ran.
            if let Some(r) = &recorded
                && !r.hash_fnv1a.is_empty()
                && railforce::dataset::file_hash(&t)? != r.hash_fnv1a
            {
                eprintln!(
                    "warning: {} was simulated on track '{}' ({}), and --track gives {}, another file: its sections may not be the run's",
                    args.file.display(),
                    r.name,
                    r.file.display(),
                    t.display()
                );
            }
            Some(t)
        }
        None => recorded.map(|r| r.file).filter(|p| p.exists()),
    };
    let sections = match &track {
        Some(t) => {
            let spec = railforce::track::TrackSpec::load(t)?;
            eprintln!("sections from {}", t.display());
            spans(&spec)
        }
        None => {
            eprintln!("no track given (--track): the whole run is one section");
            Vec::new()
        }
    };
    let a = assess_columns(
        &args.file.display().to_string(),
        &cols,
        &sections,
        &criteria,
        q0,
        args.coverage,
    )?;
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .file
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        args.file.with_file_name(format!("{stem}_assessment"))
    });
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let md = a.markdown();
    railforce::io::write_atomic(&out.join("assessment.md"), |w| w.write_all(md.as_bytes()))?;
    let csv = a.table().csv();
    railforce::io::write_atomic(&out.join("assessment.csv"), |w| w.write_all(csv.as_bytes()))?;
    let json = railforce::io::to_json_pretty(&a, &out.join("assessment.json"))?;
    railforce::io::write_atomic(&out.join("assessment.json"), |w| {
        w.write_all(json.as_bytes())
    })?;
    println!(
        "{:<34} {:<22} {:<11} {:>10} {:>10} {:<4} verdict{}",
        "section",
        "quantity",
        "place",
        "value",
        "limit",
        "unit",
        if a.intervals.is_empty() {
            ""
        } else {
            "  interval            P(exceed)"
        }
    );
    for (i, r) in a.rows.iter().enumerate() {
        let band = a.intervals.get(i).map_or(String::new(), |b| {
            format!("  {:>8.3}–{:<8.3}  {:>8.4}", b.low, b.high, b.exceedance)
        });
        println!(
            "{:<34} {:<22} {:<11} {:>10.3} {:>10.3} {:<4} {}{band}",
            r.section,
            r.quantity,
            r.place,
            r.value,
            r.limit,
            r.unit,
            if r.pass { "pass" } else { "FAIL" }
        );
    }
    let fails = a.failures().count();
    println!(
        "{} of {} quantities within their limits{}; Q0 {q0:.1} kN; tables in {} (sources of every limit in assessment.md)",
        a.rows.len() - fails,
        a.rows.len(),
        if fails > 0 {
            format!(", {fails} FAIL")
        } else {
            String::new()
        },
        out.display()
    );
    Ok(())
}
