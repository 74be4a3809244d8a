//! Experiment 1 (paper Tables 2–3): the eight models on one condition, one model per target as
//! the paper trains them, train and test MSE / R², training curves and identified-against-true
//! traces of a whole test run.

use super::{Ctx, FitJob, f4, paper, read_log, train_metrics};
use crate::error::Result;
use crate::features::NoiseProtocol;
use crate::learn::evaluate::{EvalPart, PredictionRow, evaluate};
use crate::learn::model::ModelKind;
use crate::report::Section;
use crate::report::svg::{BarChart, BarSeries, Chart, Series, WIDTH};
use crate::report::table::{MISSING, Table};

pub(super) fn run(ctx: &mut Ctx) -> Result<Section> {
    let opts = ctx.opts;
    let cond = std::slice::from_ref(&opts.condition);
    let inputs = Ctx::paper21();
    let dsc = ctx.noisy(&ctx.ds.subset(Some(cond), None)?, opts.snr_db, &inputs)?;
    let dir = opts.out.join("comparison");
    let mut tables: [Table; 2] = std::array::from_fn(|_| {
        Table::new(&[
            "model",
            "train MSE",
            "train R²",
            "test MSE",
            "test R²",
            "Var(y_test)",
            "test RMSE kN",
            "fit s",
            "paper train MSE",
            "paper train R²",
            "paper test MSE",
            "paper test R²",
        ])
    });
    let mut curves: [Vec<Series>; 2] = [Vec::new(), Vec::new()];
    let mut traces: [Option<(ModelKind, Vec<PredictionRow>)>; 2] = [None, None];
    // Test R² of ours and the paper's per model, per target (the bar chart).
    let mut r2_bars: [[Vec<Option<f64>>; 2]; 2] = Default::default();
    let labels = ctx.labels();
    let mut jobs = Vec::new();
    for &kind in &opts.models {
        for k in 0..2 {
            jobs.push(FitJob {
                ds: &dsc,
                spec: ctx.spec(
                    &dsc,
                    &inputs,
                    std::slice::from_ref(&labels[k]),
                    NoiseProtocol::Matched,
                    ctx.split.clone(),
                )?,
                kind,
                dir: dir
                    .join("models")
                    .join(format!("{}_{}", kind.name(), ["fl", "fq"][k])),
                windows: Some(opts.condition_windows_per_epoch),
                members: 1,
                seed_offset: 0,
            });
        }
    }
    let fitted = ctx.fit_all(&jobs)?;
    for (job, (mut model, secs)) in jobs.iter().zip(fitted) {
        let (kind, mdir) = (job.kind, &job.dir);
        let k = if job.spec.targets[0] == labels[0] {
            0
        } else {
            1
        };
        {
            let tr = train_metrics(&mut model, &dsc)?;
            let te = evaluate(&mut model, &dsc, EvalPart::Test)?;
            let p = paper::COMPARISON
                .iter()
                .find(|(n, _)| *n == kind.name())
                .map(|(_, v)| [v[4 * k], v[4 * k + 1], v[4 * k + 2], v[4 * k + 3]]);
            let pv = |i: usize| p.map(|p| p[i].to_string()).unwrap_or(MISSING.into());
            let m = &te.metrics[0];
            r2_bars[k][0].push(Some(m.r2));
            r2_bars[k][1].push(p.map(|p| p[3]));
            tables[k].push(vec![
                kind.name().into(),
                f4(tr[0].mse),
                f4(tr[0].r2),
                f4(m.mse),
                f4(m.r2),
                f4(m.var_y),
                format!("{:.2}", m.rmse_kn),
                format!("{secs:.1}"),
                pv(0),
                pv(1),
                pv(2),
                pv(3),
            ]);
            if kind.architecture().is_some() {
                curves[k].push(Series::line(
                    kind.name(),
                    read_log(mdir)
                        .iter()
                        .map(|e| (e.epoch as f64, e.val_loss))
                        .collect(),
                ));
            }
            if kind == ModelKind::CnnBiLstm
                || (traces[k].is_none() && kind == *opts.models.last().expect("models"))
            {
                traces[k] = Some((kind, te.rows.clone()));
            }
        }
    }
    let [fl, fq] = tables;
    let mut sec = Section {
        title: format!(
            "1. Model comparison: {} at {} dB (paper Tables 2–3)",
            opts.condition, opts.snr_db
        ),
        text: vec![
            format!(
                "{} models on {}, one model per target as in the paper, every input noised at {} dB, trained and tested on noisy inputs (matched protocol). Train metrics on up to 20 000 training windows; test metrics on every window of the test runs.",
                opts.models.len(),
                opts.condition,
                opts.snr_db
            ),
            ctx.protocol(&ctx.split, Some(opts.snr_db)),
        ],
        tables: vec![
            (
                format!("Lateral force FL ({})", labels[0]),
                fl,
                "comparison_fl".into(),
            ),
            (
                format!("Vertical force FQ ({})", labels[1]),
                fq,
                "comparison_fq".into(),
            ),
        ],
        figures: Vec::new(),
    };
    let model_names: Vec<String> = jobs
        .iter()
        .step_by(2)
        .map(|j| j.kind.name().to_string())
        .collect();
    for (k, name) in [(0, "FL"), (1, "FQ")] {
        let [ours, theirs] = std::mem::take(&mut r2_bars[k]);
        sec.figures.push((
            format!(
                "{name}: test R² of every model, ours beside the paper's (Table {})",
                2 + k
            ),
            BarChart {
                title: format!(
                    "{name} test R² per model, {} at {} dB",
                    opts.condition, opts.snr_db
                ),
                y_label: format!("test R², {name}"),
                categories: model_names.clone(),
                series: vec![
                    BarSeries {
                        label: "ours".into(),
                        values: ours,
                    },
                    BarSeries {
                        label: "paper".into(),
                        values: theirs,
                    },
                ],
                floor: None,
                width: WIDTH,
            }
            .into(),
            format!("r2_per_model_{}.svg", name.to_lowercase()),
        ));
        let series = std::mem::take(&mut curves[k]);
        if !series.is_empty() {
            sec.figures.push((
                format!("{name}: validation MSE per epoch of the networks"),
                Chart::new(
                    format!("Validation loss, {name}"),
                    "epoch",
                    "MSE (standardised)",
                    series,
                )
                .into(),
                format!("training_curves_{}.svg", name.to_lowercase()),
            ));
        }
        if let Some((kind, rows)) = &traces[k] {
            let first = rows.first().map(|r| (r.0.clone(), r.1));
            let run: Vec<&PredictionRow> = rows
                .iter()
                .filter(|r| Some((r.0.clone(), r.1)) == first)
                .collect();
            let step = run.len().div_ceil(3000).max(1);
            let pts: Vec<&PredictionRow> = run.iter().step_by(step).copied().collect();
            let span = (
                pts.first().map_or(0.0, |r| r.2),
                pts.last().map_or(0.0, |r| r.2),
            );
            let series = vec![
                Series::line(
                    "true",
                    pts.iter().map(|r| (r.2, r.3[0].0 / 1000.0)).collect(),
                ),
                Series::line(
                    format!("{} (identified)", kind.name()),
                    pts.iter().map(|r| (r.2, r.3[0].1 / 1000.0)).collect(),
                ),
            ];
            let seed = first.map(|f| f.1).unwrap_or(0);
            sec.figures.push((
                format!(
                    "{name}: {} against the true force over the whole test run ({:.1}–{:.1} s, seed {seed}, never seen in training)",
                    kind.name(),
                    span.0,
                    span.1
                ),
                Chart::new(
                    format!("{name}, {}: identified and true, test run seed {seed}", kind.name()),
                    "time (s)",
                    "force (kN)",
                    series,
                )
                .into(),
                format!("trace_{}.svg", name.to_lowercase()),
            ));
            // A 4 s close-up around the largest true force, where a whole run's trace is too
            // dense to read.
            if let Some(peak) = run
                .iter()
                .max_by(|a, b| a.3[0].0.abs().total_cmp(&b.3[0].0.abs()))
                .map(|r| r.2)
                && span.1 - span.0 > 8.0
            {
                let from = (peak - 2.0).clamp(span.0, span.1 - 4.0);
                let near: Vec<&&PredictionRow> = run
                    .iter()
                    .filter(|r| r.2 >= from && r.2 <= from + 4.0)
                    .collect();
                sec.figures.push((
                    format!(
                        "{name}: close-up of {:.1}–{:.1} s around the largest true force of the same run",
                        from,
                        from + 4.0
                    ),
                    Chart::new(
                        format!("{name}, {}: close-up, seed {seed}", kind.name()),
                        "time (s)",
                        "force (kN)",
                        vec![
                            Series::line("true", near.iter().map(|r| (r.2, r.3[0].0 / 1000.0)).collect()),
                            Series::line(
                                format!("{} (identified)", kind.name()),
                                near.iter().map(|r| (r.2, r.3[0].1 / 1000.0)).collect(),
                            ),
                        ],
                    )
                    .into(),
                    format!("trace_{}_zoom.svg", name.to_lowercase()),
                ));
            }
        }
    }
    Ok(sec)
}
