//! A model's split conformal calibration: the conformity scores of its validation windows,
//! kept as quantiles, and the interval they give at any coverage (how a model is calibrated:
//! `learn::uncertainty`; assets/docs/learning.md §3.1).

pub use super::difficulty::{CONTEXT_ROWS, Context, WindowContexts, feature_count, features};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Quantile levels stored per target: `i / LEVELS` for `i = 0..=LEVELS`.
const LEVELS: usize = 1000;

/// How far beyond the training envelope (as a fraction of its width, on either side) an input
/// may go before its window is flagged out of distribution.
pub const OOD_MARGIN: f64 = 0.25;

/// The conformity score of a window.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Score {
    /// `|y − ŷ|`: one model.
    Absolute,
    /// `|y − ŷ| / (σ + β)`: an ensemble, σ its members' spread.
    Normalised,
}

impl Score {
    /// `absolute` or `normalised`, as `model.json` writes it.
    pub fn name(self) -> &'static str {
        match self {
            Score::Absolute => "absolute",
            Score::Normalised => "normalised",
        }
    }
}

/// A model's conformal calibration (in `model.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The conformity score.
    pub score: Score,
    /// Per target, β of the normalised score (standardised units; 0 for `absolute`).
    pub beta: Vec<f64>,
    /// Per target, the conformal quantile of the score at each level `i/1000`.
    pub quantiles: Vec<Vec<f64>>,
    /// Windows calibrated on.
    pub windows: usize,
    /// What they were.
    pub part: String,
    /// Per input channel, the 0.1 % and 99.9 % quantiles of its standardised values over the
    /// training part: what the model has seen (`identify` flags inputs beyond it).
    #[serde(default)]
    pub envelope: Vec<[f64; 2]>,
    /// Per target, the weights `w` of the window's difficulty `exp(w·f(x))` that also divides
    /// the score (locally weighted split conformal, Lei et al. 2018 §5.2): `f(x)` is 1,
    /// `ln(0.1 + rms)` of each standardised input over the window, the prediction and, where
    /// [`Calibration::context_rows`] is set, the inputs' level over the run up to the window
    /// ([`features`], [`Context`]); the weights a ridge fit of `ln |score|` on the validation
    /// runs (cross-fitted over two folds of runs for the calibration itself,
    /// [`Calibration::fit`]), centred so the median window's difficulty is 1. Empty: none (the score is the same everywhere but for an
    /// ensemble's spread).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub difficulty: Vec<Vec<f64>>,
    /// Per target, the difficulty at the edges between [`BINS`] equally filled bins of the
    /// calibrating windows (Mondrian conformal, Vovk 2003: each bin its own quantiles, so
    /// the coverage holds at every level even where the difficulty model is only roughly
    /// right). Empty with `difficulty`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub edges: Vec<Vec<f64>>,
    /// Per target and bin, the quantiles at each level `i/1000` of the score within the bin.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub binned: Vec<Vec<Vec<f64>>>,
    /// Rows of the [`Context`] the difficulty reads, up to the window's last row; 0: none
    /// (models calibrated before the context was added).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub context_rows: usize,
}

fn is_zero(v: &usize) -> bool {
    *v == 0
}

/// Difficulty bins of the Mondrian calibration.
const BINS: usize = 5;

/// Validation windows below which the difficulty is not fitted (one width everywhere): ten
/// blocks, so each bin holds at least 200 calibrating windows.
pub const MIN_WEIGHTED: usize = 10 * BLOCK;

/// The conformal quantile of sorted `scores` at every level `i / LEVELS`: the
/// `⌈(n+1)·c⌉`-th smallest.
fn levels(scores: &[f64]) -> Vec<f64> {
    let n = scores.len();
    (0..=LEVELS)
        .map(|i| {
            let c = i as f64 / LEVELS as f64;
            let rank = crate::bounds::to_count(((n + 1) as f64 * c).ceil());
            scores[rank.clamp(1, n) - 1]
        })
        .collect()
}

/// Windows per block of the folds within a single run (1 s at 200 Hz for stride-1 windows).
const BLOCK: usize = 200;

/// `a · b`.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The normal equations `XᵀX`, `Xᵀt` and row count of each of two folds, rows `f[i·d..]`
/// with targets `t`, row `i` in fold `fold(i)`: one pass for the fits on either fold and both.
fn normal_equations(
    f: &[f64],
    d: usize,
    t: &[f64],
    fold: &dyn Fn(usize) -> usize,
) -> [(nalgebra::DMatrix<f64>, nalgebra::DVector<f64>, usize); 2] {
    let mut eq = [0, 1].map(|_| {
        (
            nalgebra::DMatrix::<f64>::zeros(d, d),
            nalgebra::DVector::<f64>::zeros(d),
            0,
        )
    });
    for (i, ti) in t.iter().enumerate() {
        let r = &f[i * d..(i + 1) * d];
        let (a, b, n) = &mut eq[fold(i)];
        *n += 1;
        for j in 0..d {
            b[j] += r[j] * ti;
            // Upper triangle only; mirrored in `solve`.
            for l in j..d {
                a[(j, l)] += r[j] * r[l];
            }
        }
    }
    eq
}

/// Ridge least squares `(XᵀX + λ·n·I)⁻¹ Xᵀ t` (the bias unpenalised, λ = 1e-3) from the
/// upper triangle of `XᵀX`.
fn solve(a: &nalgebra::DMatrix<f64>, b: &nalgebra::DVector<f64>, n: usize) -> Option<Vec<f64>> {
    let d = b.len();
    let mut a = a.clone();
    for j in 0..d {
        for l in 0..j {
            a[(j, l)] = a[(l, j)];
        }
    }
    for j in 1..d {
        a[(j, j)] += 1e-3 * n as f64;
    }
    let w = a.cholesky()?.solve(b);
    w.iter()
        .all(|v| v.is_finite())
        .then(|| w.iter().copied().collect())
}

/// The difficulty features of the calibrating windows, for [`Calibration::fit`].
#[derive(Debug, Clone, Copy)]
pub struct Features<'a> {
    /// Row-major `n × d` ([`features`] of each window).
    pub values: &'a [f64],
    /// Features per window.
    pub d: usize,
    /// The run each window belongs to: the difficulty is cross-fitted over two folds of runs.
    pub runs: &'a [u32],
}

impl Calibration {
    /// Calibrates on standardised labels `y[n × outputs]`, predictions `mean`, (an
    /// ensemble's) spread and, where given, each window's difficulty [`Features`]. The
    /// difficulty is cross-fitted over two folds of runs (alternate runs by first appearance;
    /// alternate [`BLOCK`]s of windows where there is one run): each window's score is divided
    /// by the difficulty fitted on the other fold, and every window calibrates. A difficulty
    /// that read a run's own level (its context) and learned the validation runs' errors by
    /// heart would otherwise calibrate on the same runs and pass its over-confidence on to new
    /// wagons (measured: a fleet-trained model's FQ interval covering 75.6 % of held-out
    /// wagons' forces with half-blocks of the same runs, 90.5 % cross-fitted by runs). The
    /// stored difficulty is fitted on all runs.
    pub fn fit(
        y: &[f32],
        mean: &[f32],
        spread: Option<&[f32]>,
        outputs: usize,
        features: Option<Features<'_>>,
        part: String,
    ) -> Result<Self> {
        let n = y.len() / outputs.max(1);
        if n == 0
            || mean.len() != y.len()
            || spread.is_some_and(|s| s.len() != y.len())
            || features.is_some_and(|f| f.values.len() != n * f.d || f.runs.len() != n)
        {
            return Err(Error::Domain(format!(
                "calibration needs windows with one prediction each ({part})"
            )));
        }
        // Too few windows to fit a difficulty and fill its bins: one width everywhere.
        let features = features.filter(|_| n >= MIN_WEIGHTED);
        // Each window's fold: alternate runs, or alternate blocks within a single run.
        let folds: Vec<usize> = match features {
            Some(f) => {
                let mut order: Vec<u32> = Vec::new();
                let ranks: Vec<usize> = f
                    .runs
                    .iter()
                    .map(|r| match order.iter().position(|o| o == r) {
                        Some(p) => p,
                        None => {
                            order.push(*r);
                            order.len() - 1
                        }
                    })
                    .collect();
                if order.len() >= 2 {
                    ranks.iter().map(|r| r % 2).collect()
                } else {
                    (0..n).map(|i| (i / BLOCK) % 2).collect()
                }
            }
            None => Vec::new(),
        };
        let mut beta = vec![0.0; outputs];
        let mut quantiles = Vec::with_capacity(outputs);
        let mut difficulty = Vec::new();
        let (mut edges, mut binned) = (Vec::new(), Vec::new());
        for k in 0..outputs {
            if let Some(s) = spread {
                let mut sk: Vec<f64> = (0..n).map(|i| s[i * outputs + k] as f64).collect();
                sk.sort_by(f64::total_cmp);
                beta[k] = sk[n / 2].max(1e-6);
            }
            let base: Vec<f64> = (0..n)
                .map(|i| {
                    let r = (y[i * outputs + k] - mean[i * outputs + k]).abs() as f64;
                    match spread {
                        Some(s) => r / (s[i * outputs + k] as f64 + beta[k]),
                        None => r,
                    }
                })
                .collect();
            if base.iter().any(|v| !v.is_finite()) {
                return Err(Error::Domain(format!(
                    "calibration on {part}: a prediction is not finite"
                )));
            }
            let mut level = vec![1.0; n];
            if let Some(Features { values: f, d, .. }) = features {
                let mut typical = base.clone();
                typical.sort_by(f64::total_cmp);
                let eps = 0.05 * typical[n / 2].max(1e-9);
                let t: Vec<f64> = base.iter().map(|b| (b + eps).ln()).collect();
                let row = |i: usize| &f[i * d..(i + 1) * d];
                let [(a0, b0, n0), (a1, b1, n1)] = normal_equations(f, d, &t, &|i| folds[i]);
                let failed =
                    || Error::Domain(format!("calibration on {part}: the difficulty fit failed"));
                // Centred so the median window it was fitted on has difficulty 1.
                let centred = |mut w: Vec<f64>, on: &dyn Fn(usize) -> bool| {
                    let mut fitted: Vec<f64> =
                        (0..n).filter(|&i| on(i)).map(|i| dot(row(i), &w)).collect();
                    fitted.sort_by(f64::total_cmp);
                    if let Some(m) = fitted.get(fitted.len() / 2) {
                        w[0] -= m;
                    }
                    w
                };
                let all = solve(&(&a0 + &a1), &(&b0 + &b1), n0 + n1).ok_or_else(failed)?;
                // The fit on one fold scores the windows of the other.
                let on = [
                    solve(&a1, &b1, n1).filter(|_| n1 > 0),
                    solve(&a0, &b0, n0).filter(|_| n0 > 0),
                ];
                let on = [0, 1].map(|g| on[g].clone().map(|w| centred(w, &|i| folds[i] != g)));
                for (i, l) in level.iter_mut().enumerate() {
                    let w = on[folds[i]].as_ref().ok_or_else(failed)?;
                    *l = dot(row(i), w).clamp(-5.0, 5.0).exp();
                }
                difficulty.push(centred(all, &|_| true));
            }
            let mut scores: Vec<f64> = (0..n).map(|i| base[i] / level[i]).collect();
            scores.sort_by(f64::total_cmp);
            quantiles.push(levels(&scores));
            if features.is_some() {
                let mut by_level: Vec<(f64, f64)> =
                    (0..n).map(|i| (level[i], base[i] / level[i])).collect();
                by_level.sort_by(|a, b| a.0.total_cmp(&b.0));
                let m = by_level.len();
                let cut = |b: usize| b * m / BINS;
                edges.push((1..BINS).map(|b| by_level[cut(b)].0).collect());
                binned.push(
                    (0..BINS)
                        .map(|b| {
                            let mut sb: Vec<f64> =
                                by_level[cut(b)..cut(b + 1)].iter().map(|p| p.1).collect();
                            sb.sort_by(f64::total_cmp);
                            levels(&sb)
                        })
                        .collect(),
                );
            }
        }
        Ok(Calibration {
            score: if spread.is_some() {
                Score::Normalised
            } else {
                Score::Absolute
            },
            beta,
            quantiles,
            windows: n,
            part,
            envelope: Vec::new(),
            difficulty,
            edges,
            binned,
            context_rows: 0,
        })
    }

    /// The input channels (indices in model order) of a standardised window `[steps × c]` that
    /// leave the training envelope by more than [`OOD_MARGIN`] of its width anywhere in it
    /// (none where the calibration has no envelope).
    pub fn outside(&self, window: &[f32], c: usize) -> Vec<usize> {
        (0..c.min(self.envelope.len()))
            .filter(|&k| {
                let [lo, hi] = self.envelope[k];
                let m = OOD_MARGIN * (hi - lo);
                window
                    .iter()
                    .skip(k)
                    .step_by(c)
                    .any(|&v| (v as f64) < lo - m || (v as f64) > hi + m)
            })
            .collect()
    }

    /// Half-width of target `k`'s interval at `coverage` (0–1) where the ensemble's spread is
    /// `spread` and the window's difficulty [`Calibration::difficulty_of`] is `difficulty`,
    /// standardised units (the stored level at or above `coverage`).
    pub fn half_width(&self, k: usize, coverage: f64, spread: f64, difficulty: f64) -> f64 {
        let i = crate::bounds::to_count(((coverage.clamp(0.0, 1.0) * LEVELS as f64) - 1e-9).ceil());
        let q = match (self.binned.get(k), self.edges.get(k)) {
            (Some(bins), Some(edges)) => {
                let b = edges.iter().take_while(|&&e| difficulty >= e).count();
                bins[b.min(bins.len() - 1)][i.min(LEVELS)]
            }
            _ => self.quantiles[k][i.min(LEVELS)],
        } * difficulty;
        if self.score == Score::Normalised {
            q * (spread + self.beta[k])
        } else {
            q
        }
    }

    /// Half-width of target `k`'s interval at `coverage` for a typical window: the median
    /// difficulty, and an ensemble's members agreeing as usual (spread β); standardised units.
    pub fn typical_half_width(&self, k: usize, coverage: f64) -> f64 {
        self.half_width(k, coverage, self.beta.get(k).copied().unwrap_or(0.0), 1.0)
    }

    /// The context the difficulty of a run's windows reads, from the run's standardised
    /// inputs `[rows × c]` (`None` where the calibration reads none).
    pub fn context(&self, inputs: &[f32], c: usize) -> Option<Context> {
        self.reads_context()
            .then(|| Context::new(inputs, c, self.context_rows))
    }

    /// An empty context for a stream of `c` channels (`None` where the calibration reads
    /// none).
    pub fn context_stream(&self, c: usize) -> Option<Context> {
        self.reads_context()
            .then(|| Context::stream(c, self.context_rows))
    }

    /// Per target, the difficulty of a standardised window `[steps × c]` with the model's
    /// standardised `prediction`, reading the run's `context` at the window's last row where
    /// the calibration has one (1 where the calibration has no difficulty; the median
    /// calibration window's is 1).
    pub fn difficulty_of(
        &self,
        window: &[f32],
        c: usize,
        prediction: &[f32],
        context: Option<(&Context, usize)>,
    ) -> Vec<f64> {
        let ctx = match context {
            Some((ctx, row)) if self.context_rows > 0 && !self.difficulty.is_empty() => {
                Some(ctx.at(row))
            }
            _ => None,
        };
        self.difficulty_with(window, c, prediction, ctx.as_deref())
    }

    /// Whether the difficulty reads the run's context ([`Calibration::context`]).
    pub fn reads_context(&self) -> bool {
        self.context_rows > 0 && !self.difficulty.is_empty()
    }

    /// [`Calibration::difficulty_of`] with the window's context features already read
    /// ([`Context::at`] or [`WindowContexts::at`]; `None` without a context).
    pub fn difficulty_with(
        &self,
        window: &[f32],
        c: usize,
        prediction: &[f32],
        context: Option<&[f64]>,
    ) -> Vec<f64> {
        if self.difficulty.is_empty() {
            return vec![1.0; self.quantiles.len()];
        }
        let f = features(window, c, prediction, context.unwrap_or(&[]));
        self.difficulty
            .iter()
            .map(|w| {
                if w.len() != f.len() {
                    // A context-reading calibration asked without one: the typical window.
                    return 1.0;
                }
                dot(&f, w).clamp(-5.0, 5.0).exp()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// On a planted Gaussian problem (y = f + ε, ε ~ N(0, σ(x)²) with σ varying 4×) the split
    /// conformal interval covers new points at the nominal rate within ±2 %, with the absolute
    /// score and with the normalised one fed the true σ as its "spread"; the normalised
    /// intervals are narrower where σ is small.
    #[test]
    fn conformal_coverage_on_a_planted_gaussian_problem() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let mut draw = |n: usize| {
            let (mut y, mut p, mut s) = (Vec::new(), Vec::new(), Vec::new());
            for i in 0..n {
                let sigma = 0.25 + 0.75 * ((i % 100) as f64 / 99.0);
                let f = (i as f64 * 0.01).sin();
                y.push((f + sigma * unit.sample(&mut rng)) as f32);
                p.push(f as f32);
                s.push(sigma as f32);
            }
            (y, p, s)
        };
        let (yc, pc, sc) = draw(5_000);
        let (yt, pt, st) = draw(20_000);
        for normalised in [false, true] {
            let cal = Calibration::fit(
                &yc,
                &pc,
                normalised.then_some(sc.as_slice()),
                1,
                None,
                "planted".into(),
            )
            .unwrap();
            for coverage in [0.8, 0.9, 0.95] {
                let inside = (0..yt.len())
                    .filter(|&i| {
                        let h = cal.half_width(0, coverage, st[i] as f64, 1.0);
                        ((yt[i] - pt[i]).abs() as f64) <= h
                    })
                    .count() as f64
                    / yt.len() as f64;
                assert!(
                    (inside - coverage).abs() < 0.02,
                    "{} at {coverage}: {inside}",
                    cal.score.name()
                );
            }
            if normalised {
                assert!(cal.half_width(0, 0.9, 0.25, 1.0) < 0.6 * cal.half_width(0, 0.9, 1.0, 1.0));
            }
        }
    }

    /// Mismatched lengths and non-finite predictions are refused, not calibrated on.
    #[test]
    fn calibration_refuses_bad_input() {
        assert!(Calibration::fit(&[1.0, 2.0], &[1.0], None, 1, None, "x".into()).is_err());
        assert!(Calibration::fit(&[1.0], &[f32::NAN], None, 1, None, "x".into()).is_err());
        assert!(Calibration::fit(&[], &[], None, 1, None, "x".into()).is_err());
        // Features of the wrong length.
        let bad = Features {
            values: &[1.0],
            d: 2,
            runs: &[0],
        };
        assert!(Calibration::fit(&[1.0], &[1.0], None, 1, Some(bad), "x".into()).is_err());
        // Too few windows to fit a difficulty: one width everywhere.
        let few = Calibration::fit(
            &[1.0, 2.0],
            &[1.5, 1.5],
            None,
            1,
            Some(Features {
                values: &[1.0, 1.0],
                d: 1,
                runs: &[0, 0],
            }),
            "x".into(),
        )
        .unwrap();
        assert!(few.difficulty.is_empty() && few.binned.is_empty());
    }

    /// Planted: the error's σ grows with the inputs' level (five groups, 1× to 5×). One width
    /// everywhere covers the pooled windows at the nominal rate but not each group; with the
    /// window's difficulty every group is covered within ±2.5 % of nominal and the quiet
    /// group's interval is narrower.
    #[test]
    fn difficulty_weighted_intervals_cover_every_level() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let (c, steps) = (3, 20);
        let mut draw = |n: usize| {
            let (mut y, mut p, mut x, mut g) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
            for i in 0..n {
                // Groups change every 700 windows: both alternate 200-window blocks see all.
                let group = (i / 700) % 5;
                let level = 1.0 + group as f64;
                let window: Vec<f32> = (0..c * steps)
                    .map(|_| (level * unit.sample(&mut rng)) as f32)
                    .collect();
                x.extend(features(&window, c, &[0.0], &[]));
                y.push((0.2 * level * unit.sample(&mut rng)) as f32);
                p.push(0.0f32);
                g.push((group, window));
            }
            (y, p, x, g)
        };
        let (yc, pc, xc, _) = draw(21_000);
        let (yt, pt, _, gt) = draw(35_000);
        let uniform = Calibration::fit(&yc, &pc, None, 1, None, "planted".into()).unwrap();
        let weighted = Calibration::fit(
            &yc,
            &pc,
            None,
            1,
            Some(Features {
                values: &xc,
                d: feature_count(c, 1, false),
                runs: &vec![0; yc.len()],
            }),
            "planted".into(),
        )
        .unwrap();
        assert_eq!(weighted.difficulty.len(), 1);
        let covered = |cal: &Calibration, group: usize| {
            let idx: Vec<usize> = (0..yt.len()).filter(|&i| gt[i].0 == group).collect();
            idx.iter()
                .filter(|&&i| {
                    let d = cal.difficulty_of(&gt[i].1, c, &[0.0], None)[0];
                    ((yt[i] - pt[i]).abs() as f64) <= cal.half_width(0, 0.9, 0.0, d)
                })
                .count() as f64
                / idx.len() as f64
        };
        for group in 0..5 {
            let w = covered(&weighted, group);
            assert!((w - 0.9).abs() < 0.025, "group {group}: {w}");
        }
        assert!(covered(&uniform, 0) > 0.99 && covered(&uniform, 4) < 0.8);
        let quiet = weighted.half_width(
            0,
            0.9,
            0.0,
            weighted.difficulty_of(&gt[0].1, c, &[0.0], None)[0],
        );
        assert!(quiet < 0.6 * uniform.half_width(0, 0.9, 0.0, 1.0));
    }
}
