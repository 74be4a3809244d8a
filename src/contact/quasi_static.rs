//! A wheelset's contact in a quasi-static state: both wheels at a lateral shift and yaw,
//! each pressed to carry a given vertical load, rolling at a speed — the one contact
//! evaluation of a run ([`evaluate`]), without the run. `railforce contact` and its sweeps
//! print it; teaching and checks use it to read forces off the contact model alone.

use super::geometry::Side;
use super::table::ContactTable;
use super::wheel_rail::{ContactModel, WheelForces, WheelOnRail, evaluate, height_for_load};

/// The wheelset and contact a quasi-static state is solved for.
#[derive(Debug, Clone)]
pub struct QuasiStatic {
    /// Contact table of the profile pair.
    pub table: ContactTable,
    /// Material, friction, creep law and damping.
    pub model: ContactModel,
    /// Half the wheelset mass (for the contact damping), kg.
    pub mass: f64,
    /// Nominal rolling radius, m.
    pub r0: f64,
    /// Vertical load per wheel, N.
    pub load: f64,
    /// The wheel's largest flange angle (Nadal's limit), rad.
    pub flange_angle: f64,
}

/// A wheelset's position and motion relative to the track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelsetState {
    /// Lateral shift, m.
    pub y: f64,
    /// Yaw, rad.
    pub yaw: f64,
    /// Roll added to the rigid contact's, rad.
    pub extra_roll: f64,
    /// Running speed, m/s.
    pub speed: f64,
    /// Lateral velocity, m/s.
    pub lateral_velocity: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
    /// Spin about the axle, rad/s; `None`: rolling at the two wheels' mean rolling radius.
    pub spin: Option<f64>,
}

/// One wheel of a solved state.
#[derive(Debug, Clone)]
pub struct WheelResult {
    /// Which wheel.
    pub side: Side,
    /// Its forces and patches.
    pub forces: WheelForces,
    /// Approach of the wheelset centre below its rigid height, m.
    pub approach: f64,
}

/// A solved state: the rigid roll and height, the spin used, both wheels' forces.
#[derive(Debug, Clone)]
pub struct StateResult {
    /// Rigid roll, rad.
    pub roll: f64,
    /// Rigid height of the wheelset centre, m.
    pub height: f64,
    /// Spin used, rad/s.
    pub spin: f64,
    /// Mean rolling radius of the two wheels (NaN when the spin was given), m.
    pub rolling_radius: f64,
    /// Left then right.
    pub wheels: Vec<WheelResult>,
}

impl QuasiStatic {
    /// Nadal's flange-climb limit of |Y|/Q for this wheel and friction.
    pub fn nadal_limit(&self) -> f64 {
        super::nadal_limit(self.flange_angle, self.model.friction)
    }

    /// Both wheels in `state`, each at the height where it carries the load.
    pub fn solve(&self, state: &WheelsetState) -> StateResult {
        let (y, yaw, speed) = (state.y, state.yaw, state.speed);
        let rigid = self.table.lookup(y);
        let wheels_at = |spin: f64| -> Vec<WheelResult> {
            [Side::Left, Side::Right]
                .into_iter()
                .map(|side| {
                    let mut w = WheelOnRail::rolling(side, speed, self.r0, 0.0, self.mass);
                    w.y = y;
                    w.yaw = yaw;
                    w.roll = rigid.roll + state.extra_roll;
                    w.velocity = [
                        speed * yaw.cos() - state.lateral_velocity * yaw.sin(),
                        speed * yaw.sin() + state.lateral_velocity * yaw.cos(),
                        0.0,
                    ];
                    w.angular_velocity = [-spin * yaw.sin(), spin * yaw.cos(), state.yaw_rate];
                    w.height = height_for_load(&self.table, &self.model, &w, self.load);
                    WheelResult {
                        side,
                        forces: evaluate(&self.table, &self.model, &w),
                        approach: rigid.z - w.height,
                    }
                })
                .collect()
        };
        // Default spin: rolling at the mean of the two wheels' actual rolling radii at this
        // shift — the load centres of their elastic patches (one refinement from the rigid
        // contacts' radii) — so a centred wheelset rolls without longitudinal creep.
        let (spin, rolling_radius, wheels) = match state.spin {
            Some(spin) => (spin, f64::NAN, wheels_at(spin)),
            None => {
                let mut r = 0.5 * (rigid.wheels[0].rolling_radius + rigid.wheels[1].rolling_radius);
                let mut wheels = wheels_at(speed / r);
                let radii: Vec<f64> = wheels
                    .iter()
                    .filter_map(|w| w.forces.main().map(|p| p.radius))
                    .collect();
                if radii.len() == 2 {
                    r = 0.5 * (radii[0] + radii[1]);
                    wheels = wheels_at(speed / r);
                }
                (speed / r, r, wheels)
            }
        };
        StateResult {
            roll: rigid.roll,
            height: rigid.z,
            spin,
            rolling_radius,
            wheels,
        }
    }
}
