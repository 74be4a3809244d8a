//! The vehicle TOML file: its top-level tables, read and validated into a [`Vehicle`]. Each
//! force element reads its own table (`bind` in its file); the contact, hauling and sensor
//! tables are read here.

use super::binder::Binder;
use super::elements::{
    CentrePlate, CentrePlateFile, CrossBracing, CrossBracingFile, LateralStop, LateralStopFile,
    ShearPad, ShearPadFile, SideBearer, SideBearerFile, SpringNest, SpringNestFile, TrackSpring,
    TrackSpringFile, WedgeDamper, WedgeDamperFile,
};
use super::{Accelerometers, ContactSettings, Element, Hauling, SensorLayout, Vehicle};
use crate::contact::{CreepLaw, Material, WheelsetGeometry, profile};
use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::Path;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct VehicleFile {
    name: Option<String>,
    urdf: String,
    contact: ContactFile,
    #[serde(default)]
    shear_pad: Vec<ShearPadFile>,
    #[serde(default)]
    spring_nest: Vec<SpringNestFile>,
    #[serde(default)]
    wedge_damper: Vec<WedgeDamperFile>,
    #[serde(default)]
    centre_plate: Vec<CentrePlateFile>,
    #[serde(default)]
    side_bearer: Vec<SideBearerFile>,
    #[serde(default)]
    cross_bracing: Vec<CrossBracingFile>,
    #[serde(default)]
    track_spring: Vec<TrackSpringFile>,
    #[serde(default)]
    lateral_stop: Vec<LateralStopFile>,
    hauling: Option<HaulingFile>,
    sensors: Option<SensorsFile>,
    accelerometers: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactFile {
    wheelsets: Vec<String>,
    wheel_profile: String,
    rail_profile: String,
    rail_inclination: f64,
    flange_back_m: f64,
    nominal_radius_m: f64,
    #[serde(default = "default_gauge")]
    gauge_m: f64,
    friction: f64,
    #[serde(default = "default_law")]
    creep_law: String,
    young_pa: f64,
    poisson: f64,
    #[serde(default = "default_damping_ratio")]
    damping_ratio: f64,
    /// Tape circle outside the flange back, m (70 mm for S1002).
    #[serde(default = "default_tape_offset")]
    tape_offset_m: f64,
    /// Largest flange angle of the wheel profile, degrees (Nadal's limit).
    #[serde(default = "default_flange_angle")]
    flange_angle_deg: f64,
}

fn default_tape_offset() -> f64 {
    0.070
}
fn default_flange_angle() -> f64 {
    70.0
}

fn default_gauge() -> f64 {
    1.435
}
fn default_law() -> String {
    "polach".into()
}
fn default_damping_ratio() -> f64 {
    0.05
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct HaulingFile {
    link: String,
    proportional: f64,
    integral: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SensorsFile {
    bogie: [String; 3],
    carbody: String,
    wheelset: String,
    label_wheel: String,
}

/// Reads a vehicle TOML file and the URDF it names, validates everything and computes the
/// static preloads of the supporting elements from the load path.
pub(super) fn load(path: &Path) -> Result<Vehicle> {
    let raw: VehicleFile = crate::io::read_toml(path)?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let urdf_path = dir.join(&raw.urdf);
    let bodies = super::urdf::read_urdf(&urdf_path)?;
    let cfg = |field: String, msg: String| Error::config(path, field, msg);
    // One binder for the whole file: the elements bind through it, and so does the rest.
    let b = Binder {
        path,
        urdf: &urdf_path,
        bodies: &bodies,
    };
    let find = |field: String, name: &str| b.find(field, name);
    let non_negative = |field: String, values: &[f64]| b.non_negative(field, values);
    let positive = |field: String, v: f64| b.positive(field, v);
    let mut elements = Vec::new();
    for (i, e) in raw.shear_pad.iter().enumerate() {
        elements.push(Element::ShearPad(ShearPad::bind(
            &format!("shear_pad[{i}]"),
            e,
            &b,
        )?));
    }
    let mut nests = Vec::new();
    for (i, e) in raw.spring_nest.iter().enumerate() {
        nests.push(elements.len());
        elements.push(Element::SpringNest(SpringNest::bind(
            &format!("spring_nest[{i}]"),
            e,
            &b,
        )?));
    }
    let mut wedges = Vec::new();
    for (i, e) in raw.wedge_damper.iter().enumerate() {
        let f = format!("wedge_damper[{i}]");
        // The nest between the same bodies presses this wedge.
        let (u, l) = (
            b.find(format!("{f}.upper"), &e.upper)?,
            b.find(format!("{f}.lower"), &e.lower)?,
        );
        let nest = nests
            .iter()
            .find_map(|&k| match &elements[k] {
                Element::SpringNest(n) if n.upper.body == u && n.lower.body == l => {
                    Some((k, n.clone()))
                }
                _ => None,
            })
            .ok_or_else(|| {
                b.err(
                    f.clone(),
                    format!(
                        "no spring_nest between \"{}\" and \"{}\" to press the wedge",
                        e.upper, e.lower
                    ),
                )
            })?;
        wedges.push((elements.len(), nest.0));
        elements.push(Element::WedgeDamper(WedgeDamper::bind(&f, e, nest.1, &b)?));
    }
    for (i, e) in raw.centre_plate.iter().enumerate() {
        elements.push(Element::CentrePlate(CentrePlate::bind(
            &format!("centre_plate[{i}]"),
            e,
            &b,
        )?));
    }
    for (i, e) in raw.side_bearer.iter().enumerate() {
        elements.push(Element::SideBearer(SideBearer::bind(
            &format!("side_bearer[{i}]"),
            e,
            &b,
        )?));
    }
    for (i, e) in raw.lateral_stop.iter().enumerate() {
        elements.push(Element::LateralStop(LateralStop::bind(
            &format!("lateral_stop[{i}]"),
            e,
            &b,
        )?));
    }
    for (i, e) in raw.cross_bracing.iter().enumerate() {
        elements.push(Element::CrossBracing(CrossBracing::bind(
            &format!("cross_bracing[{i}]"),
            e,
            &b,
        )?));
    }
    for (i, e) in raw.track_spring.iter().enumerate() {
        elements.push(Element::TrackSpring(TrackSpring::bind(
            &format!("track_spring[{i}]"),
            e,
            &b,
        )?));
    }

    let c = &raw.contact;
    if c.wheelsets.is_empty() {
        return Err(cfg(
            "contact.wheelsets".into(),
            "list at least one wheelset link".into(),
        ));
    }
    let wheelsets = c
        .wheelsets
        .iter()
        .enumerate()
        .map(|(i, n)| find(format!("contact.wheelsets[{i}]"), n))
        .collect::<Result<Vec<_>>>()?;
    positive("contact.nominal_radius_m".into(), c.nominal_radius_m)?;
    positive("contact.flange_back_m".into(), c.flange_back_m)?;
    positive("contact.gauge_m".into(), c.gauge_m)?;
    positive("contact.friction".into(), c.friction)?;
    positive("contact.young_pa".into(), c.young_pa)?;
    non_negative("contact.rail_inclination".into(), &[c.rail_inclination])?;
    non_negative("contact.damping_ratio".into(), &[c.damping_ratio])?;
    if !(c.flange_angle_deg > 30.0 && c.flange_angle_deg < 89.0) {
        return Err(cfg(
            "contact.flange_angle_deg".into(),
            format!("must lie in (30, 89)°, got {}", c.flange_angle_deg),
        ));
    }
    if !(0.0..0.5).contains(&c.poisson) {
        return Err(cfg(
            "contact.poisson".into(),
            format!("must lie in [0, 0.5), got {}", c.poisson),
        ));
    }
    let law = CreepLaw::parse(&c.creep_law).ok_or_else(|| {
        cfg(
            "contact.creep_law".into(),
            format!(
                "unknown law \"{}\": use polach, fastsim or linear",
                c.creep_law
            ),
        )
    })?;
    let accelerometers = match &raw.accelerometers {
        None => Accelerometers::default(),
        Some(a) => Accelerometers::parse(a).ok_or_else(|| {
            cfg(
                "accelerometers".into(),
                format!("unknown reading \"{a}\": use kinematic or specific-force"),
            )
        })?,
    };
    let resolve = |spec: &str| -> String {
        if Path::new(spec).extension().is_some() {
            dir.join(spec).to_string_lossy().into_owned()
        } else {
            spec.to_string()
        }
    };
    let wheel = profile::wheel_by_name_or_file(&resolve(&c.wheel_profile))
        .map_err(|e| cfg("contact.wheel_profile".into(), e.to_string()))?;
    let rail = profile::rail_by_name_or_file(&resolve(&c.rail_profile))
        .map_err(|e| cfg("contact.rail_profile".into(), e.to_string()))?;
    let inclination = if c.rail_inclination > 0.0 {
        (1.0 / c.rail_inclination).atan()
    } else {
        0.0
    };
    let geometry = WheelsetGeometry::new(
        wheel,
        rail,
        inclination,
        c.gauge_m,
        c.flange_back_m,
        positive("contact.tape_offset_m".into(), c.tape_offset_m)?,
        c.nominal_radius_m,
    )
    .map_err(|e| cfg("contact".into(), e.to_string()))?;

    let hauling = match &raw.hauling {
        None => None,
        Some(h) => Some(Hauling {
            body: find("hauling.link".into(), &h.link)?,
            proportional: positive("hauling.proportional".into(), h.proportional)?,
            integral: {
                non_negative("hauling.integral".into(), &[h.integral])?;
                h.integral
            },
        }),
    };
    let sensors = match &raw.sensors {
        None => None,
        Some(s) => {
            let wheelset = find("sensors.wheelset".into(), &s.wheelset)?;
            let pos = wheelsets
                .iter()
                .position(|&w| w == wheelset)
                .ok_or_else(|| {
                    cfg(
                        "sensors.wheelset".into(),
                        format!("\"{}\" is not in contact.wheelsets", s.wheelset),
                    )
                })?;
            let label_wheel =
                super::parse_wheel(&s.label_wheel, wheelsets.len()).ok_or_else(|| {
                    cfg(
                        "sensors.label_wheel".into(),
                        format!(
                            "\"{}\" is not a wheel: use 1L … {}R",
                            s.label_wheel,
                            wheelsets.len()
                        ),
                    )
                })?;
            let _ = pos;
            Some(SensorLayout {
                bolster: find("sensors.bogie[0]".into(), &s.bogie[0])?,
                frame_left: find("sensors.bogie[1]".into(), &s.bogie[1])?,
                frame_right: find("sensors.bogie[2]".into(), &s.bogie[2])?,
                carbody: find("sensors.carbody".into(), &s.carbody)?,
                wheelset,
                label_wheel,
            })
        }
    };

    let mut vehicle = Vehicle {
        name: raw.name.unwrap_or_else(|| "vehicle".into()),
        source: path.to_path_buf(),
        bodies,
        elements,
        contact: ContactSettings {
            wheelsets,
            geometry,
            friction: c.friction,
            law,
            material: Material {
                young: c.young_pa,
                poisson: c.poisson,
            },
            damping_ratio: c.damping_ratio,
            flange_angle: c.flange_angle_deg.to_radians(),
            table: std::sync::OnceLock::new(),
        },
        hauling,
        sensors,
        accelerometers,
    };
    vehicle.distribute_static_load(path)?;
    // Wedges read the nest's static compression.
    for (w, n) in wedges {
        if let Element::SpringNest(nest) = vehicle.elements[n].clone()
            && let Element::WedgeDamper(wd) = &mut vehicle.elements[w]
        {
            wd.nest = nest;
        }
    }
    Ok(vehicle)
}
