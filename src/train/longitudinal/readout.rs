//! What the train tells its caller: coupler forces (and their slopes) at the 3-D wagon and
//! along the train, where the wagon's neighbours stand, the brake shoes on its treads, and
//! the state.

use super::Train;
use crate::train::brake::ShoeBrake;
use crate::train::consist::Consist;
use crate::train::draft_gear::GearForce;
use crate::train::driver::Driver;
use crate::train::longitudinal::{Neighbour, Neighbours};

impl Train {
    /// Force of coupling `j` (between vehicles `j` and `j + 1`), N, tension positive, from the
    /// current state.
    pub fn coupling_force(&self, j: usize) -> f64 {
        let e = self.s[j] - self.s[j + 1] - self.rest[j];
        self.consist
            .coupling
            .force(e, self.v[j] - self.v[j + 1])
            .force
    }

    /// Every coupling's force (tension positive, N) into `out` (length: vehicles − 1).
    pub fn coupling_forces_into(&self, out: &mut [f64]) {
        for (j, o) in out.iter_mut().enumerate().take(self.s.len() - 1) {
            *o = self.coupling_force(j);
        }
    }

    /// The forces at the 3-D wagon's couplers, N, tension positive: (front, rear), from the
    /// state after the last step (the wagon where the caller put it). 0 where the wagon ends
    /// the train.
    pub fn coupler_forces(&self) -> (f64, f64) {
        self.coupler_forces_at(self.s[self.wagon], self.v[self.wagon])
    }

    /// The forces at the 3-D wagon's couplers with the wagon at `wagon_s` moving at `wagon_v`
    /// and its neighbours where they are now: (front, rear), N, tension positive.
    pub fn coupler_forces_at(&self, wagon_s: f64, wagon_v: f64) -> (f64, f64) {
        let (f, r) = self.coupler_jacobians_at(wagon_s, wagon_v);
        (f.force, r.force)
    }

    /// The 3-D wagon's two couplings (front, rear) with the wagon at `wagon_s` moving at
    /// `wagon_v`: each one's force (N, tension positive) and its derivatives in the coupling's
    /// extension (stiffness, N/m) and extension rate (damping, N·s/m), for a caller that
    /// treats them implicitly (the draft gears' friction switch is a steep damping). The front
    /// coupling extends as the wagon falls back (`∂e/∂s_wagon = −1`) and pulls it forward; the
    /// rear one extends as the wagon runs ahead (`+1`) and pulls it back: the wagon's own
    /// along-line force is `front.force − rear.force`, of slope `−(front + rear).stiffness` in
    /// its position and `−(front + rear).damping` in its velocity. Zero where the wagon ends
    /// the train.
    pub fn coupler_jacobians_at(&self, wagon_s: f64, wagon_v: f64) -> (GearForce, GearForce) {
        self.coupler_jacobians_ahead(0.0, wagon_s, wagon_v)
    }

    /// [`Self::coupler_jacobians_at`] `ahead` seconds after the train's last step, its
    /// neighbours moved on at their velocities: for a caller that steps the train less often
    /// than its 3-D wagon (every k-th step of the wagon, `step(k·dt, …)`). The linearly
    /// implicit step stays stable at a coarse step; stepping the train at 4 × 5/6 ms moved
    /// the wagon's coupler forces by 0.4–3.5 % (root mean square, brake applications of the
    /// built-in consists) against stepping it at 5/6 ms.
    pub fn coupler_jacobians_ahead(
        &self,
        ahead: f64,
        wagon_s: f64,
        wagon_v: f64,
    ) -> (GearForce, GearForce) {
        let w = self.wagon;
        let c = &self.consist.coupling;
        let front = if w > 0 {
            let s_front = self.s[w - 1] + ahead * self.v[w - 1];
            let e = s_front - wagon_s - self.rest[w - 1];
            c.force(e, self.v[w - 1] - wagon_v)
        } else {
            GearForce::default()
        };
        let rear = if w + 1 < self.s.len() {
            let s_rear = self.s[w + 1] + ahead * self.v[w + 1];
            let e = wagon_s - s_rear - self.rest[w];
            c.force(e, wagon_v - self.v[w + 1])
        } else {
            GearForce::default()
        };
        (front, rear)
    }

    fn neighbour(&self, i: usize, towards_rear: bool) -> Neighbour {
        let veh = &self.consist.vehicles[i];
        let half = 0.5 * veh.length;
        let arm = half - veh.pivot_inset;
        Neighbour {
            index: i,
            centre: self.s[i],
            pivot: if towards_rear {
                self.s[i] - arm
            } else {
                self.s[i] + arm
            },
            half_length: half,
            pivot_inset: veh.pivot_inset,
        }
    }

    /// Where the 3-D wagon's neighbours stand: the front one's rear coupler pivot and the rear
    /// one's front pivot, along the line.
    pub fn neighbours(&self) -> Neighbours {
        let w = self.wagon;
        Neighbours {
            front: (w > 0).then(|| self.neighbour(w - 1, true)),
            rear: (w + 1 < self.s.len()).then(|| self.neighbour(w + 1, false)),
        }
    }

    /// Along-line distance from the 3-D wagon's centre to each of its coupler pivots, m
    /// (half its length less the pivot inset).
    pub fn wagon_pivot_arm(&self) -> f64 {
        let v = &self.consist.vehicles[self.wagon];
        0.5 * v.length - v.pivot_inset
    }

    /// The brake shoes on the 3-D wagon's treads now: their total normal force and the
    /// friction coefficient at its speed. In the coupled mode the caller applies them; the
    /// train does not.
    pub fn wagon_brake(&self) -> ShoeBrake {
        self.shoe_brake(self.wagon)
    }

    /// The brake shoes on vehicle `i`'s treads now.
    pub fn shoe_brake(&self, i: usize) -> ShoeBrake {
        ShoeBrake {
            normal_force: self.brake.level[i] * self.consist.vehicles[i].full_service_shoe_force,
            friction: self.consist.brake.friction_at(self.v[i]),
        }
    }

    /// Vehicle `i`'s air-brake force along +s now, N (opposing its motion).
    pub fn brake_force(&self, i: usize) -> f64 {
        self.consist
            .brake
            .shoe_force(self.shoe_brake(i).normal_force, self.v[i])
            .0
    }

    /// When the last air-brake command reached vehicle `i`'s valve (pipe signal plus valve
    /// delay), s from the start; ∞ before any command.
    pub fn brake_arrival(&self, i: usize) -> f64 {
        self.brake.arrival[i]
    }

    /// The consist.
    pub fn consist(&self) -> &Consist {
        &self.consist
    }

    /// Index of the 3-D wagon.
    pub fn wagon_index(&self) -> usize {
        self.wagon
    }

    /// Along-line positions of the vehicles' centres, m, head first.
    pub fn positions(&self) -> &[f64] {
        &self.s
    }

    /// Velocities along +s, m/s, head first.
    pub fn velocities(&self) -> &[f64] {
        &self.v
    }

    /// Time since the start, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The train's speed: its mass-weighted mean velocity, m/s (what the driver holds).
    pub fn speed(&self) -> f64 {
        self.momentum() / self.total_mass
    }

    /// Total momentum, kg·m/s.
    pub fn momentum(&self) -> f64 {
        self.mass.iter().zip(&self.v).map(|(m, v)| m * v).sum()
    }

    /// Sum of the external forces (resistance, grade, brakes, traction) of the last step on
    /// the vehicles the train advanced, N, as the step applied them (linearised in the end
    /// velocities): times the step, the change of their momentum.
    pub fn last_external_force(&self) -> f64 {
        self.last_external
    }

    /// The driver.
    pub fn driver(&self) -> &Driver {
        &self.driver
    }

    /// Whether the locomotives hold the target speed now (`false` while the control is
    /// saturated and the speed misses it by more than the tolerance).
    pub fn speed_held(&self) -> bool {
        !self.driver.not_held()
    }

    /// Total time the target speed was not held, s.
    pub fn speed_not_held_s(&self) -> f64 {
        self.driver.not_held_s()
    }
}
