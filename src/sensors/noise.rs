//! The one sensor-noise model (assets/docs/learning.md §1.4): additive white Gaussian noise per input
//! channel, `σ_c = ref_c · 10^(−SNR/20)`, where `ref_c` is the channel's standard deviation
//! over the run (its variation, the default) or its root mean square (offset included, an
//! option: a constant offset then raises the noise level). Seeded from the run's seed and the
//! channel's name, so a channel's noise does not depend on which other channels are noised.
//! Labels are never noised.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// What the SNR is measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SnrReference {
    /// The channel's standard deviation: its variation (a constant offset such as gravity in
    /// an accelerometer carries no information and does not set the noise level).
    #[default]
    Std,
    /// The channel's root mean square, offset included (a constant offset raises the noise).
    Rms,
}

impl SnrReference {
    /// Parses `std` or `rms`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "std" => Some(SnrReference::Std),
            "rms" => Some(SnrReference::Rms),
            _ => None,
        }
    }

    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SnrReference::Std => "std",
            SnrReference::Rms => "rms",
        }
    }
}

/// Noise at an SNR against a reference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NoiseModel {
    /// Signal-to-noise ratio, dB.
    pub snr_db: f64,
    /// What the SNR is measured against.
    #[serde(default)]
    pub reference: SnrReference,
}

impl NoiseModel {
    /// Noise at `snr_db` against `reference`.
    pub fn new(snr_db: f64, reference: SnrReference) -> Self {
        NoiseModel { snr_db, reference }
    }

    /// `σ` of the noise for a clean channel (its whole run).
    pub fn sigma(&self, clean: &[f64]) -> f64 {
        let n = clean.len().max(1) as f64;
        let scale = match self.reference {
            SnrReference::Rms => (clean.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
            SnrReference::Std => {
                let mean = clean.iter().sum::<f64>() / n;
                (clean.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt()
            }
        };
        scale * 10f64.powf(-self.snr_db / 20.0)
    }

    /// `σ` of the noise on `channel` of one run: [`NoiseModel::sigma`], but 0 for a known
    /// constant ([`super::VEHICLE_MASS`]: weighed, not sensed).
    pub fn sigma_of(&self, clean: &[f64], channel: &str) -> f64 {
        if super::clean_name(channel) == super::VEHICLE_MASS {
            0.0
        } else {
            self.sigma(clean)
        }
    }

    /// The noised copy of a clean channel of the run with seed `seed` (σ from
    /// [`NoiseModel::sigma_of`]).
    pub fn apply(&self, clean: &[f64], seed: u64, channel: &str) -> Vec<f64> {
        let sigma = self.sigma_of(clean, channel);
        if !(sigma > 0.0 && sigma.is_finite()) {
            return clean.to_vec();
        }
        let mut rng = rng(seed, channel_stream(channel));
        clean
            .iter()
            .map(|x| {
                let n: f64 = StandardNormal.sample(&mut rng);
                x + sigma * n
            })
            .collect()
    }

    /// One line for manifests, model files and reports.
    pub fn describe(&self) -> String {
        format!(
            "white Gaussian noise per input channel at {} dB, sigma = {}(clean channel over the run) * 10^(-SNR/20), seeded per run and channel; labels never noised",
            self.snr_db,
            self.reference.name()
        )
    }
}

/// Stream number of a channel: FNV-1a 64 of its (clean) name.
pub fn channel_stream(channel: &str) -> u64 {
    crate::io::fnv1a64(super::clean_name(channel).as_bytes())
}

/// The random stream `stream` of seed `seed`: every noise draw of railforce goes through it.
pub fn rng(seed: u64, stream: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ stream)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal() -> Vec<f64> {
        (0..20_000).map(|i| (i as f64 * 0.01).sin() * 2.0).collect()
    }

    #[test]
    fn std_noise_has_the_asked_variance_and_ignores_an_offset() {
        let x = signal();
        let m = NoiseModel::new(6.0, SnrReference::Std);
        let y = m.apply(&x, 3, "ws1_acc_z");
        let e: Vec<f64> = y.iter().zip(&x).map(|(a, b)| a - b).collect();
        let var = e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64;
        let want = (2.0f64 / 2f64.sqrt() * 10f64.powf(-0.3)).powi(2);
        assert!((var / want - 1.0).abs() < 0.05, "{var} vs {want}");
        // Gravity in a specific-force reading sets no noise level: same noise, bit for bit.
        let shifted: Vec<f64> = x.iter().map(|v| v + 9.81).collect();
        let y2 = m.apply(&shifted, 3, "ws1_acc_z");
        for ((a, b), c) in y2.iter().zip(&shifted).zip(&e) {
            assert!((a - b - c).abs() < 1e-9);
        }
        // The rms reference does depend on the offset.
        let r = NoiseModel::new(6.0, SnrReference::Rms);
        assert!(r.sigma(&shifted) > 3.0 * r.sigma(&x));
        // Seeded by run and channel; the noisy name noises like its clean channel.
        assert_eq!(m.apply(&x, 3, "ws1_acc_z_noisy"), y);
        assert_ne!(m.apply(&x, 4, "ws1_acc_z"), y);
        assert_ne!(m.apply(&x, 3, "ws1_acc_y"), y);
        // A constant channel stays clean rather than dividing by zero.
        assert_eq!(m.apply(&[1.0; 5], 1, "c"), vec![1.0; 5]);
    }
}
