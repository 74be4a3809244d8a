//! Wheel–rail contact in the simulation: each wheel's state relative to its rail (the track
//! frame, the irregularity and, on a compliant track, the rail's own deflection removed) goes
//! to the one contact evaluation [`crate::contact::evaluate`]; its force acts on the wheelset
//! and its reaction on the rail masses.

use super::Simulation;
use super::wheelset_solve::{RailCoupling, Shares};
use crate::contact::{Creepage, Side, WheelForces, WheelOnRail, evaluate_into};
use crate::error::Result;
use crate::track::discrete::Lever;
use nalgebra::{Matrix6, Vector2, Vector3};

/// What happened at one wheel in the last step.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WheelResult {
    /// Along-track position of the wheelset, m.
    pub s: f64,
    /// Lateral shift of the wheelset relative to this wheel's rail (irregularity removed), m.
    pub y_rel: f64,
    /// Lateral force of the rail on the wheel, track frame (+ left), N.
    pub y: f64,
    /// Vertical force of the rail on the wheel, track frame (+ up), N.
    pub q: f64,
    /// Normal force of the main contact, N.
    pub normal: f64,
    /// Creepages at the main contact.
    pub creepage: Creepage,
    /// Contact angle of the main contact, rad.
    pub angle: f64,
    /// Gap between wheel and rail when out of contact (0 in contact), m.
    pub lift: f64,
    /// Rise of the wheel on its flange: contact radius above the tape circle plus any gap, m.
    pub climb: f64,
    /// Yaw of the wheelset relative to the track, rad.
    pub yaw: f64,
    /// Roll of the wheelset relative to the track plane, rad.
    pub roll: f64,
    /// Lateral position of the wheelset centre relative to the track centre line, m.
    pub y_centre: f64,
    /// Slope of this wheel's rail alignment (irregularity), rad.
    pub rail_slope: f64,
}

impl Simulation<'_> {
    /// What the last step gave the contact evaluation for each wheel (1L, 1R, 2L, …).
    pub fn contact_inputs(&self) -> &[WheelOnRail] {
        &self.inputs
    }

    /// Both wheels of the `w`-th wheelset relative to their rails, as the one contact
    /// evaluation ([`crate::contact::evaluate`]) takes them (the wheelset's pose and motion in
    /// its track frame computed once for both), and the wheelset centre's lateral position
    /// relative to the track centre line, m.
    fn wheels_on_rails(&self, w: usize) -> ([WheelOnRail; 2], f64) {
        let b = self.vehicle.contact.wheelsets[w];
        let st = &self.states[b];
        let f = &self.frames[b];
        let rel = f.to_local(&(st.position - f.origin));
        let axle = (f.axes.transpose() * st.matrix()).column(1).into_owned();
        let (roll, yaw) = (
            crate::angle::asin(axle.z),
            crate::angle::atan2(-axle.x, axle.y),
        );
        let v = f.axes.transpose() * st.velocity;
        let omega = f.axes.transpose() * st.angular_velocity;
        let r = f.rails();
        let sides = [
            (Side::Left, r.left_y, r.left_z, r.left_y_ds, r.left_z_ds),
            (
                Side::Right,
                r.right_y,
                r.right_z,
                r.right_y_ds,
                r.right_z_ds,
            ),
        ];
        let wheels = std::array::from_fn(|k| {
            let (side, irr_y, mut irr_z, y_ds, mut z_ds) = sides[k];
            // An out-of-round wheel: its radius's shortfall lowers it as the rail would.
            for d in self
                .vehicle
                .wheel_defects
                .iter()
                .filter(|d| d.wheel == 2 * w + k)
            {
                let (dr, rate) = d.radius_change(f.point.s);
                irr_z += dr;
                z_ds += rate;
            }
            let rail = self.rails[2 * w + k];
            WheelOnRail {
                side,
                y: rel.y - irr_y - rail.y,
                height: rel.z - irr_z - rail.z,
                roll,
                yaw,
                velocity: [v.x, v.y - rail.vy, v.z - rail.vz],
                angular_velocity: [omega.x, omega.y, omega.z],
                surface_rate: [v.x * y_ds, v.x * z_ds],
                speed: v.x,
                mass: 0.5 * self.vehicle.bodies[b].mass,
            }
        });
        (wheels, rel.y)
    }

    /// The depth of the rails' torsion centre below their top, m (0 where they do not roll).
    pub(super) fn rail_head_lever(&self) -> f64 {
        (self.beams.as_deref()).map_or(0.0, |t| t.support().torsion_centre_depth)
    }

    /// The rail `k`'s torsion centre (0 left, 1 right) relative to its nominal place (the
    /// gauge point's lateral place, the rail's top), track axes `(y, z)`, m; none on a track
    /// whose rails do not roll.
    fn torsion_centre(&self, k: usize) -> Option<Vector2<f64>> {
        let p = self.beams.as_deref()?.support();
        let y = self.vehicle.contact.geometry.half_gauge + p.torsion_centre_offset;
        Some(Vector2::new(
            if k == 0 { y } else { -y },
            -p.torsion_centre_depth,
        ))
    }

    /// The wheelset as the rail `k` sees it when the rail has rolled by θ about its torsion
    /// centre C: its centre at `C + R(−θ)·(p − C)`, its roll less θ, its velocity relative to
    /// the rail's material (`v − v_C − θ̇·x̂ × (p − C)`) and its angular velocity (less θ̇ about
    /// x), both turned by `R(−θ)` into the rail's axes (each written as a change, so that no
    /// roll changes nothing, bit for bit).
    fn on_rolled_rail(&self, wr: &mut WheelOnRail, k: usize, rail: &super::RailState) {
        let Some(c) = self.torsion_centre(k) else {
            return;
        };
        let (sin, cos1) = (rail.roll.sin(), rail.roll.cos() - 1.0);
        // R(−θ)·(a, b) − (a, b): the change of a vector (y, z) turned into the rail's axes.
        let turn = |a: f64, b: f64| (a * cos1 + b * sin, b * cos1 - a * sin);
        let (dy, dz) = (wr.y - c.x, wr.height - c.y);
        let (ty, tz) = turn(dy, dz);
        wr.y += ty;
        wr.height += tz;
        wr.roll -= rail.roll;
        let (vy, vz) = (
            wr.velocity[1] + rail.roll_rate * dz,
            wr.velocity[2] - rail.roll_rate * dy,
        );
        let (ty, tz) = turn(vy, vz);
        wr.velocity[1] = vy + ty;
        wr.velocity[2] = vz + tz;
        let w = &mut wr.angular_velocity;
        w[0] -= rail.roll_rate;
        let (ty, tz) = turn(w[1], w[2]);
        w[1] += ty;
        w[2] += tz;
    }

    /// A force or moment `(x, y, z)` in rail `k`'s axes turned back into the track's
    /// (`R(θ)`, θ the rail's roll; unchanged where it has none).
    fn to_track_axes(&self, k: usize, v: [f64; 3]) -> [f64; 3] {
        let roll = self.rails[k].roll;
        if roll == 0.0 {
            return v;
        }
        let (sin, cos) = roll.sin_cos();
        [v[0], v[1] * cos - v[2] * sin, v[1] * sin + v[2] * cos]
    }

    /// Where a wheel's load centre lies on its rolled rail, relative to the rail's torsion
    /// centre: the patches' points (about the wheelset's centre, the rail's axes), weighed by
    /// their normal loads, from the centre's place `wr` gives.
    fn lever(
        &self,
        k: usize,
        wr: &WheelOnRail,
        patches: &[Option<crate::contact::PatchForce>; 2],
    ) -> Lever {
        let Some(c) = self.torsion_centre(k) else {
            return Lever::default();
        };
        let (mut n, mut y, mut z) = (0.0, 0.0, 0.0);
        for p in patches.iter().flatten() {
            n += p.normal;
            y += p.normal * p.point[1];
            z += p.normal * p.point[2];
        }
        if n <= 0.0 {
            return Lever::default();
        }
        Lever {
            height: z / n + wr.height - c.y,
            lateral: y / n + wr.y - c.x,
        }
    }

    pub(super) fn contact(&mut self) -> Result<()> {
        let v = self.vehicle;
        let cs = &v.contact;
        let model = cs.model();
        let shares = self.shares;
        let mut out = WheelForces::default();
        for (w, &b) in cs.wheelsets.iter().enumerate() {
            let f = &self.frames[b];
            let (inputs, y_centre) = self.wheels_on_rails(w);
            let mut damping = nalgebra::Matrix6::zeros();
            for (k, on_track) in inputs.into_iter().enumerate() {
                let idx = 2 * w + k;
                // On a rolled rail the contact takes the wheelset in the rail's axes; the
                // results below stay in the track's (the shift from the rail's head).
                let (rail, mut wr) = (self.rails[idx], on_track);
                if rail.roll != 0.0 || rail.roll_rate != 0.0 {
                    self.on_rolled_rail(&mut wr, k, &rail);
                }
                super::profile::timed!(
                    self.profile,
                    "  of which the patch solve (8 wheels)",
                    evaluate_into(self.table, &model, &wr, &mut out)
                );
                self.inputs[idx] = wr;
                if let Some(Shares { theta, alpha_dt }) = shares {
                    // The step's share of the contact: θ·Δt·D + α·Δt²·K, written as one damping
                    // D + (α·Δt/θ)·K; and the normal law's share G = θ·c_n + α·Δt·k_n on the
                    // rail surface's rate (rank one per patch: g·J·Jᵀ, of which the columns of
                    // the track's y and z).
                    let mut wheel = Matrix6::zeros();
                    let mut surface = nalgebra::SMatrix::<f64, 6, 2>::zeros();
                    for p in out.patches.iter().flatten() {
                        wheel += crate::contact::patch_damping_with_spring(
                            p,
                            &model,
                            wr.speed,
                            alpha_dt / theta,
                        );
                        if alpha_dt > 0.0 {
                            let j = crate::contact::patch_normal(p);
                            let g = theta * p.damping + alpha_dt * p.stiffness;
                            surface += j * nalgebra::RowVector2::new(j[1] * g, j[2] * g);
                        }
                    }
                    let mut coupling = RailCoupling::new(&wheel, &f.axes);
                    if alpha_dt > 0.0 {
                        coupling.set_surface(&surface, &f.axes);
                    }
                    coupling.lever = self.lever(k, &wr, &out.patches);
                    self.rail_coupling[idx] = coupling;
                    damping += wheel;
                }
                let (force, moment) = (
                    self.to_track_axes(idx, out.force),
                    self.to_track_axes(idx, out.moment),
                );
                self.wrenches[b].force += f.axes * Vector3::from(force);
                self.wrenches[b].torque += f.axes * Vector3::from(moment);
                self.rail_force[idx] = [-force[1], -force[2]];
                let lift = out.gap.max(0.0);
                let main = out.main();
                let rails = f.rails();
                self.wheels[idx] = WheelResult {
                    s: self.body_s[b],
                    // From the head (−0.0 kept where the rail does not roll, bit for bit).
                    y_rel: if rail.roll == 0.0 {
                        on_track.y
                    } else {
                        on_track.y + self.rail_head_lever() * rail.roll
                    },
                    y: force[1],
                    q: force[2],
                    normal: main.map_or(0.0, |p| p.normal),
                    creepage: main.map_or(Creepage::default(), |p| p.creepage),
                    angle: main.map_or(out.rigid_angle, |p| p.angle),
                    lift,
                    climb: main.map_or(out.rigid_radius, |p| p.radius) - cs.geometry.nominal_radius
                        + lift,
                    yaw: on_track.yaw,
                    roll: on_track.roll,
                    y_centre,
                    rail_slope: if k == 0 {
                        rails.left_y_ds
                    } else {
                        rails.right_y_ds
                    },
                };
            }
            if shares.is_some() {
                // Track axes to world: blocks A·D·Aᵀ.
                let a = f.axes;
                let mut world = nalgebra::Matrix6::zeros();
                for (r, c) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
                    let blk = damping.fixed_view::<3, 3>(r, c).into_owned();
                    world
                        .fixed_view_mut::<3, 3>(r, c)
                        .copy_from(&(a * blk * a.transpose()));
                }
                self.contact_damping[w] = world;
            }
        }
        Ok(())
    }

    /// Moves the rail masses one step under the wheels' reactions (compliant track only; the
    /// linearly implicit step moves them with their wheelset in `integrate`).
    pub(super) fn move_rails(&mut self) {
        if self.beams.is_some() {
            self.begin_beams();
            return;
        }
        let Some(sup) = self.track.spec().rail_support else {
            return;
        };
        let dt = self.cfg.dt;
        if self.shares.is_some() {
            return;
        }
        for (r, f) in self.rails.iter_mut().zip(&self.rail_force) {
            sup.lateral.step(&mut r.y, &mut r.vy, f[0], dt);
            sup.vertical.step(&mut r.z, &mut r.vz, f[1], dt);
        }
    }
}
