//! Axle-box rubber shear pad: linear spring–damper in three directions, and the pad's
//! resistance to the side frame rolling on it.
//!
//! A pad of lateral width `w` is a bed of vertical springs under the pedestal roof: rolling
//! the side frame by θ on it takes `M = k_z·w²/12·θ` (the bed's second moment, k_z spread
//! evenly over the width), damped alike (`c_z·w²/12`), until the compressed edge carries the
//! whole load and the roof tips on it: |M| ≤ N·w/2 with N the pad's current vertical force.
//! With `w = 0` the pad is a point spring and the side frame rolls freely about the line of
//! its two pads.
//!
//! The pad sits between the pedestal roof of the side frame (`upper_at`) and the crown of the
//! bearing adapter (`lower_at`), well above the axle's centre line. The adapter rides on the
//! bearing: it rolls and yaws with the axle but does not spin with it, and the pedestal jaws
//! hold its pitch to the side frame's. So the crown is found in the adapter's axes (the axle's
//! direction, and the side frame's vertical square to it), and the pad's moment about the
//! axle's axis goes to the side frame through the jaws, never spinning the wheelset.
//!
//! The rubber's damping is either viscous (`damping`, N·s/m per axis: its loss factor
//! `c·ω/k` grows with frequency) or a loss factor held over 1–50 Hz (`loss_factor` per axis:
//! [`super::rubber`]'s Maxwell chain, the file's `stiffness` its static stiffness, the
//! rocking taking the vertical axis' rubber).

use super::rubber::{BRANCHES, Rubber};
use super::{Element, ElementDamping, ForceElement, Memory, Relative, Support};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;

/// Shear pad between a side frame (upper) and a wheelset's axle box (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct ShearPad {
    /// Side frame.
    pub upper: Attachment,
    /// Adapter crown on the wheelset: its point relative to the axle's centre, read in the
    /// adapter's axes (which do not spin), m.
    pub lower: Attachment,
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Stiffness (x, y, z), N/m.
    pub stiffness: Vector3<f64>,
    /// Damping (x, y, z), N·s/m.
    pub damping: Vector3<f64>,
    /// Static vertical load carried, N.
    pub preload: f64,
    /// Lateral width of the pad under the pedestal roof, m (0: no roll resistance).
    pub width: f64,
    /// Rubber with a constant loss factor (x, y, z), where the file gives one.
    pub rubber: Option<[Rubber; 3]>,
}

impl ShearPad {
    /// The adapter's axes in the world: x ahead, y along the axle, z the side frame's vertical
    /// made square to the axle.
    fn adapter_axes(&self, states: &[BodyState]) -> Matrix3<f64> {
        let (su, sl) = (&states[self.upper.body], &states[self.lower.body]);
        let a = sl.rotation * Vector3::y();
        let up = su.rotation * Vector3::z();
        let z = (up - a * up.dot(&a)).normalize();
        Matrix3::from_columns(&[a.cross(&z), a, z])
    }

    /// Relative motion across the pad: the adapter crown against the pedestal roof.
    pub(crate) fn relative(&self, states: &[BodyState]) -> Relative {
        let (su, sl) = (&states[self.upper.body], &states[self.lower.body]);
        let axes = su.matrix();
        let p_upper = su.point(&self.upper.local);
        let ad = self.adapter_axes(states);
        let a = ad.column(1).into_owned();
        let crown = ad * self.lower.local;
        let p_lower = sl.position + crown;
        // The adapter turns with the axle but for its spin, which it takes from the side frame.
        let w_adapter =
            sl.angular_velocity - a * sl.angular_velocity.dot(&a) + a * su.angular_velocity.dot(&a);
        let v_lower = sl.velocity + w_adapter.cross(&crown);
        Relative {
            axes,
            d: axes.transpose() * (p_lower - p_upper) - self.rest,
            v: axes.transpose() * (v_lower - su.point_velocity(&self.upper.local)),
            p_upper,
            p_lower,
        }
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        let r = self.relative(states);
        let mut f = self.stiffness.component_mul(&r.d)
            + self.damping.component_mul(&r.v)
            + Vector3::new(0.0, 0.0, self.preload);
        // The branches' relaxation over the step, once for the pad's four chains.
        let decay = self.rubber.as_ref().map(|r| r[0].decays(dt));
        if let (Some(rubber), Some(decay)) = (&self.rubber, &decay) {
            for (i, rb) in rubber.iter().enumerate() {
                let u = &mut memory[i * BRANCHES..(i + 1) * BRANCHES];
                f[i] += rb.branch_force(self.stiffness[i], r.d[i], u, decay);
            }
        }
        r.apply(f, &self.upper, &self.lower, states, wrenches);
        // The moment about the axle's axis of the force at the crown goes through the adapter's
        // jaws to the side frame: the bearing carries none.
        let sl = &states[self.lower.body];
        let a = sl.rotation * Vector3::y();
        let t = (r.p_lower - sl.position).cross(&(-(r.axes * f)));
        let axial = a * t.dot(&a);
        wrenches[self.lower.body].torque -= axial;
        wrenches[self.upper.body].torque += axial;
        if self.width > 0.0 {
            let (su, sl) = (&states[self.upper.body], &states[self.lower.body]);
            // The axle's direction in the side frame's axes gives their relative roll θ,
            // independent of the wheelset's spin about that axis.
            let axle = sl.matrix().column(1).into_owned();
            let a = r.axes.transpose() * axle;
            let theta = crate::angle::atan2(-a.z, a.y);
            let w_lower = sl.angular_velocity - axle * sl.angular_velocity.dot(&axle);
            let x_upper = r.axes.column(0).into_owned();
            let theta_dot = (su.angular_velocity - w_lower).dot(&x_upper);
            let m = match (&self.rubber, &decay) {
                (Some(rubber), Some(decay)) => {
                    // The vertical axis' rubber over the bed: static `k_z·w²/12` and its
                    // branches, no more than the load tipping on an edge.
                    let u = &mut memory[3 * BRANCHES..4 * BRANCHES];
                    let k = self.rocking_stiffness();
                    let tip = 0.5 * self.width * f.z.max(0.0);
                    (k * theta + rubber[2].branch_force(k, theta, u, decay)).clamp(-tip, tip)
                }
                _ => self.rocking_moment(theta, theta_dot, f.z),
            };
            wrenches[self.upper.body].torque -= x_upper * m;
            wrenches[self.lower.body].torque += x_upper * m;
        }
    }

    /// Rolling moment the pad's width resists with, per radian of relative roll, N·m/rad.
    pub fn rocking_stiffness(&self) -> f64 {
        self.stiffness.z * self.width * self.width / 12.0
    }

    /// Moment (N·m) resisting the side frame's roll `theta` (rad) relative to the axle at the
    /// rate `theta_dot` (rad/s) with the pad carrying `normal` (N): the spring bed's
    /// `(k_z·θ + c_z·θ̇)·w²/12`, no more than the load tipping on an edge, `N·w/2`.
    pub fn rocking_moment(&self, theta: f64, theta_dot: f64, normal: f64) -> f64 {
        let tip = 0.5 * self.width * normal.max(0.0);
        (self.width * self.width / 12.0 * (self.stiffness.z * theta + self.damping.z * theta_dot))
            .clamp(-tip, tip)
    }
}

/// `[[shear_pad]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ShearPadFile {
    upper: String,
    lower: String,
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
    /// Loss factor per axis, held over 1–50 Hz (instead of `damping`).
    #[serde(default)]
    loss_factor: Option<[f64; 3]>,
    /// Lateral width of the pad, m (0 or absent: a point spring).
    #[serde(default)]
    width_m: f64,
}

impl ShearPad {
    fn from_row(f: &str, e: &ShearPadFile, b: &Binder) -> Result<Self> {
        // A pad with no stiffness on an axis leaves the side frame free on it: no rubber pad.
        for (k, v) in e.stiffness.iter().enumerate() {
            b.positive(format!("{f}.stiffness[{k}]"), *v)?;
        }
        b.non_negative(format!("{f}.damping"), &e.damping)?;
        b.non_negative(format!("{f}.width_m"), &[e.width_m])?;
        let rubber = match e.loss_factor {
            None => None,
            Some(eta) => {
                if e.damping.iter().any(|&c| c != 0.0) {
                    return Err(b.err(
                        format!("{f}.loss_factor"),
                        "give damping (viscous) or loss_factor (constant over 1–50 Hz), not both",
                    ));
                }
                let mut r = [None; 3];
                for (i, &x) in eta.iter().enumerate() {
                    r[i] = Some(Rubber::fit(x).ok_or_else(|| {
                        b.err(
                            format!("{f}.loss_factor"),
                            format!("{x}: a rubber's loss factor lies in (0, 1)"),
                        )
                    })?);
                }
                Some(r.map(|x| x.expect("fitted above")))
            }
        };
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(ShearPad {
            upper,
            lower,
            rest,
            stiffness: Vector3::from(e.stiffness),
            damping: Vector3::from(e.damping),
            preload: 0.0,
            width: e.width_m,
            rubber,
        })
    }
}

impl ForceElement for ShearPad {
    const TABLE: &'static str = "shear_pad";
    type File = ShearPadFile;
    fn bind(f: &str, e: &ShearPadFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        self.forces(states, memory, wrenches, dt)
    }
    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        Some((&self.upper, &self.lower, &self.rest))
    }
    fn deflection(&self, states: &[BodyState]) -> Option<Vector3<f64>> {
        Some(self.relative(states).d)
    }
    fn static_deflection(&self) -> Vector3<f64> {
        super::static_compression(self.preload, self.stiffness.z)
    }
    fn gauge_stem(&self, upper: &str, lower: &str, _: &str) -> Option<String> {
        Some(format!("pad_{upper}_{lower}"))
    }
    fn gauge_axes(&self) -> &'static [usize] {
        &[0, 1, 2]
    }
    fn support(&self) -> Option<Support> {
        Some(Support::Shared {
            upper: self.upper,
            lower: self.lower.body,
        })
    }
    fn take_share(&mut self, share: f64) {
        self.preload = share;
    }
    /// The pad's damping, and its rocking damping `c_z·w²/12`, on the side frame with the
    /// axle held: the side frame's pitch and bounce on its two pads (230 and 170 Hz, damping
    /// ratio 0.3–0.4) put its explicit step's limit `ω²Δt² + 4ζωΔt < 4` at about 0.8 ms.
    /// The adapter's spin taken from the side frame and the jaws' moment about the axle go
    /// with it. Linearised about the static offset (the pad's 25 mm): an estimate of the
    /// slope, as the step only needs one.
    fn implicit_damping(&self, states: &[BodyState]) -> Option<ElementDamping> {
        let su = &states[self.upper.body];
        let a = su.matrix();
        let p_upper = su.point(&self.upper.local);
        let p_lower = p_upper + a * self.rest;
        // The adapter spins with the side frame, so the crown moves with the side frame's
        // rate about the axle: `Δv = (axle·axleᵀ·Δω) × crown`.
        let axle = states[self.lower.body].rotation * Vector3::y();
        let crown = p_lower - states[self.lower.body].position;
        let turn = -crown.cross_matrix() * (axle * axle.transpose());
        let mut d = ElementDamping::two_point(
            (self.upper.body, self.lower.body),
            states,
            &a,
            &self.damping,
            (p_upper, p_lower),
            &turn,
        );
        // The moment of the force at the crown about the axle goes to the side frame through
        // the jaws (`forces`): `a·aᵀ·(r × −ΔF)`, `r × −ΔF` being the lower body's moment rows.
        let jaws = -(axle * axle.transpose()) * d.on_lower.fixed_view::<3, 6>(3, 0);
        let mut up = d.on_upper.fixed_view_mut::<3, 6>(3, 0);
        up -= jaws;
        let mut low = d.on_lower.fixed_view_mut::<3, 6>(3, 0);
        low += jaws;
        if self.width > 0.0 {
            let x = a.column(0).into_owned();
            let roll = x * x.transpose() * (self.damping.z * self.width * self.width / 12.0);
            let mut up = d.on_upper.fixed_view_mut::<3, 3>(3, 3);
            up += roll;
            let mut low = d.on_lower.fixed_view_mut::<3, 3>(3, 3);
            low -= roll;
        }
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{UnitQuaternion, Vector6};

    /// The damping a linearly implicit step takes for a pad is the slope of the pad's own
    /// force law: each body's wrench changes with the side frame's velocity as `−on_upper·Δu`
    /// and `−on_lower·Δu` (central differences of `apply`, the side frame rolled and yawed a
    /// little, the axle spinning), within 2 % of each column's size (the slope reads the pad's
    /// offset at rest).
    #[test]
    fn the_implicit_damping_is_the_slope_of_the_force_law() {
        let v = crate::vehicle::Vehicle::load("vehicles/c80.toml".as_ref()).unwrap();
        let mut states: Vec<BodyState> = v
            .bodies
            .iter()
            .map(|b| BodyState {
                position: b.position,
                rotation: UnitQuaternion::identity(),
                velocity: Vector3::new(22.0, 0.0, 0.0),
                angular_velocity: Vector3::zeros(),
            })
            .collect();
        let pad = v
            .elements
            .iter()
            .find_map(|e| match e {
                Element::ShearPad(p) => Some(p.clone()),
                _ => None,
            })
            .unwrap();
        let (upper, lower) = (pad.upper.body, pad.lower.body);
        states[upper].rotation = UnitQuaternion::from_euler_angles(2e-3, -1e-3, 3e-3);
        // At the pad's static deflection (the bodies' file positions are not), pressed
        // 0.1 mm more: loaded, its rocking not tipping on an edge.
        let off = pad.relative(&states).d;
        states[upper].position += off - Vector3::new(0.0, 0.0, 1e-4);
        states[lower].angular_velocity = Vector3::new(0.0, 22.0 / 0.42, 0.0);
        let d = pad.implicit_damping(&states).unwrap();
        assert_eq!((d.upper, d.lower), (upper, lower));
        let wrench = |states: &[BodyState], body: usize| {
            let mut w = vec![Wrench::default(); states.len()];
            pad.apply(states, &mut [0.0; super::super::MEMORY], &mut w, 1e-3);
            let (f, t) = (w[body].force, w[body].torque);
            Vector6::new(f.x, f.y, f.z, t.x, t.y, t.z)
        };
        for j in 0..6 {
            let h = 1e-4;
            let nudge = |sign: f64| {
                let mut s = states.clone();
                let mut du = Vector6::zeros();
                du[j] = sign * h;
                s[upper].velocity += du.fixed_rows::<3>(0);
                s[upper].angular_velocity += du.fixed_rows::<3>(3);
                s
            };
            let (plus, minus) = (nudge(1.0), nudge(-1.0));
            for (body, m) in [(upper, d.on_upper), (lower, d.on_lower)] {
                let slope = (wrench(&plus, body) - wrench(&minus, body)) / (2.0 * h);
                let want = -m.column(j);
                assert!(
                    (slope - want).norm() <= 0.02 * want.norm().max(1e3),
                    "body {body}, column {j}: {slope:?} against {want:?}"
                );
            }
        }
    }
}
