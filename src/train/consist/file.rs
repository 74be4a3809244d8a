//! The consist file's tables as written (serde) and their validation into the model's types:
//! every number finite, of its sign and within a physical bound, every error naming the file
//! and the field.

use super::{Vehicle, VehicleKind};
use crate::error::{Error, Result};
use crate::train::brake::AirBrake;
use crate::train::draft_gear::DraftGear;
use crate::train::driver::{Command, DriverSettings, ScheduleEntry};
use crate::train::locomotive::Locomotive;
use crate::train::resistance::BasicResistance;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ConsistFile {
    pub(super) name: String,
    pub(super) position: f64,
    pub(super) coupler: CouplerFile,
    pub(super) draft_gear: DraftGearFile,
    pub(super) brake: BrakeFile,
    pub(super) driver: DriverFile,
    pub(super) vehicles: BTreeMap<String, VehicleFile>,
    pub(super) make_up: Vec<MakeUpFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CouplerFile {
    pub(super) slack_m: f64,
    pub(super) height_m: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DraftGearFile {
    pub(super) travel_m: f64,
    pub(super) impedance_n: f64,
    pub(super) preload_n: f64,
    pub(super) exponent: f64,
    pub(super) unloading_ratio: f64,
    pub(super) solid_stiffness_n_per_m: f64,
    pub(super) switch_speed_m_s: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct BrakeFile {
    pub(super) pipe_speed_m_s: f64,
    pub(super) valve_delay_s: f64,
    pub(super) apply_time_constant_s: f64,
    pub(super) emergency_time_constant_s: f64,
    pub(super) release_time_constant_s: f64,
    pub(super) emergency_ratio: f64,
    pub(super) distributed: bool,
    pub(super) radio_delay_s: f64,
    /// Speeds of the friction table, km/h, ascending.
    pub(super) shoe_friction_speeds_kmh: Vec<f64>,
    /// μ at those speeds.
    pub(super) shoe_friction: Vec<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DriverFile {
    pub(super) traction_notches: u32,
    pub(super) brake_notches: u32,
    pub(super) proportional: f64,
    pub(super) integral: f64,
    pub(super) notch_interval_s: f64,
    pub(super) tolerance_kmh: f64,
    #[serde(default)]
    pub(super) schedule: Vec<ScheduleFile>,
    pub(super) cyclic: Option<CyclicFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CyclicFile {
    pub(super) apply_above_kmh: f64,
    pub(super) release_below_kmh: f64,
    pub(super) level: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ScheduleFile {
    pub(super) t_s: f64,
    pub(super) action: String,
    pub(super) notch: Option<i64>,
    pub(super) level: Option<f64>,
    pub(super) speed_kmh: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct VehicleFile {
    pub(super) kind: String,
    pub(super) mass_t: f64,
    pub(super) length_m: f64,
    pub(super) pivot_inset_m: f64,
    /// [a, b, c]: a + b·v + c·v², N/kN, v in km/h.
    pub(super) resistance: [f64; 3],
    pub(super) brake_shoe_force_n: f64,
    pub(super) traction: Option<TractionFile>,
    pub(super) dynamic_brake: Option<DynamicBrakeFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TractionFile {
    pub(super) max_n: f64,
    pub(super) continuous_n: f64,
    pub(super) continuous_kmh: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DynamicBrakeFile {
    pub(super) max_n: f64,
    pub(super) constant_to_kmh: f64,
    pub(super) fade_below_kmh: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MakeUpFile {
    pub(super) vehicle: String,
    pub(super) count: usize,
}

/// Checks of one file's numbers, each error naming the file and the field.
pub(super) struct Check<'a> {
    pub(super) path: &'a Path,
}

impl Check<'_> {
    pub(super) fn err(&self, field: impl Into<String>, msg: impl Into<String>) -> Error {
        Error::config(self.path, field, msg)
    }

    /// `v` finite and within `[lo, hi]` (`lo_open`: strictly above `lo`).
    pub(super) fn range(
        &self,
        field: &str,
        v: f64,
        lo: f64,
        lo_open: bool,
        hi: f64,
    ) -> Result<f64> {
        if !v.is_finite() {
            return Err(self.err(field, format!("must be finite, got {v}")));
        }
        if (lo_open && v <= lo) || v < lo {
            let what = if lo == 0.0 {
                if lo_open {
                    "must be positive".to_string()
                } else {
                    "must not be negative".to_string()
                }
            } else {
                format!("must be at least {lo}")
            };
            return Err(self.err(field, format!("{what}, got {v}")));
        }
        if v > hi {
            return Err(self.err(field, format!("{v} is beyond the physical bound of {hi}")));
        }
        Ok(v)
    }

    pub(super) fn positive(&self, field: &str, v: f64, hi: f64) -> Result<f64> {
        self.range(field, v, 0.0, true, hi)
    }

    pub(super) fn non_negative(&self, field: &str, v: f64, hi: f64) -> Result<f64> {
        self.range(field, v, 0.0, false, hi)
    }
}

pub(super) fn vehicle(c: &Check, name: &str, v: &VehicleFile) -> Result<Vehicle> {
    let f = |k: &str| format!("vehicles.{name}.{k}");
    let kind = match v.kind.as_str() {
        "locomotive" => VehicleKind::Locomotive,
        "wagon" => VehicleKind::Wagon,
        other => {
            return Err(c.err(
                f("kind"),
                format!("unknown vehicle kind \"{other}\" (known: locomotive, wagon)"),
            ));
        }
    };
    let mass = c.positive(&f("mass_t"), v.mass_t, 1000.0)? * 1000.0;
    let length = c.positive(&f("length_m"), v.length_m, 100.0)?;
    let pivot_inset = c.non_negative(&f("pivot_inset_m"), v.pivot_inset_m, 0.5 * length)?;
    if pivot_inset >= 0.5 * length {
        return Err(c.err(f("pivot_inset_m"), "must be less than half the length"));
    }
    for (k, &x) in v.resistance.iter().enumerate() {
        c.non_negative(&format!("vehicles.{name}.resistance[{k}]"), x, 100.0)?;
    }
    let [a, b, cc] = v.resistance;
    let shoe = c.non_negative(&f("brake_shoe_force_n"), v.brake_shoe_force_n, 5e6)?;
    let locomotive = match (kind, &v.traction, &v.dynamic_brake) {
        (VehicleKind::Locomotive, Some(t), Some(d)) => {
            let max_traction = c.positive(&f("traction.max_n"), t.max_n, 5e6)?;
            let cont = c.positive(&f("traction.continuous_n"), t.continuous_n, max_traction)?;
            let cont_v = c.positive(&f("traction.continuous_kmh"), t.continuous_kmh, 500.0)? / 3.6;
            let max_db = c.positive(&f("dynamic_brake.max_n"), d.max_n, 5e6)?;
            let db_v = c.positive(
                &f("dynamic_brake.constant_to_kmh"),
                d.constant_to_kmh,
                500.0,
            )?;
            let fade =
                c.non_negative(&f("dynamic_brake.fade_below_kmh"), d.fade_below_kmh, db_v)?;
            Some(Locomotive {
                max_traction,
                traction_power: cont * cont_v,
                max_dynamic_brake: max_db,
                dynamic_brake_power: max_db * db_v / 3.6,
                dynamic_brake_fade: fade / 3.6,
            })
        }
        (VehicleKind::Locomotive, t, _) => {
            let missing = if t.is_none() {
                "traction"
            } else {
                "dynamic_brake"
            };
            return Err(c.err(f(missing), "missing: a locomotive gives its effort curve"));
        }
        (VehicleKind::Wagon, None, None) => None,
        (VehicleKind::Wagon, t, _) => {
            let extra = if t.is_some() {
                "traction"
            } else {
                "dynamic_brake"
            };
            return Err(c.err(f(extra), "a wagon has no effort curve (kind = \"wagon\")"));
        }
    };
    Ok(Vehicle {
        type_name: name.to_string(),
        kind,
        mass,
        length,
        pivot_inset,
        resistance: BasicResistance { a, b, c: cc },
        full_service_shoe_force: shoe,
        locomotive,
    })
}

pub(super) fn draft_gear(c: &Check, d: &DraftGearFile) -> Result<DraftGear> {
    let travel = c.positive("draft_gear.travel_m", d.travel_m, 0.5)?;
    let impedance = c.positive("draft_gear.impedance_n", d.impedance_n, 2e7)?;
    let preload = c.non_negative("draft_gear.preload_n", d.preload_n, impedance)?;
    Ok(DraftGear {
        travel,
        impedance,
        preload,
        exponent: c.positive("draft_gear.exponent", d.exponent, 20.0)?,
        unloading_ratio: c.range(
            "draft_gear.unloading_ratio",
            d.unloading_ratio,
            0.0,
            true,
            1.0,
        )?,
        solid_stiffness: c.positive(
            "draft_gear.solid_stiffness_n_per_m",
            d.solid_stiffness_n_per_m,
            1e11,
        )?,
        switch_speed: c.positive("draft_gear.switch_speed_m_s", d.switch_speed_m_s, 1.0)?,
    })
}

pub(super) fn air_brake(c: &Check, b: &BrakeFile) -> Result<AirBrake> {
    if b.shoe_friction.is_empty() || b.shoe_friction.len() != b.shoe_friction_speeds_kmh.len() {
        return Err(c.err(
            "brake.shoe_friction",
            format!(
                "must give one μ per speed of shoe_friction_speeds_kmh ({} speeds, {} values), at least one",
                b.shoe_friction_speeds_kmh.len(),
                b.shoe_friction.len()
            ),
        ));
    }
    let mut friction = Vec::new();
    for (k, (&v, &mu)) in b
        .shoe_friction_speeds_kmh
        .iter()
        .zip(&b.shoe_friction)
        .enumerate()
    {
        let field = format!("brake.shoe_friction_speeds_kmh[{k}]");
        let v = c.non_negative(&field, v, 500.0)? / 3.6;
        c.positive(&format!("brake.shoe_friction[{k}]"), mu, 1.0)?;
        if friction.last().is_some_and(|&(last, _)| v <= last) {
            return Err(c.err(field, "speeds must ascend"));
        }
        friction.push((v, mu));
    }
    Ok(AirBrake {
        pipe_speed: c.positive("brake.pipe_speed_m_s", b.pipe_speed_m_s, 400.0)?,
        valve_delay: c.non_negative("brake.valve_delay_s", b.valve_delay_s, 60.0)?,
        apply_time_constant: c.positive(
            "brake.apply_time_constant_s",
            b.apply_time_constant_s,
            600.0,
        )?,
        emergency_time_constant: c.positive(
            "brake.emergency_time_constant_s",
            b.emergency_time_constant_s,
            600.0,
        )?,
        release_time_constant: c.positive(
            "brake.release_time_constant_s",
            b.release_time_constant_s,
            600.0,
        )?,
        emergency_ratio: c.range("brake.emergency_ratio", b.emergency_ratio, 1.0, false, 3.0)?,
        distributed: b.distributed,
        radio_delay: c.non_negative("brake.radio_delay_s", b.radio_delay_s, 60.0)?,
        friction,
    })
}

pub(super) fn driver(c: &Check, d: &DriverFile) -> Result<DriverSettings> {
    if (d.traction_notches == 0) != (d.brake_notches == 0) {
        return Err(c.err(
            "driver.brake_notches",
            "a stepless handle has no notches on either side: both 0, or both at least 1",
        ));
    }
    for (field, n) in [
        ("driver.traction_notches", d.traction_notches),
        ("driver.brake_notches", d.brake_notches),
    ] {
        if n > 100 {
            return Err(c.err(field, format!("{n} is beyond the bound of 100 notches")));
        }
    }
    let mut schedule = Vec::new();
    for (k, e) in d.schedule.iter().enumerate() {
        let f = |x: &str| format!("driver.schedule[{k}].{x}");
        let time = c.non_negative(&f("t_s"), e.t_s, 1e6)?;
        if schedule
            .last()
            .is_some_and(|l: &ScheduleEntry| time < l.time)
        {
            return Err(c.err(f("t_s"), "times must not go back"));
        }
        let need = |v: Option<f64>, key: &str| {
            v.ok_or_else(|| c.err(f(key), format!("missing: action \"{}\" needs it", e.action)))
        };
        let command = match e.action.as_str() {
            "notch" => {
                let n = e
                    .notch
                    .ok_or_else(|| c.err(f("notch"), "missing: action \"notch\" needs it"))?;
                let (lo, hi) = (-(d.brake_notches as i64), d.traction_notches as i64);
                if n < lo || n > hi {
                    return Err(c.err(f("notch"), format!("{n} is outside [{lo}, {hi}]")));
                }
                Command::Notch(n as i32)
            }
            "hold" => Command::Hold(
                c.non_negative(&f("speed_kmh"), need(e.speed_kmh, "speed_kmh")?, 500.0)? / 3.6,
            ),
            "air" => {
                Command::AirBrake(c.range(&f("level"), need(e.level, "level")?, 0.0, true, 1.0)?)
            }
            "emergency" => Command::Emergency,
            "release" => Command::Release,
            other => {
                return Err(c.err(
                    f("action"),
                    format!(
                        "unknown action \"{other}\" (known: notch, hold, air, emergency, release)"
                    ),
                ));
            }
        };
        schedule.push(ScheduleEntry { time, command });
    }
    Ok(DriverSettings {
        traction_notches: d.traction_notches,
        brake_notches: d.brake_notches,
        proportional: c.non_negative("driver.proportional", d.proportional, 1e3)?,
        integral: c.non_negative("driver.integral", d.integral, 1e3)?,
        notch_interval: c.non_negative("driver.notch_interval_s", d.notch_interval_s, 60.0)?,
        tolerance: c.positive("driver.tolerance_kmh", d.tolerance_kmh, 100.0)? / 3.6,
        schedule,
        cyclic: match &d.cyclic {
            None => None,
            Some(cy) => Some(crate::train::driver::CyclicBraking {
                apply_above: c.positive(
                    "driver.cyclic.apply_above_kmh",
                    cy.apply_above_kmh,
                    100.0,
                )? / 3.6,
                release_below: c.positive(
                    "driver.cyclic.release_below_kmh",
                    cy.release_below_kmh,
                    100.0,
                )? / 3.6,
                level: c.positive("driver.cyclic.level", cy.level, 1.0)?,
            }),
        },
    })
}
