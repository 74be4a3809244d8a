//! The consist file: vehicle types, the make-up, couplers and draft gears, the air brake and
//! the driver, read and validated into a [`Consist`]. Every number is checked (finite, of its
//! sign, within a physical bound) and every error names the file and the field
//! (`vehicles.c80.mass_t`, `make_up[1].vehicle`, `position`).

use super::brake::AirBrake;
use super::draft_gear::Coupling;
use super::driver::DriverSettings;
use super::locomotive::Locomotive;
use super::resistance::BasicResistance;
use crate::error::{Error, Result};
use file::{Check, ConsistFile, air_brake, draft_gear, driver, vehicle};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod file;

/// What a vehicle of the consist is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VehicleKind {
    /// Powered: traction and dynamic brake.
    Locomotive,
    /// Unpowered; the 3-D wagon is one of these.
    Wagon,
}

/// One vehicle of the make-up (SI units).
#[derive(Debug, Clone, PartialEq)]
pub struct Vehicle {
    /// The vehicle type's name in the file (`hxd1`, `c80`).
    pub type_name: String,
    /// Locomotive or wagon.
    pub kind: VehicleKind,
    /// Mass, kg.
    pub mass: f64,
    /// Length over the coupler faces (knuckle pulling faces), m.
    pub length: f64,
    /// Distance from a coupler face inward to that coupler's pivot, m: the pivots stand
    /// `length/2 − pivot_inset` from the vehicle's centre.
    pub pivot_inset: f64,
    /// Basic running resistance.
    pub resistance: BasicResistance,
    /// Total shoe normal force at a full-service application, N.
    pub full_service_shoe_force: f64,
    /// Effort curves of a locomotive (`None` for a wagon).
    pub locomotive: Option<Locomotive>,
}

/// A validated consist: its vehicles from the head (index 0) to the tail, and what joins,
/// brakes and drives them.
#[derive(Debug, Clone, PartialEq)]
pub struct Consist {
    /// Name given in the file.
    pub name: String,
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// The vehicles, head first.
    pub vehicles: Vec<Vehicle>,
    /// The 3-D wagon's place: a fraction of the train's length from the head, in [0, 1].
    pub position: f64,
    /// Height of the coupler centre line above the rail top, m.
    pub coupler_height: f64,
    /// Every coupling's slack and draft gears.
    pub coupling: Coupling,
    /// The air brake.
    pub brake: AirBrake,
    /// The driver.
    pub driver: DriverSettings,
}

/// The most vehicles a consist may have (a typing error, not a train, beyond it).
const MAX_VEHICLES: usize = 2_000;

impl Consist {
    /// Reads and validates a consist file.
    pub fn load(path: &Path) -> Result<Consist> {
        Self::parse(&crate::io::read_text(path)?, path)
    }

    /// Parses and validates a consist from its TOML `text`; `path` names it in messages (an
    /// embedded copy passes the path it stands for).
    pub fn parse(text: &str, path: &Path) -> Result<Consist> {
        let raw: ConsistFile = crate::io::parse_toml(text, path)?;
        let c = Check { path };
        if raw.name.trim().is_empty() {
            return Err(c.err("name", "must not be empty"));
        }
        let mut types = BTreeMap::new();
        for (name, v) in &raw.vehicles {
            types.insert(name.as_str(), vehicle(&c, name, v)?);
        }
        if raw.make_up.is_empty() {
            return Err(c.err("make_up", "must list at least one vehicle"));
        }
        let mut vehicles = Vec::new();
        for (k, m) in raw.make_up.iter().enumerate() {
            let Some(v) = types.get(m.vehicle.as_str()) else {
                return Err(c.err(
                    format!("make_up[{k}].vehicle"),
                    format!(
                        "unknown vehicle \"{}\" (the file's [vehicles.*] tables: {})",
                        m.vehicle,
                        raw.vehicles
                            .keys()
                            .map(String::as_str)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            };
            if m.count == 0 || vehicles.len() + m.count > MAX_VEHICLES {
                return Err(c.err(
                    format!("make_up[{k}].count"),
                    format!(
                        "must be at least 1 and the train at most {MAX_VEHICLES} vehicles, got {}",
                        m.count
                    ),
                ));
            }
            vehicles.extend(std::iter::repeat_n(v.clone(), m.count));
        }
        let cf = &raw.coupler;
        let slack = c.non_negative("coupler.slack_m", cf.slack_m, 0.1)?;
        let coupler_height = c.positive("coupler.height_m", cf.height_m, 2.0)?;
        let coupling = Coupling {
            slack,
            gear: draft_gear(&c, &raw.draft_gear)?,
        };
        let brake = air_brake(&c, &raw.brake)?;
        let driver = driver(&c, &raw.driver)?;
        let position = c.range("position", raw.position, 0.0, false, 1.0)?;
        let consist = Consist {
            name: raw.name,
            path: path.to_path_buf(),
            vehicles,
            position,
            coupler_height,
            coupling,
            brake,
            driver,
        };
        consist.index_at(position)?;
        Ok(consist)
    }

    /// Length of the train over its end coupler faces, m.
    pub fn length(&self) -> f64 {
        self.vehicles.iter().map(|v| v.length).sum()
    }

    /// Total mass, kg.
    pub fn mass(&self) -> f64 {
        self.vehicles.iter().map(|v| v.mass).sum()
    }

    /// Indices of the locomotives, head first.
    pub fn locomotives(&self) -> Vec<usize> {
        (0..self.vehicles.len())
            .filter(|&i| self.vehicles[i].kind == VehicleKind::Locomotive)
            .collect()
    }

    /// The index of the vehicle at `fraction` of the train's length from the head (a point on
    /// a boundary belongs to the vehicle behind it; 1.0 to the last). Refused, naming the file
    /// and `position`, when the fraction lies outside [0, 1] or the vehicle there is not a
    /// wagon.
    pub fn index_at(&self, fraction: f64) -> Result<usize> {
        if !(0.0..=1.0).contains(&fraction) {
            return Err(Error::config(
                &self.path,
                "position",
                format!(
                    "{fraction} lies outside the train: the 3-D wagon's place is a fraction of its length from the head, in [0, 1]"
                ),
            ));
        }
        let at = fraction * self.length();
        let mut front = 0.0;
        let last = self.vehicles.len() - 1;
        let mut index = last;
        for (i, v) in self.vehicles.iter().enumerate() {
            if at < front + v.length {
                index = i;
                break;
            }
            front += v.length;
        }
        let v = &self.vehicles[index];
        if v.kind != VehicleKind::Wagon {
            return Err(Error::config(
                &self.path,
                "position",
                format!(
                    "{fraction} of the train's length ({at:.1} m from the head) lands on vehicle {index}, a locomotive (\"{}\"): the 3-D vehicle must be a wagon",
                    v.type_name
                ),
            ));
        }
        Ok(index)
    }
}
