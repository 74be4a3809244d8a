//! One wheel on its rail, the single contact evaluation every caller uses (the simulation
//! step, `railforce contact`, `bench contact`): the elastic strip contact of
//! [`super::elastic`] gives one or two patches, each gets its normal damping from the
//! wheel's approach velocity, its creepages from the wheel's motion relative to the rail,
//! its Hertz ellipse and the creep law; the result is the rail's force and moment on the
//! wheelset in the track frame.

use super::creep::{CreepContact, CreepForce, CreepLaw, Creepage};
use super::geometry::Side;
use super::hertz::{HertzEllipse, Material};
use super::kalker::KalkerCoefficients;
use super::table::ContactTable;

/// Creepages are slip velocities over the running speed; below this speed (m/s) the speed is
/// held here: creep forces act as dampers of strength `G·a·b·C/V`, which neither creep theory
/// nor an explicit step follows as V → 0.
pub const CREEP_SPEED_FLOOR: f64 = 5.0;

/// Contact angle beyond which a patch lies on the rail's gauge face and takes the flange's
/// friction, rad (35°: past the gauge corner's middle, where wayside lubricators' grease
/// lies; an estimate).
pub const GAUGE_FACE_ANGLE: f64 = 35.0 * std::f64::consts::PI / 180.0;

/// Contact settings of a vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactModel {
    /// Elastic constants.
    pub material: Material,
    /// Friction coefficient.
    pub friction: f64,
    /// Friction coefficient of a patch on the gauge face (contact angle beyond
    /// [`GAUGE_FACE_ANGLE`]): the flange's, lubricated or dry.
    pub flange_friction: f64,
    /// Creep force law.
    pub law: CreepLaw,
    /// Damping ratio of the normal contact (of the linearised contact spring with the mass
    /// behind it).
    pub damping_ratio: f64,
}

/// A wheel relative to its rail (track axes: x ahead, y left, z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelOnRail {
    /// Which wheel.
    pub side: Side,
    /// Lateral shift of the wheelset centre relative to this rail's nominal place (the
    /// irregularity and the rail's own deflection removed), m.
    pub y: f64,
    /// Height of the wheelset centre above this rail's top, m.
    pub height: f64,
    /// Roll of the wheelset relative to the rail plane, rad (+ raises the left wheel).
    pub roll: f64,
    /// Yaw of the wheelset relative to the track, rad.
    pub yaw: f64,
    /// Velocity of the wheelset centre relative to the rail's material, m/s.
    pub velocity: [f64; 3],
    /// Angular velocity of the wheelset, rad/s.
    pub angular_velocity: [f64; 3],
    /// Lateral and vertical velocity of the rail surface under the moving wheel from the
    /// irregularity's slope (`V·dy/ds`, `V·dz/ds`), m/s: closes the gap without moving the
    /// rail's material.
    pub surface_rate: [f64; 2],
    /// Running speed (for the creepages), m/s.
    pub speed: f64,
    /// Mass behind the contact (half the wheelset), kg.
    pub mass: f64,
}

impl WheelOnRail {
    /// A wheelset rolling at `speed` on wheels of radius `r0`, centred on its rail at
    /// `height`, no other motion.
    pub fn rolling(side: Side, speed: f64, r0: f64, height: f64, mass: f64) -> Self {
        WheelOnRail {
            side,
            y: 0.0,
            height,
            roll: 0.0,
            yaw: 0.0,
            velocity: [speed, 0.0, 0.0],
            angular_velocity: [0.0, speed / r0, 0.0],
            surface_rate: [0.0; 2],
            speed,
            mass,
        }
    }
}

/// One contact patch of a wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchForce {
    /// Normal load (elastic + damping), N.
    pub normal: f64,
    /// Contact angle, rad.
    pub angle: f64,
    /// Load centre relative to the wheelset centre, track axes, m.
    pub point: [f64; 3],
    /// Rolling radius at the load centre, m.
    pub radius: f64,
    /// Hertz ellipse under `normal`.
    pub ellipse: HertzEllipse,
    /// Kalker's coefficients of that ellipse.
    pub kalker: KalkerCoefficients,
    /// Creepages.
    pub creepage: Creepage,
    /// Creep forces in the contact plane, N.
    pub creep: CreepForce,
    /// Force of the rail on the wheel, track axes, N.
    pub force: [f64; 3],
    /// Contact frame.
    pub frame: ContactFrame,
    /// Normal damping coefficient of the patch, N·s/m.
    pub damping: f64,
    /// Normal stiffness of the patch, linearised at its load, N/m.
    pub stiffness: f64,
    /// Rate at which wheel and rail approach along the normal, m/s (the rail surface's rise
    /// under the moving wheel included).
    pub approach_rate: f64,
}

/// Everything the rail does to one wheel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelForces {
    /// The patches, the larger load first.
    pub patches: [Option<PatchForce>; 2],
    /// Total force of the rail on the wheel, track axes, N.
    pub force: [f64; 3],
    /// Its moment about the wheelset centre, track axes, N·m.
    pub moment: [f64; 3],
    /// Least gap between wheel and rail, m (negative: the deepest penetration).
    pub gap: f64,
    /// Contact angle and rolling radius of the rigid contact at this shift (for reports when
    /// the wheel is lifted).
    pub rigid_angle: f64,
    /// See `rigid_angle`.
    pub rigid_radius: f64,
}

impl WheelForces {
    /// |Y|/Q of the wheel (NaN when it carries no load).
    pub fn y_over_q(&self) -> f64 {
        if self.force[2] > 1.0 {
            self.force[1].abs() / self.force[2]
        } else {
            f64::NAN
        }
    }

    /// The patch with the larger load.
    pub fn main(&self) -> Option<&PatchForce> {
        self.patches[0].as_ref()
    }
}

/// Contact frame of a wheel: rolling direction `t_x`, lateral in the contact plane `t_y`, and
/// the normal `n` along which the rail pushes the wheel, all in the track frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// Rolling direction.
    pub tx: [f64; 3],
    /// Lateral direction in the contact plane.
    pub ty: [f64; 3],
    /// Normal, pointing into the wheel.
    pub n: [f64; 3],
}

impl ContactFrame {
    /// Frame of a contact with angle `angle` on `side` (positive angles tilt the normal toward
    /// the track centre… of the wheel: the flange is pushed toward the field side).
    pub fn new(side: Side, angle: f64, yaw: f64) -> Self {
        let (sy, cy) = crate::angle::sin_cos(yaw);
        Self::with_yaw(side, angle, sy, cy)
    }

    /// [`Self::new`] from the yaw's sine and cosine (both patches of a wheel share them).
    fn with_yaw(side: Side, angle: f64, sy: f64, cy: f64) -> Self {
        let s = side.sign();
        let (sd, cd) = crate::angle::sin_cos(angle);
        ContactFrame {
            tx: [cy, sy, 0.0],
            ty: [-sy * cd, cy * cd, s * sd],
            n: [sy * s * sd, -cy * s * sd, cd],
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The one contact evaluation: the rail's forces on one wheel in the state `w`, from the
/// vehicle's contact table and settings.
///
/// ```no_run
/// use railforce::contact::{Side, WheelOnRail, evaluate, height_for_load};
/// use railforce::vehicle::Vehicle;
/// let v = Vehicle::load("vehicles/c80.toml".as_ref())?;
/// let (table, model) = (v.contact.table(), v.contact.model());
/// let mut w = WheelOnRail::rolling(Side::Left, 60.0 / 3.6, 0.42, 0.0, 650.0);
/// w.y = 3e-3; // the wheelset 3 mm to the left
/// w.height = height_for_load(table, &model, &w, 122.6e3);
/// let f = evaluate(table, &model, &w);
/// println!("Y {:.1} kN, Q {:.1} kN", f.force[1] / 1e3, f.force[2] / 1e3);
/// # Ok::<(), railforce::Error>(())
/// ```
pub fn evaluate(table: &ContactTable, model: &ContactModel, w: &WheelOnRail) -> WheelForces {
    let mut out = WheelForces::default();
    evaluate_into(table, model, w, &mut out);
    out
}

/// [`evaluate`] into `out` (overwritten whole): a step's loop keeps one and spares the copies
/// of a large result.
pub fn evaluate_into(
    table: &ContactTable,
    model: &ContactModel,
    w: &WheelOnRail,
    out: &mut WheelForces,
) {
    let k = match w.side {
        Side::Left => 0,
        Side::Right => 1,
    };
    let (i, t) = table.locate(w.y);
    let (z, roll, rigid_angle, rigid_radius) = table.rigid(i, t, k);
    // Approach of the centre below the rigid height, and roll beyond the table's.
    let approach = z - w.height;
    let droll = w.roll - roll;
    let at = super::StripQuery {
        i,
        t,
        k,
        approach,
        roll: droll,
    };
    let (loads, gap) = table.strips().patches(&at, &model.material);
    let speed = w.speed.abs().max(CREEP_SPEED_FLOOR);
    let (sy, cy) = crate::angle::sin_cos(w.yaw);
    let (sr, cr) = crate::angle::sin_cos(droll);
    out.patches = [None, None];
    let (mut force, mut moment) = ([0.0; 3], [0.0; 3]);
    for (slot, load) in out.patches.iter_mut().zip(loads) {
        let Some(l) = load else { continue };
        // Load centre from the table (zero yaw, table roll), turned by the extra roll and the
        // yaw so it stays on the spinning wheel (else the spin about a slightly tilted axle
        // shows up as false longitudinal creepage).
        let (y1, z1) = (cr * l.y - sr * l.z, sr * l.y + cr * l.z);
        let point = [-sy * y1, cy * y1, z1];
        let frame = ContactFrame::with_yaw(w.side, l.angle, sy, cy);
        let vc = {
            let r = cross(w.angular_velocity, point);
            [
                w.velocity[0] + r[0],
                w.velocity[1] + r[1],
                w.velocity[2] + r[2],
            ]
        };
        // Normal damping on the approach rate (wheel into rail, the rail surface rising under
        // it), with the linearised patch stiffness and the mass behind the contact.
        let rate =
            -dot(vc, frame.n) + (w.surface_rate[0] * frame.n[1] + w.surface_rate[1] * frame.n[2]);
        let k_n = l.stiffness / frame.n[2].max(0.2); // n_z = cos(contact angle)
        let damping = 2.0 * model.damping_ratio * (k_n * w.mass).sqrt();
        let normal = (l.normal + damping * rate).max(0.0);
        if normal <= 0.0 {
            continue;
        }
        let creepage = Creepage {
            x: dot(vc, frame.tx) / speed,
            y: dot(vc, frame.ty) / speed,
            spin: dot(w.angular_velocity, frame.n) / speed,
        };
        let ellipse = l.hertz.ellipse(normal, &model.material);
        let kalker = KalkerCoefficients::new(ellipse.a / ellipse.b, model.material.poisson);
        let creep = model.law.force_with(
            &CreepContact {
                a: ellipse.a,
                b: ellipse.b,
                normal,
                mu: if l.angle.abs() > GAUGE_FACE_ANGLE {
                    model.flange_friction
                } else {
                    model.friction
                },
                shear_modulus: model.material.shear_modulus(),
                poisson: model.material.poisson,
                speed,
            },
            &kalker,
            creepage,
        );
        let f: [f64; 3] = std::array::from_fn(|j| {
            creep.x * frame.tx[j] + creep.y * frame.ty[j] + normal * frame.n[j]
        });
        let m = cross(point, f);
        for j in 0..3 {
            force[j] += f[j];
            moment[j] += m[j];
        }
        *slot = Some(PatchForce {
            normal,
            angle: l.angle,
            point,
            radius: l.radius,
            ellipse,
            kalker,
            creepage,
            creep,
            force: f,
            frame,
            damping,
            stiffness: k_n,
            approach_rate: rate,
        });
    }
    let patches = &mut out.patches;
    if let [Some(a), Some(b)] = &patches
        && b.normal > a.normal
    {
        patches.swap(0, 1);
    }
    if patches[0].is_none() && patches[1].is_some() {
        patches.swap(0, 1);
    }
    out.force = force;
    out.moment = moment;
    out.gap = gap;
    out.rigid_angle = rigid_angle;
    out.rigid_radius = rigid_radius;
}

/// Largest approach, either way, that [`height_for_load`] searches, m.
const APPROACH_BRACKET: f64 = 0.02;

/// The height of the wheelset centre above the rail at which this wheel carries the vertical
/// load `load` (N) in the state `w` otherwise (bisection on the approach, the same
/// evaluation as a run; damping plays no part when nothing moves).
pub fn height_for_load(
    table: &ContactTable,
    model: &ContactModel,
    w: &WheelOnRail,
    load: f64,
) -> f64 {
    let ts = table.lookup(w.y);
    let q = |approach: f64| {
        let mut v = *w;
        v.height = ts.z - approach;
        evaluate(table, model, &v).force[2]
    };
    // Bracket the approach: up from the rigid height, or down from it when the wheel already
    // carries more (a roll beyond the table's presses one wheel in and lifts the other by up
    // to a few millimetres).
    let (mut lo, mut hi) = (0.0, 1e-4);
    while q(hi) < load && hi < APPROACH_BRACKET {
        lo = hi;
        hi *= 2.0;
    }
    let mut step = 1e-4;
    while lo > -APPROACH_BRACKET && q(lo) > load {
        hi = lo;
        lo -= step;
        step *= 2.0;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if q(mid) < load {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    ts.z - 0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_frames_are_orthonormal() {
        for side in [Side::Left, Side::Right] {
            let f = ContactFrame::new(side, 0.3, 0.01);
            for (p, q) in [(f.tx, f.ty), (f.ty, f.n), (f.tx, f.n)] {
                assert!(dot(p, q).abs() < 1e-12);
            }
            for v in [f.tx, f.ty, f.n] {
                assert!((dot(v, v) - 1.0).abs() < 1e-12);
            }
        }
    }
}
