//! The rail's support under each wheel: a compliant track as lumped "moving" rail masses that
//! travel with the wheels (as in the track models of multibody codes): per wheel a lateral and
//! a vertical mass on a spring and a damper to the ground. The vertical mass on its stiffness
//! with the wheelset's unsprung mass gives Q its P2 resonance; laterally, flange contact meets
//! the rail head's compliance (lateral bending, fastening and rail roll in series), not a
//! rigid wall.

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::Path;

/// One direction of the rail support.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Support {
    /// Effective mass moving with the wheel, kg.
    pub mass: f64,
    /// Stiffness to the ground, N/m.
    pub stiffness: f64,
    /// Damping to the ground, N·s/m.
    pub damping: f64,
}

impl Support {
    /// Undamped natural frequency of the mass on its spring, Hz.
    pub fn natural_frequency(&self) -> f64 {
        (self.stiffness / self.mass).sqrt() / (2.0 * std::f64::consts::PI)
    }

    /// Acceleration of the mass at displacement `x` and velocity `v` under the external
    /// force `f` (N), m/s².
    #[inline]
    pub fn acceleration(&self, x: f64, v: f64, f: f64) -> f64 {
        (f - self.stiffness * x - self.damping * v) / self.mass
    }

    /// One semi-implicit Euler step of the mass at displacement `x` and velocity `v` under
    /// the external force `f` (N) for `dt` (s).
    #[inline]
    pub fn step(&self, x: &mut f64, v: &mut f64, f: f64, dt: f64) {
        *v += self.acceleration(*x, *v, f) * dt;
        *x += *v * dt;
    }
}

/// Lateral and vertical support of the rail under each wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RailSupport {
    /// Lateral (at the rail head).
    pub lateral: Support,
    /// Vertical.
    pub vertical: Support,
}

impl super::TrackSpec {
    /// Chooses the rails' support by name, over the file's (`simulate --rail-support`, the
    /// plan key `rail_support`): "rigid", "lumped" (the file's lumped masses, which it must
    /// have) or "discrete" (the file's discrete parameters, else the default set).
    pub fn set_rail_model(&mut self, model: &str) -> Result<()> {
        match model {
            "rigid" => (self.rail_support, self.discrete_rails) = (None, None),
            "lumped" => {
                if self.rail_support.is_none() {
                    return Err(Error::Domain(format!(
                        "rail support \"lumped\": track '{}' has no lumped [rail_support] masses to take",
                        self.name
                    )));
                }
                self.discrete_rails = None;
            }
            "discrete" => {
                self.discrete_rails = Some(self.discrete_rails.unwrap_or_default());
                self.rail_support = None;
            }
            other => {
                return Err(Error::Domain(format!(
                    "rail support must be \"rigid\", \"lumped\" or \"discrete\", got \"{other}\""
                )));
            }
        }
        Ok(())
    }

    /// The rails' support by name: "rigid", "lumped" or "discrete".
    pub fn rail_model(&self) -> &'static str {
        match (self.rail_support, self.discrete_rails) {
            (_, Some(_)) => "discrete",
            (Some(_), None) => "lumped",
            (None, None) => "rigid",
        }
    }
}

/// `[rail_support]` in a track file: `model = "lumped"` (the default: the six keys below) or
/// `model = "discrete"` (rails on sleepers, [`super::discrete`]; its keys, all optional, in
/// `[rail_support.discrete]`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RailSupportFile {
    model: Option<String>,
    lateral_mass_kg: Option<f64>,
    lateral_stiffness_n_per_m: Option<f64>,
    lateral_damping_ns_per_m: Option<f64>,
    vertical_mass_kg: Option<f64>,
    vertical_stiffness_n_per_m: Option<f64>,
    vertical_damping_ns_per_m: Option<f64>,
    discrete: Option<super::discrete::DiscreteFile>,
}

/// The rail support a track file chose.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum RailModel {
    /// Lumped rail masses under each wheel.
    Lumped(RailSupport),
    /// Rails on discrete sleepers.
    Discrete(Box<super::discrete::DiscreteSupport>),
}

impl RailSupportFile {
    /// The model the table chose, every key checked.
    pub(super) fn model(&self, path: &Path) -> Result<RailModel> {
        let lumped_keys = [
            self.lateral_mass_kg,
            self.lateral_stiffness_n_per_m,
            self.lateral_damping_ns_per_m,
            self.vertical_mass_kg,
            self.vertical_stiffness_n_per_m,
            self.vertical_damping_ns_per_m,
        ];
        match self.model.as_deref().unwrap_or("lumped") {
            "lumped" => {
                if self.discrete.is_some() {
                    return Err(Error::config(
                        path,
                        "rail_support.discrete",
                        "belongs to model = \"discrete\" (this table's model is \"lumped\")",
                    ));
                }
                RailSupport::from_file(self, path).map(RailModel::Lumped)
            }
            "discrete" => {
                if lumped_keys.iter().any(Option::is_some) {
                    return Err(Error::config(
                        path,
                        "rail_support",
                        "model = \"discrete\" takes its keys in [rail_support.discrete], not the lumped masses' (lateral_mass_kg, …)",
                    ));
                }
                let d = self.discrete.as_ref();
                let p = match d {
                    Some(d) => d.support(path)?,
                    None => super::discrete::DiscreteFile::default().support(path)?,
                };
                Ok(RailModel::Discrete(Box::new(p)))
            }
            other => Err(Error::config(
                path,
                "rail_support.model",
                format!("must be \"lumped\" or \"discrete\", got \"{other}\""),
            )),
        }
    }
}

/// A track-file number that must be positive (at least zero where `zero_ok`), its error
/// naming the file and `field`.
pub(super) fn checked(path: &Path, field: String, v: f64, zero_ok: bool) -> Result<f64> {
    if v.is_finite() && (v > 0.0 || (zero_ok && v == 0.0)) {
        Ok(v)
    } else {
        Err(Error::config(
            path,
            field,
            format!(
                "must be {}, got {v}",
                if zero_ok { "≥ 0" } else { "positive" }
            ),
        ))
    }
}

impl RailSupport {
    fn from_file(f: &RailSupportFile, path: &Path) -> Result<Self> {
        let check = |field: &str, v: Option<f64>, zero_ok: bool| -> Result<f64> {
            let Some(v) = v else {
                return Err(Error::config(
                    path,
                    format!("rail_support.{field}"),
                    "missing (the lumped model needs all six masses, stiffnesses and dampings)",
                ));
            };
            checked(path, format!("rail_support.{field}"), v, zero_ok)
        };
        let support = RailSupport {
            lateral: Support {
                mass: check("lateral_mass_kg", f.lateral_mass_kg, false)?,
                stiffness: check(
                    "lateral_stiffness_n_per_m",
                    f.lateral_stiffness_n_per_m,
                    false,
                )?,
                damping: check("lateral_damping_ns_per_m", f.lateral_damping_ns_per_m, true)?,
            },
            vertical: Support {
                mass: check("vertical_mass_kg", f.vertical_mass_kg, false)?,
                stiffness: check(
                    "vertical_stiffness_n_per_m",
                    f.vertical_stiffness_n_per_m,
                    false,
                )?,
                damping: check(
                    "vertical_damping_ns_per_m",
                    f.vertical_damping_ns_per_m,
                    true,
                )?,
            },
        };
        // The semi-implicit step must resolve the rail on its own springs with margin.
        for (name, s) in [("lateral", support.lateral), ("vertical", support.vertical)] {
            if s.natural_frequency() > 400.0 {
                return Err(Error::config(
                    path,
                    format!("rail_support.{name}_mass_kg"),
                    format!(
                        "the {name} rail mass on its spring rings at {:.0} Hz, above the 400 Hz the semi-implicit 0.2 ms step resolves: use more mass or less stiffness",
                        s.natural_frequency()
                    ),
                ));
            }
        }
        Ok(support)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rail mass released from a displacement swings at `√(k/m)/2π` (closed form), counted
    /// from the zero crossings of the step the simulation uses.
    #[test]
    fn rail_mass_rings_at_its_natural_frequency() {
        let s = Support {
            mass: 250.0,
            stiffness: 1e8,
            damping: 0.0,
        };
        let (mut x, mut v, dt) = (1e-3, 0.0, 2e-5);
        let mut crossings = Vec::new();
        for i in 0..20_000 {
            let before = x;
            s.step(&mut x, &mut v, 0.0, dt);
            if before > 0.0 && x <= 0.0 {
                crossings.push(i as f64 * dt);
            }
        }
        let n = crossings.len() - 1;
        let period = (crossings[n] - crossings[0]) / n as f64;
        let f = 1.0 / period;
        assert!((f / s.natural_frequency() - 1.0).abs() < 2e-3, "{f} Hz");
        assert!((s.natural_frequency() - 100.66).abs() < 0.01);
        // Static deflection under a load: f/k.
        let (mut x, mut v) = (0.0, 0.0);
        let s = Support { damping: 2e5, ..s };
        for _ in 0..200_000 {
            s.step(&mut x, &mut v, -1e5, dt);
        }
        assert!((x + 1e-3).abs() < 1e-9);
    }
}
