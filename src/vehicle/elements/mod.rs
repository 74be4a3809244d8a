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
pub mod rubber;
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
pub use spring_nest::{NestLaw, NestStaging, SpringNest};
pub use track_spring::TrackSpring;
pub use wedge_damper::{WedgeDamper, WedgeStatics, slider};

/// Internal state of an element that has one (the friction sliders of wedges, centre plates and
/// side bearers, the shear pads' rubber branches, the nests' seated inner coils), zero at the
/// static position; the simulation keeps one per element.
pub type Memory = [f64; MEMORY];

/// Length of an element's [`Memory`]: the shear pad's rubber holds three Maxwell branches on
/// each of its three axes and its rocking.
pub const MEMORY: usize = 12;

use super::binder::Binder;
use super::body::{Attachment, BodyState, Wrench};
use crate::error::Result;
use nalgebra::{Matrix3, Matrix6, Vector3};

/// The registration of every force element kind, in the order a vehicle file's tables are
/// bound (and the simulation adds their forces): variant, table name in the vehicle file, and
/// what it is. **A new kind is its file (the element, its table, its `impl ForceElement`) plus
/// one line here** (and its `mod` and `pub use` above). The enum [`Element`], its dispatch and
/// the vehicle file's element tables are all made from this list.
macro_rules! for_each_element {
    ($then:ident) => {
        $then! {
            ShearPad shear_pad "Axle-box rubber shear pad (side frame ↔ wheelset).",
            SpringNest spring_nest "Two-stage spring nest (bolster ↔ side frame).",
            WedgeDamper wedge_damper "Wedge friction damper (bolster ↔ side frame).",
            CentrePlate centre_plate "Centre plate (carbody ↔ bolster).",
            SideBearer side_bearer "Constant-contact side bearer (carbody ↔ bolster).",
            LateralStop lateral_stop "Lateral stop with clearance (bolster gibs ↔ side frame).",
            CrossBracing cross_bracing "Cross-bracing between the two side frames of a bogie.",
            TrackSpring track_spring "Lateral and yaw spring to the track (Wickens' restrained wheelset).",
        }
    };
}
pub(crate) use for_each_element;

/// How an element carries its upper body's weight in the static load path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Support {
    /// Carries a share of the load, equal among the body's supports, set by the load path.
    Shared {
        /// Where it meets the upper body.
        upper: Attachment,
        /// The body below.
        lower: usize,
    },
    /// Carries its own given preload (a side bearer's).
    Preloaded {
        /// The body above.
        upper: usize,
        /// The body below.
        lower: usize,
        /// Its preload, N.
        preload: f64,
    },
}

/// What every force element kind provides: its vehicle-file table, how a row of it is bound
/// (checked, named by file and field), its force law, and its part in the gauges and the
/// static load path. Implemented in each element's own file.
pub(crate) trait ForceElement: Sized {
    /// The element's table in the vehicle file (`[[shear_pad]]`).
    const TABLE: &'static str;
    /// One row of that table as the file writes it.
    type File: serde::de::DeserializeOwned;
    /// Binds row `file` (field path `field`, e.g. `shear_pad[3]`); `bound` holds the elements
    /// bound before it (a wedge finds the nest that presses it).
    fn bind(field: &str, file: &Self::File, b: &Binder, bound: &[Element]) -> Result<Self>;
    /// Adds the element's forces to the wrenches of its bodies; `dt` is the step over which a
    /// slider's memory advances (its damper's rate, [`wedge_damper::slider`]).
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64);
    /// Where it meets its two bodies and their static offset (kinds with gauges or supports).
    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        None
    }
    /// Relative displacement across it from the static loaded position (upper body's axes).
    fn deflection(&self, states: &[BodyState]) -> Option<Vector3<f64>> {
        let (upper, lower, rest) = self.attachments()?;
        Some(Relative::new(upper, lower, rest, states).d)
    }
    /// Its compression in the static loaded position, from its unloaded (free) state (upper
    /// body's axes, `+z` compressing): what its gauge reads at rest, a gauge zeroed on the free
    /// element. Zero for elements that carry no static load.
    fn static_deflection(&self) -> Vector3<f64> {
        Vector3::zeros()
    }
    /// Stem of its gauge channels from its bodies' names and its side (`l`/`r`).
    fn gauge_stem(&self, _upper: &str, _lower: &str, _side: &str) -> Option<String> {
        None
    }
    /// The deflection axes its gauges record (0 x, 1 y, 2 z), in order.
    fn gauge_axes(&self) -> &'static [usize] {
        &[]
    }
    /// Its part in the static load path.
    fn support(&self) -> Option<Support> {
        None
    }
    /// Takes its share of the static load, N (for [`Support::Shared`]).
    fn take_share(&mut self, _share: f64) {}
    /// Once every static load is set: reads what other elements settled to (a wedge, its
    /// nest's static compression).
    fn settle(&mut self, _elements: &[Element]) {}
    /// Sets its friction to zero (the sliding limit of a linear analysis).
    fn frictionless(&mut self) {}
    /// Its damping as a linearly implicit step takes it ([`ElementDamping`]); none for the
    /// kinds whose damping stays explicit (every kind but the stiffest).
    fn implicit_damping(&self, _states: &[BodyState]) -> Option<ElementDamping> {
        None
    }
}

macro_rules! define_element {
    ($($variant:ident $table:ident $doc:literal,)*) => {
        /// Any force element.
        #[derive(Debug, Clone, PartialEq)]
        pub enum Element {
            $(#[doc = $doc] $variant($variant),)*
        }

        impl Element {
            /// Adds this element's forces to the wrenches of the bodies it connects, updating its
            /// internal state (`memory`, used by elements with sliders).
            #[inline]
            pub fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
                match self {
                    $(Element::$variant(e) => e.apply(states, memory, wrenches, dt),)*
                }
            }

            /// Relative displacement across the element from its unloaded (free) state, in the
            /// upper body's axes (lower attachment relative to the upper: `+z` compresses a
            /// supporting element), for the kinds that carry a displacement gauge
            /// (assets/docs/physics.md §5): the motion from the static loaded position plus
            /// the static compression the element's load puts in it. A gauge zeroed on the
            /// free element reads it, so a heavier wagon reads more (one zeroed on the loaded
            /// wagon could not see its load).
            pub fn deflection(&self, states: &[BodyState]) -> Option<Vector3<f64>> {
                match self {
                    $(Element::$variant(e) => e.deflection(states).map(|d| d + e.static_deflection()),)*
                }
            }

            /// Its compression in the static loaded position from its unloaded state, m (upper
            /// body's axes): what [`Element::deflection`] reads at rest.
            pub fn static_deflection(&self) -> Vector3<f64> {
                match self {
                    $(Element::$variant(e) => e.static_deflection(),)*
                }
            }

            /// The axes (0 x, 1 y, 2 z) of the deflection that [`Element::gauges`] records, in
            /// its order; empty for elements without gauges. Allocation-free: the recorder calls
            /// it at every step.
            pub fn gauge_axes(&self) -> &'static [usize] {
                match self {
                    $(Element::$variant(e) => e.gauge_axes(),)*
                }
            }

            fn gauge_stem(&self, upper: &str, lower: &str, side: &str) -> Option<String> {
                match self {
                    $(Element::$variant(e) => e.gauge_stem(upper, lower, side),)*
                }
            }

            fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
                match self {
                    $(Element::$variant(e) => e.attachments(),)*
                }
            }

            /// Its part in the static load path.
            pub(crate) fn support(&self) -> Option<Support> {
                match self {
                    $(Element::$variant(e) => e.support(),)*
                }
            }

            /// Takes its share of the static load, N.
            pub(crate) fn take_share(&mut self, share: f64) {
                match self {
                    $(Element::$variant(e) => e.take_share(share),)*
                }
            }

            /// Reads what the other elements settled to, once every static load is set.
            pub(crate) fn settle(&mut self, elements: &[Element]) {
                match self {
                    $(Element::$variant(e) => e.settle(elements),)*
                }
            }

            /// Sets its friction to zero (the sliding limit of a linear analysis).
            pub(crate) fn frictionless(&mut self) {
                match self {
                    $(Element::$variant(e) => e.frictionless(),)*
                }
            }

            /// Its damping as a linearly implicit step takes it (none where it stays explicit).
            #[inline]
            pub(crate) fn implicit_damping(&self, states: &[BodyState]) -> Option<ElementDamping> {
                match self {
                    $(Element::$variant(e) => e.implicit_damping(states),)*
                }
            }

            /// Kind name as in the vehicle file.
            pub fn kind(&self) -> &'static str {
                match self {
                    $(Element::$variant(_) => <$variant as ForceElement>::TABLE,)*
                }
            }
        }
    };
}
for_each_element!(define_element);

impl Element {
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
        let Some(stem) = self.gauge_stem(u, l, side) else {
            return Vec::new();
        };
        self.gauge_axes()
            .iter()
            .map(|&a| (format!("{stem}_{}", ["x", "y", "z"][a]), a))
            .collect()
    }
}

/// Static compression `load / k` along z of a linear supporting element, m; none when it has
/// no stiffness to compress (a rigid or absent spring reads nothing).
fn static_compression(load: f64, k: f64) -> Vector3<f64> {
    Vector3::new(0.0, 0.0, if k > 0.0 { load / k } else { 0.0 })
}

/// A stiff element's damping, linearised for a linearly implicit step: how its two bodies'
/// wrenches (world axes, about each body's centre) change with a velocity change
/// `Δu = (Δv, Δω)` (world) of the upper body, the lower body held: `ΔW_upper = −on_upper·Δu`,
/// `ΔW_lower = −on_lower·Δu`. The step solves the upper body in it and hands the lower body
/// the reaction, so the pair's momentum balances (`sim::integrator`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ElementDamping {
    /// The upper body.
    pub upper: usize,
    /// The lower body.
    pub lower: usize,
    /// On the upper body's wrench.
    pub on_upper: Matrix6<f64>,
    /// On the lower body's wrench.
    pub on_lower: Matrix6<f64>,
}

impl ElementDamping {
    /// The damping `c` (upper axes `a`, diagonal) of a two-point element between `p_upper` and
    /// `p_lower` (world) that [`Relative::apply`] applies: the force
    /// `F = a·diag(c)·aᵀ·(Δv_lower − Δv_upper)` with `Δv_upper = Δv − [p_upper − x_upper]×·Δω`
    /// the upper point's velocity change and `Δv_lower = turn·Δω` the lower point's (zero
    /// unless the lower point turns with the upper body), on the upper body with the couple
    /// of the points' offset (so about its centre `(p_lower − x_upper) × F`), its opposite on
    /// the lower body at `p_lower`.
    pub(crate) fn two_point(
        (upper, lower): (usize, usize),
        states: &[BodyState],
        a: &Matrix3<f64>,
        c: &Vector3<f64>,
        (p_upper, p_lower): (Vector3<f64>, Vector3<f64>),
        turn: &Matrix3<f64>,
    ) -> Self {
        let (xu, xl) = (states[upper].position, states[lower].position);
        let ac = a * Matrix3::from_diagonal(c) * a.transpose();
        let mut g = nalgebra::SMatrix::<f64, 3, 6>::zeros();
        g.fixed_view_mut::<3, 3>(0, 0).copy_from(&ac);
        g.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-ac * ((p_upper - xu).cross_matrix() + turn)));
        let arm = |r: Vector3<f64>| {
            let mut m = Matrix6::zeros();
            m.fixed_view_mut::<3, 6>(0, 0).copy_from(&g);
            m.fixed_view_mut::<3, 6>(3, 0)
                .copy_from(&(r.cross_matrix() * g));
            m
        };
        ElementDamping {
            upper,
            lower,
            on_upper: arm(p_lower - xu),
            on_lower: -arm(p_lower - xl),
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
