//! The train around the 3-D wagon: pure one-dimensional longitudinal dynamics of a consist.
//!
//! Every vehicle of a consist (locomotives and wagons, index 0 = head) is a mass on the line,
//! at the along-line position `s` of its centre, moving in +s. Neighbours are joined by a
//! coupling: the free slack of two 16/17-type coupler heads and one MT-2 friction draft gear
//! per car end, in series ([`draft_gear`]). Each vehicle feels its basic running resistance,
//! the curve and the grade ([`resistance`]), the tractive or dynamic-brake effort of a
//! locomotive ([`locomotive`]), the air brake ([`brake`]: a brake-pipe signal travelling from
//! each locomotive, each car's cylinder following with a delay and a time constant) and a
//! driver that holds a speed by notches or follows a schedule ([`driver`]).
//!
//! One vehicle is the 3-D wagon. In the coupled mode ([`Train::step`]) the caller moves it
//! (its own multibody simulation) and reads back the coupler forces at its two ends
//! ([`Train::coupler_forces`]), where its neighbours stand ([`Train::neighbours`]) and the
//! brake shoes' normal force and friction on its treads ([`Train::wagon_brake`]). In the
//! alone mode ([`Train::step_alone`], [`Train::run_alone`]) it is a plain 1-D mass like the
//! others: the mode of the tests and the closed-form checks.
//!
//! The consist is read from a TOML file ([`Consist::load`], [`Consist::parse`]); the built-in
//! make-ups are named by [`BUILTIN`] and found by [`builtin_path`]. Every public number in them
//! carries its source in a comment; every shape the sources do not give is marked an estimate.
//!
//! Conventions: SI units in code (files say their unit in the key: `_t`, `_m`, `_kmh`, `_n`);
//! coupler force positive in tension; grade positive uphill in the direction of travel.
//! Nothing here depends on the 3-D simulation or on the track module: the caller describes
//! the line through [`Route`].

pub mod brake;
pub mod checks;
pub mod consist;
pub mod draft_gear;
pub mod driver;
pub mod locomotive;
mod longitudinal;
pub mod resistance;

pub use brake::{AirBrake, ShoeBrake};
pub use consist::{Consist, Vehicle, VehicleKind};
pub use draft_gear::{Coupling, DraftGear, GearForce};
pub use driver::{Command, Driver, DriverSettings, ScheduleEntry};
pub use locomotive::Locomotive;
pub use longitudinal::{Neighbour, Neighbours, Train, WagonAt};
pub use resistance::BasicResistance;

use std::path::PathBuf;

/// The line as the train sees it: grade and curvature at an along-line position.
///
/// `s` is the distance along the line of the point asked about, m, in the same coordinate as
/// the vehicles' positions; it may lie outside the described track (before its start or after
/// its end): the implementation decides what the line is there (for example the nearest end's
/// value).
pub trait Route {
    /// Grade at `s`: rise over run (0.020 for 20 ‰), positive uphill in the direction of
    /// travel (+s).
    fn grade(&self, s: f64) -> f64;
    /// Curvature at `s`, 1/m (1/R); the sign (left or right) is ignored by the resistance.
    fn curvature(&self, s: f64) -> f64;
}

/// A line of one constant grade and one constant curvature everywhere: the closed-form checks'
/// route.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ConstantRoute {
    /// Grade, rise over run, positive uphill.
    pub grade: f64,
    /// Curvature, 1/m.
    pub curvature: f64,
}

impl Route for ConstantRoute {
    fn grade(&self, _s: f64) -> f64 {
        self.grade
    }
    fn curvature(&self, _s: f64) -> f64 {
        self.curvature
    }
}

/// The built-in consists, by name: HXD1 + 105 C80 (`daqin_10kt`) and HXD1 + 105 C80 + HXD1 +
/// 105 C80 (`daqin_20kt`, distributed power), loaded and empty.
pub const BUILTIN: [&str; 4] = [
    "daqin_10kt",
    "daqin_10kt_empty",
    "daqin_20kt",
    "daqin_20kt_empty",
];

/// The shipped file of a built-in consist (`vehicles/NAME.consist.toml` in the crate's
/// folder), or `None` when `name` is not one of [`BUILTIN`].
pub fn builtin_path(name: &str) -> Option<PathBuf> {
    builtin_file(name).map(PathBuf::from)
}

/// The path of a built-in consist's file relative to the repository root
/// (`vehicles/NAME.consist.toml`), for an embedded copy keyed as `builtin::FILES` keys them.
pub fn builtin_relative_path(name: &str) -> Option<String> {
    BUILTIN
        .contains(&name)
        .then(|| format!("vehicles/{name}.consist.toml"))
}

fn builtin_file(name: &str) -> Option<&'static str> {
    match name {
        "daqin_10kt" => Some(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/vehicles/daqin_10kt.consist.toml"
        )),
        "daqin_10kt_empty" => Some(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/vehicles/daqin_10kt_empty.consist.toml"
        )),
        "daqin_20kt" => Some(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/vehicles/daqin_20kt.consist.toml"
        )),
        "daqin_20kt_empty" => Some(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/vehicles/daqin_20kt_empty.consist.toml"
        )),
        _ => None,
    }
}

/// A smooth sign of `v`: `v / √(v² + ε²)`, and its derivative in `v`. Friction-like forces
/// (resistance, brake shoes, the draft gear's branch switch) use it, so a force that opposes
/// motion goes through zero smoothly when the motion stops and the step stays well behaved.
#[inline]
pub(crate) fn smooth_sign(v: f64, eps: f64) -> (f64, f64) {
    let inv = 1.0 / (v * v + eps * eps).sqrt();
    (v * inv, eps * eps * inv * inv * inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_name_has_its_file() {
        for name in BUILTIN {
            let p = builtin_path(name).unwrap();
            assert!(p.exists(), "{}", p.display());
            assert_eq!(
                builtin_relative_path(name).unwrap(),
                format!("vehicles/{name}.consist.toml")
            );
        }
        assert!(builtin_path("daqin_5kt").is_none());
    }

    #[test]
    fn smooth_sign_and_its_slope() {
        let (s, d) = smooth_sign(0.0, 0.1);
        assert_eq!(s, 0.0);
        assert!((d - 10.0).abs() < 1e-12);
        let (s, _) = smooth_sign(10.0, 0.01);
        assert!((s - 1.0).abs() < 1e-5);
        let h = 1e-6;
        let num = (smooth_sign(0.03 + h, 0.05).0 - smooth_sign(0.03 - h, 0.05).0) / (2.0 * h);
        assert!((num - smooth_sign(0.03, 0.05).1).abs() < 1e-6);
    }
}
