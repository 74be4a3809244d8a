//! Checks of the simulator's fidelity beyond the closed forms of [`super::checks`]: the
//! critical speed by kink-and-coast and by run-down, the motion left long after a kink
//! at constant speed, the side frames' roll, the high-frequency content of the wheel forces in a
//! tight curve, convergence in the step, the anti-alias filter at the output's Nyquist
//! frequency and the smoothness of the recorded track position.

use super::filter::Lowpass;
use super::output::{Recording, record};
use super::{SimConfig, Simulation};
use crate::dsp::welch::welch_psd;
use crate::error::{Error, Result};
use crate::track::{Track, TrackSpec};
use crate::vehicle::Vehicle;
use std::path::Path;

/// A smooth (irregularity-free) version of a track file, for stability runs.
pub fn smooth(path: &Path) -> Result<Track> {
    let mut spec = TrackSpec::load(path)?;
    spec.irregularity = None;
    Ok(Track::new(spec, None))
}

/// Kink-and-coast: the vehicle starts 6 mm off the centre line (a kink) at `from` (m/s),
/// holds that speed 5 s, then slows at `decel` (m/s²) to `to`. Any hunting limit cycle of the
/// leading wheelset dies out at the critical speed.
#[derive(Debug, Clone)]
pub struct CriticalSpeed {
    /// Lowest speed at which the limit cycle (half peak-to-peak ≥ 1.5 mm over a 1 s block)
    /// was still present, m/s; `None` if the wagon was stable already at `from`.
    pub critical: Option<f64>,
    /// Speed and half peak-to-peak lateral amplitude of the leading wheelset per 1 s block.
    pub blocks: Vec<(f64, f64)>,
    /// Frequency of the leading wheelset's lateral motion at each block, over the 3 s ending
    /// with it (crossings of its mean), Hz; 0 where it crossed fewer than twice.
    pub frequencies: Vec<f64>,
    /// Every wheel's Y and Q and the track position at 200 Hz (sampled, not filtered): what
    /// the acceptance statistics judge ([`crate::assess`], running stability).
    pub forces: crate::assess::RunForces,
}

impl CriticalSpeed {
    /// Frequency of the limit cycle at the lowest speed where it still held its amplitude,
    /// Hz: the last block of the hunting (≥ 1.5 mm) whose amplitude is within
    /// [`CYCLE_HOLD`] of the block before it. A limit cycle keeps its amplitude from second to
    /// second as the speed falls (by 1–3 % on the C80's branch); the blocks after it are its
    /// collapse, whose frequency is a decaying transient's (the loaded C80's run-down: 1.97 Hz
    /// at 103 km/h on the cycle, 1.58 Hz in the collapse at 92 km/h).
    /// Returns the block's speed (m/s) and the frequency.
    pub fn cycle_frequency(&self) -> Option<(f64, f64)> {
        self.critical?;
        let hunting: Vec<(f64, f64, f64)> = self
            .blocks
            .iter()
            .zip(&self.frequencies)
            .skip(2)
            .take_while(|(b, _)| b.1 >= HUNTING_AMPLITUDE)
            .map(|(b, f)| (b.0, b.1, *f))
            .collect();
        hunting
            .windows(2)
            .rfind(|w| w[1].1 >= (1.0 - CYCLE_HOLD) * w[0].1)
            .map(|w| (w[1].0, w[1].2))
            .or(hunting.last().map(|h| (h.0, h.2)))
    }
}

/// How much a limit cycle's amplitude may fall from one 1 s block to the next and still be
/// the cycle rather than its collapse.
pub const CYCLE_HOLD: f64 = 0.10;

/// Half peak-to-peak lateral amplitude of the leading wheelset over a 1 s block from which a
/// wagon is said to hunt, m.
pub const HUNTING_AMPLITUDE: f64 = 1.5e-3;

/// Frequency of `x` by upward crossings of its mean, Hz (`dt` s between samples; 0 with fewer
/// than two crossings).
fn crossing_frequency(x: &[f64], dt: f64) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    let ups: Vec<usize> = (1..x.len())
        .filter(|&i| x[i - 1] < mean && x[i] >= mean)
        .collect();
    match (ups.first(), ups.last()) {
        (Some(a), Some(b)) if b > a => (ups.len() - 1) as f64 / ((b - a) as f64 * dt),
        _ => 0.0,
    }
}

/// A run that starts 6 mm off the centre line (the kink) at `speed`, without settling, and
/// stops on derailment.
fn kinked<'a>(
    vehicle: &'a Vehicle,
    track: &'a Track,
    speed: f64,
    duration: f64,
    base: &SimConfig,
) -> Result<Simulation<'a>> {
    Simulation::new(
        vehicle,
        track,
        SimConfig {
            speed,
            duration,
            settle: 0.0,
            initial_offset: 6e-3,
            stop_on_derailment: true,
            ..base.clone()
        },
    )
}

/// Runs the kink-and-coast test of `vehicle` on the smooth `track`.
pub fn critical_speed(
    vehicle: &Vehicle,
    track: &Track,
    from: f64,
    to: f64,
    decel: f64,
) -> Result<CriticalSpeed> {
    coast(vehicle, track, (from, to, decel), 5.0, None)
}

/// Lateral velocity given to every wheelset by [`run_down`]'s kick, m/s (alternating in
/// sign from wheelset to wheelset, so the bogies yaw): enough to throw the leading wheelset
/// onto its flange at the top speed.
pub const RUN_DOWN_KICK: f64 = 0.25;

/// The run-down of Iwnicki, Stichel, Orlova & Hecht (2015, "Dynamics of railway freight
/// vehicles", Vehicle System Dynamics 53): the kink of [`critical_speed`], then a large kick
/// at the top speed `from` ([`RUN_DOWN_KICK`] to every wheelset, flange to flange), 8 s held
/// there so a limit cycle can form, then a slow run down at `decel`. It starts on the limit
/// cycle where one exists, so it finds the lowest speed at which that cycle survives (the
/// nonlinear critical speed), which a small kink at a lower speed can overstate.
pub fn run_down(
    vehicle: &Vehicle,
    track: &Track,
    from: f64,
    to: f64,
    decel: f64,
) -> Result<CriticalSpeed> {
    coast(vehicle, track, (from, to, decel), 8.0, Some(RUN_DOWN_KICK))
}

/// The coast of both tests: the kinked run held `hold` s at `from` (kicked after 0.5 s when
/// `kick` is given, m/s), then slowing at `decel` to `to`.
fn coast(
    vehicle: &Vehicle,
    track: &Track,
    (from, to, decel): (f64, f64, f64),
    hold: f64,
    kick: Option<f64>,
) -> Result<CriticalSpeed> {
    let duration = hold + (from - to) / decel + 2.0;
    let mut sim = kinked(vehicle, track, from, duration, &SimConfig::default())?;
    let lead = 0;
    let steps_per_block = crate::bounds::to_count((1.0 / sim.config().dt).round());
    let mut blocks = Vec::new();
    let mut frequencies = Vec::new();
    let mut block = Vec::with_capacity(steps_per_block);
    let mut window: Vec<f64> = Vec::new();
    let n_wheels = 2 * vehicle.contact.wheelsets.len();
    let mut forces = crate::assess::RunForces {
        time: Vec::new(),
        s: Vec::new(),
        wheels: (0..n_wheels)
            .map(|k| crate::assess::WheelSeries {
                wheel: format!("w{}", crate::vehicle::wheel_name(k).to_ascii_lowercase()),
                y: Vec::new(),
                q: Vec::new(),
            })
            .collect(),
        carbody: None,
        couplers: None,
    };
    let every = (1.0 / (crate::sensors::RATE_HZ * sim.config().dt))
        .round()
        .max(1.0) as usize;
    let mut step = 0usize;
    let mut kick = kick;
    while sim.time() < duration {
        let t = sim.time();
        if let Some(dv) = kick.filter(|_| t >= 0.5) {
            for (k, &w) in vehicle.contact.wheelsets.iter().enumerate() {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                sim.kick(
                    w,
                    nalgebra::Vector3::new(0.0, sign * dv, 0.0),
                    nalgebra::Vector3::zeros(),
                );
            }
            kick = None;
        }
        let v = if t < hold {
            from
        } else {
            (from - decel * (t - hold)).max(to)
        };
        sim.set_speed(v);
        sim.step()?;
        block.push(sim.wheels[2 * lead].y_centre);
        if step.is_multiple_of(every) {
            forces.time.push(sim.time());
            forces.s.push(sim.body_s()[vehicle.contact.wheelsets[0]]);
            for (w, r) in forces.wheels.iter_mut().zip(&sim.wheels) {
                w.y.push(r.y);
                w.q.push(r.q);
            }
        }
        step += 1;
        if block.len() == steps_per_block {
            let (lo, hi) = block
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), y| {
                    (l.min(*y), h.max(*y))
                });
            blocks.push((v, 0.5 * (hi - lo)));
            window.extend_from_slice(&block);
            let keep = 3 * steps_per_block;
            if window.len() > keep {
                window.drain(..window.len() - keep);
            }
            frequencies.push(crossing_frequency(&window, sim.config().dt));
            block.clear();
        }
    }
    // Skip the first 2 s (the kink's own transient).
    let hunting = |a: f64| a >= HUNTING_AMPLITUDE;
    let critical = blocks
        .iter()
        .skip(2)
        .take_while(|b| hunting(b.1))
        .last()
        .map(|b| b.0);
    Ok(CriticalSpeed {
        critical,
        blocks,
        frequencies,
        forces,
    })
}

/// Roll of the side frames relative to the track frame (the `sideframe*_roll` channels):
/// standard deviation and peak over all of them, rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SideFrameRoll {
    /// Largest standard deviation of one side frame's roll, rad.
    pub std: f64,
    /// Largest |roll| of any side frame, rad.
    pub peak: f64,
}

/// Side-frame roll over a recording (every `sideframe*_roll` channel; a real three-piece side
/// frame hangs on its pads and rolls well under a degree).
pub fn sideframe_roll(rec: &Recording) -> Result<SideFrameRoll> {
    let mut out = SideFrameRoll {
        std: 0.0,
        peak: 0.0,
    };
    let names: Vec<&String> = rec
        .names
        .iter()
        .filter(|n| n.starts_with("sideframe") && n.ends_with("_roll"))
        .collect();
    if names.is_empty() {
        return Err(Error::Domain(
            "no sideframe*_roll channel in the recording".into(),
        ));
    }
    for name in names {
        let x = column(rec, name)?;
        let n = x.len().max(1) as f64;
        let mean = x.iter().sum::<f64>() / n;
        let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
        out.std = out.std.max(sd);
        out.peak = x.iter().fold(out.peak, |p, v| p.max(v.abs()));
    }
    Ok(out)
}

/// Stability at one constant speed: what is left of the kink after a long run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settled {
    /// Half peak-to-peak lateral displacement of the leading wheelset over the tail, m.
    pub wheelset: f64,
    /// The same of the heaviest body (the carbody), m.
    pub carbody: f64,
    /// Its frequency by zero crossings of the leading wheelset's motion over the tail, Hz (0
    /// when it crossed its mean fewer than twice).
    pub frequency: f64,
}

impl Settled {
    /// A limit cycle remains: the leading wheelset still moves ≥ 1.5 mm (the hunting
    /// threshold of [`critical_speed`]) or the carbody sways ≥ 1.5 mm.
    pub fn cycling(&self) -> bool {
        self.wheelset >= 1.5e-3 || self.carbody >= 1.5e-3
    }
}

/// Constant-speed stability: the kink of [`critical_speed`] (6 mm off the centre line), then
/// `duration` s at `speed` (m/s) on the smooth straight `track`; the motion over the last
/// `tail` s. Where kink-and-coast enters every limit cycle from above, this finds the ones a
/// large disturbance starts at service speed (a subcritical cycle below the coast's critical
/// speed shows here and not there).
pub fn settled(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    duration: f64,
    tail: f64,
) -> Result<Settled> {
    settled_with(vehicle, track, speed, duration, tail, &SimConfig::default())
}

/// [`settled`] with the step and integrator of `base`.
pub fn settled_with(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    duration: f64,
    tail: f64,
    base: &SimConfig,
) -> Result<Settled> {
    let mut sim = kinked(vehicle, track, speed, duration, base)?;
    let heaviest = (0..vehicle.bodies.len())
        .max_by(|&a, &b| vehicle.bodies[a].mass.total_cmp(&vehicle.bodies[b].mass))
        .unwrap_or(0);
    let (mut w, mut c) = (Vec::new(), Vec::new());
    while sim.time() < duration {
        sim.step()?;
        if sim.time() >= duration - tail {
            w.push(sim.wheels[0].y_centre);
            c.push(sim.states()[heaviest].position.y);
        }
    }
    let half_range = |x: &[f64]| {
        let (lo, hi) = x
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        if x.is_empty() { 0.0 } else { 0.5 * (hi - lo) }
    };
    let frequency = crossing_frequency(&w, sim.config().dt);
    Ok(Settled {
        wheelset: half_range(&w),
        carbody: half_range(&c),
        frequency,
    })
}

/// Share of a signal's variance above `f` (Hz), by Welch's periodogram of the recorded signal
/// at `rate` (Hz).
pub fn power_above(x: &[f64], rate: f64, f: f64) -> f64 {
    let p = welch_psd(x, 1.0 / rate, 512);
    let total: f64 = p.density.iter().skip(1).sum();
    let high: f64 = p
        .freq
        .iter()
        .zip(&p.density)
        .filter(|(fr, _)| **fr > f)
        .map(|(_, d)| d)
        .sum();
    if total > 0.0 { high / total } else { 0.0 }
}

/// Records `vehicle` on `track` at `speed` for `duration` seconds with step `dt`.
pub fn run(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    duration: f64,
    dt: f64,
) -> Result<Recording> {
    run_with(
        vehicle,
        track,
        SimConfig {
            speed,
            duration,
            dt,
            ..SimConfig::default()
        },
    )
}

/// Records `vehicle` on `track` with the settings `cfg`.
pub fn run_with(vehicle: &Vehicle, track: &Track, cfg: SimConfig) -> Result<Recording> {
    let mut sim = Simulation::new(vehicle, track, cfg)?;
    record(&mut sim, |_| {})
}

/// A column of a recording by name.
pub fn column(rec: &Recording, name: &str) -> Result<Vec<f64>> {
    let i = rec
        .names
        .iter()
        .position(|n| n == name)
        .ok_or_else(|| Error::Domain(format!("no channel '{name}' in the recording")))?;
    Ok(rec.column(i))
}

/// RMS of |Y/Q| and standard deviation of Q of every wheel of a recording.
pub fn yq_and_q(rec: &Recording, wheels: usize) -> Result<Vec<(f64, f64)>> {
    (0..wheels)
        .map(|k| {
            let name = crate::vehicle::wheel_name(k).to_lowercase();
            let y = column(rec, &format!("w{name}_force_y"))?;
            let q = column(rec, &format!("w{name}_force_z"))?;
            let n = y.len() as f64;
            let yq = (y.iter().zip(&q).map(|(a, b)| (a / b).powi(2)).sum::<f64>() / n).sqrt();
            let mean = q.iter().sum::<f64>() / n;
            let sd = (q.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            Ok((yq, sd))
        })
        .collect()
}

/// Attenuation of the default anti-alias filter at the output's Nyquist frequency, dB
/// (negative).
pub fn anti_alias_db(cfg: &SimConfig) -> f64 {
    let lp = Lowpass::new(cfg.cutoff, 1.0 / cfg.dt);
    20.0 * lp.gain(0.5 * cfg.output_rate).log10()
}

/// Largest second difference of the recorded track position, m: `|s[i+1] − 2·s[i] + s[i−1]|`
/// is `a·Δt²` for a smooth motion (0.06 mm at 0.5 m/s² and 200 Hz), while a position refreshed
/// only every few steps jumps by centimetres.
pub fn position_jitter(s: &[f64]) -> f64 {
    s.windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cycle's frequency is read where it last held its amplitude, not in its collapse (the
    /// loaded C80's run-down, where the cycle's amplitude falls 6.82 → 5.63 → 2.85 mm as it
    /// collapses).
    #[test]
    fn cycle_frequency_is_read_where_the_cycle_holds() {
        let kmh = |v: f64| v / 3.6;
        let c = CriticalSpeed {
            critical: Some(kmh(92.0)),
            blocks: vec![
                (kmh(200.0), 5.0e-3), // the first two blocks are the kick
                (kmh(195.0), 5.0e-3),
                (kmh(108.2), 6.84e-3),
                (kmh(102.8), 6.82e-3),
                (kmh(97.4), 5.63e-3),
                (kmh(92.0), 2.85e-3),
                (kmh(86.6), 0.85e-3),
            ],
            frequencies: vec![2.6, 2.6, 2.00, 1.97, 1.84, 1.58, 1.2],
            forces: crate::assess::RunForces {
                time: vec![],
                s: vec![],
                wheels: vec![],
                carbody: None,
                couplers: None,
            },
        };
        let (v, f) = c.cycle_frequency().unwrap();
        assert!((v * 3.6 - 102.8).abs() < 1e-9 && f == 1.97, "{v} {f}");
        // A cycle seen in one block only is read there.
        let one = CriticalSpeed {
            blocks: c.blocks[..3].to_vec(),
            frequencies: c.frequencies[..3].to_vec(),
            ..c.clone()
        };
        assert_eq!(one.cycle_frequency().unwrap().1, 2.00);
    }
}
