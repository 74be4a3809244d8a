//! The vehicle TOML file: its top-level tables, read and validated into a [`Vehicle`]. Each
//! force element reads its own table (`bind` in its file); the contact, hauling and sensor
//! tables are read here.

use super::binder::Binder;
use super::elements::{ForceElement, for_each_element};
use super::{Accelerometers, ContactSettings, Element, Hauling, SensorLayout, Vehicle};
use crate::contact::{CreepLaw, Material, WheelsetGeometry, profile};
use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::Path;

/// The vehicle file and the binding of its element tables, made from the one registration
/// list of element kinds (`elements::for_each_element`): one array of tables per kind, bound in
/// the list's order.
macro_rules! define_vehicle_file {
    ($($variant:ident $table:ident $doc:literal,)*) => {
        #[derive(Debug, Deserialize)]
        #[serde(deny_unknown_fields)]
        struct VehicleFile {
            name: Option<String>,
            urdf: String,
            contact: ContactFile,
            $(
                #[serde(default)]
                $table: Vec<<super::elements::$variant as ForceElement>::File>,
            )*
            hauling: Option<HaulingFile>,
            sensors: Option<SensorsFile>,
            accelerometers: Option<String>,
            #[serde(default)]
            wheel_defect: Vec<super::wheel_defect::WheelDefectFile>,
        }

        /// Binds every element table, kind by kind in registration order, each row named by
        /// its table and index (`shear_pad[3]`).
        fn bind_elements(raw: &VehicleFile, b: &Binder) -> Result<Vec<Element>> {
            let mut elements = Vec::new();
            $(
                for (i, e) in raw.$table.iter().enumerate() {
                    let field = format!("{}[{i}]", stringify!($table));
                    let element = super::elements::$variant::bind(&field, e, b, &elements)?;
                    elements.push(Element::$variant(element));
                }
            )*
            Ok(elements)
        }
    };
}
for_each_element!(define_vehicle_file);

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
    /// Friction on the gauge face (default: `friction`).
    flange_friction: Option<f64>,
    #[serde(default = "default_law")]
    creep_law: String,
    /// Polach 2005's parameters (with `creep_law = "polach"`).
    polach: Option<PolachFile>,
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
    /// Mirror the wheel profile file's y (its field side to −y).
    #[serde(default)]
    wheel_profile_mirror_y: bool,
    /// Mirror the rail profile file's y (MiniProf rails are measured with the field side to −y).
    #[serde(default)]
    rail_profile_mirror_y: bool,
}

/// `[contact.polach]`: Polach 2005's reduction factors and falling friction.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PolachFile {
    /// Reduction factor of the adhesion term, kA.
    ka: f64,
    /// Reduction factor of the slip term, kS.
    ks: f64,
    /// Friction at infinite slip velocity over the static, A.
    floor: f64,
    /// Fall of friction with slip velocity, B, s/m.
    decay_s_per_m: f64,
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
    load_edited(path, None, &mut |_| Ok(()))
}

/// [`load`] with the file's text given (`text`, the path still resolving the URDF and the
/// profiles) and the URDF's bodies changed by `bodies` before anything binds to them.
pub(super) fn load_edited(
    path: &Path,
    text: Option<&str>,
    bodies: &mut dyn FnMut(&mut [super::Body]) -> Result<()>,
) -> Result<Vehicle> {
    let raw: VehicleFile = match text {
        Some(t) => crate::io::parse_toml(t, path)?,
        None => crate::io::read_toml(path)?,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let urdf_path = dir.join(&raw.urdf);
    if !urdf_path.is_file() {
        return Err(Error::config(
            path,
            "urdf",
            format!(
                "{} is not there (a vehicle's URDF is found beside its TOML file)",
                urdf_path.display()
            ),
        ));
    }
    let mut bodies_read = super::urdf::read_urdf(&urdf_path)?;
    bodies(&mut bodies_read)?;
    let bodies = bodies_read;
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
    let elements = bind_elements(&raw, &b)?;

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
    let mut law = CreepLaw::parse(&c.creep_law).ok_or_else(|| {
        cfg(
            "contact.creep_law".into(),
            format!(
                "unknown law \"{}\": use polach, fastsim or linear",
                c.creep_law
            ),
        )
    })?;
    if let Some(p) = &c.polach {
        let CreepLaw::Polach(_) = law else {
            return Err(cfg(
                "contact.polach".into(),
                format!(
                    "Polach's parameters need creep_law = \"polach\", not \"{}\"",
                    c.creep_law
                ),
            ));
        };
        if !(p.ks > 0.0 && p.ks <= p.ka && p.ka <= 1.0) {
            return Err(cfg(
                "contact.polach.ka".into(),
                format!(
                    "Polach's reduction factors need 0 < ks ≤ ka ≤ 1, got ka {} and ks {}",
                    p.ka, p.ks
                ),
            ));
        }
        if !(p.floor > 0.0 && p.floor <= 1.0) {
            return Err(cfg(
                "contact.polach.floor".into(),
                format!(
                    "the friction at infinite slip over the static lies in (0, 1], got {}",
                    p.floor
                ),
            ));
        }
        if !(p.decay_s_per_m >= 0.0 && p.decay_s_per_m.is_finite()) {
            return Err(cfg(
                "contact.polach.decay_s_per_m".into(),
                format!("must be ≥ 0 s/m, got {}", p.decay_s_per_m),
            ));
        }
        law = CreepLaw::Polach(crate::contact::PolachParams {
            ka: p.ka,
            ks: p.ks,
            floor: p.floor,
            decay: p.decay_s_per_m,
        });
    }
    let flange_friction = c.flange_friction.unwrap_or(c.friction);
    if !(flange_friction > 0.0 && flange_friction < 1.0) {
        return Err(cfg(
            "contact.flange_friction".into(),
            format!("must lie in (0, 1), got {flange_friction}"),
        ));
    }
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
    let mirror = |m: bool| profile::LoadOptions { mirror_y: m };
    let wheel = profile::wheel_by_name_or_file(
        &resolve(&c.wheel_profile),
        mirror(c.wheel_profile_mirror_y),
    )
    .map_err(|e| cfg("contact.wheel_profile".into(), e.to_string()))?;
    let rail =
        profile::rail_by_name_or_file(&resolve(&c.rail_profile), mirror(c.rail_profile_mirror_y))
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

    let wheel_defects =
        super::wheel_defect::bind(path, &raw.wheel_defect, c.nominal_radius_m, wheelsets.len())?;
    let mut vehicle = Vehicle {
        name: raw.name.unwrap_or_else(|| "vehicle".into()),
        source: path.to_path_buf(),
        bodies,
        elements,
        contact: ContactSettings {
            wheelsets,
            geometry,
            friction: c.friction,
            flange_friction,
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
        wheel_defects,
    };
    vehicle.distribute_static_load(path)?;
    // Elements that read others' static state (wedges, their nest's compression).
    let settled = vehicle.elements.clone();
    for e in &mut vehicle.elements {
        e.settle(&settled);
    }
    Ok(vehicle)
}
