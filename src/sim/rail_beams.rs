//! The run's side of rails on discrete sleepers ([`crate::track::discrete`]): the window
//! follows the wagon, each wheel reads the rail under it at its own position, and each
//! wheelset's linearly implicit solve takes the rail's step mobility under its wheels.
//!
//! In a wheelset's solve the rail's point under the wheel's load centre behaves as a body of
//! mass matrix `W⁻¹` (W the track's 2×2 step mobility there, lateral and vertical, coupled by
//! the rail's roll: [`crate::track::discrete::TrackDynamics::contact_free`]) already moving by
//! the rails' free change `Δv_free`: its rows are `(W⁻¹ + θΔt·C_c)·Δr = W⁻¹·Δv_free + Δt·F − …`,
//! the lumped rail's rows with the beams in place of the mass on its spring. The wheelsets solve
//! one after another. The step starts with every wheel's impulse of the step before on the
//! beams (a prediction); each wheelset takes its own back, solves, and leaves its new ones, so
//! a wheel sees the new impulses of the wheelsets solved before it and the predicted ones of
//! those after it (Gauss–Seidel over the wheelsets, predicted). Without the prediction the
//! first wheelset carried the others' static loads' missing share: its Q 2.7 % high at
//! 0.75 ms (the cross-mobility at 1.83 m is −4 % of the point's own).

use super::Simulation;
use super::wheelset_solve::{Inverse, RailState, THETA, with_rail_rows};
use crate::error::{Error, Result};
use crate::track::discrete::{DiscreteSupport, Load, TrackDynamics};
use nalgebra::{Matrix2, Matrix6, Vector2, Vector6};

/// The track settled under the wagon's static wheel loads (the wagon's first body at `start`,
/// each wheel `static_load` N) at the run's step, and the rails' mean sag under the wheels, m;
/// refused with the reason when the run's integrator cannot take the beams or the window is
/// too short for the wagon.
pub(super) fn settled(
    p: DiscreteSupport,
    vehicle: &crate::vehicle::Vehicle,
    track: &crate::track::Track,
    start: f64,
    static_load: f64,
    cfg: &super::SimConfig,
) -> Result<(Box<TrackDynamics>, f64)> {
    if (cfg.integrator.shares(cfg.dt)).is_none_or(|s| s.alpha_dt == 0.0) {
        return Err(Error::Domain(format!(
            "track '{}' has rails on discrete sleepers: they run with the integrator that takes the Hertz spring into the wheelsets' solve (linearly-implicit-hertz, the default), not {} (the rail's modal mass under a wheel is tens of kg: an explicit Hertz spring on it bursts)",
            track.spec().name,
            cfg.integrator.name()
        )));
    }
    let wheel_s: Vec<f64> = (vehicle.contact.wheelsets.iter())
        .map(|&w| start + vehicle.bodies[w].position.x)
        .collect();
    // Each end of the window at least 6/β beyond the outer wheels (the basin down to e^(−6),
    // 0.25 %), with a bay for the window's shifts.
    let span = wheel_s.iter().fold(f64::MIN, |a, &b| a.max(b))
        - wheel_s.iter().fold(f64::MAX, |a, &b| a.min(b));
    let needed = span + 12.0 / p.beta() + p.spacing;
    if p.window() < needed {
        return Err(Error::Domain(format!(
            "track '{}': rail_support.discrete.window_bays = {} ({:.1} m) is too short for vehicle '{}' (wheels over {:.1} m): the window needs {:.1} m ({} bays of {} m)",
            track.spec().name,
            p.bays,
            p.window(),
            vehicle.name,
            span,
            needed,
            (needed / p.spacing).ceil(),
            p.spacing
        )));
    }
    let centre = wheel_s.iter().sum::<f64>() / wheel_s.len().max(1) as f64;
    let mut t = TrackDynamics::new(p, centre);
    let loads: Vec<Load> = wheel_s
        .iter()
        .flat_map(|&s| Load::wheelset(s, 0.0, -static_load))
        .collect();
    t.settle(cfg.dt, 1.5, &loads);
    let sag = wheel_s
        .iter()
        .flat_map(|&s| [t.rail(0, s)[2], t.rail(1, s)[2]])
        .sum::<f64>()
        / (2 * wheel_s.len()).max(1) as f64;
    Ok((Box::new(t), sag))
}

impl Simulation<'_> {
    /// Each wheel's rail head under it, its top's lateral and vertical deflection (m, track
    /// axes): the rail's own motion, and on sleepers its roll about the torsion centre below
    /// (`y − d·θ`, d the centre's depth); none on a rigid track.
    pub fn rail_heads(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        let depth = self.rail_head_lever();
        (self.rails.iter()).map(move |r| (r.y - depth * r.roll, r.z))
    }

    /// Starts the beams' step with every wheel's impulse of the step before on them.
    pub(super) fn begin_beams(&mut self) {
        let Some(t) = self.beams.as_deref_mut() else {
            return;
        };
        t.begin(self.cfg.dt);
        for (w, &b) in self.vehicle.contact.wheelsets.iter().enumerate() {
            for side in 0..2 {
                let (i, lever) = (
                    self.beam_impulses[2 * w + side],
                    self.rail_coupling[2 * w + side].lever,
                );
                t.contact_impulse(side, self.body_s[b], lever, i);
            }
        }
    }

    /// Brings the window to the wagon and every wheel's rail state to the beams under it.
    pub(super) fn rails_from_beams(&mut self) {
        let Some(t) = self.beams.as_deref_mut() else {
            return;
        };
        let ws = &self.vehicle.contact.wheelsets;
        let centre = ws.iter().map(|&b| self.body_s[b]).sum::<f64>() / ws.len() as f64;
        t.recentre(centre);
        for (w, &b) in ws.iter().enumerate() {
            for side in 0..2 {
                let [y, vy, z, vz, roll, roll_rate] = t.rail(side, self.body_s[b]);
                self.rails[2 * w + side] = RailState {
                    y,
                    vy,
                    z,
                    vz,
                    roll,
                    roll_rate,
                };
            }
        }
    }

    /// Wheelset `k`'s solve on the beams (`surface`: the rail surface's change under each
    /// wheel, as [`super::wheelset_solve::with_rails`] takes it); hands its impulses to the
    /// beams.
    pub(super) fn wheelset_on_beams(
        &mut self,
        k: usize,
        body: &Inverse,
        d: &Matrix6<f64>,
        du: Vector6<f64>,
        surface: &[Vector2<f64>; 2],
    ) -> Vector6<f64> {
        let dt = self.cfg.dt;
        let s = self.body_s[self.vehicle.contact.wheelsets[k]];
        let t = self
            .beams
            .as_deref_mut()
            .expect("a wheelset solves on beams only when the track has them");
        let pair = 2 * k..2 * k + 2;
        let coupling = &self.rail_coupling[pair.clone()];
        for (side, c) in coupling.iter().enumerate() {
            t.contact_impulse(side, s, c.lever, -self.beam_impulses[2 * k + side]);
        }
        let mut free = [(Vector2::zeros(), Matrix2::zeros()); 2];
        let blocks = std::array::from_fn(|side| {
            let (c, f) = (&coupling[side], self.rail_force[2 * k + side]);
            let (dv_free, w) = t.contact_free(side, s, c.lever);
            let mass = w.try_inverse().unwrap_or_else(Matrix2::zeros);
            free[side] = (dv_free, mass);
            let l = mass + c.damping * (THETA * dt);
            let mut r = mass * dv_free + Vector2::from(f) * dt;
            if surface[side] != Vector2::zeros() {
                r -= c.surface_on_rail * surface[side];
            }
            (l, r)
        });
        let (du, dv) = with_rail_rows(body, d, du, dt, coupling, blocks);
        for (side, (dv, (dv_free, mass))) in dv.into_iter().zip(free).enumerate() {
            let impulse = mass * (dv - dv_free);
            t.contact_impulse(side, s, coupling[side].lever, impulse);
            self.beam_impulses[2 * k + side] = impulse;
        }
        du
    }
}
