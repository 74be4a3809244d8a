//! Wagons and tracks that vary (`[vary]` in plan files): a drawn value reaches the
//! simulation, the same seed draws the same wagon, no two runs share a draw, bad keys and
//! ranges are refused naming the plan key, and a varied data set is the same bytes twice.

use railforce::plan::Plan;
use railforce::vary::{Drawn, Draws, vehicle_for};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn plan() -> Plan {
    Plan::load(&root().join("tests/fixtures/plans/varied.plan.toml")).unwrap()
}

/// A plan with `vary` as its `[vary]` table, written next to the fixtures.
fn plan_with(vary: &str, name: &str) -> railforce::error::Result<Plan> {
    let dir = std::env::temp_dir().join(format!("railforce-vary-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let r = root();
    let text = format!(
        "vehicle = \"{}\"\nduration_s = 1.0\n[vary]\n{vary}\n[[condition]]\nname = \"t\"\ntrack = \"{}\"\nspeed_kmh = 60.0\n",
        r.join("vehicles/c80.toml").display(),
        r.join("tracks/tangent.toml").display()
    );
    let path = dir.join("p.plan.toml");
    std::fs::write(&path, text).unwrap();
    Plan::load(&path).and_then(|p| p.check_vary().map(|_| p))
}

/// The C80 as its file gives it, and the same wagon drawn 10 t heavier in the carbody.
fn nominal_and_heavier() -> (railforce::vehicle::Vehicle, railforce::vehicle::Vehicle) {
    let file = root().join("vehicles/c80.toml");
    let base = railforce::vehicle::Vehicle::load(&file).unwrap();
    let carbody = base
        .bodies
        .iter()
        .find(|b| b.name == "carbody")
        .unwrap()
        .mass;
    let mut draws = Draws::new();
    draws.insert(
        "vehicle.body.carbody.mass".into(),
        Drawn {
            value: toml::Value::Float(carbody + 10_000.0),
            scale: false,
        },
    );
    let heavy = vehicle_for(&file, &draws).unwrap();
    (base, heavy)
}

/// `v` standing still on `track` for `duration` s, no settling.
fn at_rest<'a>(
    v: &'a railforce::vehicle::Vehicle,
    track: &'a railforce::track::Track,
    duration: f64,
) -> railforce::sim::Simulation<'a> {
    let cfg = railforce::sim::SimConfig {
        speed: 0.0,
        duration,
        settle: 0.0,
        ..Default::default()
    };
    railforce::sim::Simulation::new(v, track, cfg).unwrap()
}

/// A heavier carbody raises every wheel's static load by its share: +10 t over 8 wheels is
/// +12.26 kN per wheel, within 0.5 %.
#[test]
fn a_heavier_draw_raises_the_static_wheel_load_by_its_share() {
    let (base, heavy) = nominal_and_heavier();
    let q = |v: &railforce::vehicle::Vehicle| {
        let s = railforce::sim::checks::static_loads(v, 1.0).unwrap();
        s.loads.iter().sum::<f64>() / s.loads.len() as f64
    };
    let rise = q(&heavy) - q(&base);
    let want = 10_000.0 * railforce::GRAVITY / 8.0;
    assert!((rise / want - 1.0).abs() < 0.005, "{rise} N vs {want} N");
}

/// The displacement gauges read from each element's unloaded state, so they see the load: at
/// rest a pad's vertical gauge reads its static compression, and +10 t on the carbody raises
/// it by the pad's share over its stiffness, 12.26 kN / k_z, within 2 % (a gauge zeroed on
/// the loaded wagon could not tell a part-loaded one).
#[test]
fn a_heavier_draw_compresses_every_pad_gauge_by_its_share() {
    use railforce::sim::checks::smooth_tangent;
    use railforce::vehicle::Element;
    let (base, heavy) = nominal_and_heavier();
    let track = smooth_tangent(200.0);
    // Each pad's (vertical gauge reading, stiffness) after 0.5 s at rest.
    let pads = |v: &railforce::vehicle::Vehicle| -> Vec<(f64, f64, f64)> {
        let mut sim = at_rest(v, &track, 0.5);
        for _ in 0..(0.5 / sim.config().dt).round() as usize {
            sim.step().unwrap();
        }
        sim.elements()
            .iter()
            .filter_map(|e| match e {
                Element::ShearPad(p) => Some((
                    e.deflection(sim.states()).unwrap().z,
                    e.static_deflection().z,
                    p.stiffness.z,
                )),
                _ => None,
            })
            .collect()
    };
    let (light, loaded) = (pads(&base), pads(&heavy));
    assert_eq!(light.len(), 8);
    let share = 10_000.0 * railforce::GRAVITY / 8.0;
    for (&(a, a0, k), &(b, _, _)) in light.iter().zip(&loaded) {
        assert!(
            a0 > 0.0 && (a / a0 - 1.0).abs() < 0.02,
            "at rest {a} m vs static {a0} m"
        );
        let want = share / k;
        assert!(
            ((b - a) / want - 1.0).abs() < 0.02,
            "rise {} m vs {want} m",
            b - a
        );
    }
}

/// The weighed mass (`vehicle_mass_t`) is recorded as the drawn wagon's total
/// mass, 10 t more for the heavier draw, and no noise model ever touches it (a known number,
/// not a sensor): the fleet's models may read the payload that no gauge can.
#[test]
fn the_weighed_mass_is_recorded_as_drawn_and_never_noised() {
    use railforce::sensors::{NoiseModel, SnrReference, VEHICLE_MASS};
    use railforce::sim::{Recorder, checks::smooth_tangent};
    let (base, heavy) = nominal_and_heavier();
    let track = smooth_tangent(200.0);
    let recorded = |v: &railforce::vehicle::Vehicle| -> Vec<f64> {
        let mut sim = at_rest(v, &track, 0.05);
        let mut rec = Recorder::new(&sim);
        let k = rec.names().iter().position(|n| n == VEHICLE_MASS).unwrap();
        assert_eq!(rec.units()[k], "t");
        let mut out = Vec::new();
        for _ in 0..50 {
            sim.step().unwrap();
            if let Some(row) = rec.sample(&mut sim) {
                out.push(row[k]);
            }
        }
        out
    };
    let (a, b) = (recorded(&base), recorded(&heavy));
    assert!(!a.is_empty());
    for (&x, &y) in a.iter().zip(&b) {
        assert!(
            (x - base.mass() * 1e-3).abs() < 1e-9,
            "{x} t vs {} t",
            base.mass() * 1e-3
        );
        assert!((y - x - 10.0).abs() < 1e-9, "{y} − {x} t");
    }
    for reference in [SnrReference::Std, SnrReference::Rms] {
        let m = NoiseModel::new(0.0, reference);
        assert_eq!(m.apply(&b, 7, VEHICLE_MASS), b);
        assert_eq!(m.sigma_of(&b, &format!("{VEHICLE_MASS}_noisy")), 0.0);
        assert!(m.apply(&b, 7, "carbody_acc_z") != b || reference == SnrReference::Std);
    }
}

/// The same condition and seed draw the same values; another seed or condition draws others;
/// the condition's own `[condition.vary]` adds its keys; scaled keys say so.
#[test]
fn the_same_seed_draws_the_same_wagon_and_no_two_runs_share_one() {
    let p = plan();
    let (t, c) = (&p.conditions[0], &p.conditions[1]);
    assert_eq!(t.vary.draw("tangent", 1), t.vary.draw("tangent", 1));
    let all: Vec<Draws> = [(t, 1), (t, 2), (c, 1), (c, 2)]
        .iter()
        .map(|(cond, seed)| cond.vary.draw(&cond.name, *seed))
        .collect();
    for i in 0..all.len() {
        for j in 0..i {
            assert_ne!(
                all[i]["vehicle.contact.friction"], all[j]["vehicle.contact.friction"],
                "runs {i} and {j} share a draw"
            );
        }
    }
    let d = &all[0];
    assert!(d["vehicle.body.carbody.mass"].scale);
    assert_eq!(
        d["vehicle.body.carbody.mass"], d["vehicle.body.carbody.inertia"],
        "with takes the same value"
    );
    assert!(!d.contains_key("track.irregularity.spectrum"));
    assert!(all[2].contains_key("track.irregularity.spectrum"));
    for d in &all {
        let f = d["vehicle.contact.friction"].value.as_float().unwrap();
        assert!((0.15..=0.5).contains(&f));
        let v = d["speed_kmh"].value.as_float().unwrap();
        assert!((55.0..=85.0).contains(&v), "normal truncated at ±3σ: {v}");
    }
    p.check_vary().unwrap();
}

/// A key that names nothing, a value the file's loader refuses at an end of the range, a body
/// that is not in the URDF and a list set without scale are refused before any run, naming the
/// plan key.
#[test]
fn bad_vary_keys_and_ranges_are_refused_naming_the_key() {
    for (vary, key, says) in [
        (
            "\"vehicle.contactt.friction\" = { uniform = [0.2, 0.4] }",
            "vehicle.contactt.friction",
            "no \"contactt\"",
        ),
        (
            "\"vehicle.contact.frictio\" = { uniform = [0.2, 0.4] }",
            "vehicle.contact.frictio",
            "frictio",
        ),
        (
            "\"vehicle.contact.friction\" = { uniform = [-0.1, 0.4] }",
            "vehicle.contact.friction",
            "outside the physical range of a friction coefficient",
        ),
        (
            "\"vehicle.body.payload.mass\" = { uniform = [1.0, 2.0] }",
            "vehicle.body.payload.mass",
            "no body \"payload\"",
        ),
        (
            "\"vehicle.shear_pad.stiffness\" = { uniform = [1e6, 2e6] }",
            "vehicle.shear_pad.stiffness",
            "scale it",
        ),
        (
            "\"track.irregularity.class\" = { one_of = [5, 9] }",
            "track.irregularity.class",
            "unknown FRA class 9",
        ),
        (
            "\"speed_kmh\" = { uniform = [150.0, 250.0] }",
            "speed_kmh",
            "outside (0, 200]",
        ),
        (
            "\"wagon.mass\" = { uniform = [1.0, 2.0] }",
            "wagon.mass",
            "a key starts with",
        ),
        (
            "\"vehicle.contact.friction\" = { uniform = [0.4, 0.2] }",
            "vehicle.contact.friction",
            "runs downwards",
        ),
    ] {
        let e = plan_with(vary, &key.replace('.', "_"))
            .err()
            .unwrap_or_else(|| panic!("{vary} was accepted"))
            .to_string();
        assert!(
            e.contains(&format!("vary.\"{key}\"")) && e.contains(says),
            "{vary}: {e}"
        );
    }
}

/// A varied data set: every run's draws in the manifest, the drawn speed as its speed, and the
/// same bytes when generated again.
#[test]
fn a_varied_data_set_records_its_draws_and_repeats_byte_for_byte() {
    let out =
        |k: u32| std::env::temp_dir().join(format!("railforce-varied-{}-{k}", std::process::id()));
    for k in [1, 2] {
        let o = out(k);
        let _ = std::fs::remove_dir_all(&o);
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
            .args(["generate", "--plan"])
            .arg(root().join("tests/fixtures/plans/varied.plan.toml"))
            .args(["--format", "csv", "--out"])
            .arg(&o)
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
    }
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out(1).join("manifest.json")).unwrap())
            .unwrap();
    let runs = m["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 4);
    for r in runs {
        let d = &r["draws"];
        assert!(d["vehicle.contact.friction"].is_number(), "{r}");
        assert!(d["vehicle.body.carbody.mass"]["scale"].is_number(), "{r}");
        assert_eq!(r["speed_kmh"], d["speed_kmh"]);
        let file = r["file"].as_str().unwrap();
        let a = std::fs::read(out(1).join(file)).unwrap();
        let b = std::fs::read(out(2).join(file)).unwrap();
        assert!(a == b, "{file} differs between two generations");
    }
    for k in [1, 2] {
        let _ = std::fs::remove_dir_all(out(k));
    }
    let _ = Path::new("");
}

/// A fleet's wagons share their contact table where their wheelset geometry is the same bit
/// for bit (a heavier carbody, another friction) and get their own where it is not (another
/// flange back): a table is built once per geometry, not once per drawn wagon.
#[test]
fn drawn_wagons_share_the_contact_table_of_their_geometry() {
    let (base, heavy) = nominal_and_heavier();
    assert!(std::ptr::eq(base.contact.table(), heavy.contact.table()));
    let mut draws = Draws::new();
    draws.insert(
        "vehicle.contact.flange_back_m".into(),
        Drawn {
            value: toml::Value::Float(1.360),
            scale: false,
        },
    );
    let other = vehicle_for(&root().join("vehicles/c80.toml"), &draws).unwrap();
    assert_ne!(
        other.contact.geometry.flange_back,
        base.contact.geometry.flange_back
    );
    let t = other.contact.table();
    assert!(!std::ptr::eq(base.contact.table(), t));
    // The other flange back moves the flange contact: the tables differ, not just their
    // addresses.
    assert_ne!(
        format!("{:?}", t.states().last().map(|s| s.wheels[0].wheel_y)),
        format!(
            "{:?}",
            base.contact
                .table()
                .states()
                .last()
                .map(|s| s.wheels[0].wheel_y)
        )
    );
}
