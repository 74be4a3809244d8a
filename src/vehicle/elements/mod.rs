//! Force elements of the suspension, one file per kind. Each acts between two bodies through
//! an attachment point on each (`upper_at`, `lower_at`: where the parts meet, not one point for
//! both) and adds equal and opposite forces (and torques) to their wrenches. Axes of an element
//! are those of its upper body; displacements are those of the lower attachment relative to
//! the upper one less their static offset, zero in the static loaded position, where
//! supporting elements carry their preload.
//!
//! Each body takes the element's force at its own point. The two points are not on one line of
//! action, so the pair of forces has a couple `(p_lower − p_upper) × F`; the upper body carries
//! it (as the clamped top of a coil spring carries its shear couple), so the lower body feels
//! the force exactly where it meets the element: a side frame loaded at its spring seat and
//! carried at its pedestal roofs hangs, as built (assets/docs/physics.md §2).

mod centre_plate;
mod cross_bracing;
mod lateral_stop;
mod shear_pad;
mod side_bearer;
mod spring_nest;
mod track_spring;
mod wedge_damper;

pub use centre_plate::CentrePlate;
pub use cross_bracing::CrossBracing;
pub use lateral_stop::LateralStop;
pub use shear_pad::ShearPad;
pub use side_bearer::SideBearer;
pub use spring_nest::{NestLaw, SpringNest};
pub use track_spring::TrackSpring;
pub use wedge_damper::{WedgeDamper, slider};

pub(crate) use centre_plate::CentrePlateFile;
pub(crate) use cross_bracing::CrossBracingFile;
pub(crate) use lateral_stop::LateralStopFile;
pub(crate) use shear_pad::ShearPadFile;
pub(crate) use side_bearer::SideBearerFile;
pub(crate) use spring_nest::SpringNestFile;
pub(crate) use track_spring::TrackSpringFile;
pub(crate) use wedge_damper::WedgeDamperFile;

/// Internal state of an element that has one (the friction sliders of wedges, centre plates and
/// side bearers), zero at the static position; the simulation keeps one per element.
pub type Memory = [f64; 4];

use super::body::{Attachment, BodyState, Wrench};
use nalgebra::{Matrix3, Vector3};

/// Any force element.
#[derive(Debug, Clone, PartialEq)]
pub enum Element {
    /// Axle-box rubber shear pad (side frame ↔ wheelset).
    ShearPad(ShearPad),
    /// Two-stage spring nest (bolster ↔ side frame).
    SpringNest(SpringNest),
    /// Wedge friction damper (bolster ↔ side frame).
    WedgeDamper(WedgeDamper),
    /// Centre plate (carbody ↔ bolster).
    CentrePlate(CentrePlate),
    /// Constant-contact side bearer (carbody ↔ bolster).
    SideBearer(SideBearer),
    /// Cross-bracing between the two side frames of a bogie.
    CrossBracing(CrossBracing),
    /// Lateral stop with clearance (bolster gibs ↔ side frame).
    LateralStop(LateralStop),
    /// Lateral and yaw spring to the track (Wickens' restrained wheelset).
    TrackSpring(TrackSpring),
}

impl Element {
    /// Adds this element's forces to the wrenches of the bodies it connects, updating its
    /// internal state (`memory`, used by elements with sliders).
    #[inline]
    pub fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench]) {
        match self {
            Element::ShearPad(e) => e.apply(states, wrenches),
            Element::SpringNest(e) => e.apply(states, wrenches),
            Element::WedgeDamper(e) => e.apply(states, memory, wrenches),
            Element::LateralStop(e) => e.apply(states, wrenches),
            Element::CentrePlate(e) => e.apply(states, memory, wrenches),
            Element::SideBearer(e) => e.apply(states, memory, wrenches),
            Element::CrossBracing(e) => e.apply(states, wrenches),
            // Needs the track frame: applied by the simulation (see `Simulation::step`).
            Element::TrackSpring(_) => {}
        }
    }

    /// Relative displacement across the element from its static loaded position, in the upper
    /// body's axes (lower attachment relative to the upper: `+z` compresses a supporting
    /// element), for the kinds that carry a displacement gauge (assets/docs/physics.md §5).
    pub fn deflection(&self, states: &[BodyState]) -> Option<Vector3<f64>> {
        match self {
            Element::ShearPad(e) => Some(e.relative(states).d),
            _ => {
                let (upper, lower, rest) = self.attachments()?;
                Some(Relative::new(upper, lower, rest, states).d)
            }
        }
    }

    /// The displacement gauges across this element: channel name and axis (0 x, 1 y, 2 z) of
    /// [`Element::deflection`]. Spring nests read vertical and lateral (`nest_<side frame>_z`,
    /// `_y`), shear pads x, y, z (`pad_<side frame>_<wheelset>_x` …), side bearers vertical
    /// (`sidebearer_<bolster>_<l|r>_z`), centre plates vertical (`centreplate_<bolster>_z`).
    /// Vertical readings are positive in compression.
    pub fn gauges(&self, bodies: &[super::body::Body]) -> Vec<(String, usize)> {
        let Some((upper, lower, _)) = self.attachments() else {
            return Vec::new();
        };
        let (u, l) = (&bodies[upper.body].name, &bodies[lower.body].name);
        let side = if lower.local.y > 1e-3 { "l" } else { "r" };
        let stem = match self {
            Element::SpringNest(_) => format!("nest_{l}"),
            Element::ShearPad(_) => format!("pad_{u}_{l}"),
            Element::SideBearer(_) => format!("sidebearer_{l}_{side}"),
            Element::CentrePlate(_) => format!("centreplate_{l}"),
            _ => return Vec::new(),
        };
        self.gauge_axes()
            .iter()
            .map(|&a| (format!("{stem}_{}", ["x", "y", "z"][a]), a))
            .collect()
    }

    /// The axes (0 x, 1 y, 2 z) of the deflection that [`Element::gauges`] records, in its
    /// order; empty for elements without gauges. Allocation-free: the recorder calls it at
    /// every step.
    pub fn gauge_axes(&self) -> &'static [usize] {
        match self {
            Element::SpringNest(_) => &[2, 1],
            Element::ShearPad(_) => &[0, 1, 2],
            Element::SideBearer(_) | Element::CentrePlate(_) => &[2],
            _ => &[],
        }
    }

    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        match self {
            Element::ShearPad(e) => Some((&e.upper, &e.lower, &e.rest)),
            Element::SpringNest(e) => Some((&e.upper, &e.lower, &e.rest)),
            Element::CentrePlate(e) => Some((&e.upper, &e.lower, &e.rest)),
            Element::SideBearer(e) => Some((&e.upper, &e.lower, &e.rest)),
            _ => None,
        }
    }

    /// Kind name as in the vehicle file.
    pub fn kind(&self) -> &'static str {
        match self {
            Element::ShearPad(_) => "shear_pad",
            Element::SpringNest(_) => "spring_nest",
            Element::WedgeDamper(_) => "wedge_damper",
            Element::CentrePlate(_) => "centre_plate",
            Element::SideBearer(_) => "side_bearer",
            Element::CrossBracing(_) => "cross_bracing",
            Element::LateralStop(_) => "lateral_stop",
            Element::TrackSpring(_) => "track_spring",
        }
    }
}

/// Relative motion across a two-point element, in the upper body's axes.
pub(crate) struct Relative {
    /// Upper body axes.
    pub axes: Matrix3<f64>,
    /// Displacement of the lower attachment relative to the upper, upper axes, less the static
    /// offset between the two (zero at the static position).
    pub d: Vector3<f64>,
    /// Velocity of the lower attachment relative to the upper, upper axes.
    pub v: Vector3<f64>,
    /// World positions of the two attachments.
    pub p_upper: Vector3<f64>,
    /// See `p_upper`.
    pub p_lower: Vector3<f64>,
}

impl Relative {
    #[inline]
    pub fn new(
        upper: &Attachment,
        lower: &Attachment,
        rest: &Vector3<f64>,
        states: &[BodyState],
    ) -> Self {
        let (su, sl) = (&states[upper.body], &states[lower.body]);
        let axes = su.matrix();
        let p_upper = su.point(&upper.local);
        let p_lower = sl.point(&lower.local);
        let d = axes.transpose() * (p_lower - p_upper) - rest;
        let v =
            axes.transpose() * (sl.point_velocity(&lower.local) - su.point_velocity(&upper.local));
        Relative {
            axes,
            d,
            v,
            p_upper,
            p_lower,
        }
    }

    /// Applies `f_upper_local` (upper axes) to the upper body at its point and its opposite to
    /// the lower body at its point; the couple of the offset between the points goes to the
    /// upper body (module docs), so the element's moments balance.
    #[inline]
    pub fn apply(
        &self,
        f_upper_local: Vector3<f64>,
        upper: &Attachment,
        lower: &Attachment,
        states: &[BodyState],
        wrenches: &mut [Wrench],
    ) {
        let f = self.axes * f_upper_local;
        wrenches[upper.body].add_at(f, self.p_upper, states[upper.body].position);
        wrenches[upper.body].torque += (self.p_lower - self.p_upper).cross(&f);
        wrenches[lower.body].add_at(-f, self.p_lower, states[lower.body].position);
    }
}
