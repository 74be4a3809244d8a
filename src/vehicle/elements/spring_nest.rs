//! Two-stage spring nest of a three-piece bogie: outer springs alone up to a travel, then outer
//! and inner springs together (bilinear), linear laterally. Springs only push. The nest is a
//! group of springs spread over the spring seat (half-spacings `footprint` along x and y), so
//! it also resists tilt between bolster end and side frame: `k·l²` per axis with the current
//! tangent stiffness k, up to the moment `F·l` at which the springs on one side unload.
//! Without that a side frame, carried from below by its pads and loaded from above by the
//! nest, would be an inverted pendulum.

use super::Relative;
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Vertical force–compression law of a two-stage nest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NestLaw {
    /// First-stage stiffness, N/m.
    pub k1: f64,
    /// Second-stage stiffness (both stages), N/m.
    pub k2: f64,
    /// Compression where the second stage engages, m.
    pub travel1: f64,
}

impl NestLaw {
    /// Force at compression `c` (m from the free height); zero when not compressed.
    #[inline]
    pub fn force(&self, c: f64) -> f64 {
        if c <= 0.0 {
            0.0
        } else if c <= self.travel1 {
            self.k1 * c
        } else {
            self.k1 * self.travel1 + self.k2 * (c - self.travel1)
        }
    }

    /// Tangent stiffness at compression `c`, N/m.
    #[inline]
    pub fn tangent(&self, c: f64) -> f64 {
        if c <= 0.0 {
            0.0
        } else if c <= self.travel1 {
            self.k1
        } else {
            self.k2
        }
    }

    /// Compression that carries `f` (N).
    pub fn compression(&self, f: f64) -> f64 {
        let f1 = self.k1 * self.travel1;
        if f <= f1 {
            f / self.k1
        } else {
            self.travel1 + (f - f1) / self.k2
        }
    }
}

/// Spring nest between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct SpringNest {
    /// Bolster end.
    pub upper: Attachment,
    /// Side frame spring seat.
    pub lower: Attachment,
    /// Vertical law.
    pub law: NestLaw,
    /// Lateral and longitudinal stiffness, N/m.
    pub lateral_stiffness: f64,
    /// Static compression (from the static load), m.
    pub static_compression: f64,
    /// Half-spacing of the springs in the group along x and y, m.
    pub footprint: [f64; 2],
}

impl SpringNest {
    /// Vertical force at the current state, N.
    #[inline]
    pub(crate) fn vertical_force(&self, rel: &Relative) -> f64 {
        self.law.force(self.static_compression + rel.d.z)
    }

    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let c = self.static_compression + r.d.z;
        let fz = self.law.force(c);
        let f = Vector3::new(
            self.lateral_stiffness * r.d.x,
            self.lateral_stiffness * r.d.y,
            fz,
        );
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
    at: [f64; 3],
    vertical_stiffness: [f64; 2],
    first_stage_travel_m: f64,
    lateral_stiffness: f64,
    footprint_m: [f64; 2],
}

impl SpringNest {
    pub(crate) fn bind(f: &str, e: &SpringNestFile, b: &Binder) -> Result<Self> {
        b.positive(format!("{f}.vertical_stiffness"), e.vertical_stiffness[0])?;
        b.positive(format!("{f}.vertical_stiffness"), e.vertical_stiffness[1])?;
        b.non_negative(format!("{f}.lateral_stiffness"), &[e.lateral_stiffness])?;
        b.positive(format!("{f}.first_stage_travel_m"), e.first_stage_travel_m)?;
        b.non_negative(format!("{f}.footprint_m"), &e.footprint_m)?;
        let (upper, lower) = b.pair(f, &e.upper, &e.lower, e.at)?;
        Ok(SpringNest {
            upper,
            lower,
            law: NestLaw {
                k1: e.vertical_stiffness[0],
                k2: e.vertical_stiffness[1],
                travel1: e.first_stage_travel_m,
            },
            lateral_stiffness: e.lateral_stiffness,
            static_compression: 0.0,
            footprint: e.footprint_m,
        })
    }
}
