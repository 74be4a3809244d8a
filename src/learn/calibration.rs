//! A model's split conformal calibration: the conformity scores of its validation windows,
//! kept as quantiles, and the interval they give at any coverage (how a model is calibrated:
//! `learn::uncertainty`; assets/docs/learning.md §3.1).

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
}

impl Calibration {
    /// Calibrates on standardised labels `y[n × outputs]`, predictions `mean` and (an
    /// ensemble's) spread.
    pub fn fit(
        y: &[f32],
        mean: &[f32],
        spread: Option<&[f32]>,
        outputs: usize,
        part: String,
    ) -> Result<Self> {
        let n = y.len() / outputs.max(1);
        if n == 0 || mean.len() != y.len() || spread.is_some_and(|s| s.len() != y.len()) {
            return Err(Error::Domain(format!(
                "calibration needs windows with one prediction each ({part})"
            )));
        }
        let mut beta = vec![0.0; outputs];
        let mut quantiles = Vec::with_capacity(outputs);
        for k in 0..outputs {
            if let Some(s) = spread {
                let mut sk: Vec<f64> = (0..n).map(|i| s[i * outputs + k] as f64).collect();
                sk.sort_by(f64::total_cmp);
                beta[k] = sk[n / 2].max(1e-6);
            }
            let mut scores: Vec<f64> = (0..n)
                .map(|i| {
                    let r = (y[i * outputs + k] - mean[i * outputs + k]).abs() as f64;
                    match spread {
                        Some(s) => r / (s[i * outputs + k] as f64 + beta[k]),
                        None => r,
                    }
                })
                .collect();
            if scores.iter().any(|v| !v.is_finite()) {
                return Err(Error::Domain(format!(
                    "calibration on {part}: a prediction is not finite"
                )));
            }
            scores.sort_by(f64::total_cmp);
            quantiles.push(
                (0..=LEVELS)
                    .map(|i| {
                        let c = i as f64 / LEVELS as f64;
                        let rank = ((n + 1) as f64 * c).ceil() as usize;
                        scores[rank.clamp(1, n) - 1]
                    })
                    .collect(),
            );
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
    /// `spread`, standardised units (the stored level at or above `coverage`).
    pub fn half_width(&self, k: usize, coverage: f64, spread: f64) -> f64 {
        let i = ((coverage.clamp(0.0, 1.0) * LEVELS as f64) - 1e-9).ceil() as usize;
        let q = self.quantiles[k][i.min(LEVELS)];
        if self.score == Score::Normalised {
            q * (spread + self.beta[k])
        } else {
            q
        }
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
                "planted".into(),
            )
            .unwrap();
            for coverage in [0.8, 0.9, 0.95] {
                let inside = (0..yt.len())
                    .filter(|&i| {
                        let h = cal.half_width(0, coverage, st[i] as f64);
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
                assert!(cal.half_width(0, 0.9, 0.25) < 0.6 * cal.half_width(0, 0.9, 1.0));
            }
        }
    }

    /// Mismatched lengths and non-finite predictions are refused, not calibrated on.
    #[test]
    fn calibration_refuses_bad_input() {
        assert!(Calibration::fit(&[1.0, 2.0], &[1.0], None, 1, "x".into()).is_err());
        assert!(Calibration::fit(&[1.0], &[f32::NAN], None, 1, "x".into()).is_err());
        assert!(Calibration::fit(&[], &[], None, 1, "x".into()).is_err());
    }
}
