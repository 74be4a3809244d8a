//! Test metrics (assets/docs/learning.md §1.5): MSE and R² on standardised targets, RMSE and MAE in
//! kN, and Var(y_test) beside them (MSE and R² only compare through it).

use crate::features::ZScore;
use serde::{Deserialize, Serialize};

/// Metrics of one target.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Label channel.
    pub target: String,
    /// Windows.
    pub n: usize,
    /// Mean squared error, standardised units.
    pub mse: f64,
    /// `1 − Σ(y − ŷ)² / Σ(y − ȳ_test)²`.
    pub r2: f64,
    /// Variance of the standardised test targets.
    pub var_y: f64,
    /// Root mean squared error, kN.
    pub rmse_kn: f64,
    /// Mean absolute error, kN.
    pub mae_kn: f64,
}

/// Metrics per output of `[n, outputs]` standardised truths and predictions; `stats`
/// de-standardises (labels are in N, reported in kN).
pub fn metrics(y: &[f32], pred: &[f32], stats: &ZScore) -> Vec<Metrics> {
    let outputs = stats.names.len();
    let n = y.len() / outputs;
    (0..outputs)
        .map(|k| {
            let col = |v: &[f32]| -> Vec<f64> {
                v.iter()
                    .skip(k)
                    .step_by(outputs)
                    .map(|&x| x as f64)
                    .collect()
            };
            let (t, p) = (col(y), col(pred));
            let mean = t.iter().sum::<f64>() / n.max(1) as f64;
            let sst: f64 = t.iter().map(|v| (v - mean).powi(2)).sum();
            let sse: f64 = t.iter().zip(&p).map(|(a, b)| (a - b).powi(2)).sum();
            let sae: f64 = t.iter().zip(&p).map(|(a, b)| (a - b).abs()).sum();
            let nn = n.max(1) as f64;
            let kn = stats.std[k] / 1000.0;
            Metrics {
                target: stats.names[k].clone(),
                n,
                mse: sse / nn,
                r2: if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN },
                var_y: sst / nn,
                rmse_kn: (sse / nn).sqrt() * kn,
                mae_kn: sae / nn * kn,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_match_a_hand_computed_example() {
        // y = [1, 2, 3, 4], ŷ = [1, 2, 2, 5]: SSE = 2, mean 2.5, SST = 5, SAE = 2.
        let stats = ZScore {
            names: vec!["w1l_force_y".into()],
            mean: vec![0.0],
            std: vec![2000.0],
        };
        let m = &metrics(&[1.0, 2.0, 3.0, 4.0], &[1.0, 2.0, 2.0, 5.0], &stats)[0];
        assert_eq!(m.n, 4);
        assert!((m.mse - 0.5).abs() < 1e-12);
        assert!((m.r2 - (1.0 - 2.0 / 5.0)).abs() < 1e-12);
        assert!((m.var_y - 1.25).abs() < 1e-12);
        assert!((m.rmse_kn - 0.5f64.sqrt() * 2.0).abs() < 1e-12);
        assert!((m.mae_kn - 0.5 * 2.0).abs() < 1e-12);
    }

    #[test]
    fn two_outputs_are_interleaved() {
        let stats = ZScore {
            names: vec!["a".into(), "b".into()],
            mean: vec![0.0, 0.0],
            std: vec![1000.0, 1000.0],
        };
        let m = metrics(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.0, 2.0, 0.0], &stats);
        assert_eq!(m[0].mse, 0.0);
        assert!((m[1].mse - 4.5).abs() < 1e-12);
    }
}
