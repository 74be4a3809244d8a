//! Rigid contact geometry of a wheelset on a pair of rails.
//!
//! For a lateral shift `y` and yaw `ψ` of the wheelset (track frame: y left, z up), the roll
//! `φ` and height `z` are found such that both wheels just touch their rails (minimum vertical
//! gap zero on each side). Each wheel's surface is a stack of circles, one per profile point;
//! for each circle the point of least gap to the (locally straight, prismatic) rail is found —
//! the lowest point of the circle, moved along the circle by the yaw/rail-slope correction
//! `θ* = s_r·v_y` (first order in ψ). The contact is the least gap over the profile; a second
//! local minimum within [`SECONDARY_GAP`] of it is reported as a second contact (tread and
//! flange).
//!
//! Rails are mounted so that their top is at `z = 0` and their gauge point (14 mm below the
//! top, gauge side) lies at `±gauge/2`.

use super::hertz::HertzShape;
use super::profile::Profile;
use crate::error::{Error, Result};

/// A second local minimum of the gap closer than this (m) to the contact is a second contact.
pub const SECONDARY_GAP: f64 = 1e-3;
/// Depth below the rail top at which the gauge is measured, m.
pub const GAUGE_DEPTH: f64 = 0.014;

/// Left or right, seen in the running direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// Left (+y).
    Left,
    /// Right (−y).
    Right,
}

impl Side {
    /// +1 for left, −1 for right.
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => 1.0,
            Side::Right => -1.0,
        }
    }
}

/// Description of a wheelset and its track for contact geometry.
#[derive(Debug, Clone)]
pub struct WheelsetGeometry {
    wheel: Profile,
    rail: Profile,
    /// Nominal rolling radius at the tape circle, m.
    pub nominal_radius: f64,
    /// Lateral distance from the wheelset centre to each tape circle, m.
    pub tape_circle_half: f64,
    /// Half the track gauge, m.
    pub half_gauge: f64,
    /// Flange back-to-back distance, m.
    pub flange_back: f64,
}

/// Contact between one wheel and its rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelContact {
    /// Lateral position on the wheel profile (from the tape circle, + toward the field side), m.
    pub wheel_y: f64,
    /// Lateral position on the mounted rail profile (from the gauge point, + field side), m.
    pub rail_y: f64,
    /// Contact point in the track frame (x ahead, y left, z up), m.
    pub point: [f64; 3],
    /// Rolling radius, m.
    pub rolling_radius: f64,
    /// Contact angle, rad: positive when the normal force pushes the wheel toward the field side
    /// (flange contact gives large positive angles), measured against the track plane.
    pub angle: f64,
    /// Curvature of the wheel profile across the rolling direction, 1/m (concave negative).
    pub wheel_curvature: f64,
    /// Curvature of the rail profile, 1/m (convex crown positive).
    pub rail_curvature: f64,
    /// Hertz shape from the curvatures.
    pub hertz: HertzShape,
    /// Vertical gap to the rail at this point, m (0 for the main contact).
    pub gap: f64,
}

/// Solution of the geometric contact problem for one wheelset position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactState {
    /// Lateral shift, m.
    pub y: f64,
    /// Yaw, rad.
    pub yaw: f64,
    /// Roll of the wheelset, rad (positive raises the left wheel).
    pub roll: f64,
    /// Height of the wheelset centre above the rail tops, m.
    pub z: f64,
    /// Main contact on each wheel (left, right).
    pub wheels: [WheelContact; 2],
    /// Second contact (e.g. flange beside tread) where a second gap minimum lies within
    /// `SECONDARY_GAP` (1 mm).
    pub secondary: [Option<WheelContact>; 2],
}

/// Axle direction `a`, lowest-point direction `n` and rolling direction `v` of a yawed and
/// rolled wheelset.
#[derive(Debug, Clone, Copy)]
pub(super) struct WheelFrame {
    a: [f64; 3],
    n: [f64; 3],
    v: [f64; 3],
}

impl WheelFrame {
    pub(super) fn new(yaw: f64, roll: f64) -> Self {
        let (sp, cp) = roll.sin_cos();
        let (sy, cy) = yaw.sin_cos();
        let a = [-sy * cp, cy * cp, sp];
        let n = [sp * sy, -sp * cy, cp];
        let v = [
            a[1] * n[2] - a[2] * n[1],
            a[2] * n[0] - a[0] * n[2],
            a[0] * n[1] - a[1] * n[0],
        ];
        WheelFrame { a, n, v }
    }
}

/// Where the load of an elastic contact patch lies across the rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchCentroid {
    /// Lateral position of the load centre in the track frame, m.
    pub y: f64,
    /// The same on the mounted rail profile (from the gauge point, + field side), m.
    pub rail_y: f64,
    /// Load-weighted contact angle, rad.
    pub angle: f64,
    /// Lateral extent of the interpenetration zone, m.
    pub width: f64,
}

/// One scan of a wheel: its least gap and the details of the main and secondary contacts.
struct WheelScan {
    gap: f64,
    main: WheelContact,
    second: Option<WheelContact>,
}

impl WheelsetGeometry {
    /// Builds the geometry. `rail` follows the internal convention (field side +y, depth
    /// down) and is inclined by `inclination` rad toward the track centre before mounting (0 if
    /// the profile is already inclined). `flange_back` is the back-to-back distance, and the
    /// tape circle lies `tape_offset` outside each flange back (70 mm for S1002).
    pub fn new(
        wheel: Profile,
        rail: Profile,
        inclination: f64,
        gauge: f64,
        flange_back: f64,
        tape_offset: f64,
        nominal_radius: f64,
    ) -> Result<Self> {
        let rail = if inclination != 0.0 {
            rail.rotated(inclination)?
        } else {
            rail
        };
        let (y_top, z_top) = rail.lowest_z();
        let rail = rail.shifted(0.0, z_top);
        let gp = rail.crossing_below(y_top, GAUGE_DEPTH).ok_or_else(|| {
            Error::Domain(format!(
                "rail profile '{}' does not reach {} mm below its top on the gauge side",
                rail.name,
                GAUGE_DEPTH * 1e3
            ))
        })?;
        let rail = rail.shifted(gp, 0.0);
        let half_gauge = 0.5 * gauge;
        let tape_circle_half = 0.5 * flange_back + tape_offset;
        if !(tape_circle_half > 0.0 && half_gauge > 0.0 && nominal_radius > 0.0) {
            return Err(Error::Domain(
                "gauge, flange back and wheel radius must be positive".into(),
            ));
        }
        Ok(WheelsetGeometry {
            wheel,
            rail,
            nominal_radius,
            tape_circle_half,
            half_gauge,
            flange_back,
        })
    }

    /// The mounted rail profile (top at 0, gauge point at 0, field side +y).
    pub fn rail(&self) -> &Profile {
        &self.rail
    }

    /// The wheel profile.
    pub fn wheel(&self) -> &Profile {
        &self.wheel
    }

    /// Rail surface height (z up) and slope dz/dy in the track frame at lateral position `yt`.
    #[inline]
    pub(super) fn rail_surface(&self, side: Side, yt: f64) -> (f64, f64, f64) {
        let s = side.sign();
        let ym = s * yt - self.half_gauge;
        let (d, d1, _) = self.rail.eval(ym);
        (-d, -d1 * s, ym)
    }

    /// Gap, contact point and radius of the wheel circle at profile position `eta`, with the
    /// wheelset centre at height 0.
    #[inline]
    pub(super) fn circle_gap(
        &self,
        side: Side,
        y: f64,
        frame: &WheelFrame,
        eta: f64,
    ) -> (f64, [f64; 3], f64) {
        let s = side.sign();
        let WheelFrame { a, n, v } = *frame;
        let (zw, _, _) = self.wheel.eval(eta);
        let r = self.nominal_radius + zw;
        let c = s * (self.tape_circle_half + eta);
        let p0 = [
            c * a[0] - r * n[0],
            y + c * a[1] - r * n[1],
            c * a[2] - r * n[2],
        ];
        let (_, slope, _) = self.rail_surface(side, p0[1]);
        let th = slope * v[1] / n[2];
        let (st, ct) = th.sin_cos();
        let p = [
            c * a[0] - r * ct * n[0] + r * st * v[0],
            y + c * a[1] - r * ct * n[1] + r * st * v[1],
            c * a[2] - r * ct * n[2] + r * st * v[2],
        ];
        let (zr, _, _) = self.rail_surface(side, p[1]);
        (p[2] - zr, p, r)
    }

    /// Scans one wheel for the least vertical gap with the wheelset centre at height 0.
    fn scan(&self, side: Side, y: f64, yaw: f64, roll: f64) -> WheelScan {
        let s = side.sign();
        let frame = WheelFrame::new(yaw, roll);
        let gap_at = |eta: f64| self.circle_gap(side, y, &frame, eta);
        // Coarse scan every 0.25 mm, then golden-section refinement of each local minimum.
        let (lo, hi) = self.wheel.range();
        let step = 2.5e-4;
        let m = ((hi - lo) / step) as usize;
        let g: Vec<f64> = (0..=m).map(|i| gap_at(lo + i as f64 * step).0).collect();
        let mut minima: Vec<(f64, f64)> = Vec::new();
        for i in 0..=m {
            let left = if i > 0 { g[i - 1] } else { f64::INFINITY };
            let right = if i < m { g[i + 1] } else { f64::INFINITY };
            if g[i] <= left && g[i] < right {
                let (mut x0, mut x1) = (
                    (lo + (i as f64 - 1.0) * step).max(lo),
                    (lo + (i as f64 + 1.0) * step).min(hi),
                );
                let gr = 0.618_033_988_749_894_9;
                for _ in 0..40 {
                    let xa = x1 - gr * (x1 - x0);
                    let xb = x0 + gr * (x1 - x0);
                    if gap_at(xa).0 < gap_at(xb).0 {
                        x1 = xb;
                    } else {
                        x0 = xa;
                    }
                }
                let eta = 0.5 * (x0 + x1);
                minima.push((gap_at(eta).0, eta));
            }
        }
        minima.sort_by(|p, q| p.0.total_cmp(&q.0));
        let make = |eta: f64, gap0: f64| -> WheelContact {
            let (gap, p, r) = gap_at(eta);
            let (_, slope, ym) = self.rail_surface(side, p[1]);
            let angle = (s * slope).atan();
            let (_, w1, w2) = self.wheel.eval(eta);
            let wheel_curvature = -w2 / (1.0 + w1 * w1).powf(1.5);
            let rail_curvature = self.rail.curvature(ym);
            WheelContact {
                wheel_y: eta,
                rail_y: ym,
                point: p,
                rolling_radius: r,
                angle,
                wheel_curvature,
                rail_curvature,
                hertz: HertzShape::new(
                    0.5 * angle.cos() / r,
                    0.5 * (wheel_curvature + rail_curvature),
                ),
                gap: gap - gap0,
            }
        };
        let (gap0, eta0) = minima[0];
        let main = make(eta0, gap0);
        // A second contact: another minimum at least 3 mm away on the wheel, close in gap.
        let second = minima
            .iter()
            .skip(1)
            .find(|(gp, e)| (e - eta0).abs() > 3e-3 && gp - gap0 < SECONDARY_GAP)
            .map(|&(_, e)| make(e, gap0));
        WheelScan {
            gap: gap0,
            main,
            second,
        }
    }

    /// Load centre of the elastic contact patch of one wheel of a solved state, by the virtual
    /// penetration idea of Kik and Piotrowski (1996): the bodies interpenetrate by
    /// `ε·δ` (δ the Hertz approach of the main contact under `load`, ε = 0.55), and across the
    /// rail the load per unit width grows as the local interpenetration to the power 3/2. Where
    /// the gap is flat or has two near-equal minima (tread and flange root, or two tread
    /// zones), this places the load where an elastic solution puts it, not at one rigid point.
    pub fn patch_centroid(
        &self,
        state: &ContactState,
        side: Side,
        load: f64,
        material: &super::hertz::Material,
    ) -> PatchCentroid {
        let k = match side {
            Side::Left => 0,
            Side::Right => 1,
        };
        let main = state.wheels[k];
        let pen = 0.55 * main.hertz.ellipse(load, material).approach;
        let frame = WheelFrame::new(state.yaw, state.roll);
        let s = side.sign();
        let (lo, hi) = self.wheel.range();
        let step = 2e-5;
        let m = ((hi - lo) / step) as usize;
        // Gaps relative to the main contact (the centre height does not change differences).
        let g0 = self.circle_gap(side, state.y, &frame, main.wheel_y).0;
        let (mut w_sum, mut y_sum, mut a_sum) = (0.0, 0.0, 0.0);
        let (mut y_min, mut y_max) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=m {
            let eta = lo + i as f64 * step;
            let (g, p, _) = self.circle_gap(side, state.y, &frame, eta);
            let d = pen - (g - g0);
            if d > 0.0 {
                let w = d.powf(1.5);
                let (_, slope, _) = self.rail_surface(side, p[1]);
                w_sum += w;
                y_sum += w * p[1];
                a_sum += w * (s * slope).atan();
                y_min = y_min.min(p[1]);
                y_max = y_max.max(p[1]);
            }
        }
        if w_sum <= 0.0 {
            return PatchCentroid {
                y: main.point[1],
                rail_y: main.rail_y,
                angle: main.angle,
                width: 0.0,
            };
        }
        let y = y_sum / w_sum;
        PatchCentroid {
            y,
            rail_y: s * y - self.half_gauge,
            angle: a_sum / w_sum,
            width: y_max - y_min,
        }
    }

    /// Solves the rigid contact problem for lateral shift `y` (m) and yaw `yaw` (rad).
    pub fn solve(&self, y: f64, yaw: f64) -> ContactState {
        // D(φ) = gap_L − gap_R grows with φ (the left wheel rises): find its root.
        let d = |roll: f64| {
            self.scan(Side::Left, y, yaw, roll).gap - self.scan(Side::Right, y, yaw, roll).gap
        };
        let (mut lo, mut hi) = (-0.05, 0.05);
        let (mut dlo, mut dhi) = (d(lo), d(hi));
        // Illinois (regula falsi) with bisection safeguard.
        let mut roll = 0.0;
        for _ in 0..60 {
            roll = if dhi != dlo {
                (lo - dlo * (hi - lo) / (dhi - dlo)).clamp(lo, hi)
            } else {
                0.5 * (lo + hi)
            };
            let dm = d(roll);
            if dm.abs() < 1e-10 || (hi - lo) < 1e-10 {
                break;
            }
            if (dm < 0.0) == (dlo < 0.0) {
                lo = roll;
                dlo = dm;
                dhi *= 0.5;
            } else {
                hi = roll;
                dhi = dm;
                dlo *= 0.5;
            }
        }
        let l = self.scan(Side::Left, y, yaw, roll);
        let r = self.scan(Side::Right, y, yaw, roll);
        let z = -0.5 * (l.gap + r.gap);
        let lift = |mut w: WheelContact| {
            w.point[2] += z;
            w
        };
        ContactState {
            y,
            yaw,
            roll,
            z,
            wheels: [lift(l.main), lift(r.main)],
            secondary: [l.second.map(lift), r.second.map(lift)],
        }
    }
}
