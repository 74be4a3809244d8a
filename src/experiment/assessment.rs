//! The test runs of an experiment judged as acceptance engineers do (`assess`): the same
//! statistics of the identified and the true forces, per condition, identified ÷ true.

use super::f4;
use crate::assess::{Criteria, RunForces, StatCheck, assess, compare, spans};
use crate::dataset::DataSet;
use crate::error::Result;
use crate::identify::Identified;
use crate::learn::evaluate::PredictionRow;
use crate::plan::Plan;
use crate::report::svg::{BarChart, BarSeries, Figure, WIDTH};
use crate::report::table::{MISSING, Table};

/// Quantities summarised per condition, each at the section and place where the truth is
/// largest.
const QUANTITIES: [&str; 5] = ["(Y/Q)2m", "Q", "Yqst", "Qqst", "Y/Q (time criterion)"];

/// Per condition of `plan` with test rows: the comparison of every assessed statistic.
pub(super) fn checks(
    rows: &[PredictionRow],
    targets: &[String],
    ds: &DataSet,
    plan: &Plan,
    q0_kn: f64,
) -> Result<Vec<(String, Vec<StatCheck>)>> {
    let criteria = Criteria::builtin();
    let (t_col, s_col) = (ds.channel("time_s")?, ds.channel("s_m")?);
    let mut out = Vec::new();
    for c in &plan.conditions {
        let mine: Vec<&PredictionRow> = rows.iter().filter(|r| r.0 == c.name).collect();
        let Some(seed) = mine.first().map(|r| r.1) else {
            continue;
        };
        let mine: Vec<&PredictionRow> = mine.into_iter().filter(|r| r.1 == seed).collect();
        let Some(run) = ds
            .runs
            .iter()
            .find(|r| r.condition == c.name && r.seed == seed)
        else {
            continue;
        };
        let (time, s_run) = (&run.columns[t_col], &run.columns[s_col]);
        let t0 = time.first().copied().unwrap_or(0.0);
        let rate = crate::identify::RATE_HZ;
        let s: Vec<f64> = mine
            .iter()
            .map(|r| {
                let i = crate::bounds::cell_clamped(((r.2 - t0) * rate).round(), s_run.len());
                s_run[i]
            })
            .collect();
        let side = |k: usize| Identified {
            targets: targets.to_vec(),
            time: mine.iter().map(|r| r.2).collect(),
            values: mine
                .iter()
                .map(|r| r.3.iter().map(|p| if k == 0 { p.0 } else { p.1 }).collect())
                .collect(),
        };
        let track = crate::track::TrackSpec::load(&c.track)?;
        let sections = spans(&track);
        let judge = |id: &Identified| {
            RunForces::from_identified(id, s.clone())
                .and_then(|r| assess(&r, &sections, &criteria, q0_kn))
        };
        if let (Ok(a), Ok(b)) = (judge(&side(0)), judge(&side(1))) {
            out.push((c.name.clone(), compare(&a, &b)));
        }
    }
    Ok(out)
}

/// The check of `quantity` whose true value is largest (the section and place that decide).
fn decisive<'a>(checks: &'a [StatCheck], quantity: &str) -> Option<&'a StatCheck> {
    checks
        .iter()
        .filter(|c| c.quantity == quantity)
        .max_by(|a, b| a.true_value.total_cmp(&b.true_value))
}

/// A table (per condition: each quantity's true value and identified ÷ true at its decisive
/// section, and how many verdicts agree) and a bar chart of the ratios.
pub(super) fn report(per: &[(String, Vec<StatCheck>)]) -> (Table, Figure) {
    let mut header: Vec<String> = vec!["condition".into()];
    for q in QUANTITIES {
        header.push(format!("{q} true"));
        header.push(format!("{q} identified ÷ true"));
    }
    header.push("verdicts agree".into());
    let refs: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut t = Table::new(&refs);
    let mut bars: Vec<Vec<Option<f64>>> = vec![Vec::new(); 3];
    for (cond, checks) in per {
        let mut row = vec![cond.clone()];
        for (k, q) in QUANTITIES.iter().enumerate() {
            let d = decisive(checks, q);
            row.push(d.map(|c| f4(c.true_value)).unwrap_or(MISSING.into()));
            row.push(d.and_then(|c| c.ratio).map(f4).unwrap_or(MISSING.into()));
            if k < 3 {
                bars[k].push(d.and_then(|c| c.ratio));
            }
        }
        let agree = checks.iter().filter(|c| c.verdicts_agree).count();
        row.push(format!("{agree} of {}", checks.len()));
        t.push(row);
    }
    let chart = BarChart {
        title: "Acceptance statistics of the test runs: identified ÷ true".into(),
        y_label: "identified ÷ true (1 = exact)".into(),
        categories: per.iter().map(|p| p.0.clone()).collect(),
        series: QUANTITIES[..3]
            .iter()
            .zip(bars)
            .map(|(q, values)| BarSeries {
                label: match *q {
                    "Q" => "Q 99.85 %".to_string(),
                    "Yqst" => "Yqst (curves)".to_string(),
                    other => format!("{other} 99.85 %"),
                },
                values,
            })
            .collect(),
        floor: None,
        width: WIDTH,
    };
    (t, chart.into())
}
