//! Whether a coarser integration step gives the same physics: the same run at several steps
//! against a finer reference, read as every wheel's Y/Q rms and Q standard deviation, the label
//! wheel's FL standard deviation, the labels' power above 40 Hz, and the label wheel's FQ by
//! frequency band (0–20, 20–50 and 50–100 Hz: the quasi-static and geometry band, sleeper
//! passing, P2), so an excitation reaching short waves is read where it acts.

use super::fidelity::{column, power_above, run_with, yq_and_q};
use super::output::Recording;
use super::{Integrator, SimConfig};
use crate::dsp::welch_psd;
use crate::error::Result;
use crate::track::Track;
use crate::vehicle::Vehicle;

/// The frequency bands FQ is read in, Hz.
pub const BANDS: [(f64, f64); 3] = [(0.0, 20.0), (20.0, 50.0), (50.0, 100.0)];

/// RMS of `x` (sampled at `rate`, Hz) in each of [`BANDS`], by Welch's periodogram (the mean
/// removed), in the signal's unit.
pub fn band_rms(x: &[f64], rate: f64) -> [f64; 3] {
    let p = welch_psd(x, 1.0 / rate, 512);
    let df = p.freq.get(1).copied().unwrap_or(0.0);
    BANDS.map(|(lo, hi)| {
        let power: f64 = p
            .freq
            .iter()
            .zip(&p.density)
            .filter(|(f, _)| **f > lo && **f <= hi)
            .map(|(_, d)| d * df)
            .sum();
        power.sqrt()
    })
}

/// How one integration step compares with a finer one on the same run (whether a coarser step
/// gives the same physics): the largest relative difference over the wheels of each statistic.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepDifference {
    /// Largest |rms(Y/Q) / rms(Y/Q)_ref − 1| over the wheels.
    pub yq_rms: f64,
    /// Largest |sd(Q) / sd(Q)_ref − 1| over the wheels.
    pub q_sd: f64,
    /// |sd(FL) / sd(FL)_ref − 1| of the label wheel's lateral force.
    pub label_y_sd: f64,
    /// Share of FL's and FQ's variance above 40 Hz at this step (the reference's beside it in
    /// [`StepStudy::reference_high`]).
    pub high: [f64; 2],
    /// |rms / rms_ref − 1| of the label wheel's FQ in each of [`BANDS`].
    pub fq_bands: [f64; 3],
}

/// One step of a [`step_study`].
#[derive(Debug, Clone)]
pub struct StepTrial {
    /// Integration step, s.
    pub dt: f64,
    /// Wall time of the run (settling included), s.
    pub wall_s: f64,
    /// Its differences from the reference, or why the run stopped (diverged, derailed).
    pub outcome: std::result::Result<StepDifference, String>,
}

/// The same run at several steps against a finer reference step.
#[derive(Debug, Clone)]
pub struct StepStudy {
    /// Reference step, s.
    pub reference_dt: f64,
    /// The reference's integrator.
    pub reference_integrator: Integrator,
    /// Its wall time, s.
    pub reference_wall_s: f64,
    /// Share of FL's and FQ's variance above 40 Hz at the reference step.
    pub reference_high: [f64; 2],
    /// The label wheel's FQ rms in each of [`BANDS`] at the reference step, N.
    pub reference_fq_bands: [f64; 3],
    /// The steps tried, in the order given.
    pub trials: Vec<StepTrial>,
}

/// Runs `vehicle` on `track` at `speed` for `duration` s at the `reference` step (with its
/// integrator) and at each of `steps` with `integrator`, and compares every wheel's Y/Q rms
/// and Q standard deviation, the label wheel's lateral-force standard deviation and the labels'
/// power above 40 Hz.
pub fn step_study(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    duration: f64,
    reference: (f64, Integrator),
    steps: &[f64],
    integrator: Integrator,
) -> Result<StepStudy> {
    let run = |dt, integrator| {
        let cfg = SimConfig {
            speed,
            duration,
            dt,
            integrator,
            ..SimConfig::default()
        };
        run_with(vehicle, track, cfg)
    };
    let n = vehicle.contact.wheelsets.len() * 2;
    let label = vehicle.label_wheel_name().to_lowercase();
    let (fl, fq) = (format!("w{label}_force_y"), format!("w{label}_force_z"));
    let sd = |x: &[f64]| {
        let m = x.iter().sum::<f64>() / x.len().max(1) as f64;
        (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / x.len().max(1) as f64).sqrt()
    };
    let rate = SimConfig::default().output_rate;
    let high = |rec: &Recording| -> Result<[f64; 2]> {
        Ok([
            power_above(&column(rec, &fl)?, rate, 40.0),
            power_above(&column(rec, &fq)?, rate, 40.0),
        ])
    };
    let t = std::time::Instant::now();
    let base = run(reference.0, reference.1)?;
    let reference_wall_s = t.elapsed().as_secs_f64();
    let (base_stats, base_fl) = (yq_and_q(&base, n)?, sd(&column(&base, &fl)?));
    let base_bands = band_rms(&column(&base, &fq)?, rate);
    let worst = |a: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| {
        a.iter()
            .zip(&base_stats)
            .map(|(x, y)| (f(x) / f(y) - 1.0).abs())
            .fold(0.0f64, f64::max)
    };
    let mut trials = Vec::new();
    for &dt in steps {
        let t = std::time::Instant::now();
        let outcome = match run(dt, integrator) {
            Ok(rec) => {
                let stats = yq_and_q(&rec, n)?;
                Ok(StepDifference {
                    yq_rms: worst(&stats, |p| p.0),
                    q_sd: worst(&stats, |p| p.1),
                    label_y_sd: (sd(&column(&rec, &fl)?) / base_fl - 1.0).abs(),
                    high: high(&rec)?,
                    fq_bands: {
                        let b = band_rms(&column(&rec, &fq)?, rate);
                        [0, 1, 2].map(|i| (b[i] / base_bands[i] - 1.0).abs())
                    },
                })
            }
            Err(e) => Err(e.to_string()),
        };
        trials.push(StepTrial {
            dt,
            wall_s: t.elapsed().as_secs_f64(),
            outcome,
        });
    }
    Ok(StepStudy {
        reference_dt: reference.0,
        reference_integrator: reference.1,
        reference_wall_s,
        reference_high: high(&base)?,
        reference_fq_bands: base_bands,
        trials,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn band_rms_finds_each_sine_in_its_band() {
        let rate = 200.0;
        let x: Vec<f64> = (0..8000)
            .map(|i| {
                let t = i as f64 / rate;
                let w = |f: f64| (2.0 * std::f64::consts::PI * f * t).sin();
                3.0 * w(7.0) + 2.0 * w(33.0) + 1.0 * w(71.0)
            })
            .collect();
        let b = band_rms(&x, rate);
        for (got, amp) in b.iter().zip([3.0, 2.0, 1.0]) {
            let want = amp / 2f64.sqrt();
            assert!((got / want - 1.0).abs() < 0.02, "{b:?}");
        }
    }
}
