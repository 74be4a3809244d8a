//! The train at its start: placed on the line around the 3-D wagon, at the steady state of
//! its speed (the driver's balancing control, each coupling at its quasi-static force).

use super::{Train, WagonAt};
use crate::error::{Error, Result};
use crate::train::Route;
use crate::train::brake::BrakeState;
use crate::train::consist::{Consist, VehicleKind};
use crate::train::driver::Driver;

impl Train {
    /// A train at steady state: the 3-D wagon (`at`) centred at `s_wagon0` on the line, every
    /// vehicle moving at `v0` m/s, the driver holding `v0` with the control that balances the
    /// train's resistance (quantised to its notch; beyond the locomotives' effort, their
    /// limit), each coupling at the quasi-static force of that control (the resistance behind
    /// it less the traction behind it, and the uniform acceleration's share when the notch
    /// does not balance exactly), its extension from the draft gears' rest curve. Air brake
    /// released.
    pub fn new(
        consist: Consist,
        at: WagonAt,
        s_wagon0: f64,
        v0: f64,
        route: &dyn Route,
    ) -> Result<Train> {
        if !(s_wagon0.is_finite() && v0.is_finite()) {
            return Err(Error::Domain(format!(
                "train: the wagon's start ({s_wagon0} m) and speed ({v0} m/s) must be finite"
            )));
        }
        let n = consist.vehicles.len();
        let wagon = match at {
            WagonAt::File => consist.index_at(consist.position)?,
            WagonAt::Fraction(f) => consist.index_at(f)?,
            WagonAt::Index(i) => {
                if consist
                    .vehicles
                    .get(i)
                    .is_none_or(|v| v.kind != VehicleKind::Wagon)
                {
                    return Err(Error::config(
                        &consist.path,
                        "position",
                        format!("vehicle {i} is not a wagon of this {n}-vehicle train"),
                    ));
                }
                i
            }
        };
        let mass: Vec<f64> = consist.vehicles.iter().map(|v| v.mass).collect();
        let rest: Vec<f64> = consist
            .vehicles
            .windows(2)
            .map(|w| 0.5 * (w[0].length + w[1].length))
            .collect();
        let mut sources = vec![(0, 0.0)];
        if consist.brake.distributed {
            sources.extend(
                consist
                    .locomotives()
                    .into_iter()
                    .filter(|&k| k != 0)
                    .map(|k| (k, consist.brake.radio_delay)),
            );
        }
        let driver = Driver::new(consist.driver.clone(), v0, 0.0);
        let basic = consist.vehicles.iter().map(|v| v.resistance).collect();
        let shoe = consist
            .vehicles
            .iter()
            .map(|v| v.full_service_shoe_force)
            .collect();
        let locos = consist
            .vehicles
            .iter()
            .enumerate()
            .filter_map(|(i, v)| v.locomotive.map(|l| (i, l)))
            .collect();
        let mut t = Train {
            wagon,
            total_mass: mass.iter().sum(),
            mass,
            basic,
            shoe,
            locos,
            s: vec![0.0; n],
            v: vec![v0; n],
            rest,
            grade: vec![0.0; n],
            curvature: vec![0.0; n],
            route_at: 0.0,
            brake: BrakeState::released(n),
            sources,
            driver,
            air_queue: Vec::with_capacity(16),
            time: 0.0,
            last_external: 0.0,
            diag: vec![0.0; n],
            off: vec![0.0; n],
            rhs: vec![0.0; n],
            work: vec![0.0; n],
            piv: vec![0.0; n],
            dv: vec![0.0; n],
            consist,
        };
        // Place the vehicles with free couplings, sample the route, settle the quasi-static
        // forces, place them again with those extensions and sample once more.
        let mut ext = vec![0.0; n.saturating_sub(1)];
        for _ in 0..3 {
            t.place(s_wagon0, &ext);
            t.sample_route(route);
            ext = t.steady_extensions(v0);
        }
        t.place(s_wagon0, &ext);
        t.sample_route(route);
        Ok(t)
    }

    /// Positions from the wagon's centre and the couplings' extensions.
    fn place(&mut self, s_wagon: f64, ext: &[f64]) {
        let w = self.wagon;
        self.s[w] = s_wagon;
        for j in (0..w).rev() {
            self.s[j] = self.s[j + 1] + self.rest[j] + ext[j];
        }
        for (j, e) in ext.iter().enumerate().skip(w) {
            self.s[j + 1] = self.s[j] - self.rest[j] - e;
        }
    }

    /// The driver's steady control at `v0` and the couplings' quasi-static extensions under it.
    fn steady_extensions(&mut self, v0: f64) -> Vec<f64> {
        let c = &self.consist;
        let n = self.s.len();
        // resisting force of each vehicle (positive against the motion), N
        let resist: Vec<f64> = (0..n).map(|i| -self.passive_force(i, v0, 0.0).0).collect();
        let total: f64 = resist.iter().sum();
        let (mut trac, mut db) = (0.0, 0.0);
        for l in c.vehicles.iter().filter_map(|v| v.locomotive.as_ref()) {
            trac += l.traction(v0).0;
            db += l.dynamic_brake(v0).0;
        }
        let u0 = if total >= 0.0 && trac > 0.0 {
            total / trac
        } else if total < 0.0 && db > 0.0 {
            total / db
        } else {
            0.0
        };
        self.driver = Driver::new(c.driver.clone(), v0, u0);
        let u = self.driver.control();
        let effort: Vec<f64> = c
            .vehicles
            .iter()
            .map(|v| v.locomotive.map_or(0.0, |l| l.effort(u, v0)))
            .collect();
        let m: f64 = self.mass.iter().sum();
        let a = (effort.iter().sum::<f64>() - total) / m;
        let mut f = 0.0;
        (0..n - 1)
            .map(|j| {
                f += effort[j] - resist[j] - self.mass[j] * a;
                c.coupling.extension_at_rest(f)
            })
            .collect()
    }
}
