//! One wheel on its rail: creepages from the wheelset's motion, Hertz ellipse, creep forces,
//! and the resulting force of the rail on the wheel in the track frame.

use super::creep::{CreepContact, CreepForce, CreepLaw, Creepage};
use super::geometry::{Side, WheelContact};
use super::hertz::{HertzEllipse, Material};

/// Motion of a wheelset relative to the track (tangent track frame: x ahead, y left, z up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelsetMotion {
    /// Forward speed, m/s.
    pub speed: f64,
    /// Lateral velocity, m/s.
    pub lateral_velocity: f64,
    /// Vertical velocity, m/s.
    pub vertical_velocity: f64,
    /// Roll rate, rad/s.
    pub roll_rate: f64,
    /// Spin (rotation about the axle, positive when rolling forward), rad/s.
    pub spin: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
    /// Yaw angle, rad.
    pub yaw: f64,
}

impl WheelsetMotion {
    /// Pure rolling at `speed` on wheels of radius `r0`, no other motion.
    pub fn rolling(speed: f64, r0: f64) -> Self {
        WheelsetMotion {
            speed,
            lateral_velocity: 0.0,
            vertical_velocity: 0.0,
            roll_rate: 0.0,
            spin: speed / r0,
            yaw_rate: 0.0,
            yaw: 0.0,
        }
    }
}

/// Contact frame of a wheel: rolling direction `t_x`, lateral in the contact plane `t_y`, and
/// the normal `n` along which the rail pushes the wheel, all in the track frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactFrame {
    /// Rolling direction.
    pub tx: [f64; 3],
    /// Lateral direction in the contact plane.
    pub ty: [f64; 3],
    /// Normal, pointing into the wheel.
    pub n: [f64; 3],
}

impl ContactFrame {
    /// Frame of a contact with angle `angle` on `side` (positive angles tilt the normal toward
    /// the track centre… of the wheel: the flange is pushed toward the field side).
    pub fn new(side: Side, angle: f64, yaw: f64) -> Self {
        let s = side.sign();
        let (sd, cd) = angle.sin_cos();
        let (sy, cy) = yaw.sin_cos();
        ContactFrame {
            tx: [cy, sy, 0.0],
            ty: [-sy * cd, cy * cd, s * sd],
            n: [sy * s * sd, -cy * s * sd, cd],
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Creepages at a contact: the velocity of the wheel's material at the contact point relative
/// to the (fixed) rail, divided by the speed, in the contact frame; spin is the wheel's angular
/// velocity about the contact normal over the speed (1/m).
///
/// `rel` is the contact point relative to the wheelset centre (track frame), `roll` the
/// wheelset roll.
pub fn creepages(m: &WheelsetMotion, frame: &ContactFrame, rel: [f64; 3], roll: f64) -> Creepage {
    // Angular velocity: yaw rate about z, roll rate about x, spin about the (rolled, yawed)
    // axle.
    let (sp, cp) = roll.sin_cos();
    let (sy, cy) = m.yaw.sin_cos();
    let axle = [-sy * cp, cy * cp, sp];
    let omega = [
        m.roll_rate * cy + m.spin * axle[0],
        m.roll_rate * sy + m.spin * axle[1],
        m.yaw_rate + m.spin * axle[2],
    ];
    let w = cross(omega, rel);
    let v = [
        m.speed + w[0],
        m.lateral_velocity + w[1],
        m.vertical_velocity + w[2],
    ];
    let speed = m.speed.abs().max(1e-3);
    Creepage {
        x: dot(v, frame.tx) / speed,
        y: dot(v, frame.ty) / speed,
        spin: dot(omega, frame.n) / speed,
    }
}

/// Everything computed at one wheel's contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelForce {
    /// Normal load, N.
    pub normal: f64,
    /// Hertz ellipse.
    pub ellipse: HertzEllipse,
    /// Creepages.
    pub creepage: Creepage,
    /// Creep forces in the contact plane, N.
    pub creep: CreepForce,
    /// Force of the rail on the wheel in the track frame `[x, Y, Q]`, N.
    pub force: [f64; 3],
    /// Contact frame.
    pub frame: ContactFrame,
}

/// Evaluates one wheel's contact for a given normal load: Hertz ellipse, creepages, creep law,
/// and the total force of the rail on the wheel in the track frame.
#[allow(clippy::too_many_arguments)]
pub fn wheel_force(
    side: Side,
    contact: &WheelContact,
    centre: [f64; 3],
    roll: f64,
    motion: &WheelsetMotion,
    normal: f64,
    mu: f64,
    material: &Material,
    law: CreepLaw,
) -> WheelForce {
    let frame = ContactFrame::new(side, contact.angle, motion.yaw);
    let ellipse = contact.hertz.ellipse(normal, material);
    let rel = [
        contact.point[0] - centre[0],
        contact.point[1] - centre[1],
        contact.point[2] - centre[2],
    ];
    let creepage = creepages(motion, &frame, rel, roll);
    let creep = law.force(
        &CreepContact {
            a: ellipse.a,
            b: ellipse.b,
            normal,
            mu,
            shear_modulus: material.shear_modulus(),
            poisson: material.poisson,
        },
        creepage,
    );
    let force = std::array::from_fn(|i| {
        creep.x * frame.tx[i] + creep.y * frame.ty[i] + normal * frame.n[i]
    });
    WheelForce {
        normal,
        ellipse,
        creepage,
        creep,
        force,
        frame,
    }
}

/// Shares a wheel's load between a main contact and a second one lying `gap` (m) above it: both
/// bodies approach by δ, the main contact carries `N1(δ)` and the second `N2(δ − gap)` (Hertz,
/// `N ∝ δ^{3/2}`), with `N1 + N2 = load`. Returns `(N1, N2)`.
pub fn split_load(
    main: &super::hertz::HertzShape,
    second: &super::hertz::HertzShape,
    gap: f64,
    load: f64,
    material: &Material,
) -> (f64, f64) {
    let total = |d: f64| {
        main.load_from_approach(d, material) + second.load_from_approach(d - gap, material)
    };
    let mut hi = main.ellipse(load, material).approach;
    let mut lo = 0.0;
    // total(hi) ≥ load since N1(hi) = load; bisection on δ.
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if total(mid) > load {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let d = 0.5 * (lo + hi);
    let n1 = main.load_from_approach(d, material);
    (n1, (load - n1).max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pure_rolling_has_no_creepage_and_frames_are_orthonormal() {
        for side in [Side::Left, Side::Right] {
            let f = ContactFrame::new(side, 0.3, 0.01);
            for (p, q) in [(f.tx, f.ty), (f.ty, f.n), (f.tx, f.n)] {
                assert!(dot(p, q).abs() < 1e-12);
            }
            for v in [f.tx, f.ty, f.n] {
                assert!((dot(v, v) - 1.0).abs() < 1e-12);
            }
        }
        let m = WheelsetMotion::rolling(20.0, 0.42);
        let frame = ContactFrame::new(Side::Left, 0.0, 0.0);
        let c = creepages(&m, &frame, [0.0, 0.75, -0.42], 0.0);
        assert!(c.x.abs() < 1e-12 && c.y.abs() < 1e-12 && c.spin.abs() < 1e-12);
        // A larger rolling radius makes the wheel's contact point move backward: ξx < 0.
        let c = creepages(&m, &frame, [0.0, 0.75, -0.43], 0.0);
        assert!((c.x - (1.0 - 0.43 / 0.42)).abs() < 1e-12);
        // Lateral velocity gives lateral creepage; a contact angle gives spin −sinδ/r0.
        let mut m2 = m;
        m2.lateral_velocity = 0.2;
        assert!((creepages(&m2, &frame, [0.0, 0.75, -0.42], 0.0).y - 0.01).abs() < 1e-12);
        let frame = ContactFrame::new(Side::Left, 0.1, 0.0);
        let c = creepages(&m, &frame, [0.0, 0.75, -0.42], 0.0);
        assert!((c.spin + (0.1f64).sin() / 0.42).abs() < 1e-12);
    }

    #[test]
    fn load_split_between_two_contacts() {
        let shape = super::super::hertz::HertzShape::from_radii(0.42, f64::INFINITY, 0.3);
        let m = Material::STEEL;
        // Equal shapes at zero gap share equally; a large gap leaves all on the main contact.
        let (a, b) = split_load(&shape, &shape, 0.0, 100e3, &m);
        assert!((a - 50e3).abs() < 1.0 && (b - 50e3).abs() < 1.0);
        let (a, b) = split_load(&shape, &shape, 1e-3, 100e3, &m);
        assert!((a - 100e3).abs() < 1.0 && b < 1.0);
    }
}
