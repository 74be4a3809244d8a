//! The consist's longitudinal dynamics (`railforce::train`): the built-in consists load, a bad
//! consist file is refused naming the file and the field, the steady state on a grade carries
//! the resistance behind each coupler, momentum balances, the brake signal travels at its
//! speed, the driver holds a speed or says it cannot, and the coupled mode (the 3-D wagon
//! moved by the caller) reproduces the alone mode. Release-only checks (`#[ignore]`): peak
//! forces of a 20 000 t train braking from 60 km/h, and the step's cost.

use railforce::train::{
    BUILTIN, Command, Consist, ConstantRoute, Train, VehicleKind, WagonAt, builtin_path,
    resistance::{curve_force, grade_force},
};
use std::path::{Path, PathBuf};

const DT: f64 = 1.0 / 1200.0;
const KMH: f64 = 1.0 / 3.6;

fn load(name: &str) -> Consist {
    Consist::load(&builtin_path(name).unwrap()).unwrap()
}

fn text(name: &str) -> String {
    std::fs::read_to_string(builtin_path(name).unwrap()).unwrap()
}

/// The built-in consist `name` with `from` replaced by `to` (exactly once).
fn edited(name: &str, from: &str, to: &str) -> railforce::Result<Consist> {
    let t = text(name);
    assert_eq!(t.matches(from).count(), 1, "{from:?} in {name}");
    Consist::parse(
        &t.replacen(from, to, 1),
        Path::new("edited/daqin.consist.toml"),
    )
}

fn refused(r: railforce::Result<Consist>, field: &str) -> String {
    let e = r.expect_err("the edit must be refused").to_string();
    assert!(e.contains("edited/daqin.consist.toml"), "{e}");
    assert!(e.contains(field), "{field} not named in: {e}");
    e
}

/// A stepless handle, so the steady control balances the train exactly.
fn stepless(name: &str) -> Consist {
    let t = text(name)
        .replacen("traction_notches = 12", "traction_notches = 0", 1)
        .replacen("brake_notches = 12", "brake_notches = 0", 1);
    Consist::parse(&t, Path::new("stepless.consist.toml")).unwrap()
}

#[test]
fn the_builtin_consists_load_with_their_make_ups() {
    for name in BUILTIN {
        let c = load(name);
        let locos = c.locomotives();
        let twenty = name.starts_with("daqin_20kt");
        let n = if twenty { 212 } else { 106 };
        assert_eq!(c.vehicles.len(), n, "{name}");
        assert_eq!(locos, if twenty { vec![0, 106] } else { vec![0] });
        let length = if twenty { 2590.444 } else { 1295.222 };
        assert!((c.length() - length).abs() < 1e-9, "{name}: {}", c.length());
        let wagon_t = if name.ends_with("empty") { 20.0 } else { 100.0 };
        let mass = locos.len() as f64 * 184e3 + (n - locos.len()) as f64 * wagon_t * 1e3;
        assert!((c.mass() - mass).abs() < 1e-6, "{name}");
        let w = c.index_at(c.position).unwrap();
        assert_eq!(c.vehicles[w].kind, VehicleKind::Wagon);
        assert_eq!(w, if twenty { 25 } else { 11 }, "{name}");
        assert_eq!(c.coupler_height, 0.88);
        assert_eq!(c.coupling.slack, 0.0095);
    }
}

#[test]
fn a_bad_consist_file_is_refused_naming_the_file_and_the_field() {
    // the 3-D wagon outside the train
    refused(
        edited("daqin_10kt", "position = 0.125", "position = 1.5"),
        "position",
    );
    // ... or on a locomotive
    let e = refused(
        edited("daqin_20kt", "position = 0.125", "position = 0.5"),
        "position",
    );
    assert!(e.contains("locomotive"), "{e}");
    // a negative mass
    refused(
        edited("daqin_10kt", "mass_t = 100.0 ", "mass_t = -100.0 "),
        "vehicles.c80.mass_t",
    );
    // an unknown vehicle in the make-up
    let e = refused(
        edited("daqin_10kt", "vehicle = \"c80\"", "vehicle = \"c70\""),
        "make_up[1].vehicle",
    );
    assert!(e.contains("c70"), "{e}");
    // an unknown vehicle kind
    refused(
        edited("daqin_10kt", "kind = \"wagon\"", "kind = \"tender\""),
        "vehicles.c80.kind",
    );
    // a non-finite number, and a wagon with an effort curve
    refused(
        edited("daqin_10kt", "travel_m = 0.083", "travel_m = nan"),
        "draft_gear.travel_m",
    );
    refused(
        edited(
            "daqin_10kt",
            "brake_shoe_force_n = 100.0e3",
            "brake_shoe_force_n = 100.0e3\n[vehicles.c80.traction]\nmax_n = 1.0\ncontinuous_n = 1.0\ncontinuous_kmh = 1.0",
        ),
        "vehicles.c80.traction",
    );
    // an unknown key names the file (the parser's message)
    let e = edited("daqin_10kt", "slack_m = 0.0095", "slack_mm = 9.5")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("edited/daqin.consist.toml") && e.contains("slack_mm"),
        "{e}"
    );
    // a caller's position on the mid locomotive is refused too
    let c = load("daqin_20kt");
    let at = 106.5 / 212.0;
    let e = Train::new(
        c,
        WagonAt::Fraction(at),
        0.0,
        10.0,
        &ConstantRoute::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("position") && e.contains("locomotive"), "{e}");
}

/// Resistance of vehicle `i` of `c` at `v` on `route`, N, positive against the motion.
/// Runs `c` alone at 60 km/h on `route` for `seconds` and checks each coupler against the
/// resistance behind it less the traction behind it; returns the largest relative error
/// (against each coupler's own force, at least `floor` N).
fn steady_error(c: Consist, route: ConstantRoute, seconds: f64, floor: f64) -> f64 {
    railforce::train::checks::steady_couplers(c, route, 60.0 * KMH, seconds, DT, floor)
        .unwrap()
        .worst
}

#[test]
fn at_constant_speed_on_a_grade_each_coupler_carries_the_resistance_behind_it() {
    // HXD1 + 105 C80 up 3 ‰: one locomotive at the head, every coupler pulls what follows.
    let up = ConstantRoute {
        grade: 0.003,
        curvature: 0.0,
    };
    let e = steady_error(stepless("daqin_10kt"), up, 20.0, 0.0);
    assert!(e < 0.01, "largest error {:.3} %", 100.0 * e);
    // HXD1 + 105 C80 + HXD1 + 105 C80 up 2 ‰ in R 800 m: the mid locomotive's traction is
    // taken off the resistance behind (within 1 % of the largest coupler force there).
    let curve = ConstantRoute {
        grade: 0.002,
        curvature: 1.0 / 800.0,
    };
    let e = steady_error(stepless("daqin_20kt"), curve, 20.0, 4.5e3);
    assert!(e < 0.01, "largest error {:.3} %", 100.0 * e);
    // the empty 20 000 t train down 8 ‰ on its dynamic brakes: couplers in compression
    let down = ConstantRoute {
        grade: -0.008,
        curvature: 0.0,
    };
    let e = steady_error(stepless("daqin_20kt_empty"), down, 20.0, 0.5e3);
    assert!(e < 0.01, "largest error {:.3} %", 100.0 * e);
}

#[test]
fn momentum_changes_by_the_external_forces() {
    let route = ConstantRoute {
        grade: 0.005,
        curvature: 1.0 / 1200.0,
    };
    let mut t = Train::new(load("daqin_20kt"), WagonAt::File, 0.0, 50.0 * KMH, &route).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..6000 {
        if k == 600 {
            t.command(Command::Notch(-6));
            t.command(Command::AirBrake(0.7));
        }
        let p0 = t.momentum();
        t.step_alone(DT, &route);
        let dp = t.momentum() - p0;
        let want = DT * t.last_external_force();
        worst = worst.max((dp - want).abs() / (want.abs() + 1.0));
    }
    assert!(worst < 1e-6, "worst relative residual {worst:e}");
    assert!(
        t.speed() < 50.0 * KMH - 0.3,
        "the brakes slowed it: {}",
        t.speed()
    );
}

#[test]
fn a_full_service_application_travels_down_the_pipe_at_its_speed() {
    let route = ConstantRoute::default();
    let mut t = Train::new(load("daqin_10kt"), WagonAt::File, 0.0, 60.0 * KMH, &route).unwrap();
    let c = t.consist().clone();
    t.run_alone(2.0, DT, &route, &mut |_| {});
    let t0 = t.time();
    let head = t.positions()[0];
    let dist: Vec<f64> = t.positions().iter().map(|s| head - s).collect();
    t.command(Command::AirBrake(1.0));
    let speed = c.brake.pipe_speed;
    for (i, d) in dist.iter().enumerate() {
        let want = t0 + d / speed + c.brake.valve_delay;
        assert!((t.brake_arrival(i) - want).abs() < 1e-9, "vehicle {i}");
    }
    // when each wagon's brake force first passes 1 % of its full-service force
    let n = c.vehicles.len();
    let mut first = vec![f64::NAN; n];
    t.run_alone(10.0, DT, &route, &mut |t| {
        for (i, at) in first.iter_mut().enumerate().skip(1) {
            let full = c.vehicles[i].full_service_shoe_force * 0.30;
            if at.is_nan() && -t.brake_force(i) > 0.01 * full {
                *at = t.time() - t0;
            }
        }
    });
    // least squares of first = a + d / c over the wagons
    let pts: Vec<(f64, f64)> = (1..n).map(|i| (dist[i], first[i])).collect();
    let m = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / m, sy / m);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let fitted = sxx / sxy;
    assert!(
        (fitted - speed).abs() < 0.01 * speed,
        "fitted {fitted:.1} m/s against {speed} m/s"
    );
    let intercept = my - mx / fitted;
    let lag = c.brake.apply_time_constant * (1.0f64 / 0.99).ln();
    assert!(
        (intercept - c.brake.valve_delay - lag).abs() < 0.01,
        "{intercept}"
    );
    // with distributed power the signal also starts at the mid locomotive
    let mut t = Train::new(load("daqin_20kt"), WagonAt::File, 0.0, 60.0 * KMH, &route).unwrap();
    t.command(Command::AirBrake(1.0));
    let s = t.positions();
    let b = &t.consist().brake;
    let behind_mid = b.radio_delay + (s[106] - s[107]) / b.pipe_speed + b.valve_delay;
    assert!((t.brake_arrival(107) - behind_mid).abs() < 1e-9);
    let tail = b.radio_delay + (s[106] - s[211]) / b.pipe_speed + b.valve_delay;
    assert!((t.brake_arrival(211) - tail).abs() < 1e-9);
}

#[test]
fn the_driver_holds_the_speed_on_the_descent_and_says_when_it_cannot_on_the_climb() {
    // down 3 ‰: 309 kN of gravity against 171 kN of resistance; one HXD1's dynamic brake holds it
    let down = ConstantRoute {
        grade: -0.003,
        curvature: 0.0,
    };
    let v0 = 60.0 * KMH;
    let mut t = Train::new(load("daqin_10kt"), WagonAt::File, 0.0, v0, &down).unwrap();
    let mut worst: f64 = 0.0;
    t.run_alone(120.0, DT, &down, &mut |t| {
        worst = worst.max((t.speed() - v0).abs());
    });
    assert!(t.driver().notch() < 0, "notch {}", t.driver().notch());
    assert!(worst < 2.0 * KMH, "speed off by {:.2} km/h", worst / KMH);
    assert_eq!(t.speed_not_held_s(), 0.0);
    // up 20 ‰: 2.2 MN behind the HXD1, which pulls at most 576 kN at 60 km/h
    let up = ConstantRoute {
        grade: 0.020,
        curvature: 0.0,
    };
    let mut t = Train::new(load("daqin_10kt"), WagonAt::File, 0.0, v0, &up).unwrap();
    let f0 = t.coupling_force(0);
    assert!(f0 > 0.5e6, "{f0}");
    t.run_alone(30.0, DT, &up, &mut |_| {});
    assert!(!t.speed_held());
    assert!(t.speed_not_held_s() > 20.0, "{}", t.speed_not_held_s());
    assert_eq!(t.driver().control(), 1.0);
    assert!(t.speed() < v0 - 10.0 * KMH, "{}", t.speed() / KMH);
}

/// The alone mode against the coupled mode, the caller's 1-D wagon stepped at `DT` and the
/// train every `every` of its steps, after the wagon (`Train::step_to`, `after`) or before it
/// (`Train::step`): (largest peak difference over the peak, root mean square difference over
/// the root mean square, largest velocity difference of the wagon).
fn coupled_against_alone(every: usize, after: bool) -> (f64, f64, f64) {
    let route = ConstantRoute {
        grade: 0.004,
        curvature: 1.0 / 800.0,
    };
    let v0 = 55.0 * KMH;
    let build = || Train::new(load("daqin_10kt"), WagonAt::File, 500.0, v0, &route).unwrap();
    let mut alone = build();
    let mut coupled = build();
    let w = alone.wagon_index();
    let veh = alone.consist().vehicles[w].clone();
    let (mut s, mut v) = (coupled.positions()[w], v0);
    // peaks of each mode, and the root mean square of their difference
    let (mut peak_a, mut peak_b, mut sq_diff, mut sq, mut dv_max) =
        (0.0f64, 0.0f64, 0.0, 0.0, 0.0f64);
    let mut since = 0;
    for step in 0..24_000 {
        if step == 6_000 {
            // (6 000 steps: a whole number of the coupled train's steps, so both start now)
            for t in [&mut alone, &mut coupled] {
                t.command(Command::Notch(0));
                t.command(Command::AirBrake(1.0));
            }
        }
        alone.step_alone(DT, &route);
        // the caller's 1-D wagon: linearly implicit in its couplers' stiffness and damping
        let ahead = since as f64 * DT;
        let (front, rear) = coupled.coupler_jacobians_ahead(ahead, s, v);
        let shoes = coupled.wagon_brake();
        let (fr, dr) = veh.resistance.force(veh.mass, v);
        let fb = -shoes.friction * shoes.normal_force * v.signum();
        let force = front.force - rear.force
            + fr
            + curve_force(veh.mass, route.curvature, v)
            + grade_force(veh.mass, route.grade)
            + fb;
        let c = front.damping + rear.damping;
        let k = front.stiffness + rear.stiffness;
        let nb = coupled.neighbours();
        let (vf, vr) = (
            coupled.velocities()[nb.front.unwrap().index],
            coupled.velocities()[nb.rear.unwrap().index],
        );
        // the couplings' extension rates if the neighbours kept their velocities
        let push = front.stiffness * (vf - v) - rear.stiffness * (v - vr);
        let dv = DT * (force + DT * push) / (veh.mass + DT * (c - dr) + DT * DT * k);
        if !after {
            coupled.step(DT, s, v, &route);
        }
        v += dv;
        s += DT * v;
        since += 1;
        if after && since == every {
            coupled.step_to(every as f64 * DT, s, v, &route);
            since = 0;
        }
        if !after {
            since = 0;
        }
        let a = alone.coupler_forces();
        let (bf, br) = coupled.coupler_jacobians_ahead(since as f64 * DT, s, v);
        let b = (bf.force, br.force);
        peak_a = peak_a.max(a.0.abs()).max(a.1.abs());
        peak_b = peak_b.max(b.0.abs()).max(b.1.abs());
        sq_diff += (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2);
        sq += a.0 * a.0 + a.1 * a.1;
        dv_max = dv_max.max((alone.velocities()[w] - v).abs());
    }
    assert!(peak_a > 0.3e6, "peak {peak_a}");
    // the neighbours' pivots face the wagon's, a coupler pair apart
    let nb = coupled.neighbours();
    let arm = coupled.wagon_pivot_arm();
    let gap = nb.front.unwrap().pivot - (s + arm);
    assert!((gap - 2.0 * veh.pivot_inset).abs() < 0.1, "{gap}");
    let gap = (s - arm) - nb.rear.unwrap().pivot;
    assert!((gap - 2.0 * veh.pivot_inset).abs() < 0.1, "{gap}");
    (
        (peak_a - peak_b).abs() / peak_a,
        (sq_diff / sq).sqrt(),
        dv_max,
    )
}

#[test]
fn the_coupled_mode_reproduces_the_alone_mode() {
    let (peak, rms, dv) = coupled_against_alone(1, true);
    assert!(peak < 0.01, "peaks differ by {:.2} %", 100.0 * peak);
    assert!(
        rms < 0.02,
        "the forces differ by {:.2} % (root mean square)",
        100.0 * rms
    );
    assert!(dv < 0.01, "the wagon's velocities differ by {dv} m/s");
    // the train stepped first, the wagon taken to keep its velocity over the step
    let (peak, rms, dv) = coupled_against_alone(1, false);
    assert!(peak < 0.01, "peaks differ by {:.2} %", 100.0 * peak);
    assert!(
        rms < 0.03,
        "the forces differ by {:.2} % (root mean square)",
        100.0 * rms
    );
    assert!(dv < 0.01, "the wagon's velocities differ by {dv} m/s");
    // the train stepped at a quarter of the wagon's rate
    let (peak, rms, dv) = coupled_against_alone(4, true);
    assert!(peak < 0.01, "peaks differ by {:.2} %", 100.0 * peak);
    assert!(
        rms < 0.03,
        "the forces differ by {:.2} % (root mean square)",
        100.0 * rms
    );
    assert!(dv < 0.02, "the wagon's velocities differ by {dv} m/s");
}

/// Peak tension and compression over every coupler of a 20 000 t train braking at full
/// service from 60 km/h on level tangent track, after cutting traction (Chang et al., Railway
/// Sciences 2(4):495–513, 2023: 2 250 kN is the coupler force limit of Chinese heavy-haul
/// studies).
#[test]
#[ignore = "release: a 20 000 t train braking to a stop, 144 000 steps; run with --release --ignored"]
fn a_20kt_train_braking_from_60_kmh_stays_within_the_public_force_limit() {
    let route = ConstantRoute::default();
    for name in ["daqin_20kt", "daqin_20kt_empty"] {
        let mut t = Train::new(load(name), WagonAt::File, 0.0, 60.0 * KMH, &route).unwrap();
        let n = t.consist().vehicles.len();
        let mut f = vec![0.0; n - 1];
        let (mut tension, mut compression) = ((0.0f64, 0, 0.0), (0.0f64, 0, 0.0));
        t.command(Command::Notch(0));
        t.command(Command::AirBrake(1.0));
        let mut stopped = f64::NAN;
        t.run_alone(120.0, DT, &route, &mut |t| {
            t.coupling_forces_into(&mut f);
            for (j, &x) in f.iter().enumerate() {
                if x > tension.0 {
                    tension = (x, j, t.time());
                }
                if -x > compression.0 {
                    compression = (-x, j, t.time());
                }
            }
            if stopped.is_nan() && t.speed() < 0.1 {
                stopped = t.time();
            }
        });
        println!(
            "{name}: peak tension {:.0} kN at coupler {} ({:.2} of the length) at {:.1} s; peak compression {:.0} kN at coupler {} ({:.2}) at {:.1} s; stopped after {stopped:.1} s",
            tension.0 / 1e3,
            tension.1,
            tension.1 as f64 / (n - 1) as f64,
            tension.2,
            compression.0 / 1e3,
            compression.1,
            compression.1 as f64 / (n - 1) as f64,
            compression.2,
        );
        assert!(tension.0 < 2.25e6 && compression.0 < 2.25e6);
        assert!(stopped.is_finite());
    }
}

/// The step's cost for the 212 vehicles of a 20 000 t train.
#[test]
#[ignore = "release: a timing, meaningful only in an optimised build"]
fn a_212_vehicle_step_costs_a_few_microseconds() {
    let route = ConstantRoute {
        grade: 0.01,
        curvature: 1.0 / 800.0,
    };
    let mut t = Train::new(load("daqin_20kt"), WagonAt::File, 0.0, 60.0 * KMH, &route).unwrap();
    t.command(Command::AirBrake(0.5));
    let w = t.wagon_index();
    let (mut s, v) = (t.positions()[w], t.velocities()[w]);
    // the best of 40 rounds of 5 000 steps: the least disturbed by other work on the machine
    let mut per = f64::INFINITY;
    for _ in 0..40 {
        let start = std::time::Instant::now();
        for _ in 0..5_000 {
            s += DT * v;
            t.step_to(DT, s, v, &route);
            std::hint::black_box(t.coupler_forces());
        }
        per = per.min(start.elapsed().as_secs_f64() / 5_000.0);
    }
    println!("212 vehicles: {:.2} µs per step (best round)", per * 1e6);
    assert!(per < 20e-6, "{per}");
}

#[test]
fn builtin_paths_are_the_shipped_files() {
    for name in BUILTIN {
        let p: PathBuf = builtin_path(name).unwrap();
        assert!(p.ends_with(format!("vehicles/{name}.consist.toml")));
    }
}

/// Down a 20 ‰ grade the two HXD1's dynamic brakes cannot hold a loaded 20 000 t train at
/// 60 km/h: without the air brake it runs away; with the driver's cyclic air braking it stays
/// between the release and the application speeds (with the brake's lag as margin).
#[test]
fn cyclic_air_braking_holds_the_speed_down_a_long_grade() {
    let down = ConstantRoute {
        grade: -0.020,
        curvature: 0.0,
    };
    let v0 = 60.0 * KMH;
    let dt = 1.0 / 120.0;
    let run = |cyclic: bool| {
        let mut c = load("daqin_20kt");
        assert!(
            c.driver.cyclic.is_some(),
            "the built-in driver brakes cyclically"
        );
        if !cyclic {
            c.driver.cyclic = None;
        }
        let mut t = Train::new(c, WagonAt::File, 0.0, v0, &down).unwrap();
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        t.run_alone(300.0, dt, &down, &mut |t| {
            lo = lo.min(t.speed());
            hi = hi.max(t.speed());
        });
        (lo, hi, t.driver().applications())
    };
    let (_, hi, n) = run(false);
    assert!(
        hi > v0 + 10.0 * KMH && n == 0,
        "without the air brake: up to {} km/h",
        hi / KMH
    );
    let (lo, hi, n) = run(true);
    eprintln!(
        "down 20 ‰ at 60 km/h: {:.1}–{:.1} km/h over 300 s, {n} applications",
        lo / KMH,
        hi / KMH
    );
    assert!(n >= 1, "no application");
    assert!(
        hi < v0 + 12.0 * KMH && lo > v0 - 25.0 * KMH,
        "with cyclic braking: {:.1}–{:.1} km/h, {n} applications",
        lo / KMH,
        hi / KMH
    );
}
