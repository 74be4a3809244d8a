//! The contact table: the rigid contact states of a wheelset tabulated over its lateral
//! shift, with the strips of both wheels at every state (elastic contact), for fast lookup
//! during a run. Built from the geometry (`geometry`) and the strips (`elastic`).

use super::elastic::StripTable;
use super::geometry::{ContactState, WheelContact, WheelsetGeometry};
use super::hertz::HertzShape;

impl WheelsetGeometry {
    /// Precomputes contact states over `y ∈ [−y_max, y_max]` every `dy` at zero yaw, on all
    /// cores (each shift is solved on its own, so the result does not depend on the threads).
    pub fn table(&self, y_max: f64, dy: f64) -> ContactTable {
        let n = crate::bounds::to_count((y_max / dy).round());
        let ys: Vec<f64> = (0..=2 * n).map(|i| (i as f64 - n as f64) * dy).collect();
        let threads = std::thread::available_parallelism()
            .map(|p| p.get())
            .unwrap_or(1)
            .min(ys.len());
        let chunk = ys.len().div_ceil(threads.max(1));
        let states: Vec<ContactState> = std::thread::scope(|scope| {
            let handles: Vec<_> = ys
                .chunks(chunk)
                .map(|part| {
                    scope
                        .spawn(move || part.iter().map(|&y| self.solve(y, 0.0)).collect::<Vec<_>>())
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().expect("contact solve thread"))
                .collect()
        });
        ContactTable {
            y_min: -(n as f64) * dy,
            dy,
            strips: StripTable::build(self, &states),
            states,
        }
    }
}

/// Contact states tabulated over the lateral shift, for fast lookup during simulation.
#[derive(Debug, Clone)]
pub struct ContactTable {
    pub(super) y_min: f64,
    pub(super) dy: f64,
    pub(super) states: Vec<ContactState>,
    pub(super) strips: StripTable,
}

impl ContactTable {
    /// The tabulated states.
    pub fn states(&self) -> &[ContactState] {
        &self.states
    }

    /// Lateral range of the table, m.
    pub fn range(&self) -> (f64, f64) {
        (
            self.y_min,
            self.y_min + (self.states.len() - 1) as f64 * self.dy,
        )
    }

    /// The strips of both wheels at every tabulated state (elastic contact).
    pub fn strips(&self) -> &StripTable {
        &self.strips
    }

    /// Height and roll of the rigid solution at grid interval `i`, fraction `t`, and the
    /// nearer grid point's contact angle and rolling radius of wheel `k` (a cheap part of
    /// [`ContactTable::lookup`]).
    #[inline]
    pub fn rigid(&self, i: usize, t: f64, k: usize) -> (f64, f64, f64, f64) {
        let (s0, s1) = (&self.states[i], &self.states[i + 1]);
        let w = if t < 0.5 {
            &s0.wheels[k]
        } else {
            &s1.wheels[k]
        };
        (
            s0.z + t * (s1.z - s0.z),
            s0.roll + t * (s1.roll - s0.roll),
            w.angle,
            w.rolling_radius,
        )
    }

    /// Grid interval `i` and fraction `t ∈ [0, 1]` of `y` (clamped to the table).
    pub fn locate(&self, y: f64) -> (usize, f64) {
        let (lo, hi) = self.range();
        let u = ((y.clamp(lo, hi) - self.y_min) / self.dy).min((self.states.len() - 1) as f64);
        let i = (u as usize).min(self.states.len() - 2);
        (i, u - i as f64)
    }

    /// Contact state at `y` by linear interpolation between grid points; where a wheel's contact
    /// point jumps (more than 1 mm on the wheel between neighbours), the nearer grid point is
    /// taken for that wheel instead, so a jump to the flange is never smeared.
    pub fn lookup(&self, y: f64) -> ContactState {
        let (i, t) = self.locate(y);
        let (s0, s1) = (&self.states[i], &self.states[i + 1]);
        let lerp = |a: f64, b: f64| a + t * (b - a);
        let wheel = |k: usize| {
            let (w0, w1) = (s0.wheels[k], s1.wheels[k]);
            if (w0.wheel_y - w1.wheel_y).abs() > 1e-3 {
                return if t < 0.5 { w0 } else { w1 };
            }
            let hertz = HertzShape {
                curvature_sum: lerp(w0.hertz.curvature_sum, w1.hertz.curvature_sum),
                ma: lerp(w0.hertz.ma, w1.hertz.ma),
                mb: lerp(w0.hertz.mb, w1.hertz.mb),
                k_over_e: lerp(w0.hertz.k_over_e, w1.hertz.k_over_e),
            };
            WheelContact {
                wheel_y: lerp(w0.wheel_y, w1.wheel_y),
                rail_y: lerp(w0.rail_y, w1.rail_y),
                point: std::array::from_fn(|j| lerp(w0.point[j], w1.point[j])),
                rolling_radius: lerp(w0.rolling_radius, w1.rolling_radius),
                angle: lerp(w0.angle, w1.angle),
                wheel_curvature: lerp(w0.wheel_curvature, w1.wheel_curvature),
                rail_curvature: lerp(w0.rail_curvature, w1.rail_curvature),
                hertz,
                gap: 0.0,
            }
        };
        ContactState {
            y,
            yaw: 0.0,
            roll: lerp(s0.roll, s1.roll),
            z: lerp(s0.z, s1.z),
            wheels: [wheel(0), wheel(1)],
            secondary: if t < 0.5 { s0.secondary } else { s1.secondary },
        }
    }

    /// Rolling-radius difference `r_L − r_R` at `y`, m.
    pub fn delta_r(&self, y: f64) -> f64 {
        let s = self.lookup(y);
        s.wheels[0].rolling_radius - s.wheels[1].rolling_radius
    }

    /// Equivalent conicity for the amplitude `amplitude` (m), by the EN 15302 integral method:
    /// the wavelength `L` of the wheelset's nonlinear kinematic oscillation
    /// `y'' = −Δr(y)/(2·b0·r0)` started at `y = amplitude`, and `λe = b0·r0·(2π/L)²`, with `b0`
    /// half the distance between the contact points and `r0` the rolling radius of the centred
    /// wheelset.
    pub fn equivalent_conicity(&self, amplitude: f64) -> Option<f64> {
        let c = self.lookup(0.0);
        let b0 = 0.5 * (c.wheels[0].point[1] - c.wheels[1].point[1]);
        let r0 = 0.5 * (c.wheels[0].rolling_radius + c.wheels[1].rolling_radius);
        let acc = |y: f64| -self.delta_r(y) / (2.0 * b0 * r0);
        // RK4 in distance; count two sign changes of y' (down then up again).
        let h = 0.01;
        let (mut x, mut y, mut v) = (0.0, amplitude, 0.0);
        let mut crossings = 0;
        let mut prev_v = 0.0;
        while x < 2000.0 {
            let k1 = (v, acc(y));
            let k2 = (v + 0.5 * h * k1.1, acc(y + 0.5 * h * k1.0));
            let k3 = (v + 0.5 * h * k2.1, acc(y + 0.5 * h * k2.0));
            let k4 = (v + h * k3.1, acc(y + h * k3.0));
            let ny = y + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            let nv = v + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            if x > 0.0 && prev_v < 0.0 && nv >= 0.0 {
                crossings += 1;
            }
            if crossings == 1 && prev_v > 0.0 && nv <= 0.0 {
                // Back at the start: interpolate the zero of v.
                let frac = prev_v / (prev_v - nv);
                let period = x + frac * h;
                return Some(b0 * r0 * (2.0 * std::f64::consts::PI / period).powi(2));
            }
            prev_v = nv;
            y = ny;
            v = nv;
            x += h;
        }
        None
    }
}
