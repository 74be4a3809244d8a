//! The closed-loop check written for people and programs: labelled JSON, the true and
//! identified traces as tidy CSV, and an HTML page (tables, the identified-to-true ratios of
//! the safety statistics per condition, true-against-identified plots of every run).

use super::closed_loop::RunCheck;
use super::safety::Limits;
use crate::error::Result;
use crate::report::svg::{BarChart, BarSeries, Chart, Series, WIDTH};
use crate::report::table::{MISSING, Table};
use crate::report::{Section, write_index};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Settings the report states.
pub struct CheckSettings<'a> {
    /// Model kind and directory, for the title.
    pub model: &'a str,
    /// Plan name.
    pub plan: &'a str,
    /// Seed of the fresh runs.
    pub seed: u64,
    /// Under-identification margin (0.2: more than 20 % below the truth warns).
    pub margin: f64,
    /// Limits of the indices.
    pub limits: &'a Limits,
    /// The input noise, in words.
    pub noise: String,
}

/// Writes `closed_loop.json`, `traces.csv` and `index.html` (with its `check/` folder) into
/// `dir`; returns the path of `index.html`.
pub fn write(dir: &Path, runs: &[RunCheck], s: &CheckSettings) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).map_err(|e| crate::Error::io(dir, e))?;
    let json = json!({
        "model": s.model,
        "plan": s.plan,
        "seed": s.seed,
        "inputs": s.noise,
        "under_identification_margin": s.margin,
        "limits": s.limits,
        "runs": runs,
    });
    let text = crate::io::to_json_pretty(&json, &dir.join("closed_loop.json"))?;
    crate::io::write_atomic(&dir.join("closed_loop.json"), |w| {
        w.write_all(text.as_bytes())
    })?;
    write_traces(&dir.join("traces.csv"), runs)?;
    section(runs, s).write_files(&dir.join("check"))?;
    let under = runs
        .iter()
        .flat_map(|r| &r.safety)
        .filter(|c| c.underestimated)
        .count();
    let intro = vec![
        format!(
            "Model {} on fresh runs of plan {} (seed {}, never used in training); inputs {}.",
            s.model, s.plan, s.seed, s.noise
        ),
        format!(
            "{under} index statistic(s) under-identified by more than {:.0} % (peak or 99.85 % percentile); files: closed_loop.json, traces.csv.",
            100.0 * s.margin
        ),
    ];
    write_index(
        dir,
        "railforce: closed-loop identification check",
        &intro,
        &["check"],
    )?;
    Ok(dir.join("index.html"))
}

/// `condition,seed,time_s,<target>_true_n,<target>_identified_n…`, forces in N.
fn write_traces(path: &Path, runs: &[RunCheck]) -> Result<()> {
    let mut out = String::from("condition,seed,time_s");
    if let Some(r) = runs.first() {
        for t in &r.truth.targets {
            let _ = write!(out, ",{t}_true_n,{t}_identified_n");
        }
    }
    out.push('\n');
    for r in runs {
        for (i, time) in r.truth.time.iter().enumerate() {
            let _ = write!(out, "{},{},{:.3}", r.condition, r.seed, time);
            for (a, b) in r.truth.values[i].iter().zip(&r.identified.values[i]) {
                let _ = write!(out, ",{a:.1},{b:.1}");
            }
            out.push('\n');
        }
    }
    crate::io::write_atomic(path, |w| w.write_all(out.as_bytes()))
}

fn section(runs: &[RunCheck], s: &CheckSettings) -> Section {
    let f = |v: f64| format!("{v:.4}");
    let opt = |v: Option<f64>| v.map(|v| format!("{v:.3}")).unwrap_or(MISSING.into());
    let mut fit = Table::new(&[
        "condition",
        "target",
        "R²",
        "RMSE kN",
        "peak error kN",
        "90 % interval covers",
        "mean width kN",
    ]);
    let mut safety = Table::new(&[
        "condition",
        "index",
        "place",
        "limit",
        "true peak",
        "identified peak",
        "peak ratio",
        "true 99.85 %",
        "identified 99.85 %",
        "99.85 % ratio",
        "verdicts agree",
        "under-identified",
    ]);
    for r in runs {
        for t in &r.targets {
            fit.push(vec![
                r.condition.clone(),
                t.target.clone(),
                f(t.r2),
                format!("{:.2}", t.rmse_kn),
                format!("{:.2}", t.peak_error_kn),
                t.coverage
                    .map_or(MISSING.into(), |c| format!("{:.1} %", c * 100.0)),
                t.width_kn.map_or(MISSING.into(), |w| format!("{w:.2}")),
            ]);
        }
        for c in &r.safety {
            safety.push(vec![
                r.condition.clone(),
                c.index.clone(),
                c.place.clone(),
                format!("{:.3}", c.limit),
                f(c.true_peak),
                f(c.identified_peak),
                opt(c.peak_ratio),
                f(c.true_p99_85),
                f(c.identified_p99_85),
                opt(c.p99_85_ratio),
                if c.verdicts_agree { "yes" } else { "NO" }.into(),
                if c.underestimated { "YES" } else { "no" }.into(),
            ]);
        }
    }
    let mut stats = Table::new(&[
        "condition",
        "section",
        "quantity",
        "place",
        "true",
        "identified",
        "identified ÷ true",
        "limit",
        "unit",
        "verdicts agree",
    ]);
    for r in runs {
        for c in &r.assessment {
            stats.push(vec![
                r.condition.clone(),
                c.section.clone(),
                c.quantity.clone(),
                c.place.clone(),
                f(c.true_value),
                f(c.identified_value),
                opt(c.ratio),
                format!("{:.3}", c.limit),
                c.unit.clone(),
                if c.verdicts_agree { "yes" } else { "NO" }.into(),
            ]);
        }
    }
    let conditions: Vec<String> = runs.iter().map(|r| r.condition.clone()).collect();
    // One bar series per index and place: identified / true 99.85 % percentile per condition.
    let mut keys: Vec<(String, String)> = Vec::new();
    for c in runs.iter().flat_map(|r| &r.safety) {
        let k = (c.index.clone(), c.place.clone());
        if !keys.contains(&k) {
            keys.push(k);
        }
    }
    let series = keys
        .iter()
        .map(|(index, place)| BarSeries {
            label: format!("{index} {place}"),
            values: runs
                .iter()
                .map(|r| {
                    r.safety
                        .iter()
                        .find(|c| &c.index == index && &c.place == place)
                        .and_then(|c| c.p99_85_ratio)
                })
                .collect(),
        })
        .collect();
    let mut figures = vec![(
        format!(
            "Identified ÷ true 99.85 % percentile of each safety index per condition: 1 is exact, below {:.2} warns",
            1.0 - s.margin
        ),
        BarChart {
            title: "Identified-to-true ratio of the 99.85 % percentile".into(),
            y_label: "identified ÷ true".into(),
            categories: conditions,
            series,
            floor: None,
            width: WIDTH,
        }
        .into(),
        "p99_85_ratio.svg".into(),
    )];
    for (i, r) in runs.iter().enumerate() {
        let step = r.truth.time.len().div_ceil(2000).max(1);
        for (k, target) in r.truth.targets.iter().enumerate() {
            let pts = |v: &super::Identified| -> Vec<(f64, f64)> {
                v.time
                    .iter()
                    .zip(&v.values)
                    .step_by(step)
                    .map(|(t, x)| (*t, x[k] / 1000.0))
                    .collect()
            };
            figures.push((
                format!(
                    "{}, seed {}: {target}, true and identified",
                    r.condition, r.seed
                ),
                Chart::new(
                    format!("{} seed {}: {target}", r.condition, r.seed),
                    "time (s)",
                    "force (kN)",
                    vec![
                        Series::line("true (simulator)", pts(&r.truth)),
                        Series::line("identified", pts(&r.identified)),
                    ],
                )
                .into(),
                format!("trace_{i:03}_{target}.svg"),
            ));
        }
    }
    Section {
        title: "Closed loop: identified against true".into(),
        text: vec![format!(
            "Each condition simulated afresh with seed {}, its sensor channels identified by {}, compared with the simulator's forces. Limits: |Y|/Q {}, ΔQ/Q̄ {}, H {:.1} kN (static wheel load {:.1} kN). A statistic is under-identified where identified ÷ true < {:.2}.",
            s.seed,
            s.model,
            s.limits.y_over_q,
            s.limits.unloading,
            s.limits.lateral_kn(),
            s.limits.static_wheel_load_kn,
            1.0 - s.margin
        )],
        tables: vec![
            ("Fit per condition and target".into(), fit, "fit".into()),
            (
                "Safety indices per condition and wheel".into(),
                safety,
                "safety".into(),
            ),
            (
                "Acceptance statistics (railforce assess: 20 Hz, 2 m sliding means, 99.85 %, quasi-static medians over curves) of the identified forces against the true ones, per section".into(),
                stats,
                "assessment".into(),
            ),
        ],
        figures,
    }
}
