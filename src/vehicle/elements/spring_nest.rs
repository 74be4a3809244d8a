//! Two-stage spring nest of a three-piece bogie (K6: load springs with outer and inner coils,
//! and the wedges' control springs beside them). The outer coils carry alone until the inner
//! coils, shorter by their free-height gap, engage; the control springs stand taller than the
//! outer coils and are compressed that much more. So the empty and the loaded wagon's
//! stiffness follow from the same nest data (1.2 MN/m empty, 4.8 MN/m loaded for the C80's
//! estimates). Springs only push. Laterally the coils shear: the stiffness of the stage that
//! is engaged. The nest is a group of springs spread over the spring seat (half-spacings
//! `footprint` along x and y), so it also resists tilt between bolster end and side frame:
//! `k·l²` per axis with the current tangent stiffness k, up to the moment `F·l` at which the
//! springs on one side unload.
//!
//! How the stages meet the lateral and tilt forces (`staging` in the file):
//! - `tangent`: the stiffness of the stage engaged at that instant, applied to the whole
//!   deflection, and the tilt `k·l²·θ` clamped at `F·l`. The force jumps about fourfold when
//!   the inner coils engage while deflected: it derives from no potential, and a closed cycle
//!   across the stage can return more work than it took (the test shows it).
//! - `potential`: the tilt and the vertical force from the potential of four quarter nests at
//!   `(±l_x, ±l_y)`, `V = ¼·Σ U(c_q)` with `U` the integral of the force law and `c_q` each
//!   quarter's compression; a quarter that lifts off carries nothing, so the moment saturates
//!   at `F·l` by itself. The inner coils' shear seats where they touch: engaged at lateral
//!   offset `d₀`, they carry `k_inner·(d − d₀)`, and they let go of what they held when they
//!   lift off. Within a stage the element is conservative; across one it can only lose
//!   energy (the seating), never make it (closed-cycle test).

use super::{Element, ForceElement, Memory, Relative, Support};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Vertical force–compression law of a two-stage nest with its wedges' control springs.
/// Compression `c` is that of the outer coils from their free height, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NestLaw {
    /// Outer coils of the load springs, N/m.
    pub outer: f64,
    /// Inner coils, N/m, engaged beyond `inner_gap`.
    pub inner: f64,
    /// Compression of the outer coils at which the inner coils engage, m.
    pub inner_gap: f64,
    /// Control springs of the wedges (all of the nest's), N/m.
    pub control: f64,
    /// How much taller than the outer coils the control springs stand, m.
    pub control_extra: f64,
}

impl NestLaw {
    /// Force of the control springs at compression `c`, N (what presses the wedges).
    #[inline]
    pub fn control_force(&self, c: f64) -> f64 {
        self.control * (c + self.control_extra).max(0.0)
    }

    /// Force of the whole nest at compression `c`, N; zero when no spring is compressed.
    #[inline]
    pub fn force(&self, c: f64) -> f64 {
        self.outer * c.max(0.0) + self.inner * (c - self.inner_gap).max(0.0) + self.control_force(c)
    }

    /// Tangent stiffness at compression `c`, N/m.
    #[inline]
    pub fn tangent(&self, c: f64) -> f64 {
        let on = |x: f64| if x > 0.0 { 1.0 } else { 0.0 };
        self.outer * on(c)
            + self.inner * on(c - self.inner_gap)
            + self.control * on(c + self.control_extra)
    }

    /// Whether the inner coils carry at compression `c`.
    #[inline]
    pub fn second_stage(&self, c: f64) -> bool {
        c > self.inner_gap
    }

    /// Compression that carries `f` (N): the force is piecewise linear and rising, found by
    /// bisection to 1 nm.
    pub fn compression(&self, f: f64) -> f64 {
        let (mut lo, mut hi) = (-self.control_extra, 1.0);
        while self.force(hi) < f {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.force(mid) < f {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-9 {
                break;
            }
        }
        0.5 * (lo + hi)
    }
}

/// Spring nest between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringNest {
    /// Bolster end.
    pub upper: Attachment,
    /// Side frame spring seat.
    pub lower: Attachment,
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Vertical law.
    pub law: NestLaw,
    /// Lateral and longitudinal shear stiffness, N/m: outer (and control) coils alone, and
    /// with the inner coils engaged.
    pub lateral_stiffness: [f64; 2],
    /// Static compression (from the static load), m.
    pub static_compression: f64,
    /// Half-spacing of the springs in the group along x and y, m.
    pub footprint: [f64; 2],
    /// How the stages meet the lateral and tilt forces.
    pub staging: NestStaging,
}

/// How a nest's stages meet its lateral and tilt forces (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NestStaging {
    /// The engaged stage's stiffness on the whole deflection (no potential).
    #[default]
    Tangent,
    /// Quarter nests' potential for tilt, seated inner coils for shear.
    Potential,
}

impl NestStaging {
    /// The file's names.
    pub const NAMES: [&'static str; 2] = ["tangent", "potential"];

    fn parse(s: &str) -> Option<Self> {
        match s {
            "tangent" => Some(NestStaging::Tangent),
            "potential" => Some(NestStaging::Potential),
            _ => None,
        }
    }
}

impl NestLaw {
    /// Energy stored at compression `c`, J: the integral of [`Self::force`] from where the
    /// first spring touches.
    pub fn energy(&self, c: f64) -> f64 {
        let half = |k: f64, x: f64| 0.5 * k * x.max(0.0).powi(2);
        half(self.outer, c)
            + half(self.inner, c - self.inner_gap)
            + half(self.control, c + self.control_extra)
    }
}

impl SpringNest {
    /// Shear force (x, y), N, for the lateral and longitudinal deflection `d` (m) at
    /// compression `c`. `memory[0..2]` hold where the inner coils seated and `memory[2]` is 1
    /// while they are off (zero memory: seated at the static position).
    pub fn shear(&self, c: f64, d: [f64; 2], memory: &mut Memory) -> [f64; 2] {
        let engaged = self.law.second_stage(c);
        match self.staging {
            NestStaging::Tangent => {
                let k = self.lateral_stiffness[usize::from(engaged)];
                [k * d[0], k * d[1]]
            }
            NestStaging::Potential => {
                let k0 = self.lateral_stiffness[0];
                let k_in = self.lateral_stiffness[1] - k0;
                if !engaged {
                    memory[2] = 1.0;
                    return [k0 * d[0], k0 * d[1]];
                }
                if memory[2] != 0.0 {
                    // The inner coils touch now, where the bolster is: unstrained.
                    memory[0] = d[0];
                    memory[1] = d[1];
                    memory[2] = 0.0;
                }
                [
                    k0 * d[0] + k_in * (d[0] - memory[0]),
                    k0 * d[1] + k_in * (d[1] - memory[1]),
                ]
            }
        }
    }

    /// Vertical force, N, and tilt moments (about x and y), N·m, at compression `c` and
    /// relative roll and pitch (rad).
    pub fn tilt(&self, c: f64, roll: f64, pitch: f64) -> (f64, f64, f64) {
        let [lx, ly] = self.footprint;
        match self.staging {
            NestStaging::Tangent => {
                let fz = self.law.force(c);
                let k = self.law.tangent(c);
                (
                    fz,
                    (k * ly * ly * roll).clamp(-fz * ly, fz * ly),
                    (k * lx * lx * pitch).clamp(-fz * lx, fz * lx),
                )
            }
            NestStaging::Potential => {
                let (mut fz, mut mx, mut my) = (0.0, 0.0, 0.0);
                for sx in [-1.0, 1.0] {
                    for sy in [-1.0, 1.0] {
                        let f = 0.25 * self.law.force(c + sy * ly * roll + sx * lx * pitch);
                        fz += f;
                        mx += f * sy * ly;
                        my += f * sx * lx;
                    }
                }
                (fz, mx, my)
            }
        }
    }

    /// Energy the potential form stores at compression `c`, roll and pitch, J (the shear's
    /// seated part aside).
    pub fn tilt_energy(&self, c: f64, roll: f64, pitch: f64) -> f64 {
        let [lx, ly] = self.footprint;
        let mut e = 0.0;
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                e += 0.25 * self.law.energy(c + sy * ly * roll + sx * lx * pitch);
            }
        }
        e
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        let c = self.static_compression + r.d.z;
        // Tilt of the lower body relative to the upper (roll about x, pitch about y).
        let rel = r.axes.transpose() * states[self.lower.body].matrix();
        let (roll, pitch) = (rel[(2, 1)], -rel[(2, 0)]);
        let (fz, mx, my) = self.tilt(c, roll, pitch);
        let [fx, fy] = self.shear(c, [r.d.x, r.d.y], memory);
        r.apply(
            Vector3::new(fx, fy, fz),
            &self.upper,
            &self.lower,
            states,
            wrenches,
        );
        let m_world = r.axes * Vector3::new(mx, my, 0.0);
        wrenches[self.upper.body].torque += m_world;
        wrenches[self.lower.body].torque -= m_world;
    }
}

/// `[[spring_nest]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SpringNestFile {
    upper: String,
    lower: String,
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    outer_stiffness: f64,
    inner_stiffness: f64,
    inner_gap_m: f64,
    #[serde(default)]
    control_stiffness: f64,
    #[serde(default)]
    control_extra_height_m: f64,
    lateral_stiffness: [f64; 2],
    footprint_m: [f64; 2],
    /// `tangent` (the default) or `potential`.
    #[serde(default)]
    staging: Option<String>,
}

impl SpringNest {
    fn from_row(f: &str, e: &SpringNestFile, b: &Binder) -> Result<Self> {
        b.positive(format!("{f}.outer_stiffness"), e.outer_stiffness)?;
        b.non_negative(format!("{f}.inner_stiffness"), &[e.inner_stiffness])?;
        b.non_negative(format!("{f}.inner_gap_m"), &[e.inner_gap_m])?;
        b.non_negative(format!("{f}.control_stiffness"), &[e.control_stiffness])?;
        b.non_negative(
            format!("{f}.control_extra_height_m"),
            &[e.control_extra_height_m],
        )?;
        b.non_negative(format!("{f}.lateral_stiffness"), &e.lateral_stiffness)?;
        b.non_negative(format!("{f}.footprint_m"), &e.footprint_m)?;
        let staging = match &e.staging {
            None => NestStaging::Tangent,
            Some(s) => NestStaging::parse(s).ok_or_else(|| {
                b.err(
                    format!("{f}.staging"),
                    format!("{s:?}: give one of {:?}", NestStaging::NAMES),
                )
            })?,
        };
        if staging == NestStaging::Potential && e.lateral_stiffness[1] < e.lateral_stiffness[0] {
            return Err(b.err(
                format!("{f}.lateral_stiffness"),
                "with the inner coils engaged the shear stiffness cannot fall: give [outer, outer + inner] with the second not below the first",
            ));
        }
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(SpringNest {
            upper,
            lower,
            rest,
            law: NestLaw {
                outer: e.outer_stiffness,
                inner: e.inner_stiffness,
                inner_gap: e.inner_gap_m,
                control: e.control_stiffness,
                control_extra: e.control_extra_height_m,
            },
            lateral_stiffness: e.lateral_stiffness,
            static_compression: 0.0,
            footprint: e.footprint_m,
            staging,
        })
    }
}

impl ForceElement for SpringNest {
    const TABLE: &'static str = "spring_nest";
    type File = SpringNestFile;
    fn bind(f: &str, e: &SpringNestFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], _: f64) {
        self.forces(states, memory, wrenches)
    }
    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        Some((&self.upper, &self.lower, &self.rest))
    }
    fn static_deflection(&self) -> Vector3<f64> {
        Vector3::new(0.0, 0.0, self.static_compression)
    }
    fn gauge_stem(&self, _: &str, lower: &str, _: &str) -> Option<String> {
        Some(format!("nest_{lower}"))
    }
    fn gauge_axes(&self) -> &'static [usize] {
        &[2, 1]
    }
    fn support(&self) -> Option<Support> {
        Some(Support::Shared {
            upper: self.upper,
            lower: self.lower.body,
        })
    }
    fn take_share(&mut self, share: f64) {
        self.static_compression = self.law.compression(share);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nest(staging: NestStaging) -> SpringNest {
        let at = |body| Attachment {
            body,
            local: Vector3::zeros(),
        };
        SpringNest {
            upper: at(0),
            lower: at(1),
            rest: Vector3::zeros(),
            // The C80's nest (vehicles/c80.toml).
            law: NestLaw {
                outer: 0.7e6,
                inner: 3.6e6,
                inner_gap: 0.04,
                control: 0.5e6,
                control_extra: 0.01,
            },
            lateral_stiffness: [0.5e6, 2.0e6],
            static_compression: 0.0,
            footprint: [0.15, 0.10],
            staging,
        }
    }

    /// Work the element returns to the bodies over a closed path of (c, y, roll), J: the
    /// generalised forces (vertical, lateral, roll moment) along the path's increments by the
    /// trapezoidal rule; positive is energy made.
    fn work_over_cycle(n: &SpringNest, path: &dyn Fn(f64) -> (f64, f64, f64)) -> f64 {
        let steps = 200_000;
        let mut memory = [0.0; crate::vehicle::elements::MEMORY];
        let generalised = |q: (f64, f64, f64), m: &mut Memory| {
            let (fz, mx, _) = n.tilt(q.0, q.2, 0.0);
            let [_, fy] = n.shear(q.0, [0.0, q.1], m);
            (fz, fy, mx)
        };
        let mut q0 = path(0.0);
        let mut f0 = generalised(q0, &mut memory);
        let mut w = 0.0;
        for i in 1..=steps {
            let q1 = path(i as f64 / steps as f64);
            let f1 = generalised(q1, &mut memory);
            // The forces resist compression, shear and tilt: the work done on the bodies is
            // −∫ F·dq.
            w -= 0.5 * (f0.0 + f1.0) * (q1.0 - q0.0)
                + 0.5 * (f0.1 + f1.1) * (q1.1 - q0.1)
                + 0.5 * (f0.2 + f1.2) * (q1.2 - q0.2);
            q0 = q1;
            f0 = f1;
        }
        w
    }

    /// A cycle that compresses the nest from 30 to 70 mm and back across the inner coils'
    /// 40 mm gap, shearing it most when they engage (t = 1/6) and half as much when they
    /// lift off (t = 5/6), and tilting it meanwhile.
    fn cycle(t: f64) -> (f64, f64, f64) {
        use std::f64::consts::TAU;
        let c = 0.03 + 0.04 * (1.0 - (TAU * t).cos()) / 2.0;
        (
            c,
            0.01 * (TAU * (t - 1.0 / 6.0)).cos(),
            0.02 * (TAU * t).sin(),
        )
    }

    #[test]
    fn potential_staging_makes_no_energy_over_a_closed_cycle() {
        let scale = nest(NestStaging::Potential).law.energy(0.07);
        let w = work_over_cycle(&nest(NestStaging::Potential), &cycle);
        // Seating may lose energy, never make it.
        assert!(
            w <= 1e-6 * scale,
            "potential form made {w} J (scale {scale} J)"
        );
        // Within one stage (all quarters past the inner gap) the element is conservative.
        let within = |t: f64| {
            let (c, y, roll) = cycle(t);
            (c + 0.03, y, 0.5 * roll)
        };
        let w = work_over_cycle(&nest(NestStaging::Potential), &within);
        assert!(w.abs() < 1e-6 * scale, "within a stage: {w} J");
        // The tangent form, over the same cycle, returns more work than it took.
        let w = work_over_cycle(&nest(NestStaging::Tangent), &cycle);
        assert!(w > 1.0, "tangent form: {w} J");
    }

    #[test]
    fn potential_tilt_is_the_tangent_one_within_a_stage_and_saturates_at_f_l() {
        let (t, p) = (nest(NestStaging::Tangent), nest(NestStaging::Potential));
        let c = 0.06;
        for roll in [-0.01, -0.001, 0.0, 0.002, 0.01] {
            let (a, b) = (t.tilt(c, roll, 0.0), p.tilt(c, roll, 0.0));
            assert!((a.0 - b.0).abs() < 1e-6 * a.0 && (a.1 - b.1).abs() < 1e-6 * a.0);
        }
        // Tilted far enough that one side lifts off, the moment is the nest force times l_y.
        let (fz, mx, _) = p.tilt(0.02, 0.5, 0.0);
        assert!((mx - fz * 0.10).abs() < 1e-9 * fz, "{mx} vs {}", fz * 0.10);
        // The moment is the potential's derivative.
        let h = 1e-7;
        let de = (p.tilt_energy(0.045, 0.03 + h, 0.004) - p.tilt_energy(0.045, 0.03 - h, 0.004))
            / (2.0 * h);
        let (_, mx, _) = p.tilt(0.045, 0.03, 0.004);
        assert!((de - mx).abs() < 1e-4 * mx.abs(), "{de} vs {mx}");
    }
}
