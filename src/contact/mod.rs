//! Wheel–rail contact: profiles, contact geometry, Hertz normal contact, creep forces.

mod codec;
mod creep;
mod elastic;
mod flange;
mod geometry;
mod hertz;
mod jacobian;
mod kalker;
mod miniprof;
pub mod profile;
mod quasi_static;
mod table;
mod table_cache;
pub mod validate;
mod wheel_rail;

pub use creep::{CreepContact, CreepForce, CreepLaw, Creepage, PolachParams};
pub use elastic::{PatchLoad, StripQuery, StripTable};
pub use flange::{Flange, MIN_FLANGE_HEIGHT};
pub use geometry::{ContactState, Side, WheelContact, WheelsetGeometry};
pub use hertz::{HertzEllipse, HertzShape, Material};
pub use jacobian::{patch_damping, patch_damping_with_spring, patch_normal, patch_stiffness};
pub use kalker::KalkerCoefficients;
pub use profile::Profile;
pub use quasi_static::{QuasiStatic, StateResult, WheelResult, WheelsetState};
pub use table::ContactTable;
pub use wheel_rail::{
    CREEP_SPEED_FLOOR, ContactFrame, ContactModel, GAUGE_FACE_ANGLE, PatchForce, WheelForces,
    WheelOnRail, evaluate, evaluate_into, height_for_load,
};

/// Nadal's flange-climb limit `(tan δ − μ)/(1 + μ·tan δ)` of |Y|/Q for the flange angle δ
/// (rad) and friction μ: the one formula the simulator's derailment check and `railforce
/// contact` use.
pub fn nadal_limit(flange_angle: f64, mu: f64) -> f64 {
    let t = flange_angle.tan();
    (t - mu) / (1.0 + mu * t)
}
