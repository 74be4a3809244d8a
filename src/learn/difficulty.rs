//! A window's difficulty features: what the conformal calibration's interval widths read
//! (`learn::calibration`): the window's own level, the model's prediction and the run's
//! context up to the window; the tests plant whole runs whose difficulty only the context sees.

/// Rows of the context of a window's difficulty, ending at the window's last row: 2000 rows,
/// 10 s at the data sets' 200 Hz. A 0.1 s window sees too little of the track to say how hard
/// it is; over 10 s the inputs' level and mean tell a sharp curve from a tangent and a rough
/// realisation from a smooth one. It looks back only, so a stream gets the same intervals as
/// the whole record (measured on paper34 at 6 dB, assets/docs/learning.md §3.1: FQ coverage
/// of the 34 conditions' test runs 87.4–93.8 % with it, 86.1–94.4 % without, and
/// 86.4–94.9 % for intervals calibrated on each condition's own validation run).
pub const CONTEXT_ROWS: usize = 2000;

/// Running sums of a run's standardised inputs (`c` channels), from which the context of any
/// row comes in constant time: per channel the mean, its magnitude and `ln(0.1 + rms)` over
/// the [`CONTEXT_ROWS`] rows up to it (fewer at the run's start). Whole records and streams
/// sum in the same order, so both give the same numbers.
#[derive(Debug, Clone)]
pub struct Context {
    c: usize,
    span: usize,
    /// Absolute row of the first prefix sum kept.
    first: usize,
    /// Prefix sums of x and x² per channel (`2c` per row boundary), from row `first`.
    sums: Vec<f64>,
    /// Whether rows too old to be read again are dropped (a stream).
    bounded: bool,
}

impl Context {
    /// The running sums of a whole run's `inputs` (`rows × c`, row-major).
    pub fn new(inputs: &[f32], c: usize, span: usize) -> Self {
        let mut ctx = Self::stream(c, span);
        ctx.bounded = false;
        for row in inputs.chunks_exact(ctx.c) {
            ctx.push(row);
        }
        ctx
    }

    /// Empty running sums for a stream: feed rows with [`Context::push`].
    pub fn stream(c: usize, span: usize) -> Self {
        let c = c.max(1);
        Context {
            c,
            span: span.max(1),
            first: 0,
            sums: vec![0.0; 2 * c],
            bounded: true,
        }
    }

    /// Appends the next row (`c` standardised values).
    pub fn push(&mut self, row: &[f32]) {
        let c = self.c;
        let last = self.sums.len() - 2 * c;
        for k in 0..2 * c {
            let v = row[k % c] as f64;
            let next = self.sums[last + k] + if k < c { v } else { v * v };
            self.sums.push(next);
        }
        // A stream keeps what the newest row's context reads (dropped in halves).
        let kept = self.sums.len() / (2 * c);
        if self.bounded && kept > 2 * (self.span + 1) {
            let drop = kept - (self.span + 1);
            self.sums.drain(..drop * 2 * c);
            self.first += drop;
        }
    }

    /// Rows pushed so far.
    pub fn rows(&self) -> usize {
        self.first + self.sums.len() / (2 * self.c) - 1
    }

    /// The `3c` context features of row `last` (pushed, and for a stream among the newest
    /// [`CONTEXT_ROWS`]): every channel's mean over the rows up to it, then the means'
    /// magnitudes, then `ln(0.1 + rms)` of every channel.
    pub fn at(&self, last: usize) -> Vec<f64> {
        let c = self.c;
        let hi = (last + 1).min(self.rows());
        let lo = hi.saturating_sub(self.span).max(self.first).min(hi);
        let n = (hi - lo).max(1) as f64;
        let (h, l) = ((hi - self.first) * 2 * c, (lo - self.first) * 2 * c);
        let mut f = vec![0.0; 3 * c];
        for k in 0..c {
            f[k] = (self.sums[h + k] - self.sums[l + k]) / n;
            f[c + k] = f[k].abs();
            let ms = (self.sums[h + c + k] - self.sums[l + c + k]) / n;
            f[2 * c + k] = (0.1 + ms.max(0.0).sqrt()).ln();
        }
        f
    }
}

/// The context features ([`Context::at`]) of windows met one by one in any order, each run's
/// running sums built once. Windows that come run after run (a split by seeds, blocks or
/// conditions) stream through one run's sums at a time; windows in no run order (a shuffled
/// split) get theirs computed run by run beforehand, `3c` values a window, where building a
/// run's sums for each window anew cost minutes. Either way a window's features are the same
/// numbers.
#[derive(Debug, Clone)]
pub struct WindowContexts {
    c: usize,
    span: usize,
    /// The run whose sums are built, and the sums.
    current: Option<(usize, Context)>,
    /// Every window's features, `3c` a window, where the windows come in no run order.
    ahead: Vec<f64>,
}

impl WindowContexts {
    /// For `n` windows: window `i` belongs to run `place(i).0` and ends at its row
    /// `place(i).1`; `inputs(run)` is a run's standardised inputs `[rows × c]`.
    pub fn new<'a>(
        n: usize,
        place: impl Fn(usize) -> (usize, usize),
        inputs: impl Fn(usize) -> &'a [f32],
        c: usize,
        span: usize,
    ) -> Self {
        let mut me = WindowContexts {
            c: c.max(1),
            span,
            current: None,
            ahead: Vec::new(),
        };
        if (1..n).any(|i| place(i - 1).0 > place(i).0) {
            let w = 3 * me.c;
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by_key(|&i| place(i).0);
            let mut ahead = vec![0.0; n * w];
            for i in order {
                let (run, last) = place(i);
                ahead[i * w..(i + 1) * w].copy_from_slice(&me.streamed(run, last, &inputs));
            }
            (me.current, me.ahead) = (None, ahead);
        }
        me
    }

    fn streamed<'a>(
        &mut self,
        run: usize,
        last: usize,
        inputs: impl Fn(usize) -> &'a [f32],
    ) -> Vec<f64> {
        if self.current.as_ref().is_none_or(|(r, _)| *r != run) {
            self.current = Some((run, Context::new(inputs(run), self.c, self.span)));
        }
        self.current
            .as_ref()
            .map_or_else(Vec::new, |(_, x)| x.at(last))
    }

    /// The context features of window `i`, of run `run`, ending at its row `last`.
    pub fn at<'a>(
        &mut self,
        i: usize,
        (run, last): (usize, usize),
        inputs: impl Fn(usize) -> &'a [f32],
    ) -> Vec<f64> {
        if self.ahead.is_empty() {
            self.streamed(run, last, inputs)
        } else {
            let w = 3 * self.c;
            self.ahead[i * w..(i + 1) * w].to_vec()
        }
    }
}

/// The difficulty features of a standardised window `[steps × c]`, the model's standardised
/// `prediction` for it and its `context` ([`Context::at`] of its last row, or empty): 1, then
/// `ln(0.1 + rms)` of each channel over the window (the inputs' own level: faster, rougher or
/// sharper running raises it; 0.1 keeps a silent channel finite), then each predicted target
/// and its magnitude (a sharp curve's large lateral force), then the context. [`feature_count`]
/// of them.
pub fn features(window: &[f32], c: usize, prediction: &[f32], context: &[f64]) -> Vec<f64> {
    let steps = (window.len() / c.max(1)).max(1);
    let mut f = vec![0.0; c + 1];
    f[0] = 1.0;
    for (i, v) in window.iter().enumerate() {
        f[1 + i % c] += (*v as f64) * (*v as f64);
    }
    for v in &mut f[1..] {
        *v = (0.1 + (*v / steps as f64).sqrt()).ln();
    }
    f.extend(prediction.iter().map(|&p| p as f64));
    f.extend(prediction.iter().map(|&p| (p as f64).abs()));
    f.extend_from_slice(context);
    f
}

/// How many [`features`] a window of `c` channels has for a model of `outputs` targets, with
/// or without its [`Context`].
pub fn feature_count(c: usize, outputs: usize, context: bool) -> usize {
    1 + c + 2 * outputs + if context { 3 * c } else { 0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row's context reads the rows up to it (fewer at the start); a stream gives the same
    /// numbers while keeping only what its newest row reads.
    #[test]
    fn context_reads_the_rows_up_to_a_row_and_streams_the_same() {
        let x: Vec<f32> = (0..10).map(|i| i as f32).collect();
        let ctx = Context::new(&x, 1, 3);
        assert_eq!(
            ctx.at(5),
            vec![4.0, 4.0, (0.1f64 + (50.0f64 / 3.0).sqrt()).ln()]
        );
        assert_eq!(ctx.at(0)[0], 0.0);
        assert_eq!(ctx.at(1)[0], 0.5);
        let mut stream = Context::stream(1, 3);
        for (i, v) in x.iter().enumerate() {
            stream.push(&[*v]);
            assert_eq!(stream.at(i), ctx.at(i), "row {i}");
        }
        assert!(stream.sums.len() < ctx.sums.len());
    }

    // Calibration with a context: planted problems over whole runs.
    use super::super::calibration::{Calibration, Features};
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Windows in no run order (a shuffled split) read the same context features as the
    /// same windows run after run, to the bit.
    #[test]
    fn shuffled_windows_read_the_same_contexts_as_ordered_ones() {
        let c = 3;
        let runs: Vec<Vec<f32>> = (0..4)
            .map(|r| {
                (0..300 * c)
                    .map(|k| ((k * 7 + r * 13) % 17) as f32 * 0.1 - 0.8)
                    .collect()
            })
            .collect();
        let ordered: Vec<(usize, usize)> = (0..4)
            .flat_map(|r| (10..300).step_by(7).map(move |l| (r, l)))
            .collect();
        let mut shuffled = ordered.clone();
        // A fixed permutation that mixes the runs.
        shuffled.sort_by_key(|&(r, l)| (l * 31 + r * 97) % 101);
        assert!(shuffled.windows(2).any(|w| w[0].0 > w[1].0));
        let inputs = |r: usize| runs[r].as_slice();
        let mut a = WindowContexts::new(ordered.len(), |i| ordered[i], inputs, c, 50);
        let mut b = WindowContexts::new(shuffled.len(), |i| shuffled[i], inputs, c, 50);
        let of_a: std::collections::HashMap<(usize, usize), Vec<u64>> = (0..ordered.len())
            .map(|i| {
                let f = a.at(i, ordered[i], inputs);
                (ordered[i], f.iter().map(|v| v.to_bits()).collect())
            })
            .collect();
        for (i, &p) in shuffled.iter().enumerate() {
            let f: Vec<u64> = b.at(i, p, inputs).iter().map(|v| v.to_bits()).collect();
            assert_eq!(f.len(), 3 * c);
            assert_eq!(f, of_a[&p], "window {p:?}");
            let direct = Context::new(runs[p.0].as_slice(), c, 50).at(p.1);
            assert_eq!(f, direct.iter().map(|v| v.to_bits()).collect::<Vec<_>>());
        }
    }

    fn dot(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    /// Planted: five kinds of run whose error σ grows 1× to 3× with a slow offset of the one
    /// input (0 to 0.4 σ of its noise), which a 20-step window hardly sees and 2000 rows see
    /// clearly. With the context every kind is covered within ±2.5 % of nominal; without it
    /// the quietest and the roughest kinds miss by more. The context is the running mean and
    /// level of the rows up to the window's end, the same from a stream as from the record.
    #[test]
    fn context_tells_runs_apart_that_a_window_cannot() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let (c, steps, rows) = (1, 20, 3_000);
        let mut draw = |runs: usize| {
            let (mut y, mut p, mut plain, mut ctx, mut kind, mut run) = (
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
                Vec::new(),
            );
            for r in 0..runs {
                let k = r % 5;
                let x: Vec<f32> = (0..rows)
                    .map(|_| (0.1 * k as f64 + unit.sample(&mut rng)) as f32)
                    .collect();
                let context = Context::new(&x, c, CONTEXT_ROWS);
                for s in 0..rows - steps {
                    let w = &x[s..s + steps];
                    let row = s + steps - 1;
                    plain.extend(features(w, c, &[0.0], &[]));
                    ctx.extend(features(w, c, &[0.0], &context.at(row)));
                    y.push((0.2 * (1.0 + 0.5 * k as f64) * unit.sample(&mut rng)) as f32);
                    p.push(0.0f32);
                    kind.push((k, w.to_vec(), context.at(row)));
                    run.push(r as u32);
                }
            }
            (y, p, plain, ctx, kind, run)
        };
        let (yc, pc, xc_plain, xc_ctx, _, runs) = draw(10);
        let (yt, pt, _, _, kt, _) = draw(20);
        let fit = |x: &[f64], context: bool| {
            let mut cal = Calibration::fit(
                &yc,
                &pc,
                None,
                1,
                Some(Features {
                    values: x,
                    d: feature_count(c, 1, context),
                    runs: &runs,
                }),
                "planted".into(),
            )
            .unwrap();
            cal.context_rows = if context { CONTEXT_ROWS } else { 0 };
            cal
        };
        let (plain, with) = (fit(&xc_plain, false), fit(&xc_ctx, true));
        let covered = |cal: &Calibration, kind: usize| {
            let idx: Vec<usize> = (0..yt.len()).filter(|&i| kt[i].0 == kind).collect();
            idx.iter()
                .filter(|&&i| {
                    let f = features(&kt[i].1, c, &[0.0], &kt[i].2);
                    let d = if cal.context_rows > 0 {
                        cal.difficulty
                            .iter()
                            .map(|w| dot(&f, w).exp())
                            .next()
                            .unwrap()
                    } else {
                        cal.difficulty_of(&kt[i].1, c, &[0.0], None)[0]
                    };
                    ((yt[i] - pt[i]).abs() as f64) <= cal.half_width(0, 0.9, 0.0, d)
                })
                .count() as f64
                / idx.len() as f64
        };
        let spread = |cal: &Calibration| {
            (0..5)
                .map(|k| (covered(cal, k) - 0.9).abs())
                .fold(0.0, f64::max)
        };
        assert!(spread(&with) < 0.025, "with the context: {}", spread(&with));
        assert!(spread(&plain) > 0.04, "without: {}", spread(&plain));
    }
    /// Planted: every run has its own error scale (log-normal, unrelated to anything the
    /// model sees) and its own input offsets, which a difficulty reading the run's context
    /// could try to learn by heart. Calibrated on 40 runs, new runs are covered at the
    /// nominal rate within ±2.5 %. (This planted case does not separate the fold rules: at 20
    /// or 40 runs, alternate blocks covered new runs too; the over-confidence the cross-fit
    /// removes was measured on a fleet-trained model, assets/docs/learning.md §3.1.)
    #[test]
    fn a_difficulty_that_learns_runs_by_heart_stays_calibrated_on_new_runs() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let (c, steps, rows) = (5, 20, 1_000);
        let mut draw = |runs: usize| {
            let (mut y, mut f, mut run, mut at) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for r in 0..runs {
                let scale = (0.5f64 * unit.sample(&mut rng)).exp();
                let offset: Vec<f64> = (0..c).map(|_| unit.sample(&mut rng)).collect::<Vec<f64>>();
                let x: Vec<f32> = (0..rows * c)
                    .map(|i| (offset[i % c] + unit.sample(&mut rng)) as f32)
                    .collect();
                let context = Context::new(&x, c, CONTEXT_ROWS);
                for s in 0..rows - steps {
                    let w = &x[s * c..(s + steps) * c];
                    let last = s + steps - 1;
                    f.extend(features(w, c, &[0.0], &context.at(last)));
                    y.push((0.2 * scale * unit.sample(&mut rng)) as f32);
                    run.push(r as u32);
                    at.push((w.to_vec(), context.at(last)));
                }
            }
            (y, f, run, at)
        };
        let (yc, fc, runs, _) = draw(40);
        let (yt, _, _, at) = draw(40);
        let mut cal = Calibration::fit(
            &yc,
            &vec![0.0; yc.len()],
            None,
            1,
            Some(Features {
                values: &fc,
                d: feature_count(c, 1, true),
                runs: &runs,
            }),
            "planted".into(),
        )
        .unwrap();
        cal.context_rows = CONTEXT_ROWS;
        let inside = (0..yt.len())
            .filter(|&i| {
                let f = features(&at[i].0, c, &[0.0], &at[i].1);
                let d = dot(&f, &cal.difficulty[0]).clamp(-5.0, 5.0).exp();
                (yt[i].abs() as f64) <= cal.half_width(0, 0.9, 0.0, d)
            })
            .count() as f64
            / yt.len() as f64;
        assert!((inside - 0.9).abs() < 0.025, "new runs covered {inside}");
    }
}
