//! Beyond the paper: the CNN-BiLSTM under the seed, block, condition and shuffled splits side
//! by side (assets/docs/learning.md §4.4), so a reader sees what each number measures and how much a
//! leaky split inflates it.

use super::{Ctx, FitJob, f4};
use crate::error::Result;
use crate::features::{NoiseProtocol, Split};
use crate::learn::evaluate::{EvalPart, evaluate};
use crate::learn::model::ModelKind;
use crate::report::Section;
use crate::report::table::Table;

pub(super) fn run(ctx: &mut Ctx) -> Result<Section> {
    let opts = ctx.opts;
    let inputs = Ctx::paper21();
    let labels = ctx.labels();
    let dsn = ctx.noisy(&ctx.ds, opts.snr_db, &inputs)?;
    let dir = opts.out.join("protocols");
    // Held out: a curve, a tangent and a gradient case where the plan has them, leaving at
    // least one condition to validate and one to train on.
    let mut held: Vec<String> = ["curve_r400_v60", "tangent_v80", "grade20_L50_v60"]
        .iter()
        .map(|s| s.to_string())
        .filter(|c| ctx.conditions.contains(c))
        .collect();
    held.truncate(ctx.conditions.len().saturating_sub(2).max(1));
    if held.is_empty() {
        held.push(ctx.conditions[0].clone());
    }
    let val: Vec<String> = ctx
        .conditions
        .iter()
        .filter(|c| !held.contains(c))
        .step_by(8)
        .take(2)
        .cloned()
        .collect();
    let mut t = Table::new(&[
        "protocol",
        "what the test part is",
        "test windows",
        "FL R²",
        "FQ R²",
        "FL RMSE kN",
        "FQ RMSE kN",
    ]);
    let splits = [
        ("seeds", ctx.split.clone()),
        ("blocks", Split::default()),
        (
            "conditions",
            Split::Conditions {
                val,
                test: held.clone(),
            },
        ),
        ("shuffled (leaky)", Split::shuffled(opts.train.seed)),
    ];
    let jobs: Vec<FitJob> = splits
        .iter()
        .filter(|(name, _)| !(*name == "seeds" && ctx.pooled.is_some()))
        .map(|(_, split)| {
            Ok(FitJob {
                ds: &dsn,
                spec: ctx.spec(
                    &dsn,
                    &inputs,
                    &labels,
                    NoiseProtocol::Matched,
                    split.clone(),
                )?,
                kind: ModelKind::CnnBiLstm,
                dir: dir.join(format!("models/{}", split.name())),
                windows: None,
                members: 1,
                seed_offset: 0,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut fitted = ctx.fit_all(&jobs)?.into_iter();
    for (name, split) in splits {
        let e = match (&ctx.pooled, name) {
            (Some(m), "seeds") => m.clone(),
            _ => {
                let (mut m, _) = fitted.next().expect("one model per split");
                evaluate(&mut m, &dsn, EvalPart::Test)?.metrics
            }
        };
        t.push(vec![
            name.into(),
            split.describe(),
            e[0].n.to_string(),
            f4(e[0].r2),
            f4(e[1].r2),
            format!("{:.2}", e[0].rmse_kn),
            format!("{:.2}", e[1].rmse_kn),
        ]);
    }
    Ok(Section {
        title: "4. Protocols side by side (not in the paper)".into(),
        text: vec![
            format!(
                "The same CNN-BiLSTM (paper's 21 channels, FL and FQ as two outputs) on all {} conditions at {} dB, trained and tested under four splits. Only the seed split tests on independent stretches of track; blocks test on the end of each run; conditions test transfer to unseen conditions ({}); shuffled leaks (neighbouring windows share all but one step) and is shown only to measure how much such a protocol inflates R². Never a default, never a bar.",
                ctx.conditions.len(),
                opts.snr_db,
                held.join(", ")
            ),
            ctx.protocol(&ctx.split, Some(opts.snr_db)),
        ],
        tables: vec![(
            "CNN-BiLSTM test metrics per protocol".into(),
            t,
            "protocols".into(),
        )],
        figures: Vec::new(),
    })
}
