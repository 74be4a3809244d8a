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
    /// How the wedge's balance sets the column's normal force.
    pub statics: WedgeStatics,
    /// Friction coefficient of the sloped face (two-face statics only).
    pub slope_friction: f64,
}

/// The wedge's statics: how the control springs' force becomes the column face's normal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WedgeStatics {
    /// `N = P / tan α`: the slope frictionless, both strokes alike.
    #[default]
    OneFace,
    /// Friction on both faces: loading and unloading strokes differ.
    TwoFace,
}

impl WedgeStatics {
    /// The file's names.
    pub const NAMES: [&'static str; 2] = ["one_face", "two_face"];

    fn parse(s: &str) -> Option<Self> {
        match s {
            "one_face" => Some(WedgeStatics::OneFace),
            "two_face" => Some(WedgeStatics::TwoFace),
            _ => None,
        }
    }
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
    /// Force with which the wedges press the column face for the control springs' force `p`
    /// (N), the column slipping with vertical direction cosine `nz` (+1 loading: the force
    /// on the bolster up, the bolster moving down; −1 unloading): `P / tan α` one-face,
    /// `P / (tan(α + n_z·φs) − n_z·μc)` two-face (module docs).
    #[inline]
    pub fn column_normal(&self, p: f64, nz: f64) -> f64 {
        match self.statics {
            WedgeStatics::OneFace => p / self.angle.tan(),
            WedgeStatics::TwoFace => {
                let phi = self.slope_friction.atan();
                p / ((self.angle + nz * phi).tan() - nz * self.friction)
            }
        }
    }

    /// Friction limit of the column face and the nest's vertical force, for the nest at
    /// compression `c` (m) and the slip's vertical direction cosine `nz`: `(μ·N, F_nest)`, N.
    #[inline]
    pub fn limits(&self, c: f64, nz: f64) -> (f64, f64) {
        let law = &self.nest.law;
        (
            self.friction * self.column_normal(law.control_force(c), nz),
            law.force(c),
        )
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        // The nest's own compression (its points are not the wedge's) sets the control springs.
        let n = &self.nest;
        let c = n.static_compression + Relative::new(&n.upper, &n.lower, &n.rest, states).d.z;
        let mut s = Vector2::new(memory[0], memory[1]);
        let (d, v) = (Vector2::new(r.d.y, r.d.z), Vector2::new(r.v.y, r.v.z));
        // The stroke's direction from the trial force (the slider held): only the two-face
        // statics tell the strokes apart.
        let nz = match self.statics {
            WedgeStatics::OneFace => 0.0,
            WedgeStatics::TwoFace => {
                let trial = (d - s) * self.stick_stiffness + v * self.stick_damping;
                let n = trial.norm();
                if n > 0.0 { trial.y / n } else { 0.0 }
            }
        };
        let (limit, nest_force) = self.limits(c, nz);
        let face = slider(
            &d,
            &v,
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
    /// `one_face` (the default) or `two_face`.
    #[serde(default)]
    statics: Option<String>,
    /// Sloped face's friction coefficient (two-face statics).
    #[serde(default)]
    slope_friction: Option<f64>,
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
        let statics = match &e.statics {
            None => WedgeStatics::OneFace,
            Some(s) => WedgeStatics::parse(s).ok_or_else(|| {
                b.err(
                    format!("{f}.statics"),
                    format!("{s:?}: give one of {:?}", WedgeStatics::NAMES),
                )
            })?,
        };
        let slope_friction = match (statics, e.slope_friction) {
            (WedgeStatics::OneFace, Some(_)) => {
                return Err(b.err(
                    format!("{f}.slope_friction"),
                    "the one-face statics has a frictionless slope: set statics = \"two_face\" to use it",
                ));
            }
            (WedgeStatics::OneFace, None) => 0.0,
            (WedgeStatics::TwoFace, mu_s) => {
                let mu_s = mu_s.ok_or_else(|| {
                    b.err(
                        format!("{f}.slope_friction"),
                        "the two-face statics needs the sloped face's friction coefficient",
                    )
                })?;
                b.non_negative(format!("{f}.slope_friction"), &[mu_s])?;
                // Loading must not lock: tan(α + φs) > μc, and the angle plus φs below 90°.
                let alpha = e.wedge_angle_deg.to_radians();
                let phi = mu_s.atan();
                if alpha + phi >= std::f64::consts::FRAC_PI_2
                    || (alpha + phi).tan() <= e.friction
                    || (alpha - phi).tan() + e.friction <= 0.0
                {
                    return Err(b.err(
                        format!("{f}.slope_friction"),
                        format!(
                            "with wedge_angle_deg {} and friction {} a slope friction of {mu_s} locks the wedge (tan(α + atan μs) must exceed μc, α + atan μs stay below 90°)",
                            e.wedge_angle_deg, e.friction
                        ),
                    ));
                }
                mu_s
            }
        };
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
            statics,
            slope_friction,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::elements::NestLaw;
    use nalgebra::UnitQuaternion;

    fn wedge(statics: WedgeStatics, mu_c: f64, mu_s: f64, angle_deg: f64) -> WedgeDamper {
        let at = |body| Attachment {
            body,
            local: Vector3::zeros(),
        };
        let law = NestLaw {
            outer: 1e6,
            inner: 0.0,
            inner_gap: 1.0,
            control: 5e5,
            control_extra: 0.01,
        };
        WedgeDamper {
            upper: at(0),
            lower: at(1),
            rest: Vector3::zeros(),
            friction: mu_c,
            angle: angle_deg.to_radians(),
            stick_stiffness: 2e7,
            stick_damping: 0.0,
            longitudinal_stiffness: 0.0,
            warp_stiffness: 0.0,
            warp_ratio: 0.0,
            nest: super::super::SpringNest {
                upper: at(0),
                lower: at(1),
                rest: Vector3::zeros(),
                law,
                lateral_stiffness: [0.0; 2],
                static_compression: 0.03,
                footprint: [0.0; 2],
                staging: Default::default(),
            },
            statics,
            slope_friction: mu_s,
        }
    }

    /// Drives the side frame (lower) vertically relative to the bolster through a ramp of
    /// `stroke` (m) in 400 steps and returns the column force on the bolster at the end,
    /// over the control springs' force.
    fn sliding_force_ratio(w: &WedgeDamper, stroke: f64) -> f64 {
        let still = BodyState {
            position: Vector3::zeros(),
            rotation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        };
        let mut memory = [0.0; crate::vehicle::elements::MEMORY];
        let mut f = 0.0;
        let n = 400;
        let dt = 1e-3;
        for i in 1..=n {
            let z = stroke * i as f64 / n as f64;
            let mut lower = still;
            lower.position.z = z;
            lower.velocity.z = stroke / (n as f64 * dt);
            let mut wrenches = [Wrench::default(); 2];
            w.forces(&[still, lower], &mut memory, &mut wrenches, dt);
            f = wrenches[0].force.z;
        }
        // The nest's compression follows the relative motion (its own points are the wedge's).
        let c = w.nest.static_compression + stroke;
        f / w.nest.law.control_force(c)
    }

    #[test]
    fn two_face_statics_match_the_closed_forms() {
        // Closed forms (module docs; the specification's table at θ = 37.5°):
        // loading μc/(tan(θ+φs) − μc), unloading μc/(tan(θ−φs) + μc).
        for (mu_s, load, unload) in [(0.0, 0.642, 0.281), (0.3, 0.276, 0.441)] {
            let w = wedge(WedgeStatics::TwoFace, 0.3, mu_s, 37.5);
            let phi: f64 = f64::atan(mu_s);
            let th = 37.5f64.to_radians();
            let exact_load = 0.3 / ((th + phi).tan() - 0.3);
            let exact_unload = 0.3 / ((th - phi).tan() + 0.3);
            assert!((exact_load - load).abs() < 5e-4 && (exact_unload - unload).abs() < 5e-4);
            // Loading: the side frame rises against the bolster (the bolster moves down on it),
            // the friction on the bolster acts up.
            let up = sliding_force_ratio(&w, 0.005);
            assert!(
                (up - exact_load).abs() < 1e-9,
                "loading {up} vs {exact_load}"
            );
            let down = sliding_force_ratio(&w, -0.005);
            assert!(
                (down + exact_unload).abs() < 1e-9,
                "unloading {down} vs −{exact_unload}"
            );
        }
        // One face: both strokes μ/tan α.
        let w = wedge(WedgeStatics::OneFace, 0.3, 0.0, 37.5);
        let exact = 0.3 / 37.5f64.to_radians().tan();
        assert!((sliding_force_ratio(&w, 0.005) - exact).abs() < 1e-9);
        assert!((sliding_force_ratio(&w, -0.005) + exact).abs() < 1e-9);
    }

    #[test]
    fn a_lateral_slip_takes_the_slopes_mean() {
        let w = wedge(WedgeStatics::TwoFace, 0.3, 0.3, 37.5);
        let p = 1000.0;
        assert!((w.column_normal(p, 0.0) - p / 37.5f64.to_radians().tan()).abs() < 1e-9);
        // Between the strokes, monotone in n_z.
        let ns: Vec<f64> = (-10..=10)
            .map(|i| w.column_normal(p, i as f64 / 10.0))
            .collect();
        assert!(ns.windows(2).all(|x| x[1] < x[0]), "{ns:?}");
    }
}
