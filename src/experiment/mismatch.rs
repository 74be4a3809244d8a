//! Beyond the paper (assets/docs/learning.md §4.6): a wagon the model did not learn.
//! The CNN-BiLSTM trained on the nominal wagon (the generalisation and sensors experiments'
//! models, reused when they ran) and the same network trained on a fleet (domain
//! randomisation: every training run draws its own wagon and track from the fleet plan's
//! `[vary]`), both scored on the same held-out wagons: the fleet's test-seed runs, whose draws
//! no training or validation run shares, and four named extremes of the nominal wagon.

use super::{Ctx, ExperimentOptions, FitJob, PAPER21, SELECTED, earlier, f4, sensors};
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use crate::features::{NoiseProtocol, Split};
use crate::learn::evaluate::{EVAL_COVERAGE, EvalPart, Evaluation, evaluate};
use crate::learn::model::{Model, ModelKind};
use crate::plan::Plan;
use crate::report::Section;
use crate::report::svg::{BarChart, BarSeries, WIDTH};
use crate::report::table::{MISSING, Table};
use crate::sensors::{Candidates, VEHICLE_MASS};
use crate::vary::Vary;
use std::path::PathBuf;
use std::time::Instant;

/// The fleet-trained CNN-BiLSTM on the on-board selection and the weighed mass.
const WEIGHED: &str = "selected_weighed";
/// The fleet-trained CNN-BiLSTM on the paper's 21 and the weighed mass.
const PAPER_WEIGHED: &str = "paper21_weighed";

/// The named extremes: folder, what it is, and its `[vary]` table (one fixed value on the
/// nominal wagon and track; the C80's numbers).
const EXTREMES: [(&str, &str, &str); 4] = [
    (
        "half_payload",
        "half payload (carbody link 0.565 × 91.8 t = 51.9 t: 40 of the 80 t payload, inertia scaled with it)",
        r#""vehicle.body.carbody.mass" = { one_of = [0.565], scale = true, with = ["vehicle.body.carbody.inertia"] }"#,
    ),
    (
        "wet_rail",
        "wet rail (wheel–rail friction 0.2 against the nominal 0.3)",
        r#""vehicle.contact.friction" = { one_of = [0.2] }"#,
    ),
    (
        "high_conicity",
        "the highest-conicity pair (S1002 at 1 360 mm flange back, λe 0.18 against 0.018)",
        r#""vehicle.contact.flange_back_m" = { one_of = [1.360] }"#,
    ),
    (
        "class4",
        "FRA class 4 track (rougher than the nominal class 5)",
        r#""track.irregularity.class" = { one_of = [4] }"#,
    ),
];

/// The experiment's plan varied by its fleet (`opts.fleet`): loaded and checked against
/// `plan`. `experiment::run` calls it before any simulation, so a missing or unfitting fleet
/// plan is refused at once rather than after the earlier parts' hour.
pub(super) fn fleet_plan(opts: &ExperimentOptions, plan: &Plan) -> Result<Plan> {
    let fleet_path = opts.fleet.as_ref().ok_or_else(|| {
        Error::Domain("the mismatch experiment needs a fleet plan (--fleet)".into())
    })?;
    with_fleet(plan, &Plan::load(fleet_path)?)
}

/// The experiment's plan with each condition's variation taken from the fleet plan's
/// condition of the same name.
fn with_fleet(plan: &Plan, fleet: &Plan) -> Result<Plan> {
    let mut p = plan.clone();
    p.name = fleet.name.clone();
    p.source = fleet.source.clone();
    // A fleet may draw wagons that derail: its plan says whether they are left out.
    p.drop_derailed = fleet.drop_derailed;
    for c in &mut p.conditions {
        let f = fleet
            .conditions
            .iter()
            .find(|f| f.name == c.name)
            .ok_or_else(|| {
                Error::config(
                    &fleet.source,
                    "condition",
                    format!(
                        "has no condition \"{}\" of the plan {}: the fleet plan gives each of the experiment's conditions its [vary]",
                        c.name,
                        plan.source.display()
                    ),
                )
            })?;
        c.vary = f.vary.clone();
        // Seeds the fleet plan adds train more wagons (validation and test stay the plan's).
        for s in &f.seeds {
            if !c.seeds.contains(s) {
                c.seeds.push(*s);
                c.turn_order.push(*s);
            }
        }
    }
    if p.conditions.iter().all(|c| c.vary.is_empty()) {
        return Err(Error::config(
            &fleet.source,
            "vary",
            "the fleet plan varies nothing: give it a [vary] table",
        ));
    }
    Ok(p)
}

/// The experiment's plan at `seeds` with one extreme's fixed value on every condition (a
/// run that derails left out as the fleet's are, where the fleet plan says so).
fn extreme(plan: &Plan, name: &str, table: &str, seeds: &[u64], drop: bool) -> Result<Plan> {
    let t: toml::Table = toml::from_str(table).expect("a built-in [vary] table parses");
    let vary = Vary::parse(&t, &plan.source, &format!("mismatch.{name}"))?;
    let mut p = plan.clone();
    p.name = format!("{}_{name}", plan.name);
    p.drop_derailed = drop;
    for c in &mut p.conditions {
        c.vary = vary.clone();
        c.only_seeds(seeds);
    }
    Ok(p)
}

/// One test set: name, what it is, its data (noisy inputs), which windows.
struct TestSet {
    name: String,
    about: String,
    ds: DataSet,
    part: EvalPart,
}

/// RMSE (kN) per target of the rows `pick` keeps, `None` where it keeps none.
fn rmse_kn(ev: &Evaluation, pick: &dyn Fn(usize) -> bool) -> Vec<Option<f64>> {
    let o = ev.rows.first().map_or(0, |r| r.3.len());
    (0..o)
        .map(|k| {
            let (mut n, mut s) = (0usize, 0.0);
            for (i, r) in ev.rows.iter().enumerate() {
                if pick(i) {
                    let (y, p) = r.3[k];
                    s += (y - p) * (y - p);
                    n += 1;
                }
            }
            (n > 0).then(|| (s / n as f64).sqrt() * 1e-3)
        })
        .collect()
}

pub(super) fn run(ctx: &mut Ctx) -> Result<Section> {
    let opts = ctx.opts;
    let t0 = Instant::now();
    let Split::Seeds { test, .. } = &ctx.split else {
        return Err(Error::Domain(
            "the mismatch experiment tests on wagons drawn for held-out seeds: it needs a split by seed (a plan of three or more seeds)".into(),
        ));
    };
    let test_seeds = test.clone();
    let plan = Plan::load(&opts.plan)?;
    let fleet = fleet_plan(opts, &plan)?;
    let dir = opts.out.join("mismatch");
    let labels = ctx.labels();
    let paper = Ctx::paper21();
    let selected_dir = opts
        .out
        .join(format!("sensors/models/selected_{}dB", opts.snr_db));
    let paper21_dir = opts.out.join("generalization/models/all_conditions");
    let earlier_selected = match &ctx.selected {
        Some(_) => None,
        None => earlier(ctx, &selected_dir, &ctx.ds, None, opts.mismatch_window),
    };
    let selected = match (&ctx.selected, &earlier_selected) {
        (Some(s), _) => s.clone(),
        (None, Some(m)) => m.meta.data.channels.clone(),
        (None, None) => {
            let onboard = ctx
                .ds
                .distinct_channels(&Candidates::Onboard.among(&ctx.ds.names, &ctx.ds.labels));
            let dsn = ctx.noisy(&ctx.ds, opts.snr_db, &onboard)?;
            let chosen = sensors::choose(ctx, &dsn, onboard.len())?.0;
            ctx.selected = Some(chosen.clone());
            chosen
        }
    };
    let mut inputs = paper.clone();
    inputs.extend(selected.iter().filter(|c| !paper.contains(c)).cloned());
    // The on-board selection with the weighed mass beside it: a deflection gauge reads load
    // over stiffness, and the fleet's stiffness varies, so the wheel load needs the one
    // stiffness-free number an operator has. A constant of each run: the noise model, scaled
    // by each run's own standard deviation, leaves it exact.
    let weighed = ctx.ds.channel(VEHICLE_MASS).is_ok();
    let mut selected_mass = selected.clone();
    selected_mass.push(VEHICLE_MASS.into());
    let mut paper_mass = paper.clone();
    paper_mass.push(VEHICLE_MASS.into());
    if weighed {
        inputs.push(VEHICLE_MASS.into());
    }
    let mut keep: Vec<String> = vec!["time_s".into()];
    if ctx.ds.channel("s_m").is_ok() {
        keep.push("s_m".into());
    }
    keep.extend(labels.iter().cloned());
    keep.extend(inputs.iter().cloned());
    // The test sets, simulated once (resumable) and noised as the nominal data are.
    let mut sets = vec![TestSet {
        name: "nominal".into(),
        about: "the nominal wagon on the test seeds' track".into(),
        ds: ctx.noisy(&ctx.ds.subset(None, Some(&keep))?, opts.snr_db, &inputs)?,
        part: EvalPart::Test,
    }];
    let mut plans = vec![("fleet", fleet.clone(), EvalPart::Test)];
    for (name, _, table) in EXTREMES {
        plans.push((
            name,
            extreme(&plan, name, table, &test_seeds, fleet.drop_derailed)?,
            EvalPart::All,
        ));
    }
    let ts = Instant::now();
    for (name, p, part) in plans {
        let data = dir.join("data").join(name);
        ctx.simulate_runs(&p, &data)?;
        let ds = DataSet::load(&data)?.subset(None, Some(&keep))?;
        let about = match name {
            "fleet" => format!(
                "the fleet's wagons drawn for the test seed{} {} (no training or validation run shares a draw)",
                if test_seeds.len() > 1 { "s" } else { "" },
                test_seeds
                    .iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => EXTREMES
                .iter()
                .find(|e| e.0 == name)
                .map(|e| e.1.to_string())
                .unwrap_or_default(),
        };
        sets.push(TestSet {
            name: name.into(),
            about,
            ds: ctx.noisy(&ds, opts.snr_db, &inputs)?,
            part,
        });
    }
    let sim_s = ts.elapsed().as_secs_f64();
    // The models: nominal (reused where an earlier part trained it) and fleet-trained.
    let fleet_ds = &sets[1].ds;
    let nominal_ds = &sets[0].ds;
    let cases: [(&str, &str, &Vec<String>); 2] = [
        (PAPER21, "paper's 21", &paper),
        (SELECTED, "selected on-board", &selected),
    ];
    // Fleet-trained only: on the nominal wagon the mass is one constant, nothing to learn from.
    let mut fleet_cases: Vec<(&str, &str, &Vec<String>)> = cases.to_vec();
    if weighed {
        fleet_cases.push((PAPER_WEIGHED, "paper's 21 + weighed mass", &paper_mass));
        fleet_cases.push((WEIGHED, "selected on-board + weighed mass", &selected_mass));
    }
    // The fleet trains on every seed of its plan that neither validates nor tests: a fleet
    // plan with more seeds than the nominal one gives its models more wagons to learn from,
    // while validation and test stay the nominal split's.
    let fleet_split = match &ctx.split {
        Split::Seeds { val, test, .. } => {
            let mut train: Vec<u64> = fleet_ds.runs.iter().map(|r| r.seed).collect();
            train.sort_unstable();
            train.dedup();
            train.retain(|s| !val.contains(s) && !test.contains(s));
            Split::Seeds {
                train,
                val: val.clone(),
                test: test.clone(),
            }
        }
        other => other.clone(),
    };
    let job = |fleet: bool, ins: &[String], name: String, members: usize| -> Result<FitJob> {
        let (ds, split) = if fleet {
            (fleet_ds, fleet_split.clone())
        } else {
            (nominal_ds, ctx.split.clone())
        };
        Ok(FitJob {
            ds,
            spec: ctx.spec_windowed(
                ds,
                ins,
                &labels,
                NoiseProtocol::Matched,
                split,
                opts.mismatch_window,
            )?,
            kind: ModelKind::CnnBiLstm,
            dir: dir.join(format!("models/{name}")),
            windows: None,
            members,
            seed_offset: 0,
        })
    };
    let mut jobs = Vec::new();
    let mut reused: Vec<Option<PathBuf>> = Vec::new();
    // Models trained in this invocation share the part's window only when the experiments'
    // window is the mismatch's.
    let same_window = opts.window == opts.mismatch_window;
    for (key, _, ins) in cases {
        let dir = if key == PAPER21 {
            &paper21_dir
        } else {
            &selected_dir
        };
        let on_disk =
            || earlier(ctx, dir, nominal_ds, Some(ins), opts.mismatch_window).map(|_| dir.clone());
        match ctx.trained.iter().find(|(k, _)| same_window && *k == key) {
            Some((_, d)) => reused.push(Some(d.clone())),
            None if on_disk().is_some() => {
                (ctx.log)(format!(
                    "reusing {} (trained earlier on the same data and protocol)",
                    dir.display()
                ));
                reused.push(on_disk());
            }
            None => {
                reused.push(None);
                jobs.push(job(false, ins, format!("nominal_{key}"), 1)?);
            }
        }
    }
    // The deployable models (with the weighed mass) as ensembles: one network's FL moves
    // with its training seed by more than any input or window change gained.
    for &(key, _, ins) in &fleet_cases {
        let members = if ins.iter().any(|c| c == VEHICLE_MASS) {
            opts.mismatch_members.max(1)
        } else {
            1
        };
        jobs.push(job(true, ins, format!("fleet_{key}"), members)?);
    }
    let tt = Instant::now();
    let mut fitted = ctx.fit_all(&jobs)?.into_iter().map(|(m, _)| m);
    let train_s = tt.elapsed().as_secs_f64();
    let mut models: Vec<(&str, String, Model)> = Vec::new();
    for ((_, name, _), dir) in cases.iter().zip(&reused) {
        let m = match dir {
            Some(d) => Model::load(d)?,
            None => fitted.next().expect("a nominal model per inputs"),
        };
        models.push((name, "nominal wagon".into(), m));
    }
    for &(_, name, _) in &fleet_cases {
        let m = fitted.next().expect("a fleet model per inputs");
        let trained = match m.meta.members {
            1 => "fleet".to_string(),
            n => format!("fleet, ensemble of {n}"),
        };
        models.push((name, trained, m));
    }
    // Every model on every test set.
    let mut t = Table::new(&[
        "inputs",
        "trained on",
        "tested on",
        "windows",
        "FL R²",
        "FL RMSE kN",
        "FQ R²",
        "FQ RMSE kN",
        "FL covered %",
        "FQ covered %",
        "FL width kN",
        "FQ width kN",
        "flagged %",
        "FL RMSE flagged kN",
        "FL RMSE quiet kN",
        "FQ RMSE flagged kN",
        "FQ RMSE quiet kN",
    ]);
    let mut bars: Vec<[Vec<Option<f64>>; 2]> = vec![[Vec::new(), Vec::new()]; models.len()];
    let te = Instant::now();
    for (mi, (inputs, trained, model)) in models.iter_mut().enumerate() {
        for set in &sets {
            let ev = evaluate(model, &set.ds, set.part)?;
            let pooled = ev.coverage().and_then(|c| c.last().cloned());
            let cov = |k: usize, width: bool| {
                pooled.as_ref().map_or(MISSING.to_string(), |p| {
                    let (c, w) = p.targets[k];
                    if width {
                        format!("{w:.2}")
                    } else {
                        format!("{:.1}", 100.0 * c)
                    }
                })
            };
            let flags = ev.outside.clone().unwrap_or_default();
            let share = if flags.is_empty() {
                MISSING.to_string()
            } else {
                format!(
                    "{:.1}",
                    100.0 * flags.iter().filter(|&&f| f).count() as f64 / flags.len() as f64
                )
            };
            let flagged = rmse_kn(&ev, &|i| flags.get(i) == Some(&true));
            let quiet = rmse_kn(&ev, &|i| flags.get(i) == Some(&false));
            let kn = |v: Option<f64>| v.map_or(MISSING.to_string(), |v| format!("{v:.2}"));
            let m = &ev.metrics;
            t.push(vec![
                inputs.to_string(),
                trained.to_string(),
                set.name.clone(),
                m[0].n.to_string(),
                f4(m[0].r2),
                format!("{:.2}", m[0].rmse_kn),
                f4(m[1].r2),
                format!("{:.2}", m[1].rmse_kn),
                cov(0, false),
                cov(1, false),
                cov(0, true),
                cov(1, true),
                share,
                kn(flagged[0]),
                kn(quiet[0]),
                kn(flagged[1]),
                kn(quiet[1]),
            ]);
            bars[mi][0].push(Some(m[0].rmse_kn));
            bars[mi][1].push(Some(m[1].rmse_kn));
        }
    }
    let eval_s = te.elapsed().as_secs_f64();
    let chart = |k: usize, target: &str| BarChart {
        title: format!(
            "{target} RMSE on wagons the model did not learn, CNN-BiLSTM at {} dB",
            opts.snr_db
        ),
        y_label: format!("{target} RMSE, kN"),
        categories: sets.iter().map(|s| s.name.clone()).collect(),
        series: models
            .iter()
            .zip(&bars)
            .map(|((inputs, trained, _), b)| BarSeries {
                label: format!("{inputs}, trained on {trained}"),
                values: b[k].clone(),
            })
            .collect(),
        floor: Some(0.0),
        width: WIDTH,
    };
    let variations = fleet
        .conditions
        .first()
        .map(|c| {
            c.vary
                .variations
                .iter()
                .map(|v| v.describe())
                .collect::<Vec<_>>()
                .join("; ")
        })
        .unwrap_or_default();
    Ok(Section {
        title: "6. A wagon the model did not learn (not in the paper)".into(),
        text: vec![
            format!(
                "The fleet ({}): every run draws its own wagon and track, from its condition, seed and key — {variations}.",
                fleet.source.display()
            ),
            format!(
                "Test sets: {}.",
                sets.iter()
                    .map(|s| format!("{}: {}", s.name, s.about))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
            format!("Every model here reads windows of {} steps (the other parts' {}; by default 40: on wagons they did not learn, 0.2 s read FL better than the paper's 0.1 s, as CHANGELOG.md records).", opts.mismatch_window, opts.window),
            format!("Trained on the nominal wagon: the generalisation (paper's 21) and sensors (on-board selection) experiments' CNN-BiLSTMs where they ran in the same invocation with the same window, or earlier into the same folder on the same data and protocol. Trained on the fleet (domain randomisation): the same network, inputs and noise; validated and tested on the nominal split's seeds, trained on every other seed of the fleet plan (more wagons where the fleet plan draws more seeds); and once more with the vehicle's weighed mass (`vehicle_mass_t`, a constant of each run that the weighbridge ticket gives) beside each input set (the paper's 21 carry no load channel, so without it the payload's share of the wheel load is invisible to them), {ens}. Every model is calibrated by split conformal on its own validation runs: \"covered\" is the share of true forces inside its 90 % interval, \"flagged\" the share of windows with an input beyond its training envelope (the rule `identify` warns by), and the RMSE where flagged against where quiet says whether the flag fires where the error is large.", ens = match opts.mismatch_members { 1 => "one network each".to_string(), n => format!("each an ensemble of {n} networks from consecutive training seeds, with their quantile heads: the members' mean, and as spread their disagreement and their heads' σ together (total variance)") }),
            ctx.protocol_windowed(&ctx.split, Some(opts.snr_db), opts.mismatch_window),
            format!(
                "Time: simulation {sim_s:.0} s, trainings {train_s:.0} s ({} networks), evaluation {eval_s:.0} s; the part {:.0} s. Intervals at {:.0} %.",
                jobs.iter().map(|j| j.members).sum::<usize>(),
                t0.elapsed().as_secs_f64(),
                100.0 * EVAL_COVERAGE
            ),
        ],
        tables: vec![(
            "Every model on every held-out wagon: R² and RMSE in kN, the 90 % interval's coverage and mean width, the windows flagged out of distribution".into(),
            t,
            "mismatch".into(),
        )],
        figures: vec![
            (
                "FL RMSE per test set: nominal against fleet-trained, paper's 21 against the on-board selection".into(),
                chart(0, "FL").into(),
                "rmse_fl.svg".into(),
            ),
            (
                "FQ RMSE per test set: a nominal-trained model cannot know a part-loaded wagon's static load".into(),
                chart(1, "FQ").into(),
                "rmse_fq.svg".into(),
            ),
        ],
    })
}
