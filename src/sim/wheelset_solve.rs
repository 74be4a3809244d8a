//! Each wheelset and its two rail masses solved together in one linearly implicit step: the
//! contact's damping at the share θ, and with [`super::Integrator::LinearlyImplicitHertz`] its
//! Hertz spring at the share α and the wheelset's gyroscopic moment at θ (the step's loop is
//! [`super::integrator`]'s).
//!
//! The contact's Hertz spring in the solve (`linearly-implicit-hertz`): explicit, the wheel and
//! its rail mass on the spring between them (about 2 990 rad/s, 476 Hz, `railforce modes`) limit the step to ω·Δt < 2, and
//! the statistics fall off a cliff above 0.6 ms (28–38 % off at 5/7 ms, R 400 m at 100 km/h).
//! Taking `α·Δt²·K` into the solve beside `θ·Δt·D` (`K` the patches' normal stiffness at their
//! load centres, [`crate::contact::patch_stiffness`]) makes a linear spring's step
//! `M·Δv = Δt·F(x) − α·Δt²·K·Δv`: symplectic Euler on `ω̃² = ω²/(1 + α·ω²·Δt²)`, with no
//! numerical damping and a stability limit of ω·Δt < 2/√(1 − 4α). α = 1/12 is Fox and
//! Goodwin's share (Newmark's β = 1/12, γ = ½), whose frequency is right to fourth order (5 %
//! high at ω·Δt = 2, limit 2.45); α = 0.15, the default's, puts it 10 % low at the default step
//! with a wide margin (see [`ALPHA`]); α = ¼ (the average acceleration, unconditionally
//! stable) puts the mode 13 % low at 0.5 ms (tried earlier, without the surface's change
//! below: Q's standard deviation 1.1 % off at 0.5 ms). The share sees the rail masses'
//! motion, and it must see the rail surface's: the irregularity passing under the wheel is the
//! spring's other end, and a share that ignores its change over the step acts on the wheel's
//! following of it as an extra mass `θ·Δt·c_n + α·Δt²·k_n` (25 + 38 kg per wheel at 0.5 ms
//! and α = 0.1, against the wheel's 650; measured with α = 1/12, R 400 m at 100 km/h: Q's
//! standard deviation 0.53 → 0.29 % off at 0.5 ms and 1.07 → 0.62 % at 5/7 ms with the change
//! seen). The change is taken from the last step (one step behind, an estimate).
//!
//! The same integrator takes each wheelset's gyroscopic moment into the solve at θ = ½ (the
//! spin Ω = V/r₀ couples roll and yaw by `I_y·Ω`). Explicit, that coupling lags half a step,
//! a first-order error in the hunting threshold: the restrained wheelset's critical speed
//! (`validate dynamics`, Wickens; closed form 38.33 m/s) was 38.34 / 38.28 / 38.23 / 38.06 /
//! 37.95 / 37.89 m/s at 0.05 (semi-implicit) / 0.125 / 0.25 / 0.5 / 0.625 / 5/7 ms, the Hertz
//! share making no difference at 0.5 ms; with the moment in the solve, 38.34 m/s at 0.5 and
//! 5/7 ms alike (the bisection's resolution is 0.06 m/s).

use nalgebra::{Matrix2, Matrix3, Matrix6, SMatrix, Vector2, Vector6};

/// The rail under one wheel when the track is compliant: lateral and vertical displacement
/// from its place (irregularity excluded), its roll, and their rates, track axes. The lumped
/// rail moves as a whole and does not roll; rails on sleepers give their torsion centre's
/// motion and their roll about it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RailState {
    /// Lateral displacement, m (+ left).
    pub y: f64,
    /// Lateral velocity, m/s.
    pub vy: f64,
    /// Vertical displacement, m (+ up).
    pub z: f64,
    /// Vertical velocity, m/s.
    pub vz: f64,
    /// Roll about the track's x, rad (+ moves the head to the right).
    pub roll: f64,
    /// Roll rate, rad/s.
    pub roll_rate: f64,
}

/// The contact between one wheel and its rail mass, linearised for the linearly implicit step:
/// its damping and stiffness share on the rail's lateral and vertical motion (track axes) and
/// across to the wheelset's, and how the rail surface's own rise under the rolling wheel (the
/// irregularity's rate) pushes both through the contact's normal law.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct RailCoupling {
    /// On the rail's own motion (`Pᵀ·D_k·P`), track axes.
    pub damping: nalgebra::Matrix2<f64>,
    /// How the wheelset's velocity change (world `Δv, Δω`) pushes the rail through this
    /// wheel's damping: rows `y, z` (track) of `D_k` (`Pᵀ·D_k`).
    pub to_rail: nalgebra::SMatrix<f64, 2, 6>,
    /// How the rail's velocity change (track `Δy, Δz`) pushes the wheelset through it
    /// (`D_k·P`, world wrench).
    pub from_rail: nalgebra::SMatrix<f64, 6, 2>,
    /// How a change of the rail surface's rate under the wheel (track `Δẏ, Δż` of the
    /// irregularity) pushes the wheelset through the normal law's share in the step
    /// (`G_k·P`, world wrench per m/s, with `G_k = θ·c_n + α·Δt·k_n` along the normal).
    pub from_surface: nalgebra::SMatrix<f64, 6, 2>,
    /// The same on the rail (`Pᵀ·G_k·P`, track axes), with the opposite sign.
    pub surface_on_rail: nalgebra::Matrix2<f64>,
    /// Where the contact's load centre lies on a rail on sleepers, relative to its torsion
    /// centre (the rail's roll moves the point and the load twists the rail).
    pub lever: crate::track::discrete::Lever,
}

impl RailCoupling {
    /// The coupling of one wheel's damping `d` (track axes, about the wheelset's centre, as
    /// [`crate::contact::patch_damping`] sums it) with its rail, the track's axes `a` (track
    /// to world). The rail's velocity enters the wheel's relative velocity as minus a
    /// wheelset translation along track y and z (`wheels_on_rails`), so
    /// `P = [A·e_y, A·e_z; 0, 0]` maps it to the wheelset's world coordinates.
    pub(super) fn new(d: &nalgebra::Matrix6<f64>, a: &nalgebra::Matrix3<f64>) -> Self {
        let mut c = RailCoupling {
            damping: d.fixed_view::<2, 2>(1, 1).into_owned(),
            ..RailCoupling::default()
        };
        for j in 0..2 {
            let col = d.column(1 + j).into_owned();
            c.from_rail.set_column(j, &to_world(&col, a));
            let row = d.row(1 + j);
            let lin = row.fixed_columns::<3>(0) * a.transpose();
            let ang = row.fixed_columns::<3>(3) * a.transpose();
            c.to_rail.fixed_view_mut::<1, 3>(j, 0).copy_from(&lin);
            c.to_rail.fixed_view_mut::<1, 3>(j, 3).copy_from(&ang);
        }
        c
    }

    /// Sets how the rail surface's rate pushes through the normal law's share: `g` is
    /// `G_k·P` in track axes (`Σ g_p·J_p·[n_y, n_z]` over the patches, `J_p` from
    /// [`crate::contact::patch_normal`]), `a` the track's axes.
    pub(super) fn set_surface(
        &mut self,
        g: &nalgebra::SMatrix<f64, 6, 2>,
        a: &nalgebra::Matrix3<f64>,
    ) {
        for j in 0..2 {
            self.from_surface
                .set_column(j, &to_world(&g.column(j).into_owned(), a));
        }
        self.surface_on_rail = g.fixed_view::<2, 2>(1, 0).into_owned();
    }
}

/// A pair of 3-vectors in axes `a` (a wrench `(F, M)`, or a velocity `(v, ω)`) in world axes.
pub(super) fn to_world(
    w: &nalgebra::Vector6<f64>,
    a: &nalgebra::Matrix3<f64>,
) -> nalgebra::Vector6<f64> {
    let (f, m) = (a * w.fixed_rows::<3>(0), a * w.fixed_rows::<3>(3));
    nalgebra::Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z)
}

/// Share of the contact damping taken at the step's end, on the wheelset and its rails alike
/// (the trapezoidal rule; see the module's comment).
pub(super) const THETA: f64 = 0.5;

/// Share of the contact's Hertz spring taken at the step's end with
/// [`super::Integrator::LinearlyImplicitHertz`]: `α` in `α·Δt²·K` (see the module's comment).
/// The share that puts the wheel–rail mode's frequency right at a step is
/// `(x²/(4·sin²(x/2)) − 1)/x²` at `x = ω·Δt`: 0.104 at 5/7 ms (x = 2.03), 0.113 at the
/// default 5/6 ms (x = 2.37). The limit is x < 2/√(1 − 4α), and the Hertz spring stiffens as
/// N^{1/3} (ω as N^{1/6}), most in flange contact. At 5/6 ms (`bench step`, 60 s): α = 0.1
/// (limit 2.58, passed by a load peak of 1.7 times the static load) burst on R 400 m at
/// 100 km/h (Q's standard deviation 105 % off); α = 0.12 (limit 2.77, a peak of 2.6 times)
/// held it within 0.38 % but burst on R 400 m at 80 km/h (1.35 % off); α = 0.15 (limit 3.16,
/// a peak of 5.6 times) puts the wheel–rail mode 10 % low (about 430 Hz for 476 Hz, far
/// above the recorded band) and every paper34 condition within 1 %. Fox and
/// Goodwin's 1/12 (the frequency right to fourth order, limit 2.45) left four paper34
/// conditions 1.0–1.7 % off in Q's standard deviation already at 5/7 ms.
pub(super) const ALPHA: f64 = 0.15;

/// The Hertz spring's share `α` when the rails are beams on sleepers
/// ([`crate::track::discrete`]). Under a wheel the rail's inertia over a step is its modes'
/// mass alone, about a bay of rail (36 kg; the rest of its step mass is the modes' stiffness
/// taken implicitly), so the wheel–rail mode runs at ω·Δt ≈ 5.7 at 5/6 ms, beyond α = 0.15's
/// limit of 3.16: with it, R 400 m at 60 km/h burst within a second of settling at any step
/// from 0.8 ms, and held at 0.75 ms. α = ¼ is the average acceleration's,
/// stable at any step for a linear spring; it puts that mode (P1, above 1 kHz on such a
/// track) near 360 Hz at the default step, far above the recorded 100 Hz band (an estimate
/// from `ω̃² = ω²/(1 + α·ω²·Δt²)`). A wagon on beams needs a step near 0.1 ms to follow P1.
pub(super) const ALPHA_ON_BEAMS: f64 = 0.25;

/// How the linearly implicit solve takes the contact at step `dt`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Shares {
    /// `θ` of its damping.
    pub theta: f64,
    /// `α·Δt` of its normal stiffness (0: the Hertz spring explicit).
    pub alpha_dt: f64,
}

/// Mass, support stiffness and support damping of a rail mass, lateral and vertical.
fn rail_matrices(sup: &crate::track::RailSupport) -> (Matrix2<f64>, Matrix2<f64>, Matrix2<f64>) {
    (
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.mass, sup.vertical.mass)),
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.stiffness, sup.vertical.stiffness)),
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.damping, sup.vertical.damping)),
    )
}

/// A wheelset's inverse mass: its mass and its inverse inertia tensor in world axes.
pub(super) struct Inverse {
    pub(super) mass: f64,
    pub(super) inertia: Matrix3<f64>,
    /// `θ·Δt·I⁻¹·∂(ω × I·ω)/∂ω`, world axes (zero where the gyroscopic moment stays explicit).
    pub(super) gyroscopic: Matrix3<f64>,
}

impl Inverse {
    /// `M⁻¹` applied to every column of `m`, whose rows are a wrench's (force, moment).
    pub(super) fn apply<const C: usize>(&self, m: &mut SMatrix<f64, 6, C>) {
        for col in 0..C {
            let f = m.fixed_view::<3, 1>(0, col) / self.mass;
            let t = self.inertia * m.fixed_view::<3, 1>(3, col);
            m.fixed_view_mut::<3, 1>(0, col).copy_from(&f);
            m.fixed_view_mut::<3, 1>(3, col).copy_from(&t);
        }
    }
}

/// One linearly implicit step of a wheelset (velocity change `du` explicit, damping `d` in
/// world axes) and its two rail masses solved together; moves the rails and returns the
/// wheelset's velocity change. Wheelset rows: `(I + θΔt·M⁻¹·D)·Δu − θΔt·M⁻¹·Σ D_k·P·Δr_k =
/// Δu_explicit`. Rail rows, implicit in their support and in the damper they share with the
/// wheel (θ on both sides, so the damper's impulses are equal and opposite):
/// `(M_r + Δt·(θ·C_c + C_s) + Δt²·K_s)·Δr_k − θΔt·Pᵀ·D_k·Δu = Δt·(R_k − K_s·(x + Δt·v) − C_s·v)`.
#[allow(clippy::too_many_arguments)]
pub(super) fn with_rails(
    body: &Inverse,
    d: &Matrix6<f64>,
    du: Vector6<f64>,
    dt: f64,
    rails: &mut [RailState],
    coupling: &[RailCoupling],
    rail_force: &[[f64; 2]],
    surface: &[Vector2<f64>; 2],
    sup: &crate::track::RailSupport,
) -> Vector6<f64> {
    let (m, ks, cs) = rail_matrices(sup);
    let blocks = std::array::from_fn(|side| {
        let (rail, c, f) = (&rails[side], &coupling[side], rail_force[side]);
        let (xv, vv) = (Vector2::new(rail.y, rail.z), Vector2::new(rail.vy, rail.vz));
        let l = m + (c.damping * THETA + cs) * dt + ks * (dt * dt);
        let mut r = (Vector2::from(f) - ks * (xv + vv * dt) - cs * vv) * dt;
        if surface[side] != Vector2::zeros() {
            r -= c.surface_on_rail * surface[side];
        }
        (l, r)
    });
    let (du, dv) = with_rail_rows(body, d, du, dt, coupling, blocks);
    for (rail, dv) in rails.iter_mut().zip(dv) {
        rail.vy += dv.x;
        rail.vz += dv.y;
        rail.y += rail.vy * dt;
        rail.z += rail.vz * dt;
    }
    du
}

/// The wheelset's solve with each rail's rows `L_k·Δr_k − θΔt·Pᵀ·D_k·Δu = r_k` (`blocks`:
/// `(L_k, r_k)`, track axes; the rails' velocity change `Δr_k`): the wheelset's velocity
/// change and both rails'.
pub(super) fn with_rail_rows(
    body: &Inverse,
    d: &Matrix6<f64>,
    du: Vector6<f64>,
    dt: f64,
    coupling: &[RailCoupling],
    blocks: [(Matrix2<f64>, Vector2<f64>); 2],
) -> (Vector6<f64>, [Vector2<f64>; 2]) {
    let mut a = d * (THETA * dt);
    body.apply(&mut a);
    let mut g = a.fixed_view_mut::<3, 3>(3, 3);
    g += body.gyroscopic;
    // The rails' rows eliminated (a Schur complement: each rail's block is 2×2), so the
    // solve is the wheelset's 6×6: Δr_k = L_k⁻¹·(r_k − Y_k·Δu),
    // (I + A − Σ X_k·L_k⁻¹·Y_k)·Δu = Δu_explicit − Σ X_k·L_k⁻¹·r_k.
    let mut lhs6 = Matrix6::identity() + a;
    let mut rhs6 = du;
    let mut parts = [(
        Matrix2::zeros(),
        SMatrix::<f64, 2, 6>::zeros(),
        Vector2::zeros(),
    ); 2];
    for (side, (l, r)) in blocks.into_iter().enumerate() {
        let c = &coupling[side];
        let mut x = -c.from_rail * (THETA * dt);
        body.apply(&mut x);
        let y = -c.to_rail * (THETA * dt);
        let l_inv = l.try_inverse().unwrap_or_else(Matrix2::zeros);
        lhs6 -= x * (l_inv * y);
        rhs6 -= x * (l_inv * r);
        parts[side] = (l_inv, y, r);
    }
    let du = lhs6.lu().solve(&rhs6).unwrap_or(rhs6);
    (du, parts.map(|(l_inv, y, r)| l_inv * (r - y * du)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::{RailSupport, Support};
    use nalgebra::Vector3;

    /// [`with_rails`] on rail masses of 250 kg with no support and no surface change.
    fn on_free_rails(
        body: &Inverse,
        d: &Matrix6<f64>,
        du: Vector6<f64>,
        dt: f64,
        rails: &mut [RailState; 2],
        coupling: &[RailCoupling; 2],
        force: &[[f64; 2]; 2],
    ) -> Vector6<f64> {
        let free = Support {
            mass: 250.0,
            stiffness: 0.0,
            damping: 0.0,
        };
        let sup = RailSupport {
            lateral: free,
            vertical: free,
        };
        let surface = [Vector2::zeros(); 2];
        with_rails(body, d, du, dt, rails, coupling, force, &surface, &sup)
    }

    /// A damper at point `p` (wheelset axes = track axes here rotated by `a`), damping `c`
    /// along track x, y, z: `D = [C, −C·[p]×; [p]×·C, −[p]×·C·[p]×]` in track axes.
    fn point_damper(p: Vector3<f64>, c: Vector3<f64>) -> Matrix6<f64> {
        let (c, px) = (Matrix3::from_diagonal(&c), p.cross_matrix());
        let mut d = Matrix6::zeros();
        d.fixed_view_mut::<3, 3>(0, 0).copy_from(&c);
        d.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-c * px));
        d.fixed_view_mut::<3, 3>(3, 0).copy_from(&(px * c));
        d.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-(px * c * px)));
        d
    }

    /// The damper a wheel shares with its rail moves momentum between them and creates none:
    /// with no other force (rails free, no support), a wheelset sliding sideways over its
    /// rails on a canted, turned track gives them exactly the lateral and vertical momentum it
    /// loses at every step, the energy never rises, and it settles near a perfectly
    /// inelastic collision's.
    #[test]
    fn the_shared_damper_conserves_momentum_and_dissipates() {
        let a = (nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 0.3)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), 0.1))
        .into_inner();
        let (mass, dt) = (1200.0, 5e-4);
        let body = Inverse {
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0).map(|x| 1.0 / x)),
            gyroscopic: Matrix3::zeros(),
        };
        let dampers = [
            point_damper(Vector3::new(0.0, 0.75, -0.42), Vector3::new(4e5, 3e5, 2e5)),
            point_damper(Vector3::new(0.0, -0.75, -0.42), Vector3::new(4e5, 5e5, 2e5)),
        ];
        let coupling = dampers.map(|d| RailCoupling::new(&d, &a));
        let mut d = Matrix6::zeros();
        for dk in &dampers {
            let mut w = Matrix6::zeros();
            for (r, c) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
                let blk = dk.fixed_view::<3, 3>(r, c).into_owned();
                w.fixed_view_mut::<3, 3>(r, c)
                    .copy_from(&(a * blk * a.transpose()));
            }
            d += w;
        }
        // The wheelset slides 0.1 m/s sideways (track y) and sinks 0.01 m/s; rails at rest.
        let v0 = a * Vector3::new(0.0, 0.1, -0.01);
        let mut u = Vector6::new(v0.x, v0.y, v0.z, 0.0, 0.0, 0.0);
        let mut rails = [RailState::default(); 2];
        let inertia = Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0));
        let energy = |u: &Vector6<f64>, rails: &[RailState; 2]| {
            let (v, w) = (u.fixed_rows::<3>(0), u.fixed_rows::<3>(3));
            0.5 * mass * v.norm_squared()
                + 0.5 * w.dot(&(inertia * w))
                + rails
                    .iter()
                    .map(|r| 0.5 * 250.0 * (r.vy * r.vy + r.vz * r.vz))
                    .sum::<f64>()
        };
        let e0 = energy(&u, &rails);
        let mut e = e0;
        for _ in 0..20 {
            // The law's forces at the step's start: the same damper, linear.
            let r = |k: usize| Vector2::new(rails[k].vy, rails[k].vz);
            let mut du_exp =
                (-d * u + coupling[0].from_rail * r(0) + coupling[1].from_rail * r(1)) * dt;
            body.apply(&mut du_exp);
            let force = [0, 1].map(|k| {
                let f = coupling[k].to_rail * u - coupling[k].damping * r(k);
                [f.x, f.y]
            });
            let before = rails;
            let du = on_free_rails(&body, &d, du_exp, dt, &mut rails, &coupling, &force);
            // Wheelset's momentum change along track y and z against the rails'.
            let dp = a.transpose() * (du.fixed_rows::<3>(0) * mass);
            let rails_dp: f64 = (0..2).map(|k| (rails[k].vy - before[k].vy) * 250.0).sum();
            let rails_dz: f64 = (0..2).map(|k| (rails[k].vz - before[k].vz) * 250.0).sum();
            assert!(
                (dp.y + rails_dp).abs() < 1e-9 * dp.y.abs().max(1.0),
                "{dp} {rails_dp}"
            );
            assert!(
                (dp.z + rails_dz).abs() < 1e-9 * dp.z.abs().max(1.0),
                "{dp} {rails_dz}"
            );
            u += du;
            // A damper only dissipates.
            let now = energy(&u, &rails);
            assert!(now <= e * (1.0 + 1e-12), "energy rose: {e} → {now}");
            e = now;
        }
        // The rails were dragged along the slide, and the sliding's energy went: within 10 ms
        // close to a perfectly inelastic collision's, never below it (the least energy the
        // conserved momentum allows: m_w/(m_w + 2·m_r) of the start's).
        assert!(rails.iter().all(|r| r.vy > 0.01), "{rails:?}");
        let least = e0 * mass / (mass + 500.0);
        assert!(
            e >= least && e < 1.05 * least,
            "{e0} → {e}, at least {least}"
        );
    }

    /// The contact's Hertz spring in the solve against the closed form (the stiff spring–mass
    /// the default step must carry): a wheelset on two free rail masses (250 kg each) on
    /// vertical springs of 1.5 GN/m at its wheels, their relative mode at ω = 2 880 rad/s, so
    /// ω·Δt = 2.40 at the default 5/6 ms, past the explicit step's limit of 2. With the share α the step is
    /// symplectic Euler on `Ω² = ω²/(1 + α·ω²·Δt²)`: its period is `2π·Δt / (2·asin(Ω·Δt/2))`
    /// (within 0.5 %; measured 4·10⁻⁶ off), its amplitude neither grows nor decays (the largest swing of
    /// the last cycles within 2 % of the first's), the momentum stays; explicit (α = 0) it grows
    /// without bound.
    #[test]
    fn the_hertz_share_keeps_the_stiff_mode_at_its_closed_form() {
        let (mass, k, dt) = (1300.0, 1.5e9, 5e-3 / 6.0);
        let body = Inverse {
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0).map(|x| 1.0 / x)),
            gyroscopic: Matrix3::zeros(),
        };
        let springs = [0.75, -0.75]
            .map(|y| point_damper(Vector3::new(0.0, y, -0.45), Vector3::new(0.0, 0.0, k)));
        let omega = (2.0 * k * (1.0 / mass + 1.0 / 500.0)).sqrt();
        let run = |alpha: f64| {
            let d_eff = springs.map(|s| s * (alpha * dt / THETA));
            let coupling = d_eff.map(|d| RailCoupling::new(&d, &Matrix3::identity()));
            let d: Matrix6<f64> = d_eff.iter().sum();
            let (mut u, mut x) = (Vector6::zeros(), Vector6::zeros());
            // The wheelset 10 µm into its rails, everything at rest.
            x[2] = -1e-5;
            let mut rails = [RailState::default(); 2];
            let mut rel = Vec::new();
            for _ in 0..3000 {
                let r = |k: usize| Vector6::new(0.0, rails[k].y, rails[k].z, 0.0, 0.0, 0.0);
                let f = [0, 1].map(|j| -(springs[j] * (x - r(j))));
                let mut du_exp = (f[0] + f[1]) * dt;
                body.apply(&mut du_exp);
                let force = f.map(|f| [-f[1], -f[2]]);
                let du = on_free_rails(&body, &d, du_exp, dt, &mut rails, &coupling, &force);
                u += du;
                x += u * dt;
                rel.push(x[2] - 0.5 * (rails[0].z + rails[1].z));
                if rel[rel.len() - 1].abs() > 1e-3 {
                    break; // a hundred times the start: diverging
                }
                let momentum = mass * u[2] + 250.0 * (rails[0].vz + rails[1].vz);
                let scale = mass * u[2].abs() + 250.0 * (rails[0].vz.abs() + rails[1].vz.abs());
                assert!(momentum.abs() <= 1e-12 * scale.max(1.0), "{momentum}");
            }
            rel
        };
        let rel = run(ALPHA);
        assert_eq!(rel.len(), 3000);
        let up: Vec<f64> = (1..rel.len())
            .filter(|&i| rel[i - 1] < 0.0 && rel[i] >= 0.0)
            .map(|i| (i as f64 - rel[i] / (rel[i] - rel[i - 1])) * dt)
            .collect();
        let period = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
        let big = omega / (1.0 + ALPHA * (omega * dt).powi(2)).sqrt();
        let closed = std::f64::consts::TAU * dt / (2.0 * (big * dt / 2.0).asin());
        assert!(
            (period / closed - 1.0).abs() < 0.005,
            "period {period:e} s against {closed:e} s (ω·Δt {:.3})",
            omega * dt
        );
        let swing = |r: &[f64]| r.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let (first, last) = (swing(&rel[..300]), swing(&rel[rel.len() - 300..]));
        assert!((last / first - 1.0).abs() < 0.02, "{first:e} → {last:e}");
        let explicit = run(0.0);
        assert!(
            swing(&explicit) > 50.0 * first,
            "the explicit step at ω·Δt {:.2} should not hold",
            omega * dt
        );
    }
}
