//! What a study measures of each run: the labels' statistics, kN.

use crate::dsp::percentile;
use crate::dsp::welch_psd;

/// The outputs: a CSV name and a title. The last two (a trained model's R² on the run) are
/// there only when a study names a model ([`MEASURED`] without one).
pub const OUTPUTS: [(&str, &str); 14] = [
    ("fl_mean", "FL mean"),
    ("fl_std", "FL std"),
    ("fl_p9985", "abs FL 99.85 %"),
    ("fl_std_0_5hz", "FL std 0–5 Hz"),
    ("fl_std_5_20hz", "FL std 5–20 Hz"),
    ("fl_std_20_100hz", "FL std 20–100 Hz"),
    ("fq_mean", "FQ mean"),
    ("fq_std", "FQ std"),
    ("fq_p9985", "FQ 99.85 %"),
    ("fq_std_0_5hz", "FQ std 0–5 Hz"),
    ("fq_std_5_20hz", "FQ std 5–20 Hz"),
    ("fq_std_20_100hz", "FQ std 20–100 Hz"),
    ("fl_r2", "FL R² of the model"),
    ("fq_r2", "FQ R² of the model"),
];

/// The outputs measured without a model: the labels' statistics.
pub const MEASURED: usize = 12;

/// Index of an output by its CSV name.
pub fn output(name: &str) -> Option<usize> {
    OUTPUTS.iter().position(|o| o.0 == name)
}

/// Whether output `o` is a statistic of FL (else of FQ).
pub fn is_fl(o: usize) -> bool {
    o < 6 || o == 12
}

/// The coefficient of determination of `estimate` against `truth`: 1 − Σ(y − ŷ)² / Σ(y − ȳ)².
pub fn r2(truth: &[f64], estimate: &[f64]) -> f64 {
    let n = truth.len().max(1) as f64;
    let mean = truth.iter().sum::<f64>() / n;
    let ss_tot: f64 = truth.iter().map(|y| (y - mean).powi(2)).sum();
    let ss_res: f64 = truth
        .iter()
        .zip(estimate)
        .map(|(y, e)| (y - e).powi(2))
        .sum();
    if ss_tot > 0.0 {
        1.0 - ss_res / ss_tot
    } else {
        0.0
    }
}

/// The frequency bands of the band outputs, Hz.
pub const BANDS: [(f64, f64); 3] = [(0.0, 5.0), (5.0, 20.0), (20.0, 100.0)];

/// The outputs of one run from its labels FL and FQ (N) sampled at `fs` Hz, in kN: mean, std,
/// the 99.85 % percentile (of |FL|, of FQ: the assessment's percentile), and the std in each
/// band of [`BANDS`] (from a Welch PSD with 2.56 s segments, integrated over the band).
pub fn label_statistics(fl: &[f64], fq: &[f64], fs: f64) -> [f64; MEASURED] {
    let one = |x: &[f64], abs: bool| -> [f64; 6] {
        let kn: Vec<f64> = x.iter().map(|v| v / 1e3).collect();
        let n = kn.len().max(1) as f64;
        let mean = kn.iter().sum::<f64>() / n;
        let std = (kn.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        let tail: Vec<f64> = if abs {
            kn.iter().map(|v| v.abs()).collect()
        } else {
            kn.clone()
        };
        let p = percentile(&tail, 99.85);
        let psd = welch_psd(&kn, 1.0 / fs, 512);
        let df = psd.freq.get(1).copied().unwrap_or(1.0);
        let band = |(lo, hi): (f64, f64)| {
            psd.freq
                .iter()
                .zip(&psd.density)
                .filter(|(f, _)| **f >= lo && **f < hi)
                .map(|(_, d)| d * df)
                .sum::<f64>()
                .sqrt()
        };
        [mean, std, p, band(BANDS[0]), band(BANDS[1]), band(BANDS[2])]
    };
    let (a, b) = (one(fl, true), one(fq, false));
    let mut out = [0.0; MEASURED];
    out[..6].copy_from_slice(&a);
    out[6..].copy_from_slice(&b);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 Hz sine of 10 kN amplitude on a 100 kN mean: mean 100, std 10/√2, all of it in the
    /// first band; a 30 Hz one lands in the last.
    #[test]
    fn a_sine_lands_in_its_band() {
        let fs = 200.0;
        let t: Vec<f64> = (0..6000).map(|i| i as f64 / fs).collect();
        let fq: Vec<f64> = t
            .iter()
            .map(|t| 100e3 + 10e3 * (2.0 * std::f64::consts::PI * 2.0 * t).sin())
            .collect();
        let fl: Vec<f64> = t
            .iter()
            .map(|t| 5e3 * (2.0 * std::f64::consts::PI * 30.0 * t).sin())
            .collect();
        let s = label_statistics(&fl, &fq, fs);
        let rms = 10.0 / 2f64.sqrt();
        assert!(
            (s[6] - 100.0).abs() < 1e-6 && (s[7] - rms).abs() < 1e-3,
            "{s:?}"
        );
        assert!(
            (s[9] - rms).abs() < 0.05 * rms && s[10] < 0.05 * rms,
            "{s:?}"
        );
        assert!(
            (s[5] - 5.0 / 2f64.sqrt()).abs() < 0.2 && s[3] < 0.2,
            "{s:?}"
        );
        assert!((s[2] - 5.0).abs() < 0.01, "{s:?}");
    }
}
