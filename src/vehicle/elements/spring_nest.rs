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
}

impl SpringNest {
    fn forces(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        let c = self.static_compression + r.d.z;
        let fz = self.law.force(c);
        let k_lat = self.lateral_stiffness[usize::from(self.law.second_stage(c))];
        let f = Vector3::new(k_lat * r.d.x, k_lat * r.d.y, fz);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
        // Tilt of the lower body relative to the upper (roll about x, pitch about y).
        let rel = r.axes.transpose() * states[self.lower.body].matrix();
        let (roll, pitch) = (rel[(2, 1)], -rel[(2, 0)]);
        let k = self.law.tangent(c);
        let [lx, ly] = self.footprint;
        let m = Vector3::new(
            (k * ly * ly * roll).clamp(-fz * ly, fz * ly),
            (k * lx * lx * pitch).clamp(-fz * lx, fz * lx),
            0.0,
        );
        let m_world = r.axes * m;
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
    fn apply(&self, states: &[BodyState], _: &mut Memory, wrenches: &mut [Wrench], _: f64) {
        self.forces(states, wrenches)
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
