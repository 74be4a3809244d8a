//! The stiff force elements' damping in the linearly implicit Hertz step: each body that hangs
//! on such elements (the side frames on their pads) solved in their damping at θ = ½, the
//! bodies below held, which take the reaction in the same step (the step's loop is
//! [`super::integrator`]'s; why: its module comment).
//!
//! An element's damping, read in its upper body's axes, is constant but for the relative
//! rotations and deflections across it (milliradians and millimetres): it is built once from
//! the static state ([`crate::vehicle::elements::ElementDamping`], the element's own slope) and
//! the upper body's solve `(I + θΔt·M⁻¹·D)⁻¹` inverted once. A step then costs two rotations
//! and a 6×6 product per body, and one per element for the reaction (the step only needs an
//! estimate of the slope; the forces stay the elements' own). Built each step in world axes
//! instead, the eight pads and four 6×6 solves took the C80's integration from 2.1 to 4.8 µs a
//! step (`bench simulate`'s profile).

use super::wheelset_solve::{THETA, to_world};
use crate::vehicle::elements::{Element, ElementDamping};
use crate::vehicle::{Body, BodyState};
use nalgebra::{Matrix3, Matrix6, Vector6};

/// A body solved in the damping of the stiff elements it hangs on, in its own axes.
#[derive(Debug, Clone)]
pub(super) struct DampedBody {
    /// The body.
    pub body: usize,
    /// `(I + θΔt·M⁻¹·D)⁻¹`, body axes: its velocity change from the explicit one.
    solve: Matrix6<f64>,
    /// Per element below it: the body beneath and the impulse it takes per velocity change of
    /// this body, both in this body's axes (`−θΔt·on_lower`).
    reactions: Vec<(usize, Matrix6<f64>)>,
}

/// A 6×6 map between pairs of 3-vectors (velocity and angular velocity, force and moment),
/// world axes, read in body axes `R`: `Bᵀ·M·B` with `B = [R, 0; 0, R]`.
fn to_body(r: &Matrix3<f64>, m: &Matrix6<f64>) -> Matrix6<f64> {
    let mut b = Matrix6::zeros();
    b.fixed_view_mut::<3, 3>(0, 0).copy_from(r);
    b.fixed_view_mut::<3, 3>(3, 3).copy_from(r);
    b.transpose() * m * b
}

/// The bodies the step solves in their elements' damping, from the static state `states` at
/// step `dt` (none when no element gives its damping to the step).
pub(super) fn damped_bodies(
    bodies: &[Body],
    elements: &[Element],
    states: &[BodyState],
    dt: f64,
) -> Vec<DampedBody> {
    let damping: Vec<ElementDamping> = elements
        .iter()
        .filter_map(|e| e.implicit_damping(states))
        .collect();
    let mut out: Vec<DampedBody> = Vec::new();
    for d in &damping {
        if out.iter().any(|b| b.body == d.upper) {
            continue;
        }
        let (b, r) = (&bodies[d.upper], states[d.upper].matrix());
        let mine = damping.iter().filter(|e| e.upper == d.upper);
        let on_body: Matrix6<f64> = mine.clone().map(|e| to_body(&r, &e.on_upper)).sum();
        // M⁻¹ in body axes (principal): the mass, then the principal moments of inertia.
        let inverse_mass = Vector6::new(
            1.0 / b.mass,
            1.0 / b.mass,
            1.0 / b.mass,
            1.0 / b.inertia.x,
            1.0 / b.inertia.y,
            1.0 / b.inertia.z,
        );
        let a = Matrix6::from_diagonal(&inverse_mass) * on_body * (THETA * dt);
        let solve = (Matrix6::identity() + a)
            .try_inverse()
            .unwrap_or_else(Matrix6::identity);
        out.push(DampedBody {
            body: d.upper,
            solve,
            reactions: mine
                .map(|e| (e.lower, to_body(&r, &e.on_lower) * (-THETA * dt)))
                .collect(),
        });
    }
    out
}

impl DampedBody {
    /// The body's velocity change (world) from the explicit one `du` (body axes `r`); adds
    /// each body beneath its reaction impulse (world) in `kicks`.
    pub(super) fn change(
        &self,
        r: &Matrix3<f64>,
        du: &Vector6<f64>,
        kicks: &mut [Vector6<f64>],
    ) -> Vector6<f64> {
        let solved = self.solve * du;
        for (lower, m) in &self.reactions {
            kicks[*lower] += to_world(&(m * solved), r);
        }
        to_world(&solved, r)
    }
}
