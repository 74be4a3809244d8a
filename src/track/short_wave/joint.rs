//! Dipped rail joints: both rail ends dip towards the joint, and the running surface turns
//! through the total dip angle 2α at the joint itself, the excitation of Jenkins et al.'s P1
//! and P2 forces (Railway Engineering Journal 3(1), 1974; assets/docs/physics.md §3.4).
//!
//! Each end dips along a parabola over half the joint's length L, tangent to the rail where
//! it starts and at a slope of α where it meets the other: `z(u) = −d·(1 − 2|u|/L)²` for
//! `|u| ≤ L/2`, with `d = 2α·L/8`. The only kink is the joint's; the ramps bend the wheel's
//! path by a constant curvature `2α/L` (a radius of 100 m for 20 mrad over 2 m).

/// Dipped joints along the track, on both rails.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joints {
    /// Distance between joints, m (a rail's length).
    pub spacing: f64,
    /// Position of the first joint, m.
    pub first: f64,
    /// Total dip angle 2α, rad: the change of the running surface's slope at the joint.
    pub angle: f64,
    /// Length of the dipped zone, both rail ends together, m (shorter than the spacing).
    pub length: f64,
}

/// What a kink counts as for the step, m (a choice): it holds every wavelength, and the wheel's
/// contact patch (12–15 mm long) filters the shorter ones. Below 144 km/h the short waves' cap
/// of 62.5 µs governs (20 steps a period up to 800 Hz, P1 on the lumped track near 470 Hz);
/// above it, 50 mm keeps 20 steps a period of its passing.
const KINK_WAVELENGTH: f64 = 0.05;

impl Joints {
    /// The depth of each dip at its joint, m: `2α·L/8`.
    pub fn depth(&self) -> f64 {
        self.angle * self.length / 8.0
    }

    /// The dip's height (≤ 0) and its gradient at `s`. At the joint itself the gradient is the
    /// approaching end's, −α.
    pub fn at(&self, s: f64) -> (f64, f64) {
        let k = ((s - self.first) / self.spacing).round();
        if k < 0.0 {
            return (0.0, 0.0);
        }
        let u = s - (self.first + k * self.spacing);
        let half = 0.5 * self.length;
        if u.abs() > half {
            return (0.0, 0.0);
        }
        let r = 1.0 - u.abs() / half;
        let d = self.depth();
        // dz/du = 2d·r/half · sign(u); at u = 0 from below: −2d/half = −α.
        let slope = 2.0 * d * r / half;
        (-d * r * r, if u > 0.0 { slope } else { -slope })
    }

    /// The shortest wavelength the step must follow for them, m.
    pub fn shortest_wavelength(&self) -> f64 {
        KINK_WAVELENGTH
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_turns_the_rail_through_its_angle_and_nowhere_else() {
        let j = Joints {
            spacing: 25.0,
            first: 112.5,
            angle: 20e-3,
            length: 2.0,
        };
        assert!((j.depth() - 5e-3).abs() < 1e-15);
        assert!((j.at(112.5).0 + 5e-3).abs() < 1e-15);
        assert_eq!(j.at(137.5), j.at(112.5));
        assert_eq!(j.at(50.0), (0.0, 0.0), "no joint before the first");
        assert_eq!(j.at(111.4), (0.0, 0.0));
        // The slope jumps by 2α at the joint and is continuous at the ramps' ends.
        let (h, e) = (1e-9, 112.5);
        let jump = j.at(e + h).1 - j.at(e - h).1;
        assert!((jump - 20e-3).abs() < 1e-7, "{jump}");
        assert!(j.at(111.5 + 1e-9).1.abs() < 1e-7 && j.at(113.5 - 1e-9).1.abs() < 1e-7);
        // The gradient is the height's derivative away from the kink.
        for x in [111.7, 112.2, 112.9, 113.4] {
            let fd = (j.at(x + 1e-6).0 - j.at(x - 1e-6).0) / 2e-6;
            assert!((fd - j.at(x).1).abs() < 1e-9, "at {x}");
        }
    }
}
