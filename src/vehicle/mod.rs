//! Vehicle model: rigid bodies from a URDF file, force elements, wheel–rail contact settings and
//! the sensor layout from a TOML file beside it (urdf-rs drops unknown XML, so suspension data
//! does not live in the URDF).

pub mod body;
pub mod elements;
mod urdf;
mod wheel;

pub use wheel::{parse_wheel, wheel_name};

pub use body::{Attachment, Body, BodyState, Wrench};
pub use elements::Element;

use crate::contact::{CreepLaw, Material, WheelsetGeometry, profile};
use crate::error::{Error, Result};
use elements::{CentrePlate, CrossBracing, NestLaw, ShearPad, SideBearer, SpringNest, WedgeDamper};
use nalgebra::Vector3;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct VehicleFile {
    name: Option<String>,
    urdf: String,
    contact: ContactFile,
    #[serde(default)]
    shear_pad: Vec<ShearPadFile>,
    #[serde(default)]
    spring_nest: Vec<NestFile>,
    #[serde(default)]
    wedge_damper: Vec<WedgeFile>,
    #[serde(default)]
    centre_plate: Vec<CentrePlateFile>,
    #[serde(default)]
    side_bearer: Vec<SideBearerFile>,
    #[serde(default)]
    cross_bracing: Vec<CrossBracingFile>,
    #[serde(default)]
    track_spring: Vec<TrackSpringFile>,
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
struct ShearPadFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NestFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    vertical_stiffness: [f64; 2],
    first_stage_travel_m: f64,
    lateral_stiffness: f64,
    footprint_m: [f64; 2],
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WedgeFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    friction_ratio: f64,
    regularisation_velocity: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CentrePlateFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
    friction: f64,
    radius_m: f64,
    regularisation_rate: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SideBearerFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: f64,
    preload_n: f64,
    friction: f64,
    regularisation_velocity: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CrossBracingFile {
    left: String,
    right: String,
    warp_stiffness: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackSpringFile {
    link: String,
    lateral_stiffness: f64,
    yaw_stiffness: f64,
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

/// Wheel–rail contact settings of a vehicle.
#[derive(Debug, Clone)]
pub struct ContactSettings {
    /// Body indices of the wheelsets, front to rear.
    pub wheelsets: Vec<usize>,
    /// Wheelset and rail geometry.
    pub geometry: WheelsetGeometry,
    /// Friction coefficient.
    pub friction: f64,
    /// Creep force law.
    pub law: CreepLaw,
    /// Elastic constants.
    pub material: Material,
    /// Damping ratio of the normal contact.
    pub damping_ratio: f64,
    /// Contact table, built on first use and shared by every run of this vehicle.
    table: std::sync::OnceLock<crate::contact::ContactTable>,
}

impl ContactSettings {
    /// Half-range of the contact table in lateral shift, m.
    pub const TABLE_RANGE: f64 = 40e-3;
    /// Step of the contact table, m.
    pub const TABLE_STEP: f64 = 1e-4;

    /// The contact table over ±40 mm every 0.1 mm (built once, on first use).
    pub fn table(&self) -> &crate::contact::ContactTable {
        self.table
            .get_or_init(|| self.geometry.table(Self::TABLE_RANGE, Self::TABLE_STEP))
    }
}

/// Speed control that stands for the rest of the train.
#[derive(Debug, Clone, Copy)]
pub struct Hauling {
    /// Body the force acts on.
    pub body: usize,
    /// Proportional gain per unit vehicle mass, 1/s.
    pub proportional: f64,
    /// Integral gain per unit vehicle mass, 1/s².
    pub integral: f64,
}

/// What the virtual accelerometers read (spec physics.md §5 lets either be chosen, once).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Accelerometers {
    /// Specific force `a − g` in body axes (what a DC accelerometer reads): +9.81 m/s²
    /// vertically at rest; laterally on a canted curve, the uncompensated acceleration that
    /// drives the quasi-static load transfer between the wheels. The default.
    #[default]
    SpecificForce,
    /// Kinematic acceleration `a` in body axes, gravity excluded (a multibody code's
    /// acceleration output): 0 at rest. Loses the body's tilt against gravity, hence the
    /// load transfer (README, "Vehicle files").
    Kinematic,
}

impl Accelerometers {
    /// Parses the vehicle file's spelling: `kinematic` or `specific-force`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "kinematic" => Some(Self::Kinematic),
            "specific-force" => Some(Self::SpecificForce),
            _ => None,
        }
    }

    /// The spelling of the vehicle file.
    pub fn name(self) -> &'static str {
        match self {
            Self::Kinematic => "kinematic",
            Self::SpecificForce => "specific-force",
        }
    }

    /// One sentence for metadata files.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Kinematic => {
                "kinematic acceleration a, gravity excluded (0 at rest), body axes; wheelsets in the local track axes (axle-box sensor)"
            }
            Self::SpecificForce => {
                "specific force a - g (+9.81 m/s2 vertically at rest), body axes; wheelsets in the local track axes (axle-box sensor)"
            }
        }
    }
}

/// Bodies that carry the paper's sensors.
#[derive(Debug, Clone)]
pub struct SensorLayout {
    /// Bolster of the instrumented bogie.
    pub bolster: usize,
    /// Left side frame.
    pub frame_left: usize,
    /// Right side frame.
    pub frame_right: usize,
    /// Carbody.
    pub carbody: usize,
    /// Instrumented wheelset.
    pub wheelset: usize,
    /// Label wheel as index into the contact wheels (2·wheelset position + 0 left / 1 right).
    pub label_wheel: usize,
}

/// A vehicle ready to simulate.
#[derive(Debug, Clone)]
pub struct Vehicle {
    /// Name.
    pub name: String,
    /// File it came from.
    pub source: PathBuf,
    /// Rigid bodies.
    pub bodies: Vec<Body>,
    /// Force elements.
    pub elements: Vec<Element>,
    /// Wheel–rail contact.
    pub contact: ContactSettings,
    /// Speed control.
    pub hauling: Option<Hauling>,
    /// Sensor layout (None for models without the paper's bogie, e.g. a single wheelset).
    pub sensors: Option<SensorLayout>,
    /// What every recorded acceleration is.
    pub accelerometers: Accelerometers,
}

impl Vehicle {
    /// The wheel whose forces are the labels, `1L` … (the sensor layout's `label_wheel`; 1L,
    /// the paper's, for a vehicle without one).
    pub fn label_wheel_name(&self) -> String {
        let k = self.sensors.as_ref().map_or(0, |s| s.label_wheel);
        format!(
            "{}{}",
            k / 2 + 1,
            if k.is_multiple_of(2) { 'L' } else { 'R' }
        )
    }

    /// Total mass, kg.
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// Index of a body by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Reads a vehicle TOML file and the URDF it names, validates everything and computes the
    /// static preloads of the supporting elements from the load path.
    pub fn load(path: &Path) -> Result<Self> {
        let raw: VehicleFile = crate::io::read_toml(path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let urdf_path = dir.join(&raw.urdf);
        let bodies = urdf::read_urdf(&urdf_path)?;
        let cfg = |field: String, msg: String| Error::config(path, field, msg);
        let find = |field: String, name: &str| -> Result<usize> {
            bodies.iter().position(|b| b.name == name).ok_or_else(|| {
                cfg(
                    field,
                    format!(
                        "unknown link \"{name}\" (not in {}; links: {})",
                        urdf_path.display(),
                        bodies
                            .iter()
                            .map(|b| b.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })
        };
        let attach = |field: &str, body: usize, at: [f64; 3]| -> Result<Attachment> {
            if at.iter().any(|v| !v.is_finite()) {
                return Err(cfg(format!("{field}.at"), "must be finite".into()));
            }
            Ok(Attachment {
                body,
                local: Vector3::from(at) - bodies[body].position,
            })
        };
        let non_negative = |field: String, values: &[f64]| -> Result<()> {
            if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
                return Err(cfg(field, format!("must not be negative, got {v}")));
            }
            Ok(())
        };
        let positive = |field: String, v: f64| -> Result<f64> {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(cfg(field, format!("must be positive, got {v}")))
            }
        };

        // Upper and lower attachments of a two-point element at the shared point `at`.
        let pair =
            |f: &str, upper: &str, lower: &str, at: [f64; 3]| -> Result<(Attachment, Attachment)> {
                let u = find(format!("{f}.upper"), upper)?;
                let l = find(format!("{f}.lower"), lower)?;
                Ok((attach(f, u, at)?, attach(f, l, at)?))
            };

        let mut elements = Vec::new();
        for (i, e) in raw.shear_pad.iter().enumerate() {
            let f = format!("shear_pad[{i}]");
            non_negative(format!("{f}.stiffness"), &e.stiffness)?;
            non_negative(format!("{f}.damping"), &e.damping)?;
            let (upper, lower) = pair(&f, &e.upper, &e.lower, e.at)?;
            elements.push(Element::ShearPad(ShearPad {
                upper,
                lower,
                stiffness: Vector3::from(e.stiffness),
                damping: Vector3::from(e.damping),
                preload: 0.0,
            }));
        }
        let mut nests = Vec::new();
        for (i, e) in raw.spring_nest.iter().enumerate() {
            let f = format!("spring_nest[{i}]");
            non_negative(format!("{f}.vertical_stiffness"), &e.vertical_stiffness)?;
            positive(format!("{f}.vertical_stiffness"), e.vertical_stiffness[0])?;
            positive(format!("{f}.vertical_stiffness"), e.vertical_stiffness[1])?;
            non_negative(format!("{f}.lateral_stiffness"), &[e.lateral_stiffness])?;
            positive(format!("{f}.first_stage_travel_m"), e.first_stage_travel_m)?;
            let (upper, lower) = pair(&f, &e.upper, &e.lower, e.at)?;
            let nest = SpringNest {
                upper,
                lower,
                law: NestLaw {
                    k1: e.vertical_stiffness[0],
                    k2: e.vertical_stiffness[1],
                    travel1: e.first_stage_travel_m,
                },
                lateral_stiffness: e.lateral_stiffness,
                static_compression: 0.0,
                footprint: {
                    non_negative(format!("{f}.footprint_m"), &e.footprint_m)?;
                    e.footprint_m
                },
            };
            nests.push(elements.len());
            elements.push(Element::SpringNest(nest));
        }
        let mut wedges = Vec::new();
        for (i, e) in raw.wedge_damper.iter().enumerate() {
            let f = format!("wedge_damper[{i}]");
            non_negative(format!("{f}.friction_ratio"), &[e.friction_ratio])?;
            positive(
                format!("{f}.regularisation_velocity"),
                e.regularisation_velocity,
            )?;
            let (upper, lower) = pair(&f, &e.upper, &e.lower, e.at)?;
            // The nest between the same bodies presses this wedge.
            let nest = nests
                .iter()
                .find(|&&k| matches!(&elements[k], Element::SpringNest(n) if n.upper.body == upper.body && n.lower.body == lower.body))
                .copied()
                .ok_or_else(|| {
                    cfg(
                        f.clone(),
                        format!("no spring_nest between \"{}\" and \"{}\" to press the wedge", e.upper, e.lower),
                    )
                })?;
            wedges.push((elements.len(), nest));
            elements.push(Element::WedgeDamper(WedgeDamper {
                upper,
                lower,
                friction_ratio: e.friction_ratio,
                regularisation_velocity: e.regularisation_velocity,
                nest: match &elements[nest] {
                    Element::SpringNest(n) => n.clone(),
                    _ => unreachable!(),
                },
            }));
        }
        for (i, e) in raw.centre_plate.iter().enumerate() {
            let f = format!("centre_plate[{i}]");
            non_negative(format!("{f}.stiffness"), &e.stiffness)?;
            non_negative(format!("{f}.damping"), &e.damping)?;
            non_negative(format!("{f}.friction"), &[e.friction])?;
            positive(format!("{f}.radius_m"), e.radius_m)?;
            positive(format!("{f}.regularisation_rate"), e.regularisation_rate)?;
            let (upper, lower) = pair(&f, &e.upper, &e.lower, e.at)?;
            elements.push(Element::CentrePlate(CentrePlate {
                upper,
                lower,
                stiffness: Vector3::from(e.stiffness),
                damping: Vector3::from(e.damping),
                friction: e.friction,
                radius: e.radius_m,
                regularisation_rate: e.regularisation_rate,
                preload: 0.0,
            }));
        }
        for (i, e) in raw.side_bearer.iter().enumerate() {
            let f = format!("side_bearer[{i}]");
            non_negative(
                format!("{f}.stiffness"),
                &[e.stiffness, e.preload_n, e.friction],
            )?;
            positive(
                format!("{f}.regularisation_velocity"),
                e.regularisation_velocity,
            )?;
            let (upper, lower) = pair(&f, &e.upper, &e.lower, e.at)?;
            elements.push(Element::SideBearer(SideBearer {
                upper,
                lower,
                stiffness: e.stiffness,
                preload: e.preload_n,
                friction: e.friction,
                regularisation_velocity: e.regularisation_velocity,
            }));
        }
        for (i, e) in raw.cross_bracing.iter().enumerate() {
            let f = format!("cross_bracing[{i}]");
            non_negative(format!("{f}.warp_stiffness"), &[e.warp_stiffness])?;
            elements.push(Element::CrossBracing(CrossBracing {
                left: find(format!("{f}.left"), &e.left)?,
                right: find(format!("{f}.right"), &e.right)?,
                warp_stiffness: e.warp_stiffness,
            }));
        }

        for (i, e) in raw.track_spring.iter().enumerate() {
            let f = format!("track_spring[{i}]");
            non_negative(
                format!("{f}.lateral_stiffness"),
                &[e.lateral_stiffness, e.yaw_stiffness],
            )?;
            elements.push(Element::TrackSpring(elements::TrackSpring {
                body: find(format!("{f}.link"), &e.link)?,
                lateral_stiffness: e.lateral_stiffness,
                yaw_stiffness: e.yaw_stiffness,
            }));
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
            0.070,
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
                    parse_wheel(&s.label_wheel, wheelsets.len()).ok_or_else(|| {
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

    /// Preloads of the vertical supports from the load path, top down: each body's weight plus
    /// what it carries is shared equally by its supports without a given preload (side bearers
    /// keep theirs). Checks that the shares balance the body's moments.
    fn distribute_static_load(&mut self, path: &Path) -> Result<()> {
        let g = crate::GRAVITY;
        let n = self.bodies.len();
        let mut carried = vec![0.0; n];
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| {
            self.bodies[b]
                .position
                .z
                .total_cmp(&self.bodies[a].position.z)
        });
        for &b in &order {
            let load = self.bodies[b].mass * g + carried[b];
            let mut fixed = 0.0;
            let mut free: Vec<usize> = Vec::new();
            for (k, e) in self.elements.iter().enumerate() {
                match e {
                    Element::SideBearer(sb) if sb.upper.body == b => fixed += sb.preload,
                    Element::ShearPad(x) if x.upper.body == b => free.push(k),
                    Element::SpringNest(x) if x.upper.body == b => free.push(k),
                    Element::CentrePlate(x) if x.upper.body == b => free.push(k),
                    _ => {}
                }
            }
            if free.is_empty() {
                continue; // carried by the rails (wheelsets) or free
            }
            let share = (load - fixed) / free.len() as f64;
            if share <= 0.0 {
                return Err(Error::config(
                    path,
                    self.bodies[b].name.clone(),
                    "side bearer preloads exceed the load this body puts on its supports",
                ));
            }
            // Moment check: the supports' centroid must lie under the centre of gravity.
            let centroid = free
                .iter()
                .map(|&k| self.support_point(k))
                .fold(Vector3::zeros(), |a, p| a + p)
                / free.len() as f64;
            let cg = self.bodies[b].position;
            if ((centroid.x - cg.x).abs() > 0.05) || ((centroid.y - cg.y).abs() > 0.05) {
                return Err(Error::config(
                    path,
                    self.bodies[b].name.clone(),
                    format!(
                        "its supports are centred at x {:.3}, y {:.3} m, not under its centre of gravity (x {:.3}, y {:.3}): equal static shares would not balance",
                        centroid.x, centroid.y, cg.x, cg.y
                    ),
                ));
            }
            for &k in &free {
                let lower = match &mut self.elements[k] {
                    Element::ShearPad(x) => {
                        x.preload = share;
                        x.lower.body
                    }
                    Element::SpringNest(x) => {
                        x.static_compression = x.law.compression(share);
                        x.lower.body
                    }
                    Element::CentrePlate(x) => {
                        x.preload = share;
                        x.lower.body
                    }
                    _ => unreachable!(),
                };
                carried[lower] += share;
            }
            for e in &self.elements {
                if let Element::SideBearer(sb) = e
                    && sb.upper.body == b
                {
                    carried[sb.lower.body] += sb.preload;
                }
            }
        }
        Ok(())
    }

    fn support_point(&self, k: usize) -> Vector3<f64> {
        let a = match &self.elements[k] {
            Element::ShearPad(x) => x.upper,
            Element::SpringNest(x) => x.upper,
            Element::CentrePlate(x) => x.upper,
            _ => unreachable!(),
        };
        self.bodies[a.body].position + a.local
    }
}
