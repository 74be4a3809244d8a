//! Vehicle model: rigid bodies from a URDF file, force elements, wheel–rail contact settings and
//! the sensor layout from a TOML file beside it (urdf-rs drops unknown XML, so suspension data
//! does not live in the URDF).

mod binder;
mod body;
pub mod elements;
mod file;
mod urdf;
mod wheel;
pub mod wheel_defect;

pub use wheel::{parse_wheel, wheel_name};
pub use wheel_defect::{Flat, WheelDefect};

pub use body::{Attachment, Body, BodyState, Wrench};
pub use elements::Element;
use elements::Support;

use crate::contact::{CreepLaw, Material, WheelsetGeometry};
use crate::error::{Error, Result};
use nalgebra::Vector3;
use std::path::{Path, PathBuf};

/// Wheel–rail contact settings of a vehicle.
#[derive(Debug, Clone)]
pub struct ContactSettings {
    /// Body indices of the wheelsets, front to rear.
    pub wheelsets: Vec<usize>,
    /// Wheelset and rail geometry.
    pub geometry: WheelsetGeometry,
    /// Friction coefficient.
    pub friction: f64,
    /// Friction coefficient on the rail's gauge face (the flange's; the tread's unless the
    /// file or the condition's `gauge_face` says otherwise).
    pub flange_friction: f64,
    /// Creep force law.
    pub law: CreepLaw,
    /// Elastic constants.
    pub material: Material,
    /// Damping ratio of the normal contact.
    pub damping_ratio: f64,
    /// Largest flange angle of the wheel profile, rad (Nadal's limit).
    pub flange_angle: f64,
    /// Contact table, built on first use and shared by every run of this vehicle (and every
    /// vehicle of the same geometry).
    pub(crate) table: std::sync::OnceLock<std::sync::Arc<crate::contact::ContactTable>>,
}

impl ContactSettings {
    /// Half-range of the contact table in lateral shift, m.
    pub const TABLE_RANGE: f64 = 40e-3;
    /// Step of the contact table, m.
    pub const TABLE_STEP: f64 = 1e-4;

    /// The settings of the one contact evaluation ([`crate::contact::evaluate`]).
    pub fn model(&self) -> crate::contact::ContactModel {
        crate::contact::ContactModel {
            material: self.material,
            friction: self.friction,
            flange_friction: self.flange_friction,
            law: self.law,
            damping_ratio: self.damping_ratio,
        }
    }

    /// The contact table over ±40 mm every 0.1 mm (built on first use, or shared with any
    /// vehicle of the same wheelset geometry built before in this process).
    pub fn table(&self) -> &crate::contact::ContactTable {
        self.table.get_or_init(|| {
            self.geometry
                .shared_table(Self::TABLE_RANGE, Self::TABLE_STEP)
        })
    }
}

impl Vehicle {
    /// The quasi-static contact of this vehicle's first wheelset with `load` N on each wheel:
    /// its profiles, contact table and contact settings, exactly what its runs compute
    /// (`railforce contact --vehicle`).
    pub fn quasi_static(&self, load: f64) -> crate::contact::QuasiStatic {
        let c = &self.contact;
        crate::contact::QuasiStatic {
            table: c.table().clone(),
            model: c.model(),
            mass: 0.5 * self.bodies[c.wheelsets[0]].mass,
            r0: c.geometry.nominal_radius,
            load,
            flange_angle: c.flange_angle,
        }
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

/// What the virtual accelerometers read (assets/docs/physics.md §5 lets either be chosen, once).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Accelerometers {
    /// Specific force `a − g` in body axes (what a DC accelerometer reads): +9.81 m/s²
    /// vertically at rest; laterally on a canted curve, the uncompensated acceleration that
    /// drives the quasi-static load transfer between the wheels. The default.
    #[default]
    SpecificForce,
    /// Kinematic acceleration `a` in body axes, gravity excluded (a multibody code's
    /// acceleration output): 0 at rest. Loses the body's tilt against gravity, hence the
    /// load transfer (assets/docs/physics.md §2).
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
    /// Out-of-round wheels (`[[wheel_defect]]`), none by default.
    pub wheel_defects: Vec<WheelDefect>,
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

    /// The shortest wave the wheels' out-of-roundness rolls onto the rail, m: half a flat's
    /// length, half a polygon's period; None with round wheels.
    pub fn shortest_wave(&self) -> Option<f64> {
        let turn = 2.0 * std::f64::consts::PI * self.contact.geometry.nominal_radius;
        self.wheel_defects
            .iter()
            .flat_map(|d| {
                let flat = d.flat.map(|f| 0.5 * f.rounded.unwrap_or(f.length));
                let polygon = d.polygon.map(|(n, _)| 0.5 * turn / n as f64);
                flat.into_iter().chain(polygon)
            })
            .reduce(f64::min)
    }

    /// Total mass, kg.
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// Static wheel load Q0, kN: the weight shared by all wheels (C80 loaded: 122.6 kN).
    pub fn static_wheel_load_kn(&self) -> f64 {
        self.mass() * crate::GRAVITY / (2 * self.contact.wheelsets.len()) as f64 * 1e-3
    }

    /// The same vehicle with its wheelsets' flange back-to-back distance changed by `delta`
    /// (m; the tape circles move out by half of it each). S1002's equivalent conicity turns
    /// with it (0.018 at the Chinese 1 353 mm, 0.18 at its design 1 360 mm), and so does the
    /// hunting (assets/docs/stability.md).
    pub fn with_flange_back_changed(&self, delta: f64) -> Vehicle {
        let mut v = self.clone();
        v.contact.geometry.tape_circle_half += 0.5 * delta;
        v.contact.geometry.flange_back += delta;
        v.contact.table = std::sync::OnceLock::new();
        v
    }

    /// The same vehicle on another wheel–rail pair: `wheel` and `rail` profiles (the rail
    /// inclined by `inclination`, rad; 0 when the profile is already in track position) with the
    /// wheelsets' flange back-to-back distance `flange_back` (m); gauge, tape offset and wheel
    /// radius stay the vehicle's. For stability against conicity (`railforce modes
    /// --wheel-profile …`).
    pub fn with_profile_pair(
        &self,
        wheel: crate::contact::Profile,
        rail: crate::contact::Profile,
        inclination: f64,
        flange_back: f64,
    ) -> Result<Vehicle> {
        let g = &self.contact.geometry;
        let tape_offset = g.tape_circle_half - 0.5 * g.flange_back;
        let mut v = self.clone();
        v.contact.geometry = WheelsetGeometry::new(
            wheel,
            rail,
            inclination,
            2.0 * g.half_gauge,
            flange_back,
            tape_offset,
            g.nominal_radius,
        )?;
        v.contact.table = std::sync::OnceLock::new();
        Ok(v)
    }

    /// The same vehicle with every friction element sliding freely: its friction coefficients
    /// (and the wedges' warp break-out) set to zero, so it carries no friction force — the
    /// `sliding` limit of the linear stability analysis ([`crate::sim::modes`]).
    pub fn without_friction(&self) -> Vehicle {
        let mut v = self.clone();
        for e in &mut v.elements {
            e.frictionless();
        }
        v
    }

    /// Index of a body by name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Reads a vehicle TOML file and the URDF it names, validates everything and computes the
    /// static preloads of the supporting elements from the load path.
    pub fn load(path: &Path) -> Result<Self> {
        file::load(path)
    }

    /// [`Vehicle::load`] of an edited vehicle: the file's TOML as `text` (the path still
    /// resolves its URDF and profiles; `None` reads the file) and its URDF bodies changed by
    /// `bodies` before the elements bind to them and the static loads are shared out. What a
    /// plan's `[vary]` draws reaches the wagon this way, validated as the file would be.
    pub fn load_edited(
        path: &Path,
        text: Option<&str>,
        bodies: &mut dyn FnMut(&mut [Body]) -> Result<()>,
    ) -> Result<Self> {
        file::load_edited(path, text, bodies)
    }

    /// Preloads of the vertical supports from the load path, top down: each body's weight plus
    /// what it carries is shared equally by its supports without a given preload (side bearers
    /// keep theirs). Checks that the shares balance the body's moments.
    pub(crate) fn distribute_static_load(&mut self, path: &Path) -> Result<()> {
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
                match e.support() {
                    Some(Support::Preloaded { upper, preload, .. }) if upper == b => {
                        fixed += preload
                    }
                    Some(Support::Shared { upper, .. }) if upper.body == b => free.push(k),
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
                let Some(Support::Shared { lower, .. }) = self.elements[k].support() else {
                    unreachable!("a free support is shared")
                };
                self.elements[k].take_share(share);
                carried[lower] += share;
            }
            for e in &self.elements {
                if let Some(Support::Preloaded {
                    upper,
                    lower,
                    preload,
                }) = e.support()
                    && upper == b
                {
                    carried[lower] += preload;
                }
            }
        }
        Ok(())
    }

    fn support_point(&self, k: usize) -> Vector3<f64> {
        let Some(Support::Shared { upper, .. }) = self.elements[k].support() else {
            unreachable!("a free support is shared")
        };
        self.bodies[upper.body].position + upper.local
    }
}
