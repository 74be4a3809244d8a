//! Wheel–rail contact: profiles, contact geometry, Hertz normal contact, creep forces.

pub mod creep;
pub mod hertz;
pub mod kalker;
pub mod profile;

pub use creep::{CreepContact, CreepForce, CreepLaw, Creepage};
pub use hertz::{HertzEllipse, HertzShape, Material};
pub use kalker::KalkerCoefficients;
pub use profile::Profile;
