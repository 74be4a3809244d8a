//! Constant-contact side bearer: preloaded vertical spring that only pushes, with friction in
//! the horizontal plane that sticks (the cap's elastomer in shear, `stick_stiffness`, in series
//! with a Coulomb slider at `μ·N`: the elasto-plastic element of the wedges), and a solid stop:
//! after `travel` of
//! compression beyond the static position the cage bottoms out and the much stiffer stop
//! (bolster and carbody bolster in series) carries the rest.

use super::{Element, ForceElement, Memory, Relative, Support, slider};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

/// Side bearer between the carbody (upper) and a bolster (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct SideBearer {
    /// Carbody wear plate.
    pub upper: Attachment,
    /// Bolster bearer.
    pub lower: Attachment,
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Vertical stiffness, N/m.
    pub stiffness: f64,
    /// Preload at the static position, N.
    pub preload: f64,
    /// Friction coefficient.
    pub friction: f64,
    /// Horizontal stiffness of the stuck bearer (x and y), N/m.
    pub stick_stiffness: f64,
    /// Vertical damping of the elastomer, N·s/m.
    pub damping: f64,
    /// Compression from the static position at which the bearer goes solid, m (∞: no stop).
    pub travel: f64,
    /// Stiffness of the solid stop, N/m.
    pub stop_stiffness: f64,
}

impl SideBearer {
    /// Vertical force at compression `d` (m) from the static position: the preloaded spring,
    /// plus the stop beyond `travel`; never pulls.
    #[inline]
    pub fn vertical_force(&self, d: f64) -> f64 {
        (self.preload + self.stiffness * d + self.stop_stiffness * (d - self.travel).max(0.0))
            .max(0.0)
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        let normal = (self.vertical_force(r.d.z) + self.damping * r.v.z).max(0.0);
        let mut s = Vector2::new(memory[0], memory[1]);
        // The lower body moving by d drags the upper along: the force on the upper is +F.
        let h = slider(
            &Vector2::new(r.d.x, r.d.y),
            &Vector2::new(r.v.x, r.v.y),
            &mut s,
            self.stick_stiffness,
            0.0,
            self.friction * normal,
            dt,
        );
        (memory[0], memory[1]) = (s.x, s.y);
        let f = Vector3::new(h.x, h.y, normal);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
    }
}

/// `[[side_bearer]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SideBearerFile {
    upper: String,
    lower: String,
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    stiffness: f64,
    preload_n: f64,
    friction: f64,
    /// Horizontal stick stiffness, N/m.
    stick_stiffness: f64,
    /// Vertical damping, N·s/m.
    #[serde(default)]
    damping: f64,
    /// Compression travel from the static position to solid, m (absent: no stop).
    travel_m: Option<f64>,
    /// Stop stiffness, N/m.
    #[serde(default = "default_stop_stiffness")]
    stop_stiffness: f64,
}

fn default_stop_stiffness() -> f64 {
    1e8
}

impl SideBearer {
    fn from_row(f: &str, e: &SideBearerFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.stiffness"), &[e.stiffness])?;
        b.non_negative(format!("{f}.preload_n"), &[e.preload_n])?;
        if e.preload_n > 0.0 && e.stiffness == 0.0 {
            return Err(b.err(
                format!("{f}.stiffness"),
                format!(
                    "0 with a preload of {} N: a preload is a spring's, give its stiffness",
                    e.preload_n
                ),
            ));
        }
        b.non_negative(format!("{f}.friction"), &[e.friction])?;
        b.positive(format!("{f}.stick_stiffness"), e.stick_stiffness)?;
        b.non_negative(format!("{f}.damping"), &[e.damping])?;
        b.non_negative(format!("{f}.stop_stiffness"), &[e.stop_stiffness])?;
        let travel = match e.travel_m {
            Some(t) => b.positive(format!("{f}.travel_m"), t)?,
            None => f64::INFINITY,
        };
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(SideBearer {
            upper,
            lower,
            rest,
            stiffness: e.stiffness,
            preload: e.preload_n,
            friction: e.friction,
            stick_stiffness: e.stick_stiffness,
            damping: e.damping,
            travel,
            stop_stiffness: e.stop_stiffness,
        })
    }
}

impl ForceElement for SideBearer {
    const TABLE: &'static str = "side_bearer";
    type File = SideBearerFile;
    fn bind(f: &str, e: &SideBearerFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        self.forces(states, memory, wrenches, dt)
    }
    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        Some((&self.upper, &self.lower, &self.rest))
    }
    fn static_deflection(&self) -> Vector3<f64> {
        super::static_compression(self.preload, self.stiffness)
    }
    fn gauge_stem(&self, _: &str, lower: &str, side: &str) -> Option<String> {
        Some(format!("sidebearer_{lower}_{side}"))
    }
    fn gauge_axes(&self) -> &'static [usize] {
        &[2]
    }
    fn support(&self) -> Option<Support> {
        Some(Support::Preloaded {
            upper: self.upper.body,
            lower: self.lower.body,
            preload: self.preload,
        })
    }
    fn frictionless(&mut self) {
        self.friction = 0.0;
    }
}
