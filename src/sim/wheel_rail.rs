//! Wheel–rail contact in the simulation: each wheelset's pose relative to its track frame,
//! the contact table at the lateral shift relative to each rail (alignment and gauge
//! irregularities), elastic normal contact from the Hertz approach (cross-level and vertical
//! irregularities, roll), a second contact point where the table has one, creepages from the
//! absolute motion, and the creep law.

use super::Simulation;
use crate::contact::{ContactFrame, Creepage, Side, WheelContact};
use crate::error::Result;
use nalgebra::Vector3;

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
    pub(super) fn contact(&mut self) -> Result<()> {
        let v = self.vehicle;
        let cs = &v.contact;
        let dt = self.cfg.dt;
        for (w, &b) in cs.wheelsets.iter().enumerate() {
            let st = self.states[b];
            let f = self.frames[b];
            let rel = f.to_local(&(st.position - f.origin));
            let rot_rel = f.axes.transpose() * st.matrix();
            let axle = rot_rel.column(1);
            let yaw = (-axle.x).atan2(axle.y);
            let roll = axle.z.asin();
            let rails = *f.rails();
            // Creep forces act as dampers of strength G·ab·C/V: below 5 m/s the explicit step
            // could not follow them (and creep theory no longer holds), so V is floored there.
            let speed = st.velocity.dot(&f.axes.column(0)).abs().max(5.0);
            for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                let idx = 2 * w + k;
                let (irr_y, irr_z, irr_slope) = match side {
                    Side::Left => (rails.left_y, rails.left_z, rails.left_y_ds),
                    Side::Right => (rails.right_y, rails.right_z, rails.right_y_ds),
                };
                let y_k = rel.y - irr_y;
                let ts = self.table.lookup(y_k);
                let main = ts.wheels[k];
                // Vertical approach of the wheel into its rail: the table's rigid height minus
                // the actual height over this rail, corrected for the roll difference.
                let yc = main.point[1] - y_k;
                let dv = (ts.z - (rel.z - irr_z)) - (roll - ts.roll) * yc;
                let mut contacts: [(Option<WheelContact>, f64); 2] =
                    [(Some(main), dv), (None, 0.0)];
                if let Some(sec) = ts.secondary[k] {
                    contacts[1] = (Some(sec), dv - sec.gap);
                }
                let mut total = Vector3::zeros();
                let mut result = WheelResult {
                    s: self.body_s[b],
                    y_rel: y_k,
                    angle: main.angle,
                    lift: (-dv).max(0.0),
                    climb: main.rolling_radius - cs.geometry.nominal_radius + (-dv).max(0.0),
                    yaw,
                    roll,
                    y_centre: rel.y,
                    rail_slope: irr_slope,
                    ..WheelResult::default()
                };
                for (j, (c, dvj)) in contacts.into_iter().enumerate() {
                    let Some(c) = c else { continue };
                    let approach = dvj * c.angle.cos();
                    let last = self.last_approach[idx][j];
                    self.last_approach[idx][j] = approach;
                    if approach <= 0.0 {
                        continue;
                    }
                    let hertz_n = c.hertz.load_from_approach(approach, &cs.material);
                    // Damping of the linearised Hertz spring (k = 1.5 N/δ) with half the
                    // wheelset's mass.
                    let rate = if last.is_finite() {
                        (approach - last) / dt
                    } else {
                        0.0
                    };
                    let k_lin = 1.5 * hertz_n / approach;
                    let m_half = 0.5 * v.bodies[b].mass;
                    let damp = 2.0 * cs.damping_ratio * (k_lin * m_half).sqrt();
                    let normal = (hertz_n + damp * rate).max(0.0);
                    if normal <= 0.0 {
                        continue;
                    }
                    // Contact point relative to the wheelset centre: the table's point (at the
                    // table's roll, zero yaw) turned by the actual extra roll and the yaw, so
                    // it stays consistent with the spinning axle (otherwise the spin about a
                    // slightly tilted axle shows up as false longitudinal creepage).
                    let table_rel = Vector3::new(0.0, c.point[1] - y_k, c.point[2] - ts.z);
                    let turn = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), yaw)
                        * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), roll - ts.roll);
                    let p_rel_track = turn * table_rel;
                    let p = st.position + f.axes * p_rel_track;
                    let cf = ContactFrame::new(side, c.angle, yaw);
                    let (tx, ty, n) = (
                        f.axes * Vector3::from(cf.tx),
                        f.axes * Vector3::from(cf.ty),
                        f.axes * Vector3::from(cf.n),
                    );
                    let r = p - st.position;
                    let vc = st.velocity + st.angular_velocity.cross(&r);
                    let creepage = Creepage {
                        x: vc.dot(&tx) / speed,
                        y: vc.dot(&ty) / speed,
                        spin: st.angular_velocity.dot(&n) / speed,
                    };
                    let ellipse = c.hertz.ellipse(normal, &cs.material);
                    let creep = cs.law.force(
                        &crate::contact::CreepContact {
                            a: ellipse.a,
                            b: ellipse.b,
                            normal,
                            mu: cs.friction,
                            shear_modulus: cs.material.shear_modulus(),
                            poisson: cs.material.poisson,
                        },
                        creepage,
                    );
                    let force = tx * creep.x + ty * creep.y + n * normal;
                    self.wrenches[b].add_at(force, p, st.position);
                    total += force;
                    if j == 0 {
                        result.normal = normal;
                        result.creepage = creepage;
                    }
                }
                let local = f.to_local(&total);
                result.y = local.y;
                result.q = local.z;
                self.wheels[idx] = result;
            }
        }
        Ok(())
    }
}
