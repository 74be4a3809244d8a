//! Closed-form checks of the consist's longitudinal dynamics, shared by the tests and
//! `railforce validate dynamics`.

use super::resistance::{curve_force, grade_force};
use super::{Consist, ConstantRoute, Train, WagonAt};
use crate::error::{Error, Result};

/// What [`steady_couplers`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyCouplers {
    /// The largest relative difference between a coupler's force and the resistance behind
    /// it less the traction behind it (against each coupler's own force, at least `floor`).
    pub worst: f64,
    /// The largest coupler force, N (+ tension).
    pub largest: f64,
    /// The train's speed at the end, m/s.
    pub speed: f64,
}

/// Runs `consist` alone at `v0` (m/s) on `route` for `seconds` at step `dt` and compares each
/// coupler with what a train at constant speed must carry: the running, curve and grade
/// resistance of every vehicle behind it, less the traction (or dynamic brake) of the
/// locomotives behind it. An error if the driver did not hold the speed.
pub fn steady_couplers(
    consist: Consist,
    route: ConstantRoute,
    v0: f64,
    seconds: f64,
    dt: f64,
    floor: f64,
) -> Result<SteadyCouplers> {
    let mut t = Train::new(consist, WagonAt::File, 1000.0, v0, &route)?;
    t.run_alone(seconds, dt, &route, &mut |_| {});
    if !t.speed_held() || (t.speed() - v0).abs() > 1e-3 {
        return Err(Error::Domain(format!(
            "the train did not hold {:.2} m/s on grade {} (it runs at {:.3} m/s)",
            v0,
            route.grade,
            t.speed()
        )));
    }
    let c = t.consist();
    let u = t.driver().control();
    let (mut worst, mut largest, mut behind) = (0.0f64, 0.0f64, 0.0);
    for j in (0..c.vehicles.len() - 1).rev() {
        let i = j + 1;
        let veh = &c.vehicles[i];
        let v = t.velocities()[i];
        behind -= veh.resistance.force(veh.mass, v).0
            + curve_force(veh.mass, route.curvature, v)
            + grade_force(veh.mass, route.grade);
        if let Some(l) = &veh.locomotive {
            behind -= l.effort(u, v);
        }
        let f = t.coupling_force(j);
        worst = worst.max((f - behind).abs() / behind.abs().max(floor));
        if f.abs() > largest.abs() {
            largest = f;
        }
    }
    Ok(SteadyCouplers {
        worst,
        largest,
        speed: t.speed(),
    })
}
