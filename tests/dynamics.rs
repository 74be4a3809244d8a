//! Vehicle files and the simulator: static equilibrium, reproducibility, failure detection,
//! and (ignored, run by CI in release) quasi-static curving and Klingel's wavelength.

use railforce::sim::{SimConfig, Simulation, checks, output};
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::{Element, Vehicle};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The C80, loaded once per test binary (its contact table is built on first use).
fn c80() -> &'static Vehicle {
    static V: OnceLock<Vehicle> = OnceLock::new();
    V.get_or_init(|| Vehicle::load(&root().join("vehicles/c80.toml")).unwrap())
}

#[test]
fn c80_has_eleven_bodies_of_100_t_and_its_elements() {
    let v = c80();
    assert_eq!(v.bodies.len(), 11);
    assert!((v.mass() - 100_000.0).abs() < 1e-6);
    let count = |k: &str| v.elements.iter().filter(|e| e.kind() == k).count();
    assert_eq!(count("shear_pad"), 8);
    assert_eq!(count("spring_nest"), 4);
    assert_eq!(count("wedge_damper"), 4);
    assert_eq!(count("centre_plate"), 2);
    assert_eq!(count("side_bearer"), 4);
    assert_eq!(count("cross_bracing"), 2);
    // The static load path: pads carry everything above the wheelsets.
    let pads: f64 = v
        .elements
        .iter()
        .filter_map(|e| match e {
            Element::ShearPad(p) => Some(p.preload),
            _ => None,
        })
        .sum();
    let above_wheelsets = (100_000.0 - 4.0 * 1300.0) * railforce::GRAVITY;
    assert!((pads / above_wheelsets - 1.0).abs() < 1e-12);
    // What the URDF says arrives unchanged: joint origins place the bodies, inertials give
    // mass and principal moments.
    let ws1 = &v.bodies[v.body_index("wheelset1").unwrap()];
    assert_eq!(ws1.position, nalgebra::Vector3::new(5.015, 0.0, 0.42));
    assert_eq!(ws1.mass, 1300.0);
    let b1 = &v.bodies[v.body_index("bolster1").unwrap()];
    assert_eq!(b1.inertia, nalgebra::Vector3::new(200.0, 50.0, 200.0));
    let sf = &v.bodies[v.body_index("sideframe2r").unwrap()];
    assert_eq!(sf.position, nalgebra::Vector3::new(-4.1, -0.978, 0.45));
    assert_eq!(v.contact.wheelsets.len(), 4);
    assert!(v.sensors.is_some() && v.hauling.is_some());
}

#[test]
fn static_equilibrium_each_wheel_carries_an_eighth() {
    let st = checks::static_loads(c80(), 0.5).unwrap();
    assert!((st.expected - 122_625.0).abs() < 1.0);
    for (k, q) in st.loads.iter().enumerate() {
        assert!((q / st.expected - 1.0).abs() < 0.01, "wheel {k}: {q} N");
    }
    assert!(
        (st.sum_ratio - 1.0).abs() < 1e-3,
        "ΣQ/Mg = {}",
        st.sum_ratio
    );
}

#[test]
fn same_seed_same_bytes_and_labels_written() {
    let dir = std::env::temp_dir().join(format!("railforce-sim-{}", std::process::id()));
    let track = |seed| {
        Track::new(
            TrackSpec::load(&root().join("tracks/tangent.toml")).unwrap(),
            Some(seed),
        )
    };
    let run = |seed: u64, name: &str| {
        let t = track(seed);
        let cfg = SimConfig {
            speed: 80.0 / 3.6,
            duration: 0.5,
            settle: 0.2,
            ..SimConfig::default()
        };
        let mut sim = Simulation::new(c80(), &t, cfg).unwrap();
        let out = dir.join(name);
        let summary =
            output::run_to_csv(&mut sim, &out, &serde_json::json!({"seed": seed}), |_| {}).unwrap();
        assert_eq!(summary.rows, 101, "0.5 s at 200 Hz, both ends");
        std::fs::read(out).unwrap()
    };
    let (a, b, c) = (run(3, "a.csv"), run(3, "b.csv"), run(4, "c.csv"));
    assert_eq!(a, b, "same seed, same bytes");
    assert_ne!(a, c, "another seed, other irregularities");
    let text = String::from_utf8(a).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    for name in [
        "frame_l_acc_y",
        "w1l_creep_spin",
        "w1l_force_y",
        "w1l_force_z",
        "w4r_force_z",
        "carbody_acc_z",
    ] {
        assert!(header.contains(&name), "missing {name}");
    }
    let unique: std::collections::HashSet<&&str> = header.iter().collect();
    assert_eq!(unique.len(), header.len(), "column names are unique");
    let meta = std::fs::read_to_string(dir.join("a.meta.json")).unwrap();
    assert!(meta.contains("\"channels\"") && meta.contains("w1l_force_z"));
    // Every value is finite and the vertical label is near the static load.
    let idx = header.iter().position(|h| *h == "w1l_force_z").unwrap();
    for line in text.lines().skip(1) {
        let vals: Vec<f64> = line.split(',').map(|v| v.parse().unwrap()).collect();
        assert!(vals.iter().all(|v| v.is_finite()));
        assert!(vals[idx] > 60e3 && vals[idx] < 200e3, "Q1L {}", vals[idx]);
    }
}

#[test]
fn too_short_a_track_is_refused_before_running() {
    let t = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let cfg = SimConfig {
        speed: 100.0 / 3.6,
        duration: 100.0,
        ..SimConfig::default()
    };
    let err = Simulation::new(c80(), &t, cfg).err().unwrap().to_string();
    assert!(err.contains("tangent") && err.contains("m long"), "{err}");
}

#[test]
fn flange_climb_is_reported_as_derailment() {
    // A free wheelset started 40 mm off centre rides on its flange at once.
    let w = Vehicle::load(&root().join("vehicles/single_wheelset.toml")).unwrap();
    let track = Track::new(
        TrackSpec::parse(
            "[[section]]\nkind = \"tangent\"\nlength_m = 300\n",
            Path::new("flat.toml"),
        )
        .unwrap(),
        None,
    );
    let cfg = SimConfig {
        speed: 10.0,
        duration: 5.0,
        settle: 0.0,
        initial_offset: 0.034,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(&w, &track, cfg).unwrap();
    let mut err = None;
    for _ in 0..25_000 {
        if let Err(e) = sim.step() {
            err = Some(e.to_string());
            break;
        }
    }
    let err = err.expect("a derailment is detected");
    assert!(err.contains("derail") && err.contains("wheel 1"), "{err}");
}

#[test]
fn nadal_limit_of_the_spec() {
    let cfg = SimConfig::default();
    assert!((cfg.nadal_limit(0.3) - 1.342).abs() < 1e-3);
}

fn write_vehicle(
    name: &str,
    toml_edit: impl Fn(String) -> String,
    urdf_edit: impl Fn(String) -> String,
) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("railforce-veh-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = std::fs::read_to_string(root().join("vehicles/c80.toml")).unwrap();
    let urdf = std::fs::read_to_string(root().join("vehicles/c80.urdf")).unwrap();
    std::fs::write(dir.join("c80.urdf"), urdf_edit(urdf)).unwrap();
    let path = dir.join("c80.toml");
    std::fs::write(&path, toml_edit(toml)).unwrap();
    path
}

#[test]
fn bad_vehicle_files_name_file_and_element() {
    let id = |s: String| s;
    let cases: Vec<(PathBuf, &str)> = vec![
        (
            write_vehicle(
                "link",
                |t| t.replacen("lower = \"wheelset1\"", "lower = \"wheelset9\"", 1),
                id,
            ),
            "shear_pad[0].lower: unknown link \"wheelset9\"",
        ),
        (
            write_vehicle(
                "stiff",
                |t| t.replacen("stiffness = [10.0e6,", "stiffness = [-10.0e6,", 1),
                id,
            ),
            "shear_pad[0].stiffness[0]: must be positive",
        ),
        (
            write_vehicle("mass", id, |u| {
                u.replacen("<mass value=\"650.0\"/>", "<mass value=\"-650.0\"/>", 1)
            }),
            "link \"bolster1\".mass: must be positive",
        ),
        (
            write_vehicle("inertia", id, |u| {
                u.replacen("iyy=\"50.0\"", "iyy=\"0\"", 1)
            }),
            "link \"bolster1\".inertia.iyy: must be positive",
        ),
        (
            write_vehicle(
                "key",
                |t| t.replacen("[hauling]", "[hauling]\ngain = 3", 1),
                id,
            ),
            "unknown field",
        ),
        (
            write_vehicle(
                "law",
                |t| t.replacen("creep_law = \"polach\"", "creep_law = \"magic\"", 1),
                id,
            ),
            "contact.creep_law",
        ),
        (
            write_vehicle(
                "accelerometers",
                |t| {
                    t.replacen(
                        "accelerometers = \"specific-force\"",
                        "accelerometers = \"piezo\"",
                        1,
                    )
                },
                id,
            ),
            "accelerometers",
        ),
    ];
    for (path, want) in cases {
        let e = Vehicle::load(&path).unwrap_err().to_string();
        assert!(e.contains(want), "expected '{want}' in: {e}");
        assert!(
            e.contains("c80.toml") || e.contains("c80.urdf"),
            "no file named: {e}"
        );
    }
}

/// The two accelerometer readings differ by gravity only: the same motion (the sensor model
/// does not touch the dynamics), and at every row and body the vector between the specific
/// force and the kinematic acceleration is g in length, pointing up in a level body.
#[test]
fn accelerometers_read_specific_force_or_kinematic_acceleration() {
    use railforce::vehicle::Accelerometers;
    let track = Track::new(
        TrackSpec::load(&root().join("tracks/tangent.toml")).unwrap(),
        Some(2),
    );
    let record = |a: Accelerometers| {
        let mut v = c80().clone();
        v.accelerometers = a;
        let cfg = SimConfig {
            speed: 60.0 / 3.6,
            duration: 0.2,
            settle: 0.2,
            ..SimConfig::default()
        };
        let mut sim = Simulation::new(&v, &track, cfg).unwrap();
        output::record(&mut sim, |_| {}).unwrap()
    };
    assert_eq!(c80().accelerometers, Accelerometers::SpecificForce);
    let (sf, kin) = (
        record(Accelerometers::SpecificForce),
        record(Accelerometers::Kinematic),
    );
    assert_eq!(sf.names, kin.names);
    let col = |n: &str| sf.names.iter().position(|c| c == n).unwrap();
    for (i, name) in sf.names.iter().enumerate() {
        if !name.contains("acc_") {
            for (a, b) in sf.rows.iter().zip(&kin.rows) {
                assert_eq!(a[i], b[i], "{name} depends on the accelerometer model");
            }
        }
    }
    for b in &c80().bodies {
        let c = [
            col(&format!("{}_acc_x", b.name)),
            col(&format!("{}_acc_y", b.name)),
            col(&format!("{}_acc_z", b.name)),
        ];
        for (a, k) in sf.rows.iter().zip(&kin.rows) {
            let d: Vec<f64> = c.iter().map(|&i| a[i] - k[i]).collect();
            let norm = d.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((norm / railforce::GRAVITY - 1.0).abs() < 1e-3, "{}", b.name);
            assert!(d[2] > 0.999 * railforce::GRAVITY, "{} reads g up", b.name);
        }
    }
    // The run's peak |Y/Q| of each wheel is its recorded Y over Q wherever the wheel carries
    // a tenth of its static load, read by the channels' names (every wheel, not the first
    // wheel's columns and a fixed stride), and small on a tangent.
    let static_load = c80().mass() * railforce::GRAVITY / 8.0;
    for (k, &peak) in sf.summary.peak_y_over_q.iter().enumerate() {
        let w = railforce::sim::wheel_name(k).to_ascii_lowercase();
        let (y, q) = (col(&format!("w{w}_force_y")), col(&format!("w{w}_force_z")));
        let expected = (sf.rows.iter())
            .filter(|r| r[q] > 0.1 * static_load)
            .map(|r| (r[y] / r[q]).abs())
            .fold(0.0, f64::max);
        assert_eq!(peak, expected, "wheel {w}");
        assert!(
            expected > 0.0 && expected < 0.3,
            "wheel {w}: Y/Q {expected}"
        );
    }
}

/// Quasi-static curving within 3 % of Newton's law (release: `cargo test --release -- --ignored`).
#[test]
#[ignore = "long simulation: run in release"]
fn quasi_static_curving_matches_newton() {
    for (file, kmh) in [
        ("tracks/curve_r400.toml", 60.0),
        ("tracks/curve_r800.toml", 100.0),
    ] {
        let track = checks::with_class(&root().join(file), 6).unwrap();
        let c = checks::curving(c80(), &track, kmh / 3.6, 250.0).unwrap();
        assert!(c.samples > 1000);
        assert!(
            ((c.sum_y - c.expected_y) / c.expected_y).abs() < 0.03,
            "{file}: ΣY {} vs {}",
            c.sum_y,
            c.expected_y
        );
        assert!((c.sum_q / c.expected_q - 1.0).abs() < 0.005);
        let a_nc = (kmh / 3.6f64).powi(2) / c.radius - railforce::GRAVITY * c.cant_angle.tan();
        assert_eq!(c.outer_inner_q.0 > c.outer_inner_q.1, a_nc > 0.0);
    }
}

/// Klingel's wavelength of a free wheelset on 1:40 cones within 1 %.
#[test]
#[ignore = "long simulation: run in release"]
fn free_wheelset_klingel_wavelength() {
    let w = Vehicle::load(&root().join("vehicles/single_wheelset.toml")).unwrap();
    let k = checks::klingel(&w, 5.0, 2e-3, 4).unwrap();
    assert!(
        (k.measured / k.expected - 1.0).abs() < 0.01,
        "{} m vs {} m",
        k.measured,
        k.expected
    );
}

/// Tangent track at 100 km/h with FRA class 5 irregularities: a full 60 s run stays on the
/// rails, keeps |Y/Q| far below Nadal and the wheelsets within the flangeway.
#[test]
#[ignore = "long simulation: run in release"]
fn tangent_100_kmh_class_5_runs_without_derailment() {
    let track = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let cfg = SimConfig {
        speed: 100.0 / 3.6,
        duration: 60.0,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(c80(), &track, cfg).unwrap();
    sim.settle().unwrap();
    let steps = (60.0 / sim.config().dt) as usize;
    // Y/Q over 10 ms means (the impacts of single steps are not what Nadal's limit is for).
    let mut peak_yq: f64 = 0.0;
    let mut sums = vec![(0.0, 0.0); sim.wheels.len()];
    for i in 0..steps {
        sim.step().unwrap();
        for (s, w) in sums.iter_mut().zip(&sim.wheels) {
            s.0 += w.y;
            s.1 += w.q;
        }
        if (i + 1) % 50 == 0 {
            for s in &mut sums {
                if s.1 > 50.0 * 20e3 {
                    peak_yq = peak_yq.max((s.0 / s.1).abs());
                }
                *s = (0.0, 0.0);
            }
        }
    }
    assert!(peak_yq < 0.8, "peak |Y/Q| {peak_yq}");
}

/// Wickens' critical speed of a restrained wheelset within 5 %.
#[test]
#[ignore = "long simulation: run in release"]
fn restrained_wheelset_wickens_critical_speed() {
    let w = Vehicle::load(&root().join("vehicles/restrained_wheelset.toml")).unwrap();
    let k = checks::wickens(&w).unwrap();
    assert!(
        (k.measured / k.expected - 1.0).abs() < 0.05,
        "{} m/s vs {} m/s",
        k.measured,
        k.expected
    );
}

/// The step profile: off by default; on, it counts every step and names every part (the
/// patch solve eight times a step), and leaves the motion exactly as an unprofiled run's; the
/// element costs name every kind with its count.
#[test]
fn a_profiled_step_names_its_parts_and_changes_nothing() {
    let t = Track::new(
        TrackSpec::load(&root().join("tracks/tangent.toml")).unwrap(),
        Some(2),
    );
    let cfg = SimConfig {
        speed: 80.0 / 3.6,
        duration: 0.1,
        settle: 0.0,
        ..SimConfig::default()
    };
    let mut plain = Simulation::new(c80(), &t, cfg.clone()).unwrap();
    let mut profiled = Simulation::new(c80(), &t, cfg).unwrap();
    assert!(plain.profile().is_none());
    profiled.set_profiling(true);
    for _ in 0..200 {
        plain.step().unwrap();
        profiled.step().unwrap();
    }
    assert_eq!(
        plain.states(),
        profiled.states(),
        "profiling changes no number"
    );
    let p = profiled.profile().unwrap();
    assert_eq!(p.steps, 200);
    let parts = p.per_step(0.0);
    for (name, calls) in [
        ("force elements", 1.0),
        ("contact (8 wheels)", 1.0),
        ("  of which the patch solve (8 wheels)", 8.0),
        ("integration (11 bodies)", 1.0),
        ("checks", 1.0),
    ] {
        let part = parts.iter().find(|q| q.0 == name).expect(name);
        assert_eq!(part.2, calls, "{name}");
        assert!(part.1 >= 0.0 && part.1.is_finite());
    }
    let kinds = profiled.element_costs(10);
    let pads = kinds.iter().find(|k| k.0 == "shear_pad").unwrap();
    assert_eq!(pads.1, 8, "eight axle-box pads");
    assert_eq!(
        kinds.iter().map(|k| k.1).sum::<usize>(),
        c80().elements.len()
    );
}

/// A derailment risk (|Y/Q| above Nadal's limit for 50 ms; the limit set low here, flange
/// angle 22°, so a wheel's steady curving Y/Q in R 400 m holds it) stops a run by
/// default and is only reported where the config says so, as data generation does: the run
/// then finishes with every row finite.
#[test]
fn a_derailment_risk_stops_a_run_only_when_asked() {
    // Smooth rails, so the run may start in the circular curve.
    let mut spec = TrackSpec::load(&root().join("tracks/curve_r400.toml")).unwrap();
    spec.irregularity = None;
    let track = Track::new(spec, None);
    let cfg = |stop| SimConfig {
        speed: 60.0 / 3.6,
        duration: 0.3,
        settle: 0.3,
        start: Some(500.0),
        nadal_angle: Some(22f64.to_radians()),
        stop_on_derailment_risk: stop,
        ..SimConfig::default()
    };
    let run = |stop| {
        let mut sim = Simulation::new(c80(), &track, cfg(stop)).unwrap();
        output::record(&mut sim, |_| {})
    };
    let err = run(true).unwrap_err().to_string();
    assert!(err.contains("derailment risk"), "{err}");
    let rec = run(false).unwrap();
    assert!(rec.rows.len() >= 60 && rec.rows.iter().flatten().all(|x| x.is_finite()));
}
