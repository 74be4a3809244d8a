//! `[rail_support.discrete]` in a track file: every key optional, each defaulting to the
//! parameter set of [`super::DiscreteSupport::default`].

use super::{DiscreteSupport, KelvinVoigt, RailBeam};
use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::Path;

/// The discrete track's keys (SI units in their names).
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscreteFile {
    sleeper_spacing_m: Option<f64>,
    window_bays: Option<usize>,
    rail_mass_kg_per_m: Option<f64>,
    rail_ei_vertical_nm2: Option<f64>,
    rail_ei_lateral_nm2: Option<f64>,
    rail_beam: Option<String>,
    rail_shear_stiffness_vertical_n: Option<f64>,
    rail_shear_stiffness_lateral_n: Option<f64>,
    rail_rotary_inertia_vertical_kgm: Option<f64>,
    rail_rotary_inertia_lateral_kgm: Option<f64>,
    rail_torsion_stiffness_nm2: Option<f64>,
    rail_polar_inertia_kgm: Option<f64>,
    rail_torsion_centre_depth_m: Option<f64>,
    rail_torsion_centre_offset_m: Option<f64>,
    pad_lateral_lever_m: Option<f64>,
    pad_vertical_half_width_m: Option<f64>,
    pad_vertical_stiffness_n_per_m: Option<f64>,
    pad_vertical_damping_ns_per_m: Option<f64>,
    pad_lateral_stiffness_n_per_m: Option<f64>,
    pad_lateral_damping_ns_per_m: Option<f64>,
    sleeper_mass_kg: Option<f64>,
    sleeper_roll_inertia_kgm2: Option<f64>,
    rail_seat_half_distance_m: Option<f64>,
    sleeper_lateral_stiffness_n_per_m: Option<f64>,
    sleeper_lateral_damping_ns_per_m: Option<f64>,
    ballast_mass_kg: Option<f64>,
    ballast_stiffness_n_per_m: Option<f64>,
    ballast_damping_ns_per_m: Option<f64>,
    ballast_shear_stiffness_n_per_m: Option<f64>,
    ballast_shear_damping_ns_per_m: Option<f64>,
    subgrade_stiffness_n_per_m: Option<f64>,
    subgrade_damping_ns_per_m: Option<f64>,
}

impl DiscreteFile {
    /// The parameters, each key checked (`path` names the file in errors).
    pub fn support(&self, path: &Path) -> Result<DiscreteSupport> {
        let d = DiscreteSupport::default();
        let get = |key: &str, v: Option<f64>, default: f64, zero_ok: bool| {
            let field = format!("rail_support.discrete.{key}");
            crate::track::support::checked(path, field, v.unwrap_or(default), zero_ok)
        };
        let kv = |k: &str, kd: Option<f64>, c: &str, cd: Option<f64>, def: KelvinVoigt| {
            Ok::<_, Error>(KelvinVoigt {
                stiffness: get(k, kd, def.stiffness, false)?,
                damping: get(c, cd, def.damping, true)?,
            })
        };
        let bays = self.window_bays.unwrap_or(d.bays);
        if !(16..=512).contains(&bays) {
            return Err(Error::config(
                path,
                "rail_support.discrete.window_bays",
                format!("must be 16 to 512 bays, got {bays}"),
            ));
        }
        let rail_beam = match self.rail_beam.as_deref() {
            None => d.rail_beam,
            Some("timoshenko") => RailBeam::Timoshenko,
            Some("euler_bernoulli") => RailBeam::EulerBernoulli,
            Some(other) => {
                return Err(Error::config(
                    path,
                    "rail_support.discrete.rail_beam",
                    format!("must be \"timoshenko\" or \"euler_bernoulli\", got \"{other}\""),
                ));
            }
        };
        let p = DiscreteSupport {
            spacing: get(
                "sleeper_spacing_m",
                self.sleeper_spacing_m,
                d.spacing,
                false,
            )?,
            bays,
            rail_mass: get(
                "rail_mass_kg_per_m",
                self.rail_mass_kg_per_m,
                d.rail_mass,
                false,
            )?,
            rail_ei_vertical: get(
                "rail_ei_vertical_nm2",
                self.rail_ei_vertical_nm2,
                d.rail_ei_vertical,
                false,
            )?,
            rail_ei_lateral: get(
                "rail_ei_lateral_nm2",
                self.rail_ei_lateral_nm2,
                d.rail_ei_lateral,
                false,
            )?,
            rail_beam,
            rail_shear_vertical: get(
                "rail_shear_stiffness_vertical_n",
                self.rail_shear_stiffness_vertical_n,
                d.rail_shear_vertical,
                false,
            )?,
            rail_shear_lateral: get(
                "rail_shear_stiffness_lateral_n",
                self.rail_shear_stiffness_lateral_n,
                d.rail_shear_lateral,
                false,
            )?,
            rail_rotary_vertical: get(
                "rail_rotary_inertia_vertical_kgm",
                self.rail_rotary_inertia_vertical_kgm,
                d.rail_rotary_vertical,
                true,
            )?,
            rail_rotary_lateral: get(
                "rail_rotary_inertia_lateral_kgm",
                self.rail_rotary_inertia_lateral_kgm,
                d.rail_rotary_lateral,
                true,
            )?,
            rail_torsion_stiffness: get(
                "rail_torsion_stiffness_nm2",
                self.rail_torsion_stiffness_nm2,
                d.rail_torsion_stiffness,
                false,
            )?,
            rail_polar_inertia: get(
                "rail_polar_inertia_kgm",
                self.rail_polar_inertia_kgm,
                d.rail_polar_inertia,
                false,
            )?,
            torsion_centre_depth: get(
                "rail_torsion_centre_depth_m",
                self.rail_torsion_centre_depth_m,
                d.torsion_centre_depth,
                true,
            )?,
            torsion_centre_offset: get(
                "rail_torsion_centre_offset_m",
                self.rail_torsion_centre_offset_m,
                d.torsion_centre_offset,
                true,
            )?,
            pad_lateral_lever: get(
                "pad_lateral_lever_m",
                self.pad_lateral_lever_m,
                d.pad_lateral_lever,
                true,
            )?,
            pad_vertical_half_width: get(
                "pad_vertical_half_width_m",
                self.pad_vertical_half_width_m,
                d.pad_vertical_half_width,
                true,
            )?,
            pad_vertical: kv(
                "pad_vertical_stiffness_n_per_m",
                self.pad_vertical_stiffness_n_per_m,
                "pad_vertical_damping_ns_per_m",
                self.pad_vertical_damping_ns_per_m,
                d.pad_vertical,
            )?,
            pad_lateral: kv(
                "pad_lateral_stiffness_n_per_m",
                self.pad_lateral_stiffness_n_per_m,
                "pad_lateral_damping_ns_per_m",
                self.pad_lateral_damping_ns_per_m,
                d.pad_lateral,
            )?,
            sleeper_mass: get(
                "sleeper_mass_kg",
                self.sleeper_mass_kg,
                d.sleeper_mass,
                false,
            )?,
            sleeper_roll_inertia: get(
                "sleeper_roll_inertia_kgm2",
                self.sleeper_roll_inertia_kgm2,
                d.sleeper_roll_inertia,
                false,
            )?,
            seat_half_distance: get(
                "rail_seat_half_distance_m",
                self.rail_seat_half_distance_m,
                d.seat_half_distance,
                false,
            )?,
            sleeper_lateral: kv(
                "sleeper_lateral_stiffness_n_per_m",
                self.sleeper_lateral_stiffness_n_per_m,
                "sleeper_lateral_damping_ns_per_m",
                self.sleeper_lateral_damping_ns_per_m,
                d.sleeper_lateral,
            )?,
            ballast_mass: get(
                "ballast_mass_kg",
                self.ballast_mass_kg,
                d.ballast_mass,
                false,
            )?,
            ballast: kv(
                "ballast_stiffness_n_per_m",
                self.ballast_stiffness_n_per_m,
                "ballast_damping_ns_per_m",
                self.ballast_damping_ns_per_m,
                d.ballast,
            )?,
            ballast_shear: KelvinVoigt {
                stiffness: get(
                    "ballast_shear_stiffness_n_per_m",
                    self.ballast_shear_stiffness_n_per_m,
                    d.ballast_shear.stiffness,
                    true,
                )?,
                damping: get(
                    "ballast_shear_damping_ns_per_m",
                    self.ballast_shear_damping_ns_per_m,
                    d.ballast_shear.damping,
                    true,
                )?,
            },
            subgrade: kv(
                "subgrade_stiffness_n_per_m",
                self.subgrade_stiffness_n_per_m,
                "subgrade_damping_ns_per_m",
                self.subgrade_damping_ns_per_m,
                d.subgrade,
            )?,
        };
        if !(0.4..=1.0).contains(&p.spacing) {
            return Err(Error::config(
                path,
                "rail_support.discrete.sleeper_spacing_m",
                format!("must lie in 0.4–1.0 m, got {} m", p.spacing),
            ));
        }
        if p.window() < 20.0 {
            return Err(Error::config(
                path,
                "rail_support.discrete.window_bays",
                format!(
                    "the window ({} bays of {} m = {:.1} m) must reach 20 m: the rail's basin must die out before its ends",
                    p.bays,
                    p.spacing,
                    p.window()
                ),
            ));
        }
        Ok(p)
    }
}
