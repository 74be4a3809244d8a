//! Track irregularities from the US FRA track-class PSDs or the German low- and
//! high-interference spectra (assets/docs/physics.md §3.2).
//!
//! One-sided PSDs in cm²/(rad/m), Ω in rad/m, k = 0.25:
//! vertical profile and alignment `k·A·Ω_c²/(Ω²(Ω² + Ω_c²))`, cross-level and gauge
//! `4·k·A_v·Ω_c²/((Ω² + Ω_c²)(Ω² + Ω_s²))`. Samples are a sum of cosines with uniform random
//! phases, `z(x) = Σ √(2·S(Ω_k)·ΔΩ)·cos(Ω_k·x + φ_k)`, evaluated with one inverse FFT on a grid
//! whose period is at least twice the track length (so nothing repeats along the track), then
//! read with cubic interpolation.

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Uniform};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex64;

pub(super) use crate::dsp::catmull_rom;

/// FRA PSD constant k (all classes).
const FRA_K: f64 = 0.25;
/// 1 cm² = 1e-4 m².
const CM2: f64 = 1e-4;

/// A US FRA track class (1 = worst, 6 = best) with its PSD parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FraClass {
    /// Class number 1–6.
    pub number: u8,
    /// Vertical roughness A_v, cm²·rad/m.
    pub a_v: f64,
    /// Alignment roughness A_a, cm²·rad/m.
    pub a_a: f64,
    /// Break frequency Ω_s, rad/m.
    pub omega_s: f64,
    /// Break frequency Ω_c, rad/m.
    pub omega_c: f64,
}

/// (A_v, A_a, Ω_s, Ω_c) for classes 1–6 (FRA, as tabulated in assets/docs/physics.md §3.2).
const FRA_TABLE: [(f64, f64, f64, f64); 6] = [
    (1.2107, 3.3634, 0.6046, 0.8245),
    (1.0181, 1.2107, 0.9308, 0.8245),
    (0.6816, 0.4128, 0.8520, 0.8245),
    (0.5376, 0.3027, 1.1312, 0.8245),
    (0.2095, 0.0762, 0.8209, 0.8245),
    (0.0339, 0.0339, 0.4380, 0.8245),
];

impl FraClass {
    /// Gauge limits of the class relative to the 1 435 mm (4 ft 8½ in) nominal, m: (narrowest,
    /// widest). US 49 CFR 213.53: never below 4 ft 8 in for any class (−12.7 mm); at most
    /// 4 ft 9¾ in (class 1), 4 ft 9½ in (2–3), 4 ft 9¼ in (4–5), 4 ft 9 in (6).
    pub fn gauge_limits(&self) -> (f64, f64) {
        let inch = 25.4e-3;
        let widest = match self.number {
            1 => 1.25,
            2 | 3 => 1.0,
            4 | 5 => 0.75,
            _ => 0.5,
        };
        (-0.5 * inch, widest * inch)
    }

    /// The class with this number, or `None` outside 1–6.
    pub fn new(number: i64) -> Option<Self> {
        let idx = usize::try_from(number).ok()?.checked_sub(1)?;
        let (a_v, a_a, omega_s, omega_c) = *FRA_TABLE.get(idx)?;
        Some(FraClass {
            number: number as u8,
            a_v,
            a_a,
            omega_s,
            omega_c,
        })
    }

    /// One-sided PSD of a channel at Ω (rad/m), in m²/(rad/m).
    pub fn psd(&self, channel: Channel, omega: f64) -> f64 {
        let (w2, c2, s2) = (
            omega * omega,
            self.omega_c * self.omega_c,
            self.omega_s * self.omega_s,
        );
        let cm2 = match channel {
            Channel::Vertical => FRA_K * self.a_v * c2 / (w2 * (w2 + c2)),
            Channel::Alignment => FRA_K * self.a_a * c2 / (w2 * (w2 + c2)),
            Channel::CrossLevel | Channel::Gauge => {
                4.0 * FRA_K * self.a_v * c2 / ((w2 + c2) * (w2 + s2))
            }
        };
        cm2 * CM2
    }

    /// RMS (m) that the PSD gives over the wavelength band `[λ_min, λ_max]` (see
    /// [`band_rms`]).
    pub fn band_rms(&self, channel: Channel, min_wavelength: f64, max_wavelength: f64) -> f64 {
        band_rms(|w| self.psd(channel, w), min_wavelength, max_wavelength)
    }
}

/// RMS that a one-sided PSD `psd(Ω)` (m²/(rad/m)) gives over the wavelength band
/// `[λ_min, λ_max]`: `σ² = ∫ S dΩ` from `2π/λ_max` to `2π/λ_min` (Simpson's rule in ln Ω).
pub fn band_rms(psd: impl Fn(f64) -> f64, min_wavelength: f64, max_wavelength: f64) -> f64 {
    let (lo, hi) = (
        (2.0 * std::f64::consts::PI / max_wavelength).ln(),
        (2.0 * std::f64::consts::PI / min_wavelength).ln(),
    );
    let n = 4000; // even
    let h = (hi - lo) / n as f64;
    let f = |u: f64| {
        let w = u.exp();
        psd(w) * w // dΩ = Ω du
    };
    let mut sum = f(lo) + f(hi);
    for i in 1..n {
        sum += f(lo + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
    }
    (sum * h / 3.0).sqrt()
}

/// The German track spectra for low and high interference (DB; as published in the
/// vehicle–track literature, e.g. Zhai, *Vehicle–Track Coupled Dynamics*, 2020, §2), one-sided
/// in m²/(rad/m), Ω in rad/m, `b` = 0.75 m (half the rail spacing):
/// vertical and alignment `A·Ω_c²/((Ω² + Ω_r²)(Ω² + Ω_c²))`; cross level as an angle
/// `(A_v/b²)·Ω_c²·Ω²/((Ω² + Ω_r²)(Ω² + Ω_c²)(Ω² + Ω_s²))` (rad²/(rad/m); times `(2b)²` as a
/// height difference); gauge `A_g·Ω_c²·Ω²/((Ω² + Ω_r²)(Ω² + Ω_c²)(Ω² + Ω_s²))`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GermanSpectrum {
    /// `true`: the high-interference spectrum (conventional lines); `false`: low (high-speed).
    pub high: bool,
}

/// Ω_c, Ω_r, Ω_s of the German spectra, rad/m.
const GERMAN_OMEGA: (f64, f64, f64) = (0.8246, 0.0206, 0.4380);
/// Half the rail spacing the cross-level form is written for, m.
const GERMAN_B: f64 = 0.75;

impl GermanSpectrum {
    /// (A_v, A_a, A_g), m·rad. A_v, A_a as published (low 4.032e-7, 2.119e-7; high 1.080e-6,
    /// 6.125e-7); A_g (low 5.32e-8, high 1.032e-7) from the same table, checked against one
    /// source only (an estimate until a second confirms it).
    fn roughness(&self) -> (f64, f64, f64) {
        if self.high {
            (1.080e-6, 6.125e-7, 1.032e-7)
        } else {
            (4.032e-7, 2.119e-7, 5.32e-8)
        }
    }

    /// One-sided PSD of a channel at Ω (rad/m), m²/(rad/m); cross level as the height
    /// difference between the rails over the 1.5 m rail spacing.
    pub fn psd(&self, channel: Channel, omega: f64) -> f64 {
        let (a_v, a_a, a_g) = self.roughness();
        let (wc, wr, ws) = GERMAN_OMEGA;
        let w2 = omega * omega;
        let base = wc * wc / ((w2 + wr * wr) * (w2 + wc * wc));
        let twist = base * w2 / (w2 + ws * ws);
        match channel {
            Channel::Vertical => a_v * base,
            Channel::Alignment => a_a * base,
            Channel::CrossLevel => (a_v / (GERMAN_B * GERMAN_B)) * twist * (2.0 * GERMAN_B).powi(2),
            Channel::Gauge => a_g * twist,
        }
    }
}

/// The spectrum irregularities are drawn from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spectrum {
    /// A US FRA class (the spec's `class`).
    Fra,
    /// A German spectrum.
    German(GermanSpectrum),
}

impl Spectrum {
    /// Names as the track file writes them: `fra`, `german_low`, `german_high`.
    pub const NAMES: [&'static str; 3] = ["fra", "german_low", "german_high"];

    /// The spectrum of a name in [`Spectrum::NAMES`].
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "fra" => Some(Spectrum::Fra),
            "german_low" => Some(Spectrum::German(GermanSpectrum { high: false })),
            "german_high" => Some(Spectrum::German(GermanSpectrum { high: true })),
            _ => None,
        }
    }

    /// Its name.
    pub fn name(&self) -> &'static str {
        match self {
            Spectrum::Fra => "fra",
            Spectrum::German(g) if g.high => "german_high",
            Spectrum::German(_) => "german_low",
        }
    }
}

/// The four irregularity channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Channel {
    /// Vertical profile (mean of the two rails' heights).
    Vertical,
    /// Alignment (mean lateral position of the two rails).
    Alignment,
    /// Cross-level, as a height difference left − right.
    CrossLevel,
    /// Gauge deviation (wider positive).
    Gauge,
}

impl Channel {
    /// All channels in synthesis order (the order random phases are drawn in).
    pub const ALL: [Channel; 4] = [
        Channel::Vertical,
        Channel::Alignment,
        Channel::CrossLevel,
        Channel::Gauge,
    ];

    /// Name used in files and tables.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Vertical => "vertical",
            Channel::Alignment => "alignment",
            Channel::CrossLevel => "cross_level",
            Channel::Gauge => "gauge",
        }
    }
}

/// Irregularity settings of a track file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IrregularitySpec {
    /// FRA class (its PSDs unless `spectrum` is German; always its gauge limits unless the file
    /// sets them).
    pub class: FraClass,
    /// The spectrum drawn from.
    pub spectrum: Spectrum,
    /// Shortest wavelength synthesised, m.
    pub min_wavelength: f64,
    /// Longest wavelength synthesised, m.
    pub max_wavelength: f64,
    /// Random seed of the phases.
    pub seed: u64,
    /// Smooth lead at the start of the track where the rails have no irregularity, m.
    pub smooth_start: f64,
    /// Length over which the irregularities then fade in from zero (raised cosine), m:
    /// vehicles start on smooth rails and settle onto the irregularities.
    pub fade_in: f64,
    /// Narrowest and widest gauge deviation allowed, m (default: the class's
    /// [`FraClass::gauge_limits`]). The synthesised gauge is held inside by [`soft_limit`].
    pub gauge_limits: (f64, f64),
}

impl IrregularitySpec {
    /// One-sided PSD of a channel at Ω (rad/m), m²/(rad/m), of the spectrum drawn from.
    pub fn psd(&self, channel: Channel, omega: f64) -> f64 {
        match self.spectrum {
            Spectrum::Fra => self.class.psd(channel, omega),
            Spectrum::German(g) => g.psd(channel, omega),
        }
    }

    /// RMS (m) of a channel over the spec's wavelength band, from [`IrregularitySpec::psd`].
    pub fn band_rms(&self, channel: Channel) -> f64 {
        band_rms(
            |w| self.psd(channel, w),
            self.min_wavelength,
            self.max_wavelength,
        )
    }
}

/// Holds `x` inside `(lo, hi)` (lo < 0 < hi) with a smooth knee: unchanged within 75 % of each
/// limit, beyond it `k + (L − k)·tanh((x − k)/(L − k))` (k the knee, L the limit), which
/// meets the identity with the same slope at the knee and never goes beyond L. Track that narrow or
/// wide is not in service (it would be repaired), so the PSD's rare extremes are bent back,
/// not cut: the rest of the signal and its derivative stay continuous.
pub fn soft_limit(x: f64, lo: f64, hi: f64) -> f64 {
    let bend = |x: f64, l: f64| {
        let k = 0.75 * l;
        if x.abs() <= k.abs() {
            x
        } else {
            k + (l - k) * ((x - k) / (l - k)).tanh()
        }
    };
    if x >= 0.0 { bend(x, hi) } else { bend(x, lo) }
}

/// Offsets of both rails at one position, m, with their derivatives along the track (1/1).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RailIrregularity {
    /// Lateral offset of the left rail (+ to the left).
    pub left_y: f64,
    /// Vertical offset of the left rail (+ up).
    pub left_z: f64,
    /// Lateral offset of the right rail.
    pub right_y: f64,
    /// Vertical offset of the right rail.
    pub right_z: f64,
    /// d(left_y)/ds.
    pub left_y_ds: f64,
    /// d(left_z)/ds.
    pub left_z_ds: f64,
    /// d(right_y)/ds.
    pub right_y_ds: f64,
    /// d(right_z)/ds.
    pub right_z_ds: f64,
}

/// Synthesised irregularity samples along a track.
#[derive(Debug, Clone)]
pub struct Irregularities {
    spec: IrregularitySpec,
    dx: f64,
    /// Position of the first sample, m (two steps before 0 so interpolation needs no clamping).
    origin: f64,
    /// Samples per channel (order of [`Channel::ALL`]) at `s = origin + i·dx`.
    samples: [Vec<f64>; 4],
    /// The synthesised gauge before the limit: least, greatest and RMS, m.
    gauge_raw: [f64; 3],
}

impl Irregularities {
    /// Synthesises the four channels over `[0, length]`.
    pub fn synthesize(spec: IrregularitySpec, length: f64) -> Self {
        use std::f64::consts::PI;
        // 16 points per shortest wavelength keeps cubic interpolation error below 0.1 %.
        let dx = spec.min_wavelength / 16.0;
        let n_pts = crate::bounds::to_count((length / dx).ceil()) + 6;
        let band = (
            2.0 * PI / spec.max_wavelength,
            2.0 * PI / spec.min_wavelength,
        );
        let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
        let mut gauge_raw = [0.0; 3];
        let samples = Channel::ALL.map(|ch| {
            let raw = sum_of_cosines(n_pts, dx, band, |w| spec.psd(ch, w), &mut rng);
            let (lo, hi) = spec.gauge_limits;
            if ch == Channel::Gauge {
                let n = raw.len() as f64;
                gauge_raw = [
                    raw.iter().copied().fold(f64::INFINITY, f64::min),
                    raw.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    (raw.iter().map(|v| v * v).sum::<f64>() / n).sqrt(),
                ];
            }
            raw.into_iter()
                .map(|v| match ch {
                    Channel::Gauge => soft_limit(v, lo, hi),
                    _ => v,
                })
                .collect()
        });
        Irregularities {
            spec,
            dx,
            origin: -2.0 * dx,
            samples,
            gauge_raw,
        }
    }

    /// The synthesised gauge deviation before [`soft_limit`] held it inside
    /// [`IrregularitySpec::gauge_limits`]: least, greatest and RMS over the grid, m.
    pub fn gauge_before_limit(&self) -> [f64; 3] {
        self.gauge_raw
    }

    /// The settings they were made with.
    pub fn spec(&self) -> &IrregularitySpec {
        &self.spec
    }

    /// Grid spacing of the stored samples, m.
    pub fn grid_step(&self) -> f64 {
        self.dx
    }

    /// Position of the first raw sample, m (negative: the grid starts before the track).
    pub fn grid_origin(&self) -> f64 {
        self.origin
    }

    /// Raw samples of a channel on the grid `s = grid_origin() + i·grid_step()`, m.
    pub fn channel_samples(&self, ch: Channel) -> &[f64] {
        &self.samples[ch as usize]
    }

    /// One channel and its derivative at `s` (Catmull–Rom cubic interpolation).
    pub fn channel_at(&self, ch: Channel, s: f64) -> (f64, f64) {
        let (i, t) = self.locate(s);
        self.cubic(ch, i, t)
    }

    /// The grid interval of `s` and the fraction into it (every channel has the same grid).
    #[inline]
    fn locate(&self, s: f64) -> (usize, f64) {
        locate(self.origin, self.dx, self.samples[0].len(), s)
    }

    /// One channel's Catmull–Rom value and derivative in interval `i` at fraction `t`.
    #[inline]
    fn cubic(&self, ch: Channel, i: usize, t: f64) -> (f64, f64) {
        catmull_rom(&self.samples[ch as usize], i, t, self.dx)
    }

    /// Fade-in factor at `s` and its derivative ([`fade`]).
    fn fade(&self, s: f64) -> (f64, f64) {
        fade(s, self.spec.smooth_start, self.spec.fade_in)
    }

    /// Offsets of both rails at `s`: `z_L = z_v + z_c/2`, `z_R = z_v − z_c/2`,
    /// `y_L = y_a + y_g/2`, `y_R = y_a − y_g/2`, faded in over the first
    /// [`IrregularitySpec::fade_in`] metres after a smooth lead.
    pub fn rails_at(&self, s: f64) -> RailIrregularity {
        let (f, df) = self.fade(s);
        let r = self.raw_rails_at(s);
        RailIrregularity {
            left_y: f * r.left_y,
            left_z: f * r.left_z,
            right_y: f * r.right_y,
            right_z: f * r.right_z,
            left_y_ds: f * r.left_y_ds + df * r.left_y,
            left_z_ds: f * r.left_z_ds + df * r.left_z,
            right_y_ds: f * r.right_y_ds + df * r.right_y,
            right_z_ds: f * r.right_z_ds + df * r.right_z,
        }
    }

    /// Rail offsets without the fade-in.
    pub fn raw_rails_at(&self, s: f64) -> RailIrregularity {
        let (i, t) = self.locate(s);
        let (zv, zv_d) = self.cubic(Channel::Vertical, i, t);
        let (ya, ya_d) = self.cubic(Channel::Alignment, i, t);
        let (zc, zc_d) = self.cubic(Channel::CrossLevel, i, t);
        let (yg, yg_d) = self.cubic(Channel::Gauge, i, t);
        RailIrregularity {
            left_y: ya + 0.5 * yg,
            left_z: zv + 0.5 * zc,
            right_y: ya - 0.5 * yg,
            right_z: zv - 0.5 * zc,
            left_y_ds: ya_d + 0.5 * yg_d,
            left_z_ds: zv_d + 0.5 * zc_d,
            right_y_ds: ya_d - 0.5 * yg_d,
            right_z_ds: zv_d - 0.5 * zc_d,
        }
    }
}

/// `z(x) = Σ √(2·S(Ω_k)·ΔΩ)·cos(Ω_k·x + φ_k)` over the band `(Ω_lo, Ω_hi)` (rad/m) on `n_pts`
/// points `dx` apart, by one inverse FFT on a grid at least twice as long (so nothing repeats
/// along the track); `psd` is one-sided in m²/(rad/m), the phases are drawn from `rng` in
/// order of rising Ω.
pub(super) fn sum_of_cosines(
    n_pts: usize,
    dx: f64,
    band: (f64, f64),
    psd: impl Fn(f64) -> f64,
    rng: &mut ChaCha8Rng,
) -> Vec<f64> {
    use std::f64::consts::PI;
    let n_fft = (2 * n_pts).next_power_of_two();
    let d_omega = 2.0 * PI / (n_fft as f64 * dx);
    let k_lo = crate::bounds::to_count((band.0 / d_omega).ceil().max(1.0));
    let k_hi = crate::bounds::to_count((band.1 / d_omega).floor()).min(n_fft / 2 - 1);
    let phase = Uniform::new(0.0, 2.0 * PI).expect("valid range");
    let mut buf = vec![Complex64::new(0.0, 0.0); n_fft];
    for (k, b) in buf.iter_mut().enumerate().take(k_hi + 1).skip(k_lo) {
        let amp = (2.0 * psd(k as f64 * d_omega) * d_omega).sqrt();
        *b = Complex64::from_polar(amp, phase.sample(rng));
    }
    FftPlanner::<f64>::new()
        .plan_fft_inverse(n_fft)
        .process(&mut buf);
    buf.truncate(n_pts);
    buf.into_iter().map(|c| c.re).collect()
}

/// The interval of a grid (`n` samples from `origin`, `dx` apart) that holds `s`, and the
/// fraction into it, kept where a Catmull–Rom cubic has its four points.
#[inline]
pub(super) fn locate(origin: f64, dx: f64, n: usize, s: f64) -> (usize, f64) {
    // `max` before `min`: a NaN position lands on the grid's first interval instead of
    // an index out of range (the run's own check names the divergence).
    let u = ((s - origin) / dx).max(1.0).min((n - 3) as f64);
    let i = crate::bounds::cell_clamped(u, n - 2);
    (i, u - i as f64)
}

/// Fade-in factor at `s` and its derivative: 0 on the smooth lead of `smooth_start` metres,
/// then `½(1 − cos(π·u/L))` over the fade-in length L (u measured from the end of the lead).
pub(super) fn fade(s: f64, smooth_start: f64, fade_in: f64) -> (f64, f64) {
    let l = fade_in;
    let s = s - smooth_start;
    if s <= 0.0 && (l > 0.0 || s < 0.0) {
        (0.0, 0.0)
    } else if l <= 0.0 || s >= l {
        (1.0, 0.0)
    } else if s <= 0.0 {
        (0.0, 0.0)
    } else {
        let w = std::f64::consts::PI / l;
        (0.5 * (1.0 - (w * s).cos()), 0.5 * w * (w * s).sin())
    }
}
