//! Variable-friction wedge damper of a three-piece bogie as a friction element that sticks:
//! a Coulomb slider in series with a stick spring (elasto-plastic friction, e.g. Dahl's
//! bristle idea without its rate law), so a stuck wedge is a stiff spring, not a big damper,
//! and needs no tiny step. K6 variable friction: each wedge rides on its own control spring
//! (part of the nest, taller than the outer coils), whose force P presses it through its sloped
//! face against the column with `N = P / tan α` (α the slope's angle from the vertical column
//! face; friction on the slope neglected, so up and down strokes damp alike); the column face
//! slips at `μ·N` (assets/docs/physics.md §2). The control springs' extra height keeps them loaded
//! when the empty wagon barely compresses the load springs: relatively more friction empty.
//!
//! - Column face (lateral y, vertical z of the bolster): force `k_s·(d − s) + c_s·v`, with the
//!   slider `s` moving only as far as keeps `|F| ≤ μ·N` (slip in the direction of the force).
//! - Longitudinal x: the wedges are pressed between bolster and column, a spring `k_x·d_x`.
//! - Warp (relative yaw ψ of side frame and bolster): the wedges' pressure moves across their
//!   faces, a moment `k_ψ·(ψ − ψ_s)` that slips at `warp_ratio·N` (N·m per N of nest force).

use super::{Element, ForceElement, Memory, Relative};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

/// Wedge damper between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct WedgeDamper {
    /// Bolster end.
    pub upper: Attachment,
    /// Side frame column.
    pub lower: Attachment,
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Friction coefficient of the column face.
    pub friction: f64,
    /// Angle of the wedge's sloped face from the vertical column face, rad.
    pub angle: f64,
    /// Stick stiffness on the column face (y and z), N/m.
    pub stick_stiffness: f64,
    /// Damping in parallel with the stick spring, N·s/m.
    pub stick_damping: f64,
    /// Longitudinal stiffness of the wedges between bolster and column, N/m.
    pub longitudinal_stiffness: f64,
    /// Warp (yaw) stick stiffness, N·m/rad.
    pub warp_stiffness: f64,
    /// Warp break-out moment over nest force, m.
    pub warp_ratio: f64,
    /// The nest whose load presses the wedge.
    pub nest: super::SpringNest,
}

/// One step of a slider: a stick spring `k` with a damper `c` in parallel, in series with a
/// Coulomb slider `s` (memory), whose force may not exceed `limit`. The trial force
/// `k·(d − s) + c·v` (the slider held) is returned while within the limit; beyond it the slider
/// moves by `λ` along the trial force's direction, taken implicitly over the step `dt` (backward
/// Euler, radial return): `k·(d − s − λ·n) + c·(v − λ·n/dt) = limit·n`, so
/// `λ = (|trial| − limit)/(k + c/dt)` and the force sits on the limit. With `c = 0` this is the
/// elasto-plastic return map `s = d − n·limit/k`. A damped slider is not reset to that same
/// point: that would drop the damper's share each step and turn the slip direction toward the
/// velocity by `c·|v|/limit` of a radian per step, whatever the step, so the run would depend
/// on the step at first order (`bench step`). Works for any dimension.
#[inline]
pub fn slider<const N: usize>(
    d: &nalgebra::SVector<f64, N>,
    v: &nalgebra::SVector<f64, N>,
    s: &mut nalgebra::SVector<f64, N>,
    k: f64,
    c: f64,
    limit: f64,
    dt: f64,
) -> nalgebra::SVector<f64, N> {
    let trial = (d - *s) * k + v * c;
    let n = trial.norm();
    if n <= limit || n == 0.0 {
        return trial;
    }
    let dir = trial / n;
    // Undamped, the same point in the return map's own form: the side bearers', centre
    // plates' and warp sliders' runs stay bit-identical to before the damped form.
    if c == 0.0 {
        *s = d - dir * (limit / k);
    } else {
        *s += dir * ((n - limit) / (k + c / dt));
    }
    dir * limit
}

impl WedgeDamper {
    /// Force with which the wedges press the column face, `N = P / tan α`, for the control
    /// springs' force `p` (N).
    #[inline]
    pub fn column_normal(&self, p: f64) -> f64 {
        p / self.angle.tan()
    }

    /// Friction limit of the column face and the nest's vertical force, for the nest at
    /// compression `c` (m): `(μ·N, F_nest)`, N.
    #[inline]
    pub fn limits(&self, c: f64) -> (f64, f64) {
        let law = &self.nest.law;
        (
            self.friction * self.column_normal(law.control_force(c)),
            law.force(c),
        )
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        // The nest's own compression (its points are not the wedge's) sets the control springs.
        let n = &self.nest;
        let c = n.static_compression + Relative::new(&n.upper, &n.lower, &n.rest, states).d.z;
        let (limit, nest_force) = self.limits(c);
        let mut s = Vector2::new(memory[0], memory[1]);
        let face = slider(
            &Vector2::new(r.d.y, r.d.z),
            &Vector2::new(r.v.y, r.v.z),
            &mut s,
            self.stick_stiffness,
            self.stick_damping,
            limit,
            dt,
        );
        memory[0] = s.x;
        memory[1] = s.y;
        // The lower body moving by d drags the upper along: force on the upper is +F.
        let f = Vector3::new(self.longitudinal_stiffness * r.d.x, face.x, face.y);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
        if self.warp_stiffness > 0.0 {
            let rel = r.axes.transpose() * states[self.lower.body].matrix();
            let psi = rel[(1, 0)];
            let up = r.axes.column(2).into_owned();
            let rate = (states[self.lower.body].angular_velocity
                - states[self.upper.body].angular_velocity)
                .dot(&up);
            let mut sp = nalgebra::Vector1::new(memory[2]);
            let m = slider(
                &nalgebra::Vector1::new(psi),
                &nalgebra::Vector1::new(rate),
                &mut sp,
                self.warp_stiffness,
                0.0,
                self.warp_ratio * nest_force,
                dt,
            )
            .x;
            memory[2] = sp.x;
            wrenches[self.upper.body].torque += up * m;
            wrenches[self.lower.body].torque -= up * m;
        }
    }
}

/// `[[wedge_damper]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WedgeDamperFile {
    pub upper: String,
    pub lower: String,
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    friction: f64,
    wedge_angle_deg: f64,
    stick_stiffness: f64,
    #[serde(default)]
    stick_damping: f64,
    #[serde(default)]
    longitudinal_stiffness: f64,
    #[serde(default)]
    warp_stiffness: f64,
    #[serde(default)]
    warp_ratio_m: f64,
}

impl WedgeDamper {
    /// Binds the file's table; `nest` is the spring nest between the same two bodies.
    fn from_row(f: &str, e: &WedgeDamperFile, nest: super::SpringNest, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.friction"), &[e.friction])?;
        if !(e.wedge_angle_deg > 5.0 && e.wedge_angle_deg < 85.0) {
            return Err(b.err(
                format!("{f}.wedge_angle_deg"),
                format!(
                    "must lie in (5, 85)° from the vertical column face, got {}",
                    e.wedge_angle_deg
                ),
            ));
        }
        if nest.law.control <= 0.0 {
            return Err(b.err(
                format!("{f}.upper"),
                "the spring_nest beside this wedge has no control_stiffness: a K6 wedge is pressed by its own control springs (spring_nest.control_stiffness, control_extra_height_m)",
            ));
        }
        b.positive(format!("{f}.stick_stiffness"), e.stick_stiffness)?;
        b.non_negative(format!("{f}.stick_damping"), &[e.stick_damping])?;
        b.non_negative(
            format!("{f}.longitudinal_stiffness"),
            &[e.longitudinal_stiffness],
        )?;
        b.non_negative(format!("{f}.warp_stiffness"), &[e.warp_stiffness])?;
        b.non_negative(format!("{f}.warp_ratio_m"), &[e.warp_ratio_m])?;
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(WedgeDamper {
            upper,
            lower,
            rest,
            friction: e.friction,
            angle: e.wedge_angle_deg.to_radians(),
            stick_stiffness: e.stick_stiffness,
            stick_damping: e.stick_damping,
            longitudinal_stiffness: e.longitudinal_stiffness,
            warp_stiffness: e.warp_stiffness,
            warp_ratio: e.warp_ratio_m,
            nest,
        })
    }
}

impl ForceElement for WedgeDamper {
    const TABLE: &'static str = "wedge_damper";
    type File = WedgeDamperFile;
    /// The nest between the same two bodies, bound before it, presses the wedge.
    fn bind(f: &str, e: &WedgeDamperFile, b: &Binder, bound: &[Element]) -> Result<Self> {
        let (u, l) = (
            b.find(format!("{f}.upper"), &e.upper)?,
            b.find(format!("{f}.lower"), &e.lower)?,
        );
        let nest = nest_between(bound, u, l).ok_or_else(|| {
            b.err(
                f.to_string(),
                format!(
                    "no spring_nest between \"{}\" and \"{}\" to press the wedge",
                    e.upper, e.lower
                ),
            )
        })?;
        Self::from_row(f, e, nest.clone(), b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        self.forces(states, memory, wrenches, dt)
    }
    /// Reads its nest's static compression once the load path has set it.
    fn settle(&mut self, elements: &[Element]) {
        if let Some(nest) = nest_between(elements, self.nest.upper.body, self.nest.lower.body) {
            self.nest = nest.clone();
        }
    }
    fn frictionless(&mut self) {
        self.friction = 0.0;
        self.warp_ratio = 0.0;
    }
}

/// The first spring nest between bodies `upper` and `lower`.
fn nest_between(elements: &[Element], upper: usize, lower: usize) -> Option<&super::SpringNest> {
    elements.iter().find_map(|e| match e {
        Element::SpringNest(n) if n.upper.body == upper && n.lower.body == lower => Some(n),
        _ => None,
    })
}
