//! Checks of synthesised irregularities against their PSD: sample RMS against the band RMS of
//! the formula, and Welch's PSD estimate against the formula across the band; the rails'
//! roughness by third-octave band against the spectrum it was drawn from.

use super::irregularity::{Channel, Irregularities};
use crate::dsp::welch_psd;
use crate::error::Result;
use std::path::Path;

/// Sample RMS of one channel next to the RMS the PSD formula gives over the band.
#[derive(Debug, Clone, Copy)]
pub struct RmsCheck {
    /// Channel.
    pub channel: Channel,
    /// RMS of the samples over the track, m.
    pub sample_rms: f64,
    /// `sqrt(∫ S dΩ)` over the band, m.
    pub formula_rms: f64,
}

impl RmsCheck {
    /// Relative deviation `sample / formula − 1`.
    pub fn deviation(&self) -> f64 {
        self.sample_rms / self.formula_rms - 1.0
    }
}

/// RMS check of every channel over the samples that lie on `[0, length]`.
pub fn rms_checks(irr: &Irregularities, length: f64) -> Vec<RmsCheck> {
    let spec = irr.spec();
    Channel::ALL
        .iter()
        .map(|&ch| {
            let x = on_track(irr, ch, length);
            let mean = x.iter().sum::<f64>() / x.len() as f64;
            let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
            RmsCheck {
                channel: ch,
                sample_rms: var.sqrt(),
                formula_rms: spec.band_rms(ch),
            }
        })
        .collect()
}

fn on_track(irr: &Irregularities, ch: Channel, length: f64) -> &[f64] {
    let x = irr.channel_samples(ch);
    let first = crate::bounds::to_count((-irr.grid_origin() / irr.grid_step()).round());
    let last = crate::bounds::to_count(((length - irr.grid_origin()) / irr.grid_step()).floor());
    &x[first..=last.min(x.len() - 1)]
}

/// Welch PSD of each channel beside the formula, in m²/(rad/m), on a common Ω grid.
#[derive(Debug, Clone)]
pub struct PsdComparison {
    /// Spatial angular frequency Ω, rad/m.
    pub omega: Vec<f64>,
    /// Per channel (order of [`Channel::ALL`]): Welch estimate.
    pub welch: [Vec<f64>; 4],
    /// Per channel: the formula.
    pub formula: [Vec<f64>; 4],
    /// Welch segments averaged.
    pub segments: usize,
}

/// Welch PSD (segments of about four times the longest wavelength) of the samples on the
/// track, beside the formula. Frequencies are converted from cycles/m to rad/m (`S_Ω = S_f/2π`).
pub fn psd_comparison(irr: &Irregularities, length: f64) -> PsdComparison {
    let spec = irr.spec();
    let seg_len = 4.0 * spec.max_wavelength;
    let nperseg = ((seg_len / irr.grid_step()) as usize).next_power_of_two();
    let two_pi = 2.0 * std::f64::consts::PI;
    let mut omega = Vec::new();
    let mut segments = 0;
    let welch = Channel::ALL.map(|ch| {
        let p = welch_psd(on_track(irr, ch, length), irr.grid_step(), nperseg);
        segments = p.segments;
        omega = p.freq.iter().map(|f| f * two_pi).collect();
        p.density.iter().map(|d| d / two_pi).collect::<Vec<f64>>()
    });
    let formula = Channel::ALL.map(|ch| {
        omega
            .iter()
            .map(|&w| if w > 0.0 { spec.psd(ch, w) } else { 0.0 })
            .collect()
    });
    PsdComparison {
        omega,
        welch,
        formula,
        segments,
    }
}

impl PsdComparison {
    /// Writes the comparison as CSV (atomically), only the bins inside `[Ω_min/2, 2·Ω_max]`.
    pub fn write_csv(&self, path: &Path, omega_min: f64, omega_max: f64) -> Result<()> {
        crate::io::write_atomic(path, |w| {
            write!(w, "omega_rad_per_m,wavelength_m")?;
            for ch in Channel::ALL {
                write!(
                    w,
                    ",{0}_welch_m2_per_rad_per_m,{0}_formula_m2_per_rad_per_m",
                    ch.name()
                )?;
            }
            writeln!(w)?;
            for (i, &om) in self.omega.iter().enumerate() {
                if om < 0.5 * omega_min || om > 2.0 * omega_max {
                    continue;
                }
                write!(w, "{om:.6},{:.4}", 2.0 * std::f64::consts::PI / om)?;
                for c in 0..4 {
                    write!(w, ",{:.6e},{:.6e}", self.welch[c][i], self.formula[c][i])?;
                }
                writeln!(w)?;
            }
            Ok(())
        })
    }

    /// Ratio of Welch to formula power (sum over bins) in each octave `[Ω, 2Ω)` that lies
    /// inside `[omega_min, omega_max]`, per channel: 1 where the estimate follows the formula.
    /// Power ratios over octaves average the estimate's scatter without the bias a mean of
    /// log-ratios has.
    pub fn octave_ratios(&self, omega_min: f64, omega_max: f64) -> Vec<OctaveRatio> {
        let mut out = Vec::new();
        let mut lo = omega_min;
        while 2.0 * lo <= omega_max * (1.0 + 1e-9) {
            let hi = 2.0 * lo;
            let ratio = std::array::from_fn(|c| {
                let (mut a, mut b) = (0.0, 0.0);
                for (i, &om) in self.omega.iter().enumerate() {
                    if om >= lo && om < hi {
                        a += self.welch[c][i];
                        b += self.formula[c][i];
                    }
                }
                a / b
            });
            out.push(OctaveRatio { lo, hi, ratio });
            lo = hi;
        }
        out
    }
}

/// Welch-to-formula power ratio in one octave of Ω.
#[derive(Debug, Clone, Copy)]
pub struct OctaveRatio {
    /// Lower edge, rad/m.
    pub lo: f64,
    /// Upper edge, rad/m.
    pub hi: f64,
    /// Ratio per channel (order of [`Channel::ALL`]).
    pub ratio: [f64; 4],
}

/// One third-octave band of a rail's drawn roughness beside the level it was drawn from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandLevel {
    /// The band's centre wavelength, m.
    pub wavelength: f64,
    /// The left (0) or right (1) rail.
    pub side: usize,
    /// The drawn samples' level by periodogram over the track, dB re 1 µm.
    pub drawn_db: f64,
    /// The spectrum's level through the contact filter (when on), dB re 1 µm.
    pub expected_db: f64,
}

/// The roughness of both rails by third-octave band, every band whose centre lies inside the
/// drawn wavelengths by at least a third of an octave, against the spectrum it was drawn from.
/// Empty without roughness.
pub fn roughness_bands(w: &super::short_wave::ShortWaves, length: f64) -> Vec<BandLevel> {
    use rustfft::FftPlanner;
    use rustfft::num_complex::Complex64;
    let Some(r) = w.spec().roughness else {
        return Vec::new();
    };
    let dx = w.grid_step();
    // Base-ten third octaves from 1 m down (n = 0, −1, … in k_c = 10^(n/10) cycles/m).
    let centres: Vec<f64> = (0..40)
        .map(|n| 10f64.powf(-(n as f64) / 10.0))
        .filter(|l| {
            *l <= r.max_wavelength * 10f64.powf(-0.1) && *l >= r.min_wavelength * 10f64.powf(0.1)
        })
        .collect();
    let mut out = Vec::new();
    for side in 0..2 {
        let x = w.roughness_samples(side);
        // The grid starts two steps before the track.
        let first = 2;
        let n = (crate::bounds::to_count((length / dx).floor())).min(x.len() - first);
        if n < 16 {
            continue;
        }
        let mut buf: Vec<Complex64> = x[first..first + n]
            .iter()
            .map(|&v| Complex64::new(v, 0.0))
            .collect();
        FftPlanner::new().plan_fft_forward(n).process(&mut buf);
        let dk = 1.0 / (n as f64 * dx);
        for &lambda in &centres {
            let kc = 1.0 / lambda;
            let (lo, hi) = (kc * 10f64.powf(-0.05), kc * 10f64.powf(0.05));
            let bins: Vec<usize> = (1..n / 2)
                .filter(|&i| (lo..hi).contains(&(i as f64 * dk)))
                .collect();
            // A band narrower than the track's frequency step holds no bin: nothing to read.
            if bins.is_empty() {
                continue;
            }
            let power: f64 = bins
                .iter()
                .map(|&i| 2.0 * buf[i].norm_sqr() / (n * n) as f64)
                .sum();
            let filter = if r.contact_filter {
                super::short_wave::contact_filter_db(lambda)
            } else {
                0.0
            };
            out.push(BandLevel {
                wavelength: lambda,
                side,
                drawn_db: 10.0 * (power / 1e-12).log10(),
                expected_db: r.spectrum.level_db(lambda) + filter,
            });
        }
    }
    out
}
