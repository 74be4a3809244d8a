//! Samples and feature selection: leak-free windows, training-only statistics, noise
//! protocols, and a wrapper that finds the informative channels of a known problem.

use railforce::dataset::{DataSet, Run};
use railforce::features::{self, LabelAt, NoiseProtocol, Part, SelectOptions, Split, ZScore};
use railforce::sensors::PAPER_CHANNELS;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

/// 21 random inputs and a target that depends on two of them (one with a lag of 2 steps).
fn synthetic(runs: usize, n: usize) -> DataSet {
    let mut names: Vec<String> = PAPER_CHANNELS.iter().map(|s| s.to_string()).collect();
    names.push("w1l_force_z".into());
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let runs = (0..runs)
        .map(|r| {
            let mut columns: Vec<Vec<f64>> = (0..21)
                .map(|_| (0..n).map(|_| StandardNormal.sample(&mut rng)).collect())
                .collect();
            let y: Vec<f64> = (0..n)
                .map(|t| {
                    let e: f64 = StandardNormal.sample(&mut rng);
                    2.0 * columns[3][t] + 1.5 * columns[7][t.saturating_sub(2)] + 0.1 * e
                })
                .collect();
            columns.push(y);
            Run {
                condition: format!("c{r}"),
                seed: r as u64,
                columns,
            }
        })
        .collect();
    DataSet::in_memory(std::path::Path::new("synthetic"), names, runs)
}

#[test]
fn windows_never_cross_a_block_boundary() {
    let ds = synthetic(3, 1000);
    let s = features::Samples::build(&ds, &Split::default(), 20, 1, LabelAt::Last).unwrap();
    for (windows, blocks) in [
        (&s.train, &s.train_blocks),
        (&s.val, &s.val_blocks),
        (&s.test, &s.test_blocks),
    ] {
        assert!(!windows.is_empty());
        for w in windows.iter() {
            let b = blocks.iter().find(|b| b.run == w.run as usize).unwrap();
            let (a, e) = (w.start as usize, w.start as usize + s.window);
            assert!(
                a >= b.from && e <= b.to,
                "window {a}..{e} leaves block {b:?}"
            );
        }
    }
    // Blocks are 70/15/15 of each run and do not overlap.
    let b = (s.train_blocks[0], s.val_blocks[0], s.test_blocks[0]);
    assert_eq!((b.0.from, b.0.to, b.1.to, b.2.to), (0, 700, 850, 1000));
    assert_eq!(b.1.from, b.0.to);
    assert_eq!(b.2.from, b.1.to);
    // Label at the last or centre step.
    let w = s.train[5];
    assert_eq!(s.label_row(&w), w.start as usize + 19);
    let c = features::Samples::build(&ds, &Split::default(), 20, 1, LabelAt::Centre).unwrap();
    assert_eq!(c.label_row(&w), w.start as usize + 10);
    // Holding out whole conditions.
    let h = features::Samples::build(
        &ds,
        &Split::Conditions {
            val: vec!["c1".into()],
            test: vec!["c2".into()],
        },
        20,
        1,
        LabelAt::Last,
    )
    .unwrap();
    assert!(h.test.iter().all(|w| w.run == 2) && h.val.iter().all(|w| w.run == 1));
    assert!(h.train.iter().all(|w| w.run == 0));
    let r = features::Samples::build(
        &ds,
        &Split::Runs {
            val: vec![0],
            test: vec![1],
        },
        20,
        1,
        LabelAt::Last,
    )
    .unwrap();
    assert!(r.test.iter().all(|w| w.run == 1) && r.train.iter().all(|w| w.run == 2));
}

#[test]
fn statistics_come_from_training_blocks_only() {
    let mut ds = synthetic(2, 1000);
    let s = features::Samples::build(&ds, &Split::default(), 20, 1, LabelAt::Last).unwrap();
    let clean = ZScore::fit(&ds, &s.train_blocks, &[0, 3, 21]);
    // Poison the validation and test blocks: the statistics must not move.
    for run in &mut ds.runs {
        for col in &mut run.columns {
            for v in &mut col[700..] {
                *v = 1e9;
            }
        }
    }
    let poisoned = ZScore::fit(&ds, &s.train_blocks, &[0, 3, 21]);
    assert_eq!(clean, poisoned);
    assert!(clean.std.iter().all(|s| *s > 0.5 && *s < 3.0));
}

#[test]
fn noise_protocols_pick_the_right_columns() {
    let p = NoiseProtocol::TrainCleanTestNoisy;
    assert_eq!(p.column("ws1_yaw", Part::Train), "ws1_yaw");
    assert_eq!(p.column("ws1_yaw", Part::Test), "ws1_yaw_noisy");
    assert_eq!(
        NoiseProtocol::Matched.column("ws1_yaw", Part::Train),
        "ws1_yaw_noisy"
    );
    assert_eq!(
        NoiseProtocol::Clean.column("ws1_yaw", Part::Test),
        "ws1_yaw"
    );
}

#[test]
fn filter_and_wrapper_find_the_informative_channels() {
    let ds = synthetic(2, 3000);
    // The planted target depends on its window's last step.
    let opts = SelectOptions {
        target: "FQ".into(),
        mi_threshold: 0.0,
        label_at: LabelAt::Last,
        ..SelectOptions::default()
    };
    let sel = features::select(&ds, &Split::default(), &opts).unwrap();
    let mut kept = sel.channels.clone();
    kept.sort();
    let mut want = vec![PAPER_CHANNELS[3].to_string(), PAPER_CHANNELS[7].to_string()];
    want.sort();
    assert_eq!(kept, want, "{:?}", sel.table);
    // The strongest channel first, and the filter ranks it top.
    assert_eq!(sel.channels[0], PAPER_CHANNELS[3]);
    assert_eq!(sel.table[0].channel, PAPER_CHANNELS[3]);
    // Statistics of the kept channels travel with the selection.
    assert_eq!(sel.input_stats.names, sel.channels);
    // An unknown target is an error that names it.
    let bad = SelectOptions {
        target: "nonsense".into(),
        ..SelectOptions::default()
    };
    let e = features::select(&ds, &Split::default(), &bad)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown channel 'nonsense'"), "{e}");
}

/// The noise protocols and the shuffled split are decided in the library: the
/// names `train --noise` takes parse, others are refused, and the shuffled split keeps
/// 70 / 15 % for training and validation.
#[test]
fn noise_protocols_parse_and_the_shuffled_split_has_its_fractions() {
    use railforce::features::{NoiseProtocol, Split};
    assert_eq!(NoiseProtocol::parse("clean"), Some(NoiseProtocol::Clean));
    assert_eq!(
        NoiseProtocol::parse("matched"),
        Some(NoiseProtocol::Matched)
    );
    assert_eq!(
        NoiseProtocol::parse("train-clean-test-noisy"),
        Some(NoiseProtocol::TrainCleanTestNoisy)
    );
    assert_eq!(NoiseProtocol::parse("noisy"), None);
    match Split::shuffled(7) {
        Split::Shuffled { train, val, seed } => {
            assert_eq!((train, val, seed), (0.70, 0.15, 7));
        }
        other => panic!("{other:?}"),
    }
}
