//! The three-piece bogie's parts as built against their closed forms (issue 17): the shear
//! pad's resistance to the side frame rolling on it, and the centre plate's and side bearers'
//! friction that sticks, then slips at its limit.

use nalgebra::{UnitQuaternion, Vector3};
use railforce::vehicle::elements::{Element, Memory};
use railforce::vehicle::{BodyState, Vehicle, Wrench};
use std::path::PathBuf;
use std::sync::OnceLock;

fn c80() -> &'static Vehicle {
    static V: OnceLock<Vehicle> = OnceLock::new();
    V.get_or_init(|| {
        Vehicle::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("vehicles/c80.toml")).unwrap()
    })
}

/// Every body at its static position, at rest.
fn at_rest(v: &Vehicle) -> Vec<BodyState> {
    v.bodies
        .iter()
        .map(|b| BodyState {
            position: b.position,
            rotation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        })
        .collect()
}

/// Wrenches of one element alone.
fn wrenches(e: &Element, states: &[BodyState], memory: &mut Memory) -> Vec<Wrench> {
    let mut w = vec![Wrench::default(); states.len()];
    e.apply(states, memory, &mut w);
    w
}

fn first<T: Clone>(pick: impl Fn(&Element) -> Option<T>) -> T {
    c80().elements.iter().find_map(pick).unwrap()
}

/// A side frame rolled by θ on its pad: the pad's spring bed resists with `k_z·w²/12·θ` (no
/// moment at all with w = 0), until the load tips on an edge: `N·w/2`.
#[test]
fn shear_pad_resists_side_frame_roll_by_its_width_until_it_tips() {
    let pad = first(|e| match e {
        Element::ShearPad(p) => Some(p.clone()),
        _ => None,
    });
    assert!(pad.width > 0.1, "the C80's pads have their width");
    let k = pad.stiffness.z * pad.width * pad.width / 12.0;
    assert!((pad.rocking_stiffness() - k).abs() < 1e-6 * k);
    let n = pad.preload;
    assert!((pad.rocking_moment(1e-3, 0.0, n) - k * 1e-3).abs() < 1e-6 * k * 1e-3);
    let tip = 0.5 * pad.width * n;
    assert_eq!(pad.rocking_moment(0.5, 0.0, n), tip);
    assert_eq!(pad.rocking_moment(-0.5, 0.0, n), -tip);
    assert_eq!(
        pad.rocking_moment(0.5, 0.0, -1.0),
        0.0,
        "a lifted pad holds nothing"
    );
    // In a run: the torque on the side frame about its own x axis with and without width
    // differs by exactly the bed's moment (the translational forces are the same).
    let mut states = at_rest(c80());
    let theta = 2e-3;
    states[pad.upper.body].rotation = UnitQuaternion::from_euler_angles(theta, 0.0, 0.0);
    let mut flat = pad.clone();
    flat.width = 0.0;
    let mut m = [0.0; 4];
    let with = wrenches(&Element::ShearPad(pad.clone()), &states, &mut m);
    let without = wrenches(&Element::ShearPad(flat), &states, &mut m);
    let x = states[pad.upper.body].rotation * Vector3::x();
    let dm = (with[pad.upper.body].torque - without[pad.upper.body].torque).dot(&x);
    assert!(
        (dm + k * theta).abs() < 1e-6 * k * theta,
        "{dm} vs {}",
        -k * theta
    );
    let dw = (with[pad.lower.body].torque - without[pad.lower.body].torque).dot(&x);
    assert!(
        (dw - k * theta).abs() < 1e-6 * k * theta,
        "the axle takes the reaction"
    );
}

/// The bolster yawed under the carbody by a slow ramp: the stuck centre plate twists with
/// `k_x·R²/2·ψ`, slips at `μ·N·(2/3)·R` and holds that moment; turned back it sticks at once.
#[test]
fn centre_plate_sticks_then_slips_at_its_friction_moment() {
    let cp = first(|e| match e {
        Element::CentrePlate(c) => Some(c.clone()),
        _ => None,
    });
    let (k, limit) = (cp.twist_stiffness(), cp.slip_moment(cp.preload));
    assert!((k - cp.stiffness.x * cp.radius * cp.radius / 2.0).abs() < 1e-6 * k);
    assert!((limit - cp.friction * cp.preload * 2.0 / 3.0 * cp.radius).abs() < 1e-6 * limit);
    let e = Element::CentrePlate(cp.clone());
    let mut states = at_rest(c80());
    let mut memory = [0.0; 4];
    let mut psi = 0.0;
    for i in 0..=400 {
        psi = i as f64 * 1e-4; // up to 40 mrad
        states[cp.lower.body].rotation = UnitQuaternion::from_euler_angles(0.0, 0.0, psi);
        let w = wrenches(&e, &states, &mut memory);
        // The bolster turning drags the carbody along: +M about z on the carbody.
        let expected = (k * psi.sin()).min(limit);
        let got = w[cp.upper.body].torque.z;
        assert!(
            (got - expected).abs() < 1e-3 * limit,
            "ψ {psi}: {got} vs {expected}"
        );
    }
    // Back by 2 mrad: stuck again, the moment falls by k·Δψ.
    let back = psi - 2e-3;
    states[cp.lower.body].rotation = UnitQuaternion::from_euler_angles(0.0, 0.0, back);
    let got = wrenches(&e, &states, &mut memory)[cp.upper.body].torque.z;
    let expected = limit - k * (psi.sin() - back.sin());
    assert!((got - expected).abs() < 1e-3 * limit, "{got} vs {expected}");
}

/// The bolster pushed along under the carbody by a slow ramp: each stuck side bearer carries
/// `k_s·d`, slips at `μ·N` and holds that force.
#[test]
fn side_bearer_sticks_then_slips_at_its_friction_force() {
    let sb = first(|e| match e {
        Element::SideBearer(s) => Some(s.clone()),
        _ => None,
    });
    let e = Element::SideBearer(sb.clone());
    let limit = sb.friction * sb.preload;
    let mut states = at_rest(c80());
    let x0 = states[sb.lower.body].position.x;
    let mut memory = [0.0; 4];
    for i in 0..=100 {
        let d = i as f64 * 1e-4; // up to 10 mm
        states[sb.lower.body].position.x = x0 + d;
        let w = wrenches(&e, &states, &mut memory);
        let expected = (sb.stick_stiffness * d).min(limit);
        let got = w[sb.upper.body].force.x;
        assert!(
            (got - expected).abs() < 1e-6 * limit,
            "d {d}: {got} vs {expected}"
        );
        assert!((w[sb.upper.body].force.z - sb.preload).abs() < 1e-6 * sb.preload);
    }
}
