//! The three-piece bogie's parts as built against their closed forms: the side
//! frame hanging on its pads (gravity's roll and swing stiffness), the shear pad's resistance to
//! the side frame rolling on it, the two-stage nest and the control springs that press the
//! wedges, the centre plate's and side bearers' friction that sticks, then slips at its limit;
//! static equilibrium and left–right mirror symmetry. The vehicle file's refused attachments
//! are in `tests/mutation.rs`.

use nalgebra::{UnitQuaternion, Vector3};
use railforce::vehicle::elements::{Element, Memory};
use railforce::vehicle::{BodyState, Vehicle, Wrench};
use std::path::PathBuf;
use std::sync::OnceLock;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn c80() -> &'static Vehicle {
    static V: OnceLock<Vehicle> = OnceLock::new();
    V.get_or_init(|| Vehicle::load(&root().join("vehicles/c80.toml")).unwrap())
}

fn c80_empty() -> &'static Vehicle {
    static V: OnceLock<Vehicle> = OnceLock::new();
    V.get_or_init(|| Vehicle::load(&root().join("vehicles/c80_empty.toml")).unwrap())
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
    e.apply(states, memory, &mut w, 2e-4);
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
    let with = wrenches(
        &Element::ShearPad(pad.clone()),
        &states,
        &mut [0.0; railforce::vehicle::elements::MEMORY],
    );
    let without = wrenches(
        &Element::ShearPad(flat),
        &states,
        &mut [0.0; railforce::vehicle::elements::MEMORY],
    );
    // Rolled at once from rest, the rubber answers with its unrelaxed stiffness: the static
    // bed's times 1 + Σ wᵢ of its Maxwell branches (the vertical axis').
    let k = k * pad
        .rubber
        .map_or(1.0, |r| 1.0 + r[2].weights.iter().sum::<f64>());
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
    let mut memory = [0.0; railforce::vehicle::elements::MEMORY];
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
    let mut memory = [0.0; railforce::vehicle::elements::MEMORY];
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

/// The side frame `name`'s pads (their width set to `width`, and with `thin` their crown
/// raised to the pedestal roof: no thickness) and its nest with the lateral shear and the
/// group's tilt taken out: the load path alone.
fn load_path(v: &Vehicle, name: &str, width: f64, thin: bool) -> Vec<Element> {
    let sf = v.body_index(name).unwrap();
    v.elements
        .iter()
        .filter_map(|e| match e {
            Element::ShearPad(p) if p.upper.body == sf => {
                let mut p = p.clone();
                p.width = width;
                // The static stiffness: the rubber's branches relaxed, carrying nothing.
                p.rubber = None;
                if thin {
                    p.lower.local.z -= p.rest.z;
                    p.rest.z = 0.0;
                }
                Some(Element::ShearPad(p))
            }
            Element::SpringNest(n) if n.lower.body == sf => {
                let mut n = n.clone();
                n.lateral_stiffness = [0.0; 2];
                n.footprint = [0.0; 2];
                Some(Element::SpringNest(n))
            }
            _ => None,
        })
        .collect()
}

/// The pads' own roll stiffness about the pedestal roof: the bed's width `k_z·w²/12`, and
/// their thickness t (roof to adapter crown) sheared by the roll, `k_y·t²`, with the load
/// turning with the roof, `N·t`.
fn pad_terms(elements: &[Element]) -> f64 {
    elements
        .iter()
        .filter_map(|e| match e {
            Element::ShearPad(p) => {
                let t = -p.rest.z;
                Some(p.rocking_stiffness() + p.preload * t + p.stiffness.y * t * t)
            }
            _ => None,
        })
        .sum()
}

/// Rolls side frame `sf` by `theta` about the line of its pedestal roofs, the bolster moved
/// laterally by `bolster_dy`; returns the moment about that line (x) of gravity and `elements`
/// on the side frame, with the nest's load W, the height L from spring seat to pedestal roof
/// and the side frame's centre of gravity below the roof h.
fn moment_about_pad_line(
    v: &Vehicle,
    elements: &[Element],
    sf: usize,
    theta: f64,
    bolster_dy: f64,
) -> (f64, f64, f64, f64) {
    let mut states = at_rest(v);
    let (mut roof, mut pads, mut w, mut seat, mut bolster) = (Vector3::zeros(), 0.0, 0.0, 0.0, 0);
    for e in elements {
        match e {
            Element::ShearPad(p) => {
                roof += v.bodies[sf].position + p.upper.local;
                pads += 1.0;
            }
            Element::SpringNest(n) => {
                w = n.law.force(n.static_compression);
                seat = (v.bodies[sf].position + n.lower.local).z;
                bolster = n.upper.body;
            }
            _ => {}
        }
    }
    let pivot = roof / pads;
    let rot = UnitQuaternion::from_euler_angles(theta, 0.0, 0.0);
    states[sf].position = pivot + rot * (v.bodies[sf].position - pivot);
    states[sf].rotation = rot;
    states[bolster].position.y += bolster_dy;
    let mut wr = vec![Wrench::default(); states.len()];
    for e in elements {
        e.apply(
            &states,
            &mut [0.0; railforce::vehicle::elements::MEMORY],
            &mut wr,
            2e-4,
        );
    }
    let gravity = Vector3::new(0.0, 0.0, -v.bodies[sf].mass * 9.81);
    let f = wr[sf].force + gravity;
    let moment = wr[sf].torque + (states[sf].position - pivot).cross(&f);
    (
        moment.x,
        w,
        pivot.z - seat,
        pivot.z - v.bodies[sf].position.z,
    )
}

/// A side frame rolled about the line of its pads: gravity returns it with `W·L` (the load
/// W on its spring seat L below the pedestal roofs) plus `m·g·h` (its own weight h below), and
/// each pad adds its own terms ([`pad_terms`]). The side frame hangs: with the pads acting at
/// the axle centre and the nest above them it would stand as an inverted pendulum.
#[test]
fn side_frame_hangs_roll_stiffness_about_the_pad_line() {
    for v in [c80(), c80_empty()] {
        let sf = v.body_index("sideframe1l").unwrap();
        let theta = 1e-3;
        for width in [0.0, 0.17] {
            let els = load_path(v, "sideframe1l", width, false);
            let (m, w, l, h) = moment_about_pad_line(v, &els, sf, theta, 0.0);
            assert!(
                l > 0.2 && h > 0.0,
                "the seat lies below the roof: L {l}, h {h}"
            );
            let k = w * l + v.bodies[sf].mass * 9.81 * h + pad_terms(&els);
            let got = -m / theta;
            assert!(
                (got / k - 1.0).abs() < 0.01,
                "{} width {width}: {got:.0} vs W·L + m·g·h + pads {k:.0} N·m/rad",
                v.name
            );
        }
    }
}

/// The side frame swings as a pendulum under the bolster (the nest not sheared): a lateral
/// force at the spring seat meets `(W·L + m·g·h + pads)/L²`. On pads without width or
/// thickness that is W/L but for the frame's own weight: within 5 % loaded (0.8 %), 6 % empty;
/// the C80's 25 mm pads add `N·t + k_y·t²` (assets/docs/physics.md §2).
#[test]
fn side_frame_swing_stiffness_is_w_over_l_loaded_and_empty() {
    for v in [c80(), c80_empty()] {
        let sf = v.body_index("sideframe1l").unwrap();
        for thin in [true, false] {
            let els = load_path(v, "sideframe1l", 0.0, thin);
            let theta: f64 = 2e-3;
            let (_, _, l, _) = moment_about_pad_line(v, &els, sf, 0.0, 0.0);
            let (m, w, l2, h) = moment_about_pad_line(v, &els, sf, theta, l * theta.sin());
            assert_eq!(l, l2);
            // The force at the seat that holds it there: F·L = −M, at its displacement L·θ.
            let k = -m / (l * l * theta.sin());
            let exact = (w * l + v.bodies[sf].mass * 9.81 * h + pad_terms(&els)) / (l * l);
            assert!(
                (k / exact - 1.0).abs() < 0.01,
                "{} thin {thin}: {k:.0} vs {exact:.0} N/m",
                v.name
            );
            let w_over_l = w / l;
            if thin && v.mass() > 50_000.0 {
                assert!(
                    (k / w_over_l - 1.0).abs() < 0.05,
                    "loaded: {k:.0} vs W/L {w_over_l:.0}"
                );
            }
            if thin {
                assert!(
                    (k / w_over_l - 1.0).abs() < 0.07,
                    "{}: {k:.0} vs W/L {w_over_l:.0}",
                    v.name
                );
            }
        }
    }
}

/// A side frame given a roll rate and let go returns, with the pads' width and without it (the
/// hanging load path alone), on smooth straight track at 72 km/h: within a tenth of its peak
/// after 2 s (the rubber's loss factor of 0.1 damps the hanging pendulum lightly).
#[test]
fn side_frame_rolled_and_let_go_returns() {
    let track = railforce::sim::fidelity::smooth(&root().join("tracks/tangent.toml")).unwrap();
    for width in [0.17, 0.0] {
        let mut v = c80().clone();
        for e in &mut v.elements {
            if let Element::ShearPad(p) = e {
                p.width = width;
            }
        }
        let sf = v.body_index("sideframe1l").unwrap();
        let cfg = railforce::sim::SimConfig {
            speed: 20.0,
            duration: 2.5,
            settle: 0.0,
            ..Default::default()
        };
        let mut sim = railforce::sim::Simulation::new(&v, &track, cfg).unwrap();
        sim.kick(sf, Vector3::zeros(), Vector3::new(0.5, 0.0, 0.0));
        let roll = |sim: &railforce::sim::Simulation| {
            let r = sim.frames()[sf].axes.transpose() * sim.states()[sf].matrix();
            r[(2, 1)].atan2(r[(2, 2)])
        };
        let (mut peak, mut tail) = (0.0f64, 0.0f64);
        while sim.time() < 2.5 {
            sim.step().unwrap();
            sim.refresh_frames();
            let r = roll(&sim).abs();
            peak = peak.max(r);
            if sim.time() > 2.0 {
                tail = tail.max(r);
            }
        }
        assert!(peak > 1e-3, "width {width}: the kick rolled it ({peak})");
        assert!(
            tail < 0.1 * peak && tail < 1e-3,
            "width {width}: still rolled {tail} of {peak} rad after 2 s"
        );
    }
}

/// The two-stage nest: the outer (and control) coils alone up to the inner coils' gap, then
/// all; the empty wagon sits in the first stage and the loaded one in the second, from the
/// same nest data, with 1.2 and 4.8 MN/m (assets/docs/physics.md §2).
#[test]
fn two_stage_nest_engages_its_inner_coils_after_their_gap() {
    let nest = |v: &Vehicle| {
        v.elements
            .iter()
            .find_map(|e| match e {
                Element::SpringNest(n) => Some(n.clone()),
                _ => None,
            })
            .unwrap()
    };
    let (l, e) = (nest(c80()), nest(c80_empty()));
    assert_eq!(l.law, e.law, "one nest, loaded or empty");
    let law = l.law;
    let g = law.inner_gap;
    let first = law.outer + law.control;
    assert!((law.tangent(0.5 * g) - 1.2e6).abs() < 1.0);
    assert!((law.tangent(1.5 * g) - 4.8e6).abs() < 1.0);
    for i in 1..200 {
        let c = i as f64 * 0.5e-3;
        let expected =
            law.outer * c + law.inner * (c - g).max(0.0) + law.control * (c + law.control_extra);
        assert!((law.force(c) - expected).abs() < 1e-6 * expected);
        assert!((law.compression(law.force(c)) - c).abs() < 1e-8, "c {c}");
    }
    // Below the outer coils' free height only the taller control springs push.
    assert!(
        (law.force(-0.5 * law.control_extra) - law.control * 0.5 * law.control_extra).abs() < 1e-9
    );
    assert_eq!(law.force(-2.0 * law.control_extra), 0.0);
    assert!(e.static_compression < g && l.static_compression > g);
    assert!(e.static_compression > 0.0);
    assert!((law.tangent(e.static_compression) - first).abs() < 1.0);
}

/// K6 variable friction: the wedges' control springs press them on the column with
/// `N = P/tan α`, the face slips at `μ·N`; the loaded wagon's friction is 8–10 % of its nest
/// force (assets/docs/physics.md §2), the empty one's relatively more (its control springs stand taller).
#[test]
fn wedge_friction_comes_from_its_control_springs() {
    let wedge = |v: &Vehicle| {
        v.elements
            .iter()
            .find_map(|e| match e {
                Element::WedgeDamper(w) => Some(w.clone()),
                _ => None,
            })
            .unwrap()
    };
    let mut ratios = Vec::new();
    for v in [c80(), c80_empty()] {
        let w = wedge(v);
        let c = w.nest.static_compression;
        let p = w.nest.law.control * (c + w.nest.law.control_extra);
        let (limit, nest) = w.limits(c, 0.0);
        assert!((limit - w.friction * p / w.angle.tan()).abs() < 1e-6 * limit);
        assert!((nest - w.nest.law.force(c)).abs() < 1e-6 * nest);
        ratios.push(limit / nest);
    }
    assert!(
        (0.08..=0.10).contains(&ratios[0]),
        "loaded friction / nest force {}",
        ratios[0]
    );
    assert!(
        ratios[1] > 1.5 * ratios[0],
        "empty {} vs loaded {}",
        ratios[1],
        ratios[0]
    );
}

/// At the static position every body but the wheelsets (which the rails carry) is in
/// equilibrium under gravity and all the elements, and each level of supports carries the
/// weight above it.
#[test]
fn static_equilibrium_every_support_carries_the_weight_above_it() {
    for v in [c80(), c80_empty()] {
        let states = at_rest(v);
        let mut wr = vec![Wrench::default(); states.len()];
        for e in &v.elements {
            // Each element its own memory, as a run keeps it.
            e.apply(
                &states,
                &mut [0.0; railforce::vehicle::elements::MEMORY],
                &mut wr,
                2e-4,
            );
        }
        for (i, b) in v.bodies.iter().enumerate() {
            if v.contact.wheelsets.contains(&i) {
                continue;
            }
            let f = wr[i].force + Vector3::new(0.0, 0.0, -b.mass * 9.81);
            assert!(
                f.norm() < 1e-6 * b.mass * 9.81,
                "{} {}: {f:?}",
                v.name,
                b.name
            );
            assert!(
                wr[i].torque.norm() < 1e-3,
                "{} {}: {:?}",
                v.name,
                b.name,
                wr[i].torque
            );
        }
        let weight = |pick: &dyn Fn(&str) -> bool| {
            v.bodies
                .iter()
                .filter(|b| pick(&b.name))
                .map(|b| b.mass * 9.81)
                .sum::<f64>()
        };
        let (mut pads, mut nests, mut top) = (0.0, 0.0, 0.0);
        for e in &v.elements {
            match e {
                Element::ShearPad(p) => pads += p.preload,
                Element::SpringNest(n) => nests += n.law.force(n.static_compression),
                Element::CentrePlate(c) => top += c.preload,
                Element::SideBearer(s) => top += s.preload,
                _ => {}
            }
        }
        let close = |a: f64, b: f64| (a / b - 1.0).abs() < 1e-6;
        assert!(close(pads, weight(&|n| !n.starts_with("wheelset"))));
        assert!(close(
            nests,
            weight(&|n| n == "carbody" || n.starts_with("bolster"))
        ));
        assert!(close(top, weight(&|n| n == "carbody")));
    }
}

/// Mirror the wagon left to right: every body's state mirrored (and the left and right side
/// frames swapped) gives every body's mirrored wrench.
#[test]
fn elements_are_left_right_mirror_symmetric() {
    let v = c80();
    let mirror_body = |i: usize| {
        let n = &v.bodies[i].name;
        let m = match n.chars().last() {
            Some('l') if n.starts_with("sideframe") => format!("{}r", &n[..n.len() - 1]),
            Some('r') if n.starts_with("sideframe") => format!("{}l", &n[..n.len() - 1]),
            _ => n.clone(),
        };
        v.body_index(&m).unwrap()
    };
    let flip = |p: Vector3<f64>| Vector3::new(p.x, -p.y, p.z);
    let flip_axial = |p: Vector3<f64>| Vector3::new(-p.x, p.y, -p.z);
    // A small, uneven motion of every body.
    let mut a = at_rest(v);
    for (i, s) in a.iter_mut().enumerate() {
        let k = i as f64 + 1.0;
        s.position += Vector3::new(1e-4 * k, 3e-4 * (k * 1.3).sin(), -2e-4 * (k * 0.7).cos());
        s.rotation = UnitQuaternion::from_scaled_axis(Vector3::new(
            2e-3 * (k * 0.9).sin(),
            1e-3 * (k * 1.7).cos(),
            3e-3 * (k * 0.4).sin(),
        ));
        s.velocity = Vector3::new(0.0, 0.02 * (k * 2.1).sin(), 0.01 * k.cos());
        s.angular_velocity = Vector3::new(0.01 * k.sin(), 0.0, 0.02 * (k * 0.3).cos());
    }
    let mut b = a.clone();
    for i in 0..a.len() {
        let s = &a[mirror_body(i)];
        let (axis, angle) = s
            .rotation
            .axis_angle()
            .map_or((Vector3::x(), 0.0), |(ax, an)| (ax.into_inner(), an));
        b[i].position = flip(s.position);
        b[i].rotation = UnitQuaternion::from_scaled_axis(flip_axial(axis) * angle);
        b[i].velocity = flip(s.velocity);
        b[i].angular_velocity = flip_axial(s.angular_velocity);
    }
    let all = |st: &[BodyState]| {
        let mut wr = vec![Wrench::default(); st.len()];
        for e in &v.elements {
            e.apply(
                st,
                &mut [0.0; railforce::vehicle::elements::MEMORY],
                &mut wr,
                2e-4,
            );
        }
        wr
    };
    let (wa, wb) = (all(&a), all(&b));
    for i in 0..a.len() {
        let (x, y) = (&wa[mirror_body(i)], &wb[i]);
        let scale = 1.0 + v.mass() * 9.81 * 1e-9;
        assert!(
            (flip(x.force) - y.force).norm() < 1e-6 * scale.max(x.force.norm()),
            "{}: {:?} vs {:?}",
            v.bodies[i].name,
            flip(x.force),
            y.force
        );
        assert!(
            (flip_axial(x.torque) - y.torque).norm() < 1e-6 * (1.0 + x.torque.norm()),
            "{}: {:?} vs {:?}",
            v.bodies[i].name,
            flip_axial(x.torque),
            y.torque
        );
    }
}
