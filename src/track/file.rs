//! The track file (TOML): what a user writes, parsed strictly (unknown keys are errors) and
//! validated into [`TrackSpec`] with errors that name the file and the field.

use super::alignment::{Section, SectionKind, Turn};
use super::irregularity::{FraClass, IrregularitySpec, Spectrum};
use super::profile::{Grade, VerticalProfile};
use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Largest cant accepted, in mm (Chinese and European practice stay below 150–180 mm; 200 mm
/// is the hard ceiling).
pub const MAX_CANT_MM: f64 = 200.0;
/// Longest track accepted, m.
pub const MAX_LENGTH_M: f64 = 200e3;
/// Most irregularity samples per channel (length over λ_min/16).
pub const MAX_IRREGULARITY_SAMPLES: f64 = 4e6;

/// Largest gradient accepted, in ‰ (mainline heavy haul stays below ~30 ‰).
pub const MAX_GRADIENT_PERMILLE: f64 = 60.0;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackFile {
    name: Option<String>,
    description: Option<String>,
    #[serde(default = "default_rail_spacing")]
    rail_spacing_m: f64,
    #[serde(default = "default_gauge")]
    gauge_m: f64,
    #[serde(default)]
    section: Vec<SectionFile>,
    profile: Option<ProfileFile>,
    irregularity: Option<IrregularityFile>,
    rail_support: Option<super::support::RailSupportFile>,
    roughness: Option<super::short_wave::RoughnessFile>,
    welds: Option<super::short_wave::WeldsFile>,
    joints: Option<super::short_wave::JointsFile>,
}

fn default_rail_spacing() -> f64 {
    1.5
}
fn default_gauge() -> f64 {
    1.435
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SectionFile {
    kind: String,
    length_m: f64,
    start_m: Option<f64>,
    radius_m: Option<f64>,
    cant_mm: Option<f64>,
    direction: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    #[serde(default)]
    start_elevation_m: f64,
    #[serde(default)]
    grade: Vec<GradeFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GradeFile {
    at_m: f64,
    gradient_permille: Option<f64>,
    gradient_deg: Option<f64>,
    vertical_curve_radius_m: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct IrregularityFile {
    class: i64,
    /// `fra` (default), `german_low` or `german_high`.
    spectrum: Option<String>,
    #[serde(default = "default_min_wavelength")]
    min_wavelength_m: f64,
    #[serde(default = "default_max_wavelength")]
    max_wavelength_m: f64,
    #[serde(default = "default_seed")]
    seed: u64,
    #[serde(default = "default_smooth_start")]
    smooth_start_m: f64,
    #[serde(default = "default_fade_in")]
    fade_in_m: f64,
    /// Narrowest gauge deviation, mm (default: the class's limit, 49 CFR 213.53).
    gauge_min_mm: Option<f64>,
    /// Widest gauge deviation, mm (default: the class's limit).
    gauge_max_mm: Option<f64>,
}

fn default_smooth_start() -> f64 {
    20.0
}

fn default_fade_in() -> f64 {
    50.0
}

fn default_min_wavelength() -> f64 {
    1.0
}
fn default_max_wavelength() -> f64 {
    50.0
}
fn default_seed() -> u64 {
    1
}

/// A validated track description, ready to be built into a [`super::Track`].
#[derive(Debug, Clone)]
pub struct TrackSpec {
    /// File the spec came from (used in messages).
    pub source: PathBuf,
    /// Short name for reports.
    pub name: String,
    /// Free text.
    pub description: String,
    /// Distance between the rails' contact lines, m (1.5 m for standard gauge).
    pub rail_spacing: f64,
    /// Track gauge, m.
    pub gauge: f64,
    /// Horizontal alignment, in running order.
    pub sections: Vec<Section>,
    /// Vertical profile.
    pub profile: VerticalProfile,
    /// Irregularities, if any.
    pub irregularity: Option<IrregularitySpec>,
    /// Compliant rail support under each wheel, lumped (`[rail_support]`, model "lumped");
    /// None with rigid rails or rails on sleepers.
    pub rail_support: Option<super::support::RailSupport>,
    /// Rails as beams on discrete sleepers (`[rail_support] model = "discrete"`); None
    /// otherwise. At most one of the two is set ([`TrackSpec::set_rail_model`]).
    pub discrete_rails: Option<super::discrete::DiscreteSupport>,
    /// Rail roughness, weld dips and dipped joints (`[roughness]`, `[welds]`, `[joints]`), if any.
    pub short_waves: Option<super::short_wave::ShortWaveSpec>,
}

/// The rails' supports a run can choose by name ([`TrackSpec::set_rail_model`]).
pub const RAIL_SUPPORT_MODELS: [&str; 3] = ["rigid", "lumped", "discrete"];

impl TrackSpec {
    /// Whether any section is a curve.
    pub fn has_curves(&self) -> bool {
        self.sections
            .iter()
            .any(|s| matches!(s.kind, SectionKind::Curve { .. }))
    }

    /// Turns every curve the other way (its cant goes to the other rail with it); the
    /// irregularities and the vertical profile stay as they are.
    pub fn mirror(&mut self) {
        for s in &mut self.sections {
            if let SectionKind::Curve { turn, .. } = &mut s.kind {
                *turn = match turn {
                    Turn::Left => Turn::Right,
                    Turn::Right => Turn::Left,
                };
            }
        }
    }

    /// Reads and validates a track file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        Self::parse(&text, path)
    }

    /// Parses and validates track TOML text; `path` is only used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let raw: TrackFile = crate::io::parse_toml(text, path)?;
        let err = |field: String, msg: String| Error::config(path, field, msg);

        check_range(path, "rail_spacing_m", raw.rail_spacing_m, 0.5, 3.0)?;
        check_range(path, "gauge_m", raw.gauge_m, 0.5, 3.0)?;
        if raw.section.is_empty() {
            return Err(err(
                "section".into(),
                "a track needs at least one [[section]]".into(),
            ));
        }

        let mut sections = Vec::with_capacity(raw.section.len());
        let mut start = 0.0;
        for (i, sf) in raw.section.iter().enumerate() {
            let f = |name: &str| format!("section[{i}].{name}");
            if !(sf.length_m.is_finite() && sf.length_m > 0.0) {
                return Err(err(
                    f("length_m"),
                    format!("must be positive, got {}", sf.length_m),
                ));
            }
            if let Some(s0) = sf.start_m {
                let gap = s0 - start;
                if gap.abs() > 1e-6 {
                    let what = if gap > 0.0 {
                        "leaves a gap"
                    } else {
                        "overlaps"
                    };
                    return Err(err(
                        f("start_m"),
                        format!(
                            "section {what}: it starts at {s0} m but the previous section ends at {start} m"
                        ),
                    ));
                }
            }
            let only_curve = |name: &str, present: bool| -> Result<()> {
                if present {
                    Err(err(
                        f(name),
                        format!(
                            "only curve sections take {name} (this one is '{}')",
                            sf.kind
                        ),
                    ))
                } else {
                    Ok(())
                }
            };
            let kind = match sf.kind.as_str() {
                "tangent" | "transition" => {
                    only_curve("radius_m", sf.radius_m.is_some())?;
                    only_curve("cant_mm", sf.cant_mm.is_some())?;
                    only_curve("direction", sf.direction.is_some())?;
                    if sf.kind == "tangent" {
                        SectionKind::Tangent
                    } else {
                        SectionKind::Transition
                    }
                }
                "curve" => {
                    let radius = sf
                        .radius_m
                        .ok_or_else(|| err(f("radius_m"), "a curve needs radius_m".into()))?;
                    if !(radius.is_finite() && radius > 0.0) {
                        return Err(err(
                            f("radius_m"),
                            format!("must be positive, got {radius}"),
                        ));
                    }
                    if radius < 50.0 {
                        return Err(err(
                            f("radius_m"),
                            format!("{radius} m is below the 50 m that a mainline wagon can run"),
                        ));
                    }
                    let cant_mm = sf.cant_mm.unwrap_or(0.0);
                    if !(0.0..=MAX_CANT_MM).contains(&cant_mm) {
                        return Err(err(
                            f("cant_mm"),
                            format!("must be between 0 and {MAX_CANT_MM} mm, got {cant_mm}"),
                        ));
                    }
                    let turn = match sf.direction.as_deref() {
                        Some("left") => Turn::Left,
                        Some("right") => Turn::Right,
                        Some(other) => {
                            return Err(err(
                                f("direction"),
                                format!("must be \"left\" or \"right\", got \"{other}\""),
                            ));
                        }
                        None => {
                            return Err(err(
                                f("direction"),
                                "a curve needs direction = \"left\" or \"right\"".into(),
                            ));
                        }
                    };
                    SectionKind::Curve {
                        radius,
                        cant: cant_mm * 1e-3,
                        turn,
                    }
                }
                other => {
                    return Err(err(
                        f("kind"),
                        format!("unknown kind \"{other}\": use tangent, transition or curve"),
                    ));
                }
            };
            if matches!(kind, SectionKind::Transition)
                && matches!(
                    sections.last(),
                    Some(Section {
                        kind: SectionKind::Transition,
                        ..
                    })
                )
            {
                return Err(err(
                    f("kind"),
                    "two transitions in a row: put a tangent or a curve between them".into(),
                ));
            }
            sections.push(Section {
                start,
                length: sf.length_m,
                kind,
            });
            start += sf.length_m;
        }
        let length = start;
        if length > MAX_LENGTH_M {
            return Err(err(
                "section".into(),
                format!(
                    "the sections add up to {:.0} km: at most {:.0} km (runs need a few km)",
                    length * 1e-3,
                    MAX_LENGTH_M * 1e-3
                ),
            ));
        }

        let (rail_support, discrete_rails) = match &raw.rail_support {
            None => (None, None),
            Some(f) => match f.model(path)? {
                super::support::RailModel::Lumped(l) => (Some(l), None),
                super::support::RailModel::Discrete(d) => (None, Some(*d)),
            },
        };

        let profile = match &raw.profile {
            None => VerticalProfile::level(0.0),
            Some(p) => parse_profile(p, path, length)?,
        };

        let irregularity = match &raw.irregularity {
            None => None,
            Some(irr) => {
                let class = FraClass::new(irr.class).ok_or_else(|| {
                    err(
                        "irregularity.class".into(),
                        format!("unknown FRA class {}: use 1 to 6", irr.class),
                    )
                })?;
                check_range(
                    path,
                    "irregularity.min_wavelength_m",
                    irr.min_wavelength_m,
                    0.1,
                    1000.0,
                )?;
                if !(irr.max_wavelength_m.is_finite()
                    && irr.max_wavelength_m > irr.min_wavelength_m)
                {
                    return Err(err(
                        "irregularity.max_wavelength_m".into(),
                        format!(
                            "must be above min_wavelength_m ({}), got {}",
                            irr.min_wavelength_m, irr.max_wavelength_m
                        ),
                    ));
                }
                check_range(path, "irregularity.fade_in_m", irr.fade_in_m, 0.0, 1000.0)?;
                if length / (irr.min_wavelength_m / 16.0) > MAX_IRREGULARITY_SAMPLES {
                    return Err(err(
                        "irregularity.min_wavelength_m".into(),
                        format!(
                            "{} m on a {:.0} m track needs more than {:.0} samples per channel: use a longer shortest wavelength or a shorter track",
                            irr.min_wavelength_m, length, MAX_IRREGULARITY_SAMPLES
                        ),
                    ));
                }
                check_range(
                    path,
                    "irregularity.smooth_start_m",
                    irr.smooth_start_m,
                    0.0,
                    1000.0,
                )?;
                let (lo, hi) = class.gauge_limits();
                let lo = irr.gauge_min_mm.map_or(lo, |v| v * 1e-3);
                let hi = irr.gauge_max_mm.map_or(hi, |v| v * 1e-3);
                check_range(path, "irregularity.gauge_min_mm", lo * 1e3, -50.0, -1.0)?;
                check_range(path, "irregularity.gauge_max_mm", hi * 1e3, 1.0, 50.0)?;
                let spectrum = match irr.spectrum.as_deref() {
                    None => Spectrum::Fra,
                    Some(name) => Spectrum::parse(name).ok_or_else(|| {
                        err(
                            "irregularity.spectrum".into(),
                            format!(
                                "unknown spectrum \"{name}\": use {}",
                                Spectrum::NAMES.join(", ")
                            ),
                        )
                    })?,
                };
                Some(IrregularitySpec {
                    spectrum,
                    gauge_limits: (lo, hi),
                    smooth_start: irr.smooth_start_m,
                    class,
                    min_wavelength: irr.min_wavelength_m,
                    max_wavelength: irr.max_wavelength_m,
                    seed: irr.seed,
                    fade_in: irr.fade_in_m,
                })
            }
        };

        let short_waves = super::short_wave::from_file(
            path,
            super::short_wave::Tables {
                roughness: raw.roughness.as_ref(),
                welds: raw.welds.as_ref(),
                joints: raw.joints.as_ref(),
            },
            length,
            irregularity.map(|i| (i.min_wavelength, i.seed, i.smooth_start, i.fade_in)),
        )?;

        Ok(TrackSpec {
            source: path.to_path_buf(),
            name: raw.name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            description: raw.description.unwrap_or_default(),
            rail_spacing: raw.rail_spacing_m,
            gauge: raw.gauge_m,
            sections,
            profile,
            irregularity,
            rail_support,
            discrete_rails,
            short_waves,
        })
    }

    /// Total length of the track, m.
    pub fn length(&self) -> f64 {
        self.sections
            .last()
            .map(|s| s.start + s.length)
            .unwrap_or(0.0)
    }
}

fn check_range(path: &Path, field: &str, v: f64, lo: f64, hi: f64) -> Result<()> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(Error::config(
            path,
            field,
            format!("must be between {lo} and {hi}, got {v}"),
        ))
    }
}

fn parse_profile(p: &ProfileFile, path: &Path, length: f64) -> Result<VerticalProfile> {
    let err = |field: String, msg: String| Error::config(path, field, msg);
    if !p.start_elevation_m.is_finite() {
        return Err(err(
            "profile.start_elevation_m".into(),
            "must be finite".into(),
        ));
    }
    let mut grades = Vec::with_capacity(p.grade.len());
    for (i, g) in p.grade.iter().enumerate() {
        let f = |name: &str| format!("profile.grade[{i}].{name}");
        let gradient = match (g.gradient_permille, g.gradient_deg) {
            (Some(pm), None) => pm * 1e-3,
            (None, Some(deg)) => deg.to_radians().tan(),
            (Some(_), Some(_)) => {
                return Err(err(
                    f("gradient_deg"),
                    "give gradient_permille or gradient_deg, not both".into(),
                ));
            }
            (None, None) => {
                return Err(err(
                    f("gradient_permille"),
                    "each grade needs gradient_permille (or gradient_deg)".into(),
                ));
            }
        };
        if !(gradient.is_finite() && gradient.abs() <= MAX_GRADIENT_PERMILLE * 1e-3) {
            return Err(err(
                f("gradient_permille"),
                format!(
                    "{:.2} ‰ is beyond the ±{MAX_GRADIENT_PERMILLE} ‰ limit",
                    gradient * 1e3
                ),
            ));
        }
        if !(g.at_m.is_finite() && (0.0..length).contains(&g.at_m)) {
            return Err(err(
                f("at_m"),
                format!("must lie on the track (0 to {length} m), got {}", g.at_m),
            ));
        }
        if i == 0 && g.at_m != 0.0 {
            return Err(err(
                f("at_m"),
                "the first grade starts the profile and must be at 0 m".into(),
            ));
        }
        if i > 0 && g.at_m <= p.grade[i - 1].at_m {
            return Err(err(
                f("at_m"),
                format!(
                    "grade changes must be in increasing order, {} follows {}",
                    g.at_m,
                    p.grade[i - 1].at_m
                ),
            ));
        }
        let radius = g.vertical_curve_radius_m.unwrap_or(f64::INFINITY);
        if radius.is_nan() || radius <= 0.0 {
            return Err(err(
                f("vertical_curve_radius_m"),
                format!("must be positive, got {radius}"),
            ));
        }
        if i > 0 && radius.is_infinite() && g.vertical_curve_radius_m.is_some() {
            return Err(err(f("vertical_curve_radius_m"), "must be finite".into()));
        }
        grades.push(Grade {
            at: g.at_m,
            gradient,
            vertical_curve_radius: if i == 0 { f64::INFINITY } else { radius },
        });
    }
    if grades.is_empty() {
        grades.push(Grade {
            at: 0.0,
            gradient: 0.0,
            vertical_curve_radius: f64::INFINITY,
        });
    }
    let profile = VerticalProfile::new(p.start_elevation_m, grades);
    // Vertical curves must not overlap each other nor run off the track.
    let zones = profile.rounding_zones();
    for (i, zone) in zones.iter().enumerate() {
        if let Some((a, b)) = *zone
            && (a < 0.0 || b > length)
        {
            return Err(err(
                format!("profile.grade[{i}].vertical_curve_radius_m"),
                format!("the vertical curve spans {a:.1}–{b:.1} m, off the track (0–{length} m)"),
            ));
        }
    }
    let spans: Vec<(usize, f64, f64)> = zones
        .iter()
        .enumerate()
        .filter_map(|(i, zone)| zone.map(|(a, b)| (i, a, b)))
        .collect();
    for w in spans.windows(2) {
        if w[1].1 < w[0].2 {
            return Err(err(
                format!("profile.grade[{}].at_m", w[1].0),
                format!(
                    "its vertical curve ({:.1}–{:.1} m) overlaps the previous one ({:.1}–{:.1} m)",
                    w[1].1, w[1].2, w[0].1, w[0].2
                ),
            ));
        }
    }
    Ok(profile)
}
