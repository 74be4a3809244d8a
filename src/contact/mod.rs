//! Wheel–rail contact: profiles, contact geometry, Hertz normal contact, creep forces.

pub mod creep;
pub mod elastic;
pub mod geometry;
pub mod hertz;
pub mod kalker;
pub mod profile;
pub mod validate;
pub mod wheel_rail;

pub use creep::{CreepContact, CreepForce, CreepLaw, Creepage};
pub use geometry::{ContactState, ContactTable, Side, WheelContact, WheelsetGeometry};
pub use hertz::{HertzEllipse, HertzShape, Material};
pub use kalker::KalkerCoefficients;
pub use profile::Profile;
pub use wheel_rail::{
    CREEP_SPEED_FLOOR, ContactFrame, ContactModel, PatchForce, WheelForces, WheelOnRail, evaluate,
    height_for_load,
};
