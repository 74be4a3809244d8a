//! Beyond the paper: sensor selection (assets/docs/learning.md §4.5). The Filter–Wrapper runs over
//! every on-board candidate signal for FL and for FQ (on the training and validation runs,
//! noisy at the experiments' SNR); the CNN-BiLSTM on the union of the two selections is
//! compared with the paper's 21 at each SNR of the experiment.

use super::{Ctx, FitJob, f4};
use crate::error::Result;
use crate::features::{NoiseProtocol, SelectOptions, select};
use crate::learn::evaluate::{EvalPart, evaluate};
use crate::learn::model::ModelKind;
use crate::report::Section;
use crate::report::table::Table;
use crate::sensors::{Candidates, clean_name};

pub(super) fn run(ctx: &mut Ctx) -> Result<Section> {
    let opts = ctx.opts;
    let labels = ctx.labels();
    let onboard = ctx
        .ds
        .distinct_channels(&Candidates::Onboard.among(&ctx.ds.names, &ctx.ds.labels));
    let dir = opts.out.join("sensors");
    let dsn = ctx.noisy(&ctx.ds, opts.snr_db, &onboard)?;
    let (chosen, sel_tables) = choose(ctx, &dsn, onboard.len())?;
    ctx.selected = Some(chosen.clone());
    let mut t = Table::new(&[
        "inputs",
        "channels",
        "SNR dB",
        "FL R²",
        "FQ R²",
        "FL RMSE kN",
        "FQ RMSE kN",
    ]);
    let paper = Ctx::paper21();
    // The noisy data of each SNR (the selection's at the experiments' SNR is reused).
    let others = opts
        .sensor_snrs
        .iter()
        .map(|&snr| {
            (snr != opts.snr_db)
                .then(|| ctx.noisy(&ctx.ds, snr, &onboard))
                .transpose()
        })
        .collect::<Result<Vec<_>>>()?;
    let sets: Vec<&crate::dataset::DataSet> =
        others.iter().map(|o| o.as_ref().unwrap_or(&dsn)).collect();
    let cases: Vec<(f64, &str, &Vec<String>, usize)> = opts
        .sensor_snrs
        .iter()
        .enumerate()
        .flat_map(|(i, &snr)| {
            [("paper's 21", &paper), ("selected on-board", &chosen)]
                .map(|(name, inputs)| (snr, name, inputs, i))
        })
        .collect();
    let reused =
        |snr: f64, name: &str| ctx.pooled.is_some() && name == "paper's 21" && snr == opts.snr_db;
    let jobs: Vec<FitJob> = cases
        .iter()
        .filter(|(snr, name, _, _)| !reused(*snr, name))
        .map(|&(snr, name, inputs, i)| {
            Ok(FitJob {
                ds: sets[i],
                spec: ctx.spec(
                    sets[i],
                    inputs,
                    &labels,
                    NoiseProtocol::Matched,
                    ctx.split.clone(),
                )?,
                kind: ModelKind::CnnBiLstm,
                dir: dir.join(format!(
                    "models/{}_{snr}dB",
                    if name == "paper's 21" {
                        "paper21"
                    } else {
                        "selected"
                    }
                )),
                windows: None,
                members: 1,
                seed_offset: 0,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut fitted = ctx.fit_all(&jobs)?.into_iter();
    for &(snr, name, inputs, i) in &cases {
        let e = match &ctx.pooled {
            Some(m) if reused(snr, name) => m.clone(),
            _ => {
                let (mut m, _) = fitted.next().expect("one model per case");
                evaluate(&mut m, sets[i], EvalPart::Test)?.metrics
            }
        };
        t.push(vec![
            name.into(),
            inputs.len().to_string(),
            format!("{snr}"),
            f4(e[0].r2),
            f4(e[1].r2),
            format!("{:.2}", e[0].rmse_kn),
            format!("{:.2}", e[1].rmse_kn),
        ]);
    }
    // The selected set's model at the experiments' SNR serves the mismatch experiment too.
    let selected_dir = dir.join(format!("models/selected_{}dB", opts.snr_db));
    if jobs.iter().any(|j| j.dir == selected_dir) {
        ctx.trained.push((super::SELECTED, selected_dir));
    }
    let mut tables = vec![(
        "CNN-BiLSTM (FL and FQ as two outputs), pooled test metrics".into(),
        t,
        "sensors".into(),
    )];
    tables.extend(sel_tables);
    Ok(Section {
        title: "5. On-board sensor selection (not in the paper)".into(),
        text: vec![
            format!(
                "Candidates: every on-board measurable signal railforce records ({}, a signal recorded under two names counted once): body accelerations, angular rates, track-relative displacements and angles, and the deflections of the spring nests, shear pads, side bearers and centre plates; wheel forces, contact quantities and other wheels' creepages are not candidates. Selected union for FL and FQ ({} channels): {}.",
                onboard.len(),
                chosen.len(),
                chosen.join(", ")
            ),
            ctx.protocol(&ctx.split, Some(opts.snr_db)),
        ],
        tables,
        figures: Vec::new(),
    })
}

/// A table of a report section: caption, table, file stem.
type SectionTable = (String, Table, String);

/// The Filter–Wrapper for FL and for FQ over the on-board candidates of `dsn` (noisy at the
/// experiments' SNR): the union of the two selections (clean names) and each selection's table.
pub(super) fn choose(
    ctx: &Ctx,
    dsn: &crate::dataset::DataSet,
    candidates: usize,
) -> Result<(Vec<String>, Vec<SectionTable>)> {
    let opts = ctx.opts;
    let mut chosen: Vec<String> = Vec::new();
    let mut sel_tables = Vec::new();
    for target in ["FL", "FQ"] {
        (ctx.log)(format!(
            "selecting sensors for {target} among {} on-board candidates …",
            candidates
        ));
        let so = SelectOptions {
            target: target.into(),
            noisy: true,
            window: opts.window,
            label_at: opts.label_at,
            candidates: Candidates::Onboard,
            ..SelectOptions::default()
        };
        let sel = select(dsn, &ctx.split, &so)?;
        let mut t = Table::new(&["channel", "MI nats", "wrapper gain", "kept"]);
        for r in &sel.table {
            t.push(vec![
                clean_name(&r.channel).to_string(),
                f4(r.mi),
                r.wrapper_gain
                    .map(|g| format!("{g:+.4}"))
                    .unwrap_or_else(|| "filtered".into()),
                if r.kept { "yes".into() } else { String::new() },
            ]);
        }
        (ctx.log)(format!(
            "  {target}: kept {} channels: {}",
            sel.channels.len(),
            sel.channels
                .iter()
                .map(|c| clean_name(c))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        for c in &sel.channels {
            let c = clean_name(c).to_string();
            if !chosen.contains(&c) {
                chosen.push(c);
            }
        }
        sel_tables.push((
            format!(
                "Filter–Wrapper for {target} over {} on-board candidates (MI on at most {} training rows, ridge on at most {} training windows)",
                candidates,
                so.mi_samples,
                so.max_windows
            ),
            t,
            format!("selection_{}", target.to_lowercase()),
        ));
    }
    Ok((chosen, sel_tables))
}
