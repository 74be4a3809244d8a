//! A patch's force linearised in the wheelset's velocity: the damping the creep forces and the
//! normal damping put on the wheelset, for the simulator's linearly implicit step.
//!
//! The creepages are the contact point's velocity over the running speed, so creep acts as a
//! damper of `c ≈ f/V` on the wheelset's motion (Kalker's coefficients `f = G·a·b·c_ij`): at
//! 40–60 km/h its time constant on the wheelset's lateral and yaw motion is about 1 ms, the
//! stiffest term an explicit step has to follow. Kalker's linear theory scaled by the
//! saturation the law reached (the secant `|F| / |F_linear|`) gives the damping here; the
//! step uses it only to take the velocity change implicitly, the forces themselves stay the
//! law's. The law's own slope (forward differences of Polach in the three creepages and the
//! normal load, five law calls per patch) gave the same statistics within 0.03 % of Y/Q at
//! 0.2–0.4 ms (`bench step`, R 400 m at 40 and 60 km/h) and made the step about 8 µs dearer;
//! so the secant.

use super::wheel_rail::{ContactModel, PatchForce};
use nalgebra::{Matrix3, Matrix6, Vector3};

/// `D` with `d[F; M] ≈ −D·d[v; ω]`: how the force of the rail on the wheel (track axes) and
/// its moment about the wheelset centre change with the wheelset centre's velocity `v` and
/// angular velocity `ω` (track axes), at running speed `speed` (m/s).
///
/// The contact point moves at `v_c = v + ω × p`: `dξx = t_x·dv_c/V`, `dξy = t_y·dv_c/V`,
/// `dφ = n·dω/V`. Creep along the rolling and lateral directions (`c_x = r·G·a·b·c11/V`,
/// `c_y = r·G·a·b·c22/V`), spin on the lateral force (`s = r·G·(ab)^{3/2}·c23/V`), with `r` the
/// law's saturation (1 unsaturated), and the normal damping `c_n` along the normal.
pub fn patch_damping(p: &PatchForce, model: &ContactModel, speed: f64) -> Matrix6<f64> {
    patch_damping_with_spring(p, model, speed, 0.0)
}

/// [`patch_damping`] with `spring` seconds of the patch's normal stiffness added along its
/// normal (`D + spring·K`, [`patch_stiffness`]): the linearly implicit step's `θ·Δt·D +
/// α·Δt²·K` over `θ·Δt` in one matrix. With `spring` 0 it is `patch_damping` to the bit.
pub fn patch_damping_with_spring(
    p: &PatchForce,
    model: &ContactModel,
    speed: f64,
    spring: f64,
) -> Matrix6<f64> {
    let (a, b) = (p.ellipse.a, p.ellipse.b);
    let v = speed.abs().max(super::CREEP_SPEED_FLOOR);
    let (tx, ty, n) = (
        Vector3::from(p.frame.tx),
        Vector3::from(p.frame.ty),
        Vector3::from(p.frame.n),
    );
    let mut c = n * n.transpose() * (p.damping + spring * p.stiffness);
    let mut spin = Matrix3::zeros();
    if a > 0.0 && b > 0.0 && p.normal > 0.0 {
        let k = p.kalker;
        let gab = model.material.shear_modulus() * a * b;
        let s = p.creepage;
        let linear =
            (gab * k.c11 * s.x).hypot(gab * (k.c22 * s.y + (a * b).sqrt() * k.c23 * s.spin));
        let actual = p.creep.x.hypot(p.creep.y);
        let r = if linear > 1e-9 * gab {
            (actual / linear).clamp(0.0, 1.0)
        } else {
            1.0
        };
        c += tx * tx.transpose() * (r * gab * k.c11 / v)
            + ty * ty.transpose() * (r * gab * k.c22 / v);
        spin = ty * n.transpose() * (r * gab * (a * b).sqrt() * k.c23 / v);
    }
    at_point(c, spin, p.point)
}

/// `K` with `d[F; M] ≈ −K·d[x; θ]`: how the force of the rail on the wheel and its moment
/// about the wheelset centre change with a small displacement `x` and rotation `θ` of the
/// wheelset (track axes): the patch's normal stiffness `k_n` (the strips' `dN/dδ` over the
/// contact angle's cosine) along its normal, at its load centre. The contact's Hertz spring,
/// for the linearly implicit step's stiffness share; the change of the contact angle and of the
/// creep forces with the displacement (gravitational stiffness, hundreds of times softer) is
/// left out. Rank one: `k_n·J·Jᵀ` with `J` from [`patch_normal`].
pub fn patch_stiffness(p: &PatchForce) -> Matrix6<f64> {
    let j = patch_normal(p);
    j * j.transpose() * p.stiffness
}

/// `J = [n; p × n]`, track axes: the patch's normal approach rate is `Jᵀ·[v; ω]` for the
/// wheelset centre's velocity and angular velocity, and a normal load `N` acts on the wheelset as
/// the wrench `N·J` (force and moment about its centre).
pub fn patch_normal(p: &PatchForce) -> nalgebra::Vector6<f64> {
    let n = Vector3::from(p.frame.n);
    let m = Vector3::from(p.point).cross(&n);
    nalgebra::Vector6::new(n.x, n.y, n.z, m.x, m.y, m.z)
}

/// A point's 3×3 law (`dF = −C·dv_c − S·dω`) moved to the wheelset centre, with `v_c = v + ω × p`.
fn at_point(c: Matrix3<f64>, spin: Matrix3<f64>, point: [f64; 3]) -> Matrix6<f64> {
    let px = Vector3::from(point).cross_matrix();
    // dv_c = dv − [p]×·dω, so dF = −C·dv + (C·[p]× − S)·dω and dM = [p]×·dF.
    let dw = c * px - spin;
    let mut d = Matrix6::zeros();
    d.fixed_view_mut::<3, 3>(0, 0).copy_from(&c);
    d.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-dw));
    d.fixed_view_mut::<3, 3>(3, 0).copy_from(&(px * c));
    d.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-(px * dw)));
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Side, WheelOnRail, evaluate};

    /// The linearisation is the evaluation's own slope under Kalker's linear law: a small
    /// change of each component of the wheelset's velocity and angular velocity (a wheel 2 mm
    /// off centre, yawed 1 mrad) changes the evaluated force and moment by −D·δ, within 1 % of
    /// the largest term (a vertical velocity: the normal force).
    #[test]
    fn damping_matches_the_evaluated_force_change() {
        let v = crate::vehicle::Vehicle::load("vehicles/c80.toml".as_ref()).unwrap();
        let table = v.contact.table();
        // Kalker's linear law, where the secant is exact: the test checks the kinematics
        // (points, frames, signs, the moment arms).
        let model = crate::contact::ContactModel {
            law: crate::contact::CreepLaw::Linear,
            ..v.contact.model()
        };
        let speed = 60.0 / 3.6;
        let r0 = v.contact.geometry.nominal_radius;
        let h = table.lookup(0.0).z - 1e-4;
        let mut w = WheelOnRail::rolling(Side::Left, speed, r0, h, 600.0);
        w.y = 2e-3;
        w.yaw = 1e-3;
        let base = evaluate(table, &model, &w);
        let d: Matrix6<f64> = base
            .patches
            .iter()
            .flatten()
            .map(|p| patch_damping(p, &model, speed))
            .sum();
        for (axis, delta) in [
            (0, 1e-5),
            (1, 1e-5),
            (2, 1e-5),
            (3, 2e-6),
            (4, 1e-5),
            (5, 2e-6),
        ] {
            let mut x = w;
            let mut dv = nalgebra::Vector6::zeros();
            dv[axis] = delta;
            if axis < 3 {
                x.velocity[axis] += delta;
            } else {
                x.angular_velocity[axis - 3] += delta;
            }
            let out = evaluate(table, &model, &x);
            let got: Vec<f64> = (0..3)
                .map(|j| out.force[j] - base.force[j])
                .chain((0..3).map(|j| out.moment[j] - base.moment[j]))
                .collect();
            let want = -(d * dv);
            let scale = want.amax().max(1e-9);
            // A vertical velocity moves the normal load, and the creep forces with it (the
            // ellipse grows as N^(1/3)): that coupling is left out, only Fz is compared.
            let checked: &[usize] = if axis == 2 { &[2] } else { &[0, 1, 2, 3, 4, 5] };
            for &j in checked {
                assert!(
                    (got[j] - want[j]).abs() < 0.01 * scale,
                    "axis {axis}, component {j}: evaluated {} vs linearised {}",
                    got[j],
                    want[j]
                );
            }
        }
    }

    /// The Hertz spring the linearly implicit step takes is the evaluation's own slope: a small
    /// displacement of the wheelset down into the rail changes the evaluated force along the
    /// patch's normal by `−K·δ` within 3 %, across the rail or rolled within 30 % (a tread
    /// contact and one at 0.32 rad; nothing moves, so no damping).
    #[test]
    fn stiffness_matches_the_evaluated_force_change() {
        let v = crate::vehicle::Vehicle::load("vehicles/c80.toml".as_ref()).unwrap();
        let table = v.contact.table();
        let model = v.contact.model();
        let r0 = v.contact.geometry.nominal_radius;
        for (y, approach) in [(2e-3, 1e-4), (9e-3, 1.5e-4)] {
            let state = table.lookup(y);
            let mut w = WheelOnRail::rolling(Side::Left, 0.0, r0, state.z - approach, 600.0);
            (w.y, w.roll) = (y, state.roll);
            let base = evaluate(table, &model, &w);
            let k: Matrix6<f64> = base.patches.iter().flatten().map(patch_stiffness).sum();
            let main = base.main().expect("in contact");
            let n = Vector3::from(main.frame.n);
            for (axis, delta) in [(1, 1e-6), (2, -1e-6), (3, 1e-6)] {
                let mut x = w;
                let mut dx = nalgebra::Vector6::zeros();
                dx[axis] = delta;
                match axis {
                    1 => x.y += delta,
                    2 => x.height += delta,
                    _ => x.roll += delta,
                }
                let out = evaluate(table, &model, &x);
                let got = n.dot(&(Vector3::from(out.force) - Vector3::from(base.force)));
                let want = n.dot(&(-(k * dx)).fixed_rows::<3>(0));
                // Measured: vertical within 2 %; across the rail and rolled 15–25 % off where
                // the contact angle is 0.32 rad, and 13 N in 33 N on the tread (the load centre
                // moves over the curved profiles as the wheel shifts, which the point's normal
                // leaves out): within 30 % of itself or 3 % of the vertical response.
                let tol = if axis == 2 {
                    0.03 * want.abs()
                } else {
                    (0.3 * want.abs()).max(0.03 * k[(2, 2)] * delta.abs())
                };
                assert!(
                    (got - want).abs() < tol,
                    "y {y}, axis {axis}: evaluated {got} N vs linearised {want} N"
                );
            }
        }
    }
}
