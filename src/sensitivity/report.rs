//! A study's report: the ranked table and the tornado chart per condition, every measure as
//! CSV, the labels' spread over the ranges, in `OUT/<method>/` and `OUT/index.html`.

use super::outputs::OUTPUTS;
use super::{ConditionResult, Measures, Study};
use crate::error::Result;
use crate::report::svg::Figure;
use crate::report::table::Table;
use crate::report::tornado::Tornado;
use crate::report::{Section, write_index};
use std::path::Path;

/// How many parameters a tornado chart shows.
const TOP: usize = 10;

/// Writes the report of `results` into `out/<method>/` and rebuilds `out/index.html`.
pub fn write(study: &Study, results: &[ConditionResult], out: &Path) -> Result<()> {
    let sampled = study.sampled();
    let mut sec = Section {
        title: match study.method {
            super::Method::Morris { trajectories } => format!(
                "What the labels depend on: Morris screening of {} estimates ({trajectories} trajectories, {} runs per condition)",
                sampled.len(),
                trajectories * (sampled.len() + 1) + 1
            ),
            super::Method::Sobol { rows, .. } => format!(
                "What the labels depend on: Sobol indices of {} estimates ({rows} rows, {} runs per condition)",
                sampled.len(),
                rows * (sampled.len() + 2) + 1
            ),
        },
        ..Section::default()
    };
    sec.text.push(format!(
        "Estimates: {} ({}). Base plan: {} ({} condition(s), {} s each, seed(s) {:?}); every copy of a condition shares its irregularities. Design seed {}. Outputs are statistics of the labels over the whole run, kN.",
        study.estimates.path.display(),
        study.estimates.name,
        study.base.name,
        study.base.conditions.len(),
        study.base.conditions.first().map_or(0.0, |c| c.duration),
        study.base.conditions.first().map(|c| c.seeds.clone()).unwrap_or_default(),
        study.seed
    ));
    match &study.method {
        super::Method::Morris { .. } => sec.text.push(
            "μ*: the mean absolute elementary effect, kN for a move across the whole range; σ: their spread (interaction or curvature). Rank: the largest μ* on the labels' mean and std, in % of the nominal run's std of that label (the 99.85 % percentiles are shown, not ranked on: one flange contact moves them).".into(),
        ),
        super::Method::Sobol { .. } => sec.text.push(
            "S: first-order index (Saltelli 2010), ST: total index (Jansen), each with its 95 % bootstrap interval; the other estimates stay at the files' values.".into(),
        ),
    }
    let mut all = Table::new(&[
        "condition",
        "parameter",
        "output",
        "nominal",
        "mu",
        "mu_star",
        "sigma",
        "first",
        "first_lo",
        "first_hi",
        "total",
        "total_lo",
        "total_hi",
    ]);
    let mut spread = Table::new(&[
        "condition",
        "output",
        "nominal",
        "lowest",
        "highest",
        "std over the ranges",
    ]);
    for r in results {
        for (o, (key, title)) in OUTPUTS.iter().enumerate().take(study.outputs()) {
            let s = r.spread[o];
            spread.push(vec![
                r.condition.clone(),
                title.to_string(),
                f2(r.nominal[o]),
                f2(s.min),
                f2(s.max),
                f2(s.std),
            ]);
            for (p, est) in sampled.iter().enumerate() {
                let mut row = vec![
                    r.condition.clone(),
                    est.variation.key.clone(),
                    key.to_string(),
                    f4(r.nominal[o]),
                ];
                match &r.measures {
                    Measures::Morris(m) => {
                        let e = m[o][p];
                        row.extend([f4(e.mu), f4(e.mu_star), f4(e.sigma)]);
                        row.extend(std::iter::repeat_n(String::new(), 6));
                    }
                    Measures::Sobol(m) => {
                        let s = m[o][p];
                        row.extend(std::iter::repeat_n(String::new(), 3));
                        row.extend([
                            f4(s.first),
                            f4(s.first_ci.0),
                            f4(s.first_ci.1),
                            f4(s.total),
                            f4(s.total_ci.0),
                            f4(s.total_ci.1),
                        ]);
                    }
                }
                all.push(row);
            }
        }
        let ranked = r.ranking();
        let slug = crate::report::table::key(&r.condition);
        let (table, figure) = match &r.measures {
            Measures::Morris(m) => morris_table(m, &ranked, &sampled),
            Measures::Sobol(m) => sobol_table(m, &ranked, &sampled),
        };
        sec.tables.push((
            format!("{}: the estimates ranked", r.condition),
            table,
            format!("ranked_{slug}"),
        ));
        sec.figures.push((
            format!("{}: the {TOP} most influential estimates", r.condition),
            Figure::Tornado(Tornado {
                title: format!("{} ({})", r.condition, study.method.folder()),
                rows: figure.0,
                series: figure.1,
                x_label: figure.2,
            }),
            format!("tornado_{slug}.svg"),
        ));
    }
    sec.tables.push((
        "The labels' spread over the estimates' ranges (every design point)".into(),
        spread,
        "spread".into(),
    ));
    sec.tables.push((
        "Every measure, every output (CSV)".into(),
        all,
        "measures".into(),
    ));
    let folder = study.method.folder();
    sec.write_files(&out.join(folder))?;
    write_index(
        out,
        "railforce sensitivity",
        &["What the force labels depend on, over the ranges of the estimates (assets/docs/physics.md, \"What the labels depend on\").".into()],
        &["morris", "sobol"],
    )?;
    Ok(())
}

type Bars = (Vec<String>, Vec<(String, Vec<f64>)>, String);

fn morris_table(
    m: &[Vec<super::morris::Effect>],
    ranked: &[(usize, f64)],
    sampled: &[&super::Estimate],
) -> (Table, Bars) {
    let mut t = Table::new(&[
        "rank",
        "parameter",
        "range",
        "μ* FL mean",
        "μ* FL std",
        "μ* abs FL 99.85 %",
        "μ* FQ mean",
        "μ* FQ std",
        "μ* FQ 99.85 %",
        "σ FQ std",
        "μ* FL R²",
        "μ* FQ R²",
        "rank score, % of the label's std",
        "source of the range",
    ]);
    let with_model = m.len() > super::outputs::MEASURED;
    if !with_model {
        t.header.retain(|h| !h.ends_with(" R²"));
    }
    for (i, &(p, score)) in ranked.iter().enumerate() {
        let e = sampled[p];
        let mut row = vec![
            (i + 1).to_string(),
            e.variation.key.clone(),
            e.describe_range(),
        ];
        row.extend([0usize, 1, 2, 6, 7, 8].iter().map(|&o| f2(m[o][p].mu_star)));
        row.push(f2(m[7][p].sigma));
        if with_model {
            row.extend([12usize, 13].iter().map(|&o| f4(m[o][p].mu_star)));
        }
        row.push(format!("{score:.0}"));
        row.push(e.source.clone());
        t.push(row);
    }
    let bars = tornado_bars(
        ranked,
        sampled,
        &[(0, "FL mean"), (1, "FL std"), (6, "FQ mean"), (7, "FQ std")],
        "μ*",
        |o, p| m[o][p].mu_star,
        "μ*, kN for a move across the range",
    );
    (t, bars)
}

fn sobol_table(
    m: &[Vec<super::sobol::Indices>],
    ranked: &[(usize, f64)],
    sampled: &[&super::Estimate],
) -> (Table, Bars) {
    let mut t = Table::new(&[
        "rank",
        "parameter",
        "range",
        "S FL std",
        "ST FL std",
        "S FQ std",
        "ST FQ std",
        "ST abs FL 99.85 %",
        "ST FQ 99.85 %",
    ]);
    let ci = |s: f64, (lo, hi): (f64, f64)| format!("{s:.2} [{lo:.2}, {hi:.2}]");
    for (i, &(p, _)) in ranked.iter().enumerate() {
        let e = sampled[p];
        t.push(vec![
            (i + 1).to_string(),
            e.variation.key.clone(),
            e.describe_range(),
            ci(m[1][p].first, m[1][p].first_ci),
            ci(m[1][p].total, m[1][p].total_ci),
            ci(m[7][p].first, m[7][p].first_ci),
            ci(m[7][p].total, m[7][p].total_ci),
            ci(m[2][p].total, m[2][p].total_ci),
            ci(m[8][p].total, m[8][p].total_ci),
        ]);
    }
    let bars = tornado_bars(
        ranked,
        sampled,
        &[(1, "FL std"), (7, "FQ std")],
        "ST",
        |o, p| m[o][p].total,
        "total Sobol index",
    );
    (t, bars)
}

/// The tornado's rows (the `TOP` best ranked keys) and one series per `(output, name)`,
/// labelled `<measure> <name>`, its bars `value(output, parameter)`.
fn tornado_bars(
    ranked: &[(usize, f64)],
    sampled: &[&super::Estimate],
    outputs: &[(usize, &str)],
    measure: &str,
    value: impl Fn(usize, usize) -> f64,
    x_label: &str,
) -> Bars {
    let top: Vec<usize> = ranked.iter().take(TOP).map(|x| x.0).collect();
    let series = outputs
        .iter()
        .map(|&(o, name)| {
            (
                format!("{measure} {name}"),
                top.iter().map(|&p| value(o, p)).collect(),
            )
        })
        .collect();
    (
        top.iter()
            .map(|&p| sampled[p].variation.key.clone())
            .collect(),
        series,
        x_label.into(),
    )
}

fn f2(v: f64) -> String {
    format!("{v:.2}")
}

fn f4(v: f64) -> String {
    format!("{v:.4}")
}

/// The `n` estimates ranked best by the Morris screening written in `out` (`out/morris`): a
/// key's best rank over the conditions decides, ties in the first condition's order.
pub fn top_of_screening(out: &Path, n: usize) -> Result<Vec<String>> {
    let dir = out.join("morris");
    let sec = crate::report::SavedSection::read(&dir)?.ok_or_else(|| {
        crate::error::Error::Domain(format!(
            "{}: no Morris screening here: run `railforce sensitivity --method morris` into the same --out first",
            dir.display()
        ))
    })?;
    let mut best: Vec<(String, usize)> = Vec::new();
    for (_, t, stem) in &sec.tables {
        if !stem.starts_with("ranked_") {
            continue;
        }
        for (rank, row) in t.rows.iter().enumerate() {
            let Some(key) = row.get(1) else { continue };
            match best.iter_mut().find(|b| b.0 == *key) {
                Some(b) => b.1 = b.1.min(rank),
                None => best.push((key.clone(), rank)),
            }
        }
    }
    best.sort_by_key(|b| b.1);
    Ok(best.into_iter().take(n).map(|b| b.0).collect())
}
