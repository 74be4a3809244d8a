//! Beyond the paper (assets/docs/learning.md §4.7): the simulator's own form. The same
//! CNN-BiLSTM trained on data from the lumped track and tested on rails on sleepers, and the
//! other way round: how far an identification network carries across a change of the model
//! that made its labels, the nearest honest proxy for the gap between a simulator and a line.
//! The plan's every run is simulated again with `rail_support = "discrete"` (the same
//! conditions, seeds and irregularities), and its test runs once more on the lumped track with
//! CNOSSOS rail roughness below the irregularities (short waves no training run had); the
//! labels' physics beside it: FL's and FQ's standard deviation and FQ's 20–50 Hz band per
//! condition on all three.

use super::{Ctx, FitJob, PAPER21, earlier, f4};
use crate::dataset::DataSet;
use crate::error::Result;
use crate::features::NoiseProtocol;
use crate::learn::evaluate::{EvalPart, evaluate};
use crate::learn::model::{Model, ModelKind};
use crate::plan::Plan;
use crate::report::Section;
use crate::report::table::Table;
use std::time::Instant;

/// The rail roughness of the short-wave test set.
const ROUGHNESS: &str = "cnossos_m";

/// FQ's rms in its 20–50 Hz band (sleeper passing, the short waves) over `ds`'s runs of
/// `seeds` in condition `name`, kN (power averaged over the runs).
fn fq_band(ds: &DataSet, name: &str, seeds: &[u64]) -> Result<f64> {
    let col = ds.channel(&ds.labels[1])?;
    let (mut p, mut n) = (0.0, 0usize);
    for r in ds
        .runs
        .iter()
        .filter(|r| r.condition == name && seeds.contains(&r.seed))
    {
        let b = crate::sim::step_study::band_rms(&r.columns[col], crate::sensors::RATE_HZ);
        p += b[1] * b[1];
        n += 1;
    }
    Ok((p / n.max(1) as f64).sqrt() * 1e-3)
}

/// Standard deviation of each label of `ds`'s runs of `seeds` in condition `name`, kN
/// (pooled over those runs, each run's own mean removed).
fn label_sd(ds: &DataSet, name: &str, seeds: &[u64]) -> Result<[f64; 2]> {
    let mut out = [0.0; 2];
    for (k, label) in ds.labels.iter().enumerate() {
        let col = ds.channel(label)?;
        let (mut ss, mut n) = (0.0, 0usize);
        for r in ds
            .runs
            .iter()
            .filter(|r| r.condition == name && seeds.contains(&r.seed))
        {
            let x = &r.columns[col];
            let m = x.iter().sum::<f64>() / x.len().max(1) as f64;
            ss += x.iter().map(|v| (v - m).powi(2)).sum::<f64>();
            n += x.len();
        }
        out[k] = (ss / n.max(1) as f64).sqrt() * 1e-3;
    }
    Ok(out)
}

/// The CNN-BiLSTM on `inputs` predicting `labels` on `ds` under the experiments' split.
fn fit_job<'a>(
    ctx: &Ctx,
    ds: &'a DataSet,
    inputs: &[String],
    labels: &[String],
    dir: std::path::PathBuf,
) -> Result<FitJob<'a>> {
    Ok(FitJob {
        ds,
        spec: ctx.spec(
            ds,
            inputs,
            labels,
            NoiseProtocol::Matched,
            ctx.split.clone(),
        )?,
        kind: ModelKind::CnnBiLstm,
        dir,
        windows: None,
        members: 1,
        seed_offset: 0,
    })
}

pub(super) fn run(ctx: &mut Ctx) -> Result<Section> {
    let opts = ctx.opts;
    let t0 = Instant::now();
    let plan = Plan::load(&opts.plan)?;
    let mut beams = plan.clone();
    beams.name = format!("{}_on_sleepers", plan.name);
    for c in &mut beams.conditions {
        c.rail_support = Some("discrete".into());
    }
    let dir = opts.out.join("model_form");
    let data = dir.join("data/on_sleepers");
    let ts = Instant::now();
    ctx.simulate_runs(&beams, &data)?;
    let test_seeds = match &ctx.split {
        crate::features::Split::Seeds { test, .. } => test.clone(),
        _ => plan
            .conditions
            .first()
            .map(|c| c.seeds.clone())
            .unwrap_or_default(),
    };
    let mut rough = plan.clone();
    rough.name = format!("{}_{ROUGHNESS}", plan.name);
    for c in &mut rough.conditions {
        c.roughness = Some(ROUGHNESS.into());
        c.only_seeds(&test_seeds);
    }
    let rough_data = dir.join(format!("data/{ROUGHNESS}"));
    ctx.simulate_runs(&rough, &rough_data)?;
    let sim_s = ts.elapsed().as_secs_f64();
    let paper = Ctx::paper21();
    let labels = ctx.labels();
    let mut keep: Vec<String> = vec!["time_s".into()];
    keep.extend(labels.iter().cloned());
    keep.extend(paper.iter().cloned());
    let lumped_clean = ctx.ds.subset(None, Some(&keep))?;
    let beams_clean = DataSet::load(&data)?.subset(None, Some(&keep))?;
    let rough_clean = DataSet::load(&rough_data)?.subset(None, Some(&keep))?;
    let lumped = ctx.noisy(&lumped_clean, opts.snr_db, &paper)?;
    let on_beams = ctx.noisy(&beams_clean, opts.snr_db, &paper)?;
    let on_rough = ctx.noisy(&rough_clean, opts.snr_db, &paper)?;

    // Each track's network from the experiments' training seed and, with the seed spread on,
    // the next one (a single training's R² moves by about a hundredth from one seed, or one
    // rounding of the data, to the next: the rows are stated with their spread). The
    // lumped-trained ones are the generalisation part's, where it ran on the same data and
    // protocol (in this invocation or earlier into the same folder), else trained here.
    let offsets: Vec<u64> = if opts.seed_spread {
        vec![0, 1]
    } else {
        vec![0]
    };
    let name = |base: &str, o: u64| {
        if o == 0 {
            base.to_string()
        } else {
            format!("{base}_seed{}", o + 1)
        }
    };
    let reused: Vec<Option<std::path::PathBuf>> = (offsets.iter())
        .map(|&o| {
            let dir = opts
                .out
                .join("generalization/models")
                .join(name("all_conditions", o));
            let recorded = (o == 0)
                .then(|| ctx.trained.iter().find(|(k, _)| *k == PAPER21))
                .flatten();
            match recorded {
                Some((_, d)) => Some(d.clone()),
                None => earlier(ctx, &dir, &lumped, Some(&paper), opts.window).map(|_| dir),
            }
        })
        .collect();
    let job = |ds, n: String, o: u64| -> Result<FitJob> {
        let mut j = fit_job(ctx, ds, &paper, &labels, dir.join(format!("models/{n}")))?;
        j.seed_offset = o;
        Ok(j)
    };
    let mut jobs = Vec::new();
    for (&o, r) in offsets.iter().zip(&reused) {
        jobs.push(job(&on_beams, name("on_sleepers", o), o)?);
        if r.is_none() {
            jobs.push(job(&lumped, name("lumped", o), o)?);
        }
    }
    let tt = Instant::now();
    let mut fitted = ctx.fit_all(&jobs)?.into_iter().map(|(m, _)| m);
    let train_s = tt.elapsed().as_secs_f64();
    let mut models: Vec<(String, Model)> = Vec::new();
    for (&o, r) in offsets.iter().zip(&reused) {
        let seed = |base: &str| match o {
            0 => base.to_string(),
            _ => format!("{base}, training seed {}", opts.train.seed + o),
        };
        let beams_model = fitted.next().expect("the model trained on sleepers");
        let lumped_model = match r {
            Some(d) => {
                (ctx.log)(format!(
                    "reusing {} (trained earlier on the same data and protocol)",
                    d.display()
                ));
                Model::load(d)?
            }
            None => fitted.next().expect("the lumped model"),
        };
        models.push((seed("lumped rail masses"), lumped_model));
        models.push((seed("rails on sleepers"), beams_model));
    }
    let short = format!("lumped, {ROUGHNESS} roughness");
    let mut scores: Vec<(String, String, [f64; 2])> = Vec::new();
    let sets: [(&str, &DataSet, EvalPart); 3] = [
        ("lumped rail masses", &lumped, EvalPart::Test),
        ("rails on sleepers", &on_beams, EvalPart::Test),
        (&short, &on_rough, EvalPart::All),
    ];
    let mut t = Table::new(&[
        "trained on",
        "tested on",
        "windows",
        "FL R²",
        "FL RMSE kN",
        "FQ R²",
        "FQ RMSE kN",
    ]);
    for (trained, model) in models.iter_mut() {
        for (tested, ds, part) in sets {
            let ev = evaluate(model, ds, part)?;
            let m = &ev.metrics;
            scores.push((trained.clone(), tested.to_string(), [m[0].r2, m[1].r2]));
            t.push(vec![
                trained.to_string(),
                tested.to_string(),
                m[0].n.to_string(),
                f4(m[0].r2),
                format!("{:.2}", m[0].rmse_kn),
                f4(m[1].r2),
                format!("{:.2}", m[1].rmse_kn),
            ]);
        }
    }
    // Each pair (trained on, tested on) over the training seeds: mean ± half range.
    let mut spread = Table::new(&[
        "trained on",
        "tested on",
        "FL R², mean ± half range",
        "FQ R², mean ± half range",
    ]);
    if offsets.len() == 2 {
        let half = scores.len() / 2;
        for ((trained, tested, a), (_, _, b)) in scores[..half].iter().zip(&scores[half..]) {
            let both = |k: usize| super::mean_half_range(a[k], b[k], 4);
            spread.push(vec![trained.clone(), tested.clone(), both(0), both(1)]);
        }
    }
    // The labels' physics on the three, the test seeds' runs of each condition.
    let mut phys = Table::new(&[
        "condition",
        "FL sd kN, lumped",
        "FL sd kN, sleepers",
        "FL sd kN, rough",
        "FQ sd kN, lumped",
        "FQ sd kN, sleepers",
        "FQ sd kN, rough",
        "FQ 20–50 Hz kN, lumped",
        "FQ 20–50 Hz kN, sleepers",
        "FQ 20–50 Hz kN, rough",
    ]);
    let all = [&lumped_clean, &beams_clean, &rough_clean];
    for c in &ctx.conditions {
        let mut row = vec![c.clone()];
        let sds = all
            .iter()
            .map(|ds| label_sd(ds, c, &test_seeds))
            .collect::<Result<Vec<_>>>()?;
        for k in 0..2 {
            row.extend(sds.iter().map(|sd| format!("{:.2}", sd[k])));
        }
        for ds in all {
            row.push(format!("{:.2}", fq_band(ds, c, &test_seeds)?));
        }
        phys.push(row);
    }
    Ok(Section {
        title: "7. The simulator's form: lumped track against rails on sleepers (not in the paper)".into(),
        text: vec![
            format!(
                "Every run of the plan simulated again on rails on discrete sleepers ({}: rails as beams on pads, sleepers, ballast and subgrade, the same conditions, seeds and irregularities, {} ms, and above 60 km/h at most {:.2} mm of travel a step), and one CNN-BiLSTM on the paper's 21 trained on each track's data under the same split and noise: each tested on its own track and on the other. A network that keeps its R² across the change of track model carries what it learned from the vehicle, not from one track model's numbers.",
                beams.name,
                crate::sim::MAX_STEP_ON_BEAMS * 1e3,
                crate::sim::MAX_TRAVEL_ON_BEAMS * 1e3
            ),
            format!(
                "Both also tested on short waves no training run had: the test runs again on the lumped track with {ROUGHNESS} rail roughness below the irregularities ({}: CNOSSOS-EU's average network from where the irregularities stop down to 0.1 m, through the contact filter, 62.5 µs; physics.md §3.4).",
                rough.name
            ),
            format!(
                "Each track's network from training seed {}{}; the lumped-trained one{} the generalisation part's ({}).",
                opts.train.seed,
                if offsets.len() == 2 {
                    format!(" and from seed {}, the pairs' spread in the second table", opts.train.seed + 1)
                } else {
                    String::new()
                },
                if offsets.len() == 2 { "s are" } else { " is" },
                if reused.iter().all(Option::is_some) {
                    "reused: trained on the same data and protocol"
                } else {
                    "trained here where the generalisation part did not leave it"
                }
            ),
            ctx.protocol(&ctx.split, Some(opts.snr_db)),
            format!(
                "Time: simulation on sleepers and with roughness {sim_s:.0} s, trainings {train_s:.0} s ({} network{}); the part {:.0} s.",
                jobs.len(),
                if jobs.len() == 1 { "" } else { "s" },
                t0.elapsed().as_secs_f64()
            ),
        ],
        tables: vec![
            (
                "Trained on one track model, tested on both and on short waves: R² and RMSE in kN on the test runs".into(),
                t,
                "model_form".into(),
            ),
            (
                "Over the two training seeds: each pair's R², mean ± half range".into(),
                spread,
                "model_form_spread".into(),
            ),
            (
                "The labels on the three: FL's and FQ's standard deviation and FQ's rms in 20–50 Hz (sleeper passing, short waves) on the test runs of each condition (clean)".into(),
                phys,
                "labels".into(),
            ),
        ],
        figures: Vec::new(),
    })
}
