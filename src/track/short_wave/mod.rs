//! Short waves on the rails' running surface, below the geometry's irregularities: rail
//! roughness from a published spectrum (with the contact filter a single-point Hertz contact
//! needs), weld dips and dipped joints (assets/docs/physics.md §3.4). All are vertical and each
//! rail has its own roughness; all fade in with the irregularities, so a vehicle starts on
//! smooth rails. The `[roughness]`, `[welds]` and `[joints]` tables of a track file are read here.

mod joint;
mod roughness;
mod weld;

pub use joint::Joints;
pub use roughness::{BAND_WIDTH, RoughnessSpectrum, contact_filter_db};
pub use weld::Welds;

use super::irregularity::{catmull_rom, fade, locate, sum_of_cosines};
use crate::error::{Error, Result};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use serde::Deserialize;
use std::f64::consts::PI;
use std::path::Path;

/// Grid points per shortest roughness wavelength (as the irregularities': cubic
/// interpolation within 0.1 %).
const POINTS_PER_WAVELENGTH: f64 = 16.0;
/// Most roughness samples per rail.
const MAX_SAMPLES: f64 = 4e6;
/// Shortest roughness wavelength accepted, m (the contact filter's table ends at 3.15 mm).
pub const SHORTEST_WAVELENGTH: f64 = 0.005;

/// Roughness settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RoughnessSpec {
    /// The spectrum drawn from.
    pub spectrum: RoughnessSpectrum,
    /// Shortest wavelength synthesised, m.
    pub min_wavelength: f64,
    /// Longest wavelength synthesised, m (where the irregularities stop).
    pub max_wavelength: f64,
    /// Whether the contact filter shapes the spectrum.
    pub contact_filter: bool,
    /// Seed of the phases (the track's irregularity seed: a run's seed moves both).
    pub seed: u64,
}

impl RoughnessSpec {
    /// The one-sided PSD the rails are drawn from at Ω (rad/m), m²/(rad/m): the spectrum,
    /// through the contact filter when it is on.
    pub fn psd(&self, omega: f64) -> f64 {
        let k = omega / (2.0 * PI);
        let filter = if self.contact_filter {
            10f64.powf(contact_filter_db(1.0 / k) / 10.0)
        } else {
            1.0
        };
        self.spectrum.psd_per_cycle(k) * filter / (2.0 * PI)
    }
}

/// Everything short-wave a track file asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShortWaveSpec {
    /// Rail roughness, if any.
    pub roughness: Option<RoughnessSpec>,
    /// Weld dips, if any.
    pub welds: Option<Welds>,
    /// Dipped joints, if any.
    pub joints: Option<Joints>,
    /// Smooth lead and fade-in length, m (the irregularities').
    pub smooth_start: f64,
    /// See `smooth_start`.
    pub fade_in: f64,
}

impl ShortWaveSpec {
    /// The shortest wavelength the excitation holds, m: the roughness's, half a weld's dip, a
    /// joint's kink's ([`Joints::shortest_wavelength`]).
    pub fn shortest_wavelength(&self) -> f64 {
        let r = self.roughness.map_or(f64::INFINITY, |r| r.min_wavelength);
        let w = self.welds.map_or(f64::INFINITY, |w| 0.5 * w.length);
        let j = self
            .joints
            .map_or(f64::INFINITY, |j| j.shortest_wavelength());
        r.min(w).min(j)
    }
}

/// Short waves synthesised along a track.
#[derive(Debug, Clone)]
pub struct ShortWaves {
    spec: ShortWaveSpec,
    dx: f64,
    origin: f64,
    /// Roughness of the left and right rail on the grid (empty without roughness).
    rails: [Vec<f64>; 2],
}

impl ShortWaves {
    /// Draws the roughness of both rails over `[0, length]` (independent phases, one stream
    /// apart from the irregularities' on the same seed).
    pub fn synthesize(spec: ShortWaveSpec, length: f64) -> Self {
        let Some(r) = spec.roughness else {
            return ShortWaves {
                spec,
                dx: 1.0,
                origin: 0.0,
                rails: [Vec::new(), Vec::new()],
            };
        };
        let dx = r.min_wavelength / POINTS_PER_WAVELENGTH;
        let n_pts = crate::bounds::to_count((length / dx).ceil()) + 6;
        let band = (2.0 * PI / r.max_wavelength, 2.0 * PI / r.min_wavelength);
        let mut rng = ChaCha8Rng::seed_from_u64(r.seed);
        rng.set_stream(1);
        let rails = [0, 1].map(|_| sum_of_cosines(n_pts, dx, band, |w| r.psd(w), &mut rng));
        ShortWaves {
            spec,
            dx,
            origin: -2.0 * dx,
            rails,
        }
    }

    /// The settings they were drawn with.
    pub fn spec(&self) -> &ShortWaveSpec {
        &self.spec
    }

    /// Grid spacing of the roughness samples, m.
    pub fn grid_step(&self) -> f64 {
        self.dx
    }

    /// Roughness samples of the left (0) or right (1) rail on the grid from `−2·grid_step()`
    /// (without the welds, the joints and the fade-in; empty without roughness), m.
    pub fn roughness_samples(&self, side: usize) -> &[f64] {
        &self.rails[side]
    }

    /// Height of the left and right running surface and their gradients at `s`, faded in:
    /// `(z_left, dz_left/ds, z_right, dz_right/ds)`, m and 1.
    pub fn at(&self, s: f64) -> [f64; 4] {
        let (f, df) = fade(s, self.spec.smooth_start, self.spec.fade_in);
        if f == 0.0 && df == 0.0 {
            return [0.0; 4];
        }
        let (mut wz, mut wd) = self.spec.welds.map_or((0.0, 0.0), |w| w.at(s));
        if let Some(j) = self.spec.joints {
            let (jz, jd) = j.at(s);
            wz += jz;
            wd += jd;
        }
        let mut out = [0.0; 4];
        for (side, v) in self.rails.iter().enumerate() {
            let (mut z, mut d) = (wz, wd);
            if !v.is_empty() {
                let (i, t) = locate(self.origin, self.dx, v.len(), s);
                let (rz, rd) = catmull_rom(v, i, t, self.dx);
                z += rz;
                d += rd;
            }
            out[2 * side] = f * z;
            out[2 * side + 1] = f * d + df * z;
        }
        out
    }
}

/// The short waves of `current` with the roughness of `spectrum` in place of the file's (its
/// defaults: down to [`DEFAULT_MIN_WAVELENGTH`] from where the irregularities stop, the
/// contact filter on, the irregularities' seed), or without roughness (`None`); the welds
/// and joints stay. `geometry` as [`from_file`]'s.
pub fn with_roughness(
    current: Option<ShortWaveSpec>,
    spectrum: Option<RoughnessSpectrum>,
    geometry: Option<(f64, u64, f64, f64)>,
) -> Option<ShortWaveSpec> {
    let (geo_min, seed, smooth_start, fade_in) = geometry.unwrap_or((1.0, 1, 20.0, 50.0));
    let roughness = spectrum.map(|spectrum| RoughnessSpec {
        spectrum,
        min_wavelength: DEFAULT_MIN_WAVELENGTH.min(0.5 * geo_min),
        max_wavelength: geo_min,
        contact_filter: true,
        seed,
    });
    let welds = current.and_then(|c| c.welds);
    let joints = current.and_then(|c| c.joints);
    (roughness.is_some() || welds.is_some() || joints.is_some()).then_some(ShortWaveSpec {
        roughness,
        welds,
        joints,
        smooth_start: current.map_or(smooth_start, |c| c.smooth_start),
        fade_in: current.map_or(fade_in, |c| c.fade_in),
    })
}

impl super::TrackSpec {
    /// Puts rail roughness of the named spectrum on the rails over the file's
    /// (`simulate --roughness`, the plan key `roughness`): one of
    /// [`super::short_wave::RoughnessSpectrum::NAMES`] at its defaults, or "none".
    pub fn set_roughness(&mut self, name: &str) -> crate::error::Result<()> {
        let spectrum = match name {
            "none" => None,
            n => Some(RoughnessSpectrum::parse(n).ok_or_else(|| {
                crate::error::Error::Domain(format!(
                    "roughness must be \"none\" or one of {}, got \"{n}\"",
                    RoughnessSpectrum::NAMES.join(", ")
                ))
            })?),
        };
        let geometry = self
            .irregularity
            .map(|i| (i.min_wavelength, i.seed, i.smooth_start, i.fade_in));
        let shortest = DEFAULT_MIN_WAVELENGTH.min(0.5 * geometry.map_or(1.0, |g| g.0));
        if spectrum.is_some() && self.length() / (shortest / POINTS_PER_WAVELENGTH) > MAX_SAMPLES {
            return Err(crate::error::Error::Domain(format!(
                "roughness on track '{}': {shortest} m waves over {:.0} m need more than {MAX_SAMPLES:.0} samples per rail: use a shorter track",
                self.name,
                self.length()
            )));
        }
        self.short_waves = with_roughness(self.short_waves, spectrum, geometry);
        Ok(())
    }
}

/// `[roughness]` in a track file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RoughnessFile {
    spectrum: String,
    min_wavelength_m: Option<f64>,
    max_wavelength_m: Option<f64>,
    contact_filter: Option<bool>,
    seed: Option<u64>,
}

/// `[welds]` in a track file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WeldsFile {
    spacing_m: Option<f64>,
    first_m: Option<f64>,
    depth_mm: Option<f64>,
    length_m: Option<f64>,
}

/// `[joints]` in a track file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct JointsFile {
    spacing_m: Option<f64>,
    first_m: Option<f64>,
    angle_mrad: Option<f64>,
    length_m: Option<f64>,
}

/// The shortest roughness wavelength unless the file gives one, m: 0.1 m reaches 278 Hz at
/// 100 km/h and 167 Hz at 60 km/h, past the 100 Hz a 200 Hz record holds (a choice).
pub const DEFAULT_MIN_WAVELENGTH: f64 = 0.1;
/// Weld spacing unless given, m: the 100 m factory-welded rails of Chinese continuous welded
/// track (an estimate: field welds join them every few hundred metres too).
pub const DEFAULT_WELD_SPACING: f64 = 100.0;
/// Weld dip depth unless given, m: the 0.3 mm versine over a 1 m straightedge that a
/// conventional weld is accepted at (Esveld), taken as a dip in service (an estimate).
pub const DEFAULT_WELD_DEPTH: f64 = 0.3e-3;
/// Weld dip length unless given, m: the straightedge's 1 m base.
pub const DEFAULT_WELD_LENGTH: f64 = 1.0;
/// Joint spacing unless given, m: the 25 m standard rail of Chinese jointed track.
pub const DEFAULT_JOINT_SPACING: f64 = 25.0;
/// Length of a joint's dipped zone unless given, both rail ends, m (a choice: long enough
/// that the ramps' curvature, 2α/L, unloads an 800 kg wheel at 80 km/h by under 5 kN at
/// 20 mrad).
pub const DEFAULT_JOINT_LENGTH: f64 = 2.0;

/// The short-wave tables of a track file.
pub(super) struct Tables<'a> {
    pub(super) roughness: Option<&'a RoughnessFile>,
    pub(super) welds: Option<&'a WeldsFile>,
    pub(super) joints: Option<&'a JointsFile>,
}

/// The short waves of a track file, every key checked; `geometry_min_wavelength` is where
/// the irregularities stop (none: 1 m), `seed` their seed, `(smooth_start, fade_in)` their
/// lead. None when the file has none of the tables.
pub(super) fn from_file(
    path: &Path,
    tables: Tables,
    length: f64,
    geometry: Option<(f64, u64, f64, f64)>,
) -> Result<Option<ShortWaveSpec>> {
    let Tables {
        roughness,
        welds,
        joints,
    } = tables;
    if roughness.is_none() && welds.is_none() && joints.is_none() {
        return Ok(None);
    }
    let err = |field: &str, msg: String| Error::config(path, field, msg);
    let (geo_min, geo_seed, smooth_start, fade_in) = geometry.unwrap_or((1.0, 1, 20.0, 50.0));
    let roughness = match roughness {
        None => None,
        Some(r) => {
            let spectrum = RoughnessSpectrum::parse(&r.spectrum).ok_or_else(|| {
                err(
                    "roughness.spectrum",
                    format!(
                        "unknown spectrum \"{}\": use {}",
                        r.spectrum,
                        RoughnessSpectrum::NAMES.join(", ")
                    ),
                )
            })?;
            let min = r
                .min_wavelength_m
                .unwrap_or(DEFAULT_MIN_WAVELENGTH.min(0.5 * geo_min));
            if !(min.is_finite() && (SHORTEST_WAVELENGTH..1.0).contains(&min)) {
                return Err(err(
                    "roughness.min_wavelength_m",
                    format!("must be at least {SHORTEST_WAVELENGTH} m and below 1 m, got {min}"),
                ));
            }
            let max = r.max_wavelength_m.unwrap_or(geo_min);
            if !(max.is_finite() && max > min) {
                return Err(err(
                    "roughness.max_wavelength_m",
                    format!("must be above min_wavelength_m ({min}), got {max}"),
                ));
            }
            if max > geo_min * (1.0 + 1e-9) {
                return Err(err(
                    "roughness.max_wavelength_m",
                    format!(
                        "{max} m reaches into the irregularities, which start at {geo_min} m: wavelengths between would be counted twice"
                    ),
                ));
            }
            if length / (min / POINTS_PER_WAVELENGTH) > MAX_SAMPLES {
                return Err(err(
                    "roughness.min_wavelength_m",
                    format!(
                        "{min} m on a {length:.0} m track needs more than {MAX_SAMPLES:.0} samples per rail: use a longer shortest wavelength or a shorter track"
                    ),
                ));
            }
            Some(RoughnessSpec {
                spectrum,
                min_wavelength: min,
                max_wavelength: max,
                contact_filter: r.contact_filter.unwrap_or(true),
                seed: r.seed.unwrap_or(geo_seed),
            })
        }
    };
    let welds = match welds {
        None => None,
        Some(w) => {
            let spacing = w.spacing_m.unwrap_or(DEFAULT_WELD_SPACING);
            let depth = w.depth_mm.map_or(DEFAULT_WELD_DEPTH, |d| d * 1e-3);
            let len = w.length_m.unwrap_or(DEFAULT_WELD_LENGTH);
            let first = w.first_m.unwrap_or(spacing);
            placed("welds", (spacing, first, len), 0.05, length, &err)?;
            if !(depth.is_finite() && depth > 0.0 && depth <= 5e-3) {
                return Err(err(
                    "welds.depth_mm",
                    format!("must be above 0 and at most 5 mm, got {}", depth * 1e3),
                ));
            }
            Some(Welds {
                spacing,
                first,
                depth,
                length: len,
            })
        }
    };
    let joints = joints.map(|j| joints_from(j, length, &err)).transpose()?;
    Ok(Some(ShortWaveSpec {
        roughness,
        welds,
        joints,
        smooth_start,
        fade_in,
    }))
}

/// The placement keys of a `[welds]` or `[joints]` table (`table`): `spacing_m` 1–10 000 m,
/// `length_m` of each dip from `shortest` m to half the spacing, `first_m` on the track
/// (`track` m long).
fn placed(
    table: &str,
    (spacing, first, length): (f64, f64, f64),
    shortest: f64,
    track: f64,
    err: &dyn Fn(&str, String) -> Error,
) -> Result<()> {
    if !(spacing.is_finite() && (1.0..=10_000.0).contains(&spacing)) {
        return Err(err(
            &format!("{table}.spacing_m"),
            format!("must be between 1 and 10000 m, got {spacing}"),
        ));
    }
    if !(length.is_finite() && length >= shortest && length <= 0.5 * spacing) {
        return Err(err(
            &format!("{table}.length_m"),
            format!(
                "must be between {shortest} m and half the spacing ({} m), got {length}",
                0.5 * spacing
            ),
        ));
    }
    if !(first.is_finite() && first >= 0.0 && first <= track) {
        return Err(err(
            &format!("{table}.first_m"),
            format!("must be between 0 and the track's length ({track:.0} m), got {first}"),
        ));
    }
    Ok(())
}

/// A `[joints]` table's joints on a track `length` m long, every key checked.
fn joints_from(j: &JointsFile, length: f64, err: &dyn Fn(&str, String) -> Error) -> Result<Joints> {
    let spacing = j.spacing_m.unwrap_or(DEFAULT_JOINT_SPACING);
    let (track, length) = (length, j.length_m.unwrap_or(DEFAULT_JOINT_LENGTH));
    let first = j.first_m.unwrap_or(spacing);
    placed("joints", (spacing, first, length), 0.2, track, err)?;
    let angle = j.angle_mrad.ok_or_else(|| {
        err(
            "joints.angle_mrad",
            "missing: the total dip angle 2α, mrad (the change of the rail's slope at the joint)"
                .into(),
        )
    })?;
    if !(angle.is_finite() && angle > 0.0 && angle <= 50.0) {
        return Err(err(
            "joints.angle_mrad",
            format!("must be above 0 and at most 50 mrad, got {angle}"),
        ));
    }
    Ok(Joints {
        spacing,
        first,
        angle: angle * 1e-3,
        length,
    })
}

#[cfg(test)]
mod tests;
