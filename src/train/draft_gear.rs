//! Couplers and draft gears: the force between two neighbouring vehicles.
//!
//! A coupling is two coupler heads with their free slack (a dead zone of the coupled pair's
//! total slack) and two friction draft gears in series, one per car end. Each gear is
//! compressed in buff and in draft (the yoke turns draft into compression), so its force law
//! is one curve of its deflection `x ∈ [0, travel]` with two branches:
//!
//! - loading (the gear closing): `F_L(x) = F₀ + (F_max − F₀)·(x/travel)^p`, from the preload
//!   `F₀` to the impedance `F_max` at full travel;
//! - unloading (the gear opening): `F_U(x) = r·F_L(x)`; a full cycle absorbs `1 − r` of the
//!   energy taken in;
//! - below the preload, both branches follow the structure's stiffness `k` (the gear does not
//!   move until the force passes `F₀`): `min(k·x, …)`, so the force starts from zero;
//! - beyond full travel the gear is solid: the branch's value at full travel plus `k·(x − travel)`.
//!
//! The branch is chosen smoothly by the gear's deflection rate `u`:
//! `F = F_U + w(u)·(F_L − F_U)`, `w = ½(1 + u/√(u² + u_b²))`, so at rest the gear sits halfway
//! between its branches and the step sees a steep but finite friction damping. The MT-2's
//! public figures are its travel, impedance, capacity and absorbed share; the curve's shape
//! (`F₀`, `p`, `r`, `k`, `u_b`) is an estimate: no public loading–unloading curve was found.
//!
//! The two gears of a coupling are identical and carry the same force, so each deflects by
//! half the coupling's deflection beyond the slack.

/// One friction draft gear's force law (the consist file's `[draft_gear]` table).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DraftGear {
    /// Travel to solid, m.
    pub travel: f64,
    /// Force at full travel on the loading branch (impedance), N.
    pub impedance: f64,
    /// Preload: the force at which the gear starts to close, N.
    pub preload: f64,
    /// Exponent `p` of the loading curve's rise from preload to impedance.
    pub exponent: f64,
    /// Unloading branch over loading branch, `r` (the share of a cycle's energy returned).
    pub unloading_ratio: f64,
    /// Stiffness below the preload and beyond full travel (coupler, yoke, centre sill), N/m.
    pub solid_stiffness: f64,
    /// Deflection rate scale of the branch switch `u_b`, m/s: at `u = ±u_b` the force is 85 %
    /// of the way to the branch (`w = ½(1 ± 1/√2)`).
    pub switch_speed: f64,
}

/// Force of a gear (or coupling) and its derivatives in deflection and deflection rate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GearForce {
    /// Force, N.
    pub force: f64,
    /// ∂force/∂deflection, N/m.
    pub stiffness: f64,
    /// ∂force/∂(deflection rate), N·s/m.
    pub damping: f64,
}

impl DraftGear {
    /// The loading curve without the ramp and the solid, `F₀ + (F_max − F₀)·(x/travel)^p`,
    /// and its slope, at `0 ≤ x < travel`.
    #[inline]
    fn curve(&self, x: f64) -> (f64, f64) {
        let t = self.travel;
        let rise = self.impedance - self.preload;
        if x > 0.0 {
            let xi = x / t;
            // a whole or half exponent (the shipped 2.5) by products and one square root:
            // `powf` alone would cost as much as the rest of the coupling
            let twice = 2.0 * self.exponent;
            let n = twice as i32; // (a cast: `round` would be a library call)
            let pw = if n as f64 == twice && n <= 40 {
                let mut p = 1.0;
                for _ in 0..n / 2 {
                    p *= xi; // (`powi` is a library call)
                }
                if n % 2 == 1 { p * xi.sqrt() } else { p }
            } else {
                xi.powf(self.exponent)
            };
            (self.preload + rise * pw, rise * self.exponent * pw / x)
        } else {
            (self.preload, 0.0)
        }
    }

    /// A branch (the curve scaled by `scale`: 1 loading, `r` unloading) at `x` from the
    /// curve's value and slope there: the preload ramp below, the solid beyond travel.
    #[inline]
    fn branch_of(&self, x: f64, (c, dc): (f64, f64), scale: f64) -> (f64, f64) {
        let k = self.solid_stiffness;
        if x >= self.travel {
            return (scale * self.impedance + k * (x - self.travel), k);
        }
        let ramp = k * x;
        if ramp < scale * c {
            (ramp, k)
        } else {
            (scale * c, scale * dc)
        }
    }

    #[inline]
    fn branch(&self, x: f64, scale: f64) -> (f64, f64) {
        let c = if x >= self.travel {
            (self.impedance, 0.0)
        } else {
            self.curve(x)
        };
        self.branch_of(x, c, scale)
    }

    /// The loading branch at deflection `x`, N (for plots and checks).
    pub fn loading(&self, x: f64) -> f64 {
        self.branch(x.max(0.0), 1.0).0
    }

    /// The unloading branch at deflection `x`, N.
    pub fn unloading(&self, x: f64) -> f64 {
        self.branch(x.max(0.0), self.unloading_ratio).0
    }

    /// The gear's force at deflection `x` (m, ≥ 0) and deflection rate `u` (m/s, > 0 closing).
    #[inline]
    pub fn force(&self, x: f64, u: f64) -> GearForce {
        let x = x.max(0.0);
        let c = if x >= self.travel {
            (self.impedance, 0.0)
        } else {
            self.curve(x)
        };
        let (fl, kl) = self.branch_of(x, c, 1.0);
        let (fu, ku) = self.branch_of(x, c, self.unloading_ratio);
        let ub = self.switch_speed;
        let inv = 1.0 / (u * u + ub * ub).sqrt();
        let w = 0.5 * (1.0 + u * inv);
        let dw = 0.5 * ub * ub * inv * inv * inv;
        GearForce {
            force: fu + w * (fl - fu),
            stiffness: ku + w * (kl - ku),
            damping: (fl - fu) * dw,
        }
    }

    /// The force at rest (halfway between the branches) at deflection `x`.
    pub fn force_at_rest(&self, x: f64) -> f64 {
        self.force(x, 0.0).force
    }

    /// The deflection at rest that carries `f` N (≥ 0): the inverse of [`Self::force_at_rest`]
    /// (bisection; the curve rises monotonically).
    pub fn deflection_at_rest(&self, f: f64) -> f64 {
        if f <= 0.0 {
            return 0.0;
        }
        let mut lo = 0.0;
        let mut hi = self.travel;
        while self.force_at_rest(hi) < f {
            hi = self.travel + 2.0 * (hi - self.travel).max(1e-3);
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.force_at_rest(mid) < f {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo < 1e-13 {
                break;
            }
        }
        0.5 * (lo + hi)
    }

    /// The energy the loading branch takes in from zero to full travel, J (the gear's
    /// capacity).
    pub fn capacity(&self) -> f64 {
        let n = 20_000;
        let h = self.travel / n as f64;
        (0..n).map(|i| self.loading((i as f64 + 0.5) * h) * h).sum()
    }
}

/// A coupling between two neighbouring vehicles: the coupler pair's free slack and two
/// draft gears in series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coupling {
    /// Free slack of the coupled pair of heads, total, m (a dead zone of ± half of it about
    /// the centred position).
    pub slack: f64,
    /// Each car end's draft gear.
    pub gear: DraftGear,
}

impl Coupling {
    /// The coupling's force (tension positive) at extension `e` (m: the change of the distance
    /// between the two vehicles' centres from its value with both heads centred in their slack
    /// and both gears free; positive apart) and extension rate `de` (m/s), with its derivatives
    /// in `e` and `de`.
    #[inline]
    pub fn force(&self, e: f64, de: f64) -> GearForce {
        let half = 0.5 * self.slack;
        let a = e.abs();
        if a <= half {
            return GearForce::default();
        }
        let sg = e.signum();
        let x = 0.5 * (a - half);
        let u = 0.5 * sg * de;
        let g = self.gear.force(x, u);
        GearForce {
            force: sg * g.force,
            stiffness: 0.5 * g.stiffness,
            damping: 0.5 * g.damping,
        }
    }

    /// The extension at rest that carries `f` N (either sign): slack taken up, then both gears
    /// deflected to their rest curve.
    pub fn extension_at_rest(&self, f: f64) -> f64 {
        if f == 0.0 {
            return 0.0;
        }
        f.signum() * (0.5 * self.slack + 2.0 * self.gear.deflection_at_rest(f.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped MT-2 estimate (vehicles/*.consist.toml, `[draft_gear]`).
    const MT2: DraftGear = DraftGear {
        travel: 0.083,
        impedance: 2.27e6,
        preload: 80e3,
        exponent: 2.5,
        unloading_ratio: 0.18,
        solid_stiffness: 2.0e8,
        switch_speed: 0.01,
    };

    #[test]
    fn loading_branch_runs_from_the_preload_to_the_impedance() {
        assert_eq!(MT2.loading(0.0), 0.0);
        // the preload ramp: k·x until it meets the curve
        let x0 = MT2.preload / MT2.solid_stiffness;
        assert!((MT2.loading(0.5 * x0) - 0.5 * MT2.preload).abs() < 1.0);
        assert!((MT2.loading(MT2.travel) - MT2.impedance).abs() < 1e-6);
        let mid = MT2.loading(0.5 * MT2.travel);
        let want = MT2.preload + (MT2.impedance - MT2.preload) * 0.5f64.powf(2.5);
        assert!((mid - want).abs() < 1e-6);
        // rises monotonically
        let mut last = -1.0;
        for i in 0..=1000 {
            let f = MT2.loading(i as f64 * 1e-4);
            assert!(f >= last);
            last = f;
        }
    }

    #[test]
    fn any_exponent_gives_the_same_curve() {
        for p in [1.0, 2.0, 2.5, 3.0, 2.7] {
            let g = DraftGear { exponent: p, ..MT2 };
            for x in [0.005, 0.03, 0.07] {
                let want = g.preload + (g.impedance - g.preload) * (x / g.travel).powf(p);
                assert!((g.loading(x) - want).abs() < 1e-6 * want, "{p} {x}");
            }
        }
    }

    #[test]
    fn unloading_branch_is_the_ratio_of_loading() {
        for x in [0.01, 0.04, 0.08] {
            assert!((MT2.unloading(x) - 0.18 * MT2.loading(x)).abs() < 1e-6);
        }
    }

    #[test]
    fn solid_beyond_travel() {
        let f = MT2.loading(MT2.travel + 0.001);
        assert!((f - (MT2.impedance + MT2.solid_stiffness * 0.001)).abs() < 1e-6);
        let f = MT2.unloading(MT2.travel + 0.001);
        assert!((f - (0.18 * MT2.impedance + MT2.solid_stiffness * 0.001)).abs() < 1e-6);
    }

    #[test]
    fn branch_switch_by_deflection_rate() {
        let x = 0.05;
        let closing = MT2.force(x, 0.1).force;
        let opening = MT2.force(x, -0.1).force;
        let rest = MT2.force(x, 0.0).force;
        assert!((closing - MT2.loading(x)).abs() < 3e-3 * MT2.loading(x));
        assert!((opening - MT2.unloading(x)).abs() < 3e-3 * MT2.loading(x));
        assert!((rest - 0.5 * (MT2.loading(x) + MT2.unloading(x))).abs() < 1e-6);
        // derivatives against finite differences
        for (x, u) in [(0.03, 0.001), (0.06, -0.0005), (0.085, 0.0)] {
            let g = MT2.force(x, u);
            let h = 1e-8;
            let kx = (MT2.force(x + h, u).force - MT2.force(x - h, u).force) / (2.0 * h);
            let cu = (MT2.force(x, u + h).force - MT2.force(x, u - h).force) / (2.0 * h);
            assert!((kx - g.stiffness).abs() < 1e-4 * g.stiffness.abs().max(1.0));
            assert!((cu - g.damping).abs() < 1e-4 * g.damping.abs().max(1.0));
        }
    }

    #[test]
    fn slack_is_a_dead_zone_of_the_pair() {
        let c = Coupling {
            slack: 0.0095,
            gear: MT2,
        };
        for e in [-0.00474, 0.0, 0.003, 0.00474] {
            let g = c.force(e, 0.2);
            assert_eq!(g.force, 0.0, "{e}");
            assert_eq!(g.stiffness, 0.0);
        }
        // beyond the slack each gear takes half the deflection
        let e = 0.00475 + 0.02;
        let g = c.force(e, 0.0);
        assert!((g.force - MT2.force_at_rest(0.01)).abs() < 1e-6);
        let g = c.force(-e, 0.0);
        assert!((g.force + MT2.force_at_rest(0.01)).abs() < 1e-6);
        // tension opening gives the unloading branch; compression opening too
        let t_open = c.force(e, -0.2).force;
        let c_open = c.force(-e, 0.2).force;
        assert!((t_open - MT2.unloading(0.01)).abs() < 3e-3 * MT2.loading(0.01));
        assert!((c_open + MT2.unloading(0.01)).abs() < 3e-3 * MT2.loading(0.01));
        // extension at rest inverts the force
        for f in [-1.5e6, -2e4, 3e5, 2.5e6] {
            let e = c.extension_at_rest(f);
            assert!((c.force(e, 0.0).force - f).abs() < 1e-3 * f.abs(), "{f}");
        }
    }

    #[test]
    fn one_cycle_absorbs_its_share_and_the_capacity_is_met() {
        // MT-2: capacity ≥ 50 kJ, ≥ 80 % absorbed (product sheets, TB/T 2915).
        let cap = MT2.capacity();
        assert!(cap >= 50e3, "capacity {cap} J");
        // a quasi-static cycle driven at 0.1 m/s, ten times the switch speed
        let n = 20_000;
        let h = MT2.travel / n as f64;
        let (mut into, mut back) = (0.0, 0.0);
        for i in 0..n {
            let x = (i as f64 + 0.5) * h;
            into += MT2.force(x, 0.1).force * h;
            back += MT2.force(x, -0.1).force * h;
        }
        let absorbed = (into - back) / into;
        assert!(absorbed >= 0.80, "absorbed {absorbed}");
        assert!((into - cap).abs() < 0.01 * cap);
    }
}
