//! Conditions as a line has them: curves both ways, a lubricated gauge face, the regulation's
//! cant, and what a derailing run does to a data set; and the revised elements' file keys
//! refused as their loaders promise.

use railforce::contact::{GAUGE_FACE_ANGLE, Side, WheelOnRail, evaluate, height_for_load};
use railforce::dataset::{self, DataSet, Format, GenerateOptions};
use railforce::plan::Plan;
use railforce::vehicle::Vehicle;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("railforce-line-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn opts(out: &Path) -> GenerateOptions {
    GenerateOptions {
        out: out.to_path_buf(),
        format: Format::Npz,
        jobs: 2,
        shard: None,
        noise: None,
        settle: 1.0,
        stepping: Default::default(),
    }
}

/// A smooth right-hand curve R 400 m with 60 mm of cant (46 mm short of balance at 60 km/h),
/// entered straight from a short tangent.
const CURVE: &str = r#"name = "r400"
description = "smooth right-hand curve"
rail_spacing_m = 1.5
gauge_m = 1.435
[[section]]
kind = "tangent"
length_m = 20.0
[[section]]
kind = "curve"
length_m = 400.0
radius_m = 400.0
cant_mm = 60.0
direction = "right"
"#;

fn plan(dir: &Path, top: &str, conditions: &str) -> Plan {
    std::fs::write(dir.join("r400.toml"), CURVE).unwrap();
    std::fs::write(dir.join("tangent.toml"), CURVE.replace("kind = \"curve\"\nlength_m = 400.0\nradius_m = 400.0\ncant_mm = 60.0\ndirection = \"right\"", "kind = \"tangent\"\nlength_m = 400.0")).unwrap();
    let text = format!(
        "name = \"line\"\nvehicle = \"{}\"\nduration_s = 0.5\nseeds = [1, 2]\n{top}\n{conditions}",
        root().join("vehicles/c80.toml").display()
    );
    let p = dir.join("line.plan.toml");
    std::fs::write(&p, text).unwrap();
    Plan::load(&p).unwrap()
}

fn mean(ds: &DataSet, run: usize, channel: &str) -> f64 {
    let c = &ds.runs[run].columns[ds.channel(channel).unwrap()];
    c.iter().sum::<f64>() / c.len() as f64
}

/// `turn = "both"`: the curve condition (second in the plan) runs its first seed mirrored
/// and its second as drawn; the manifest says which; and the physics turns with it: short of
/// balance the outer wheel carries more, so wheel 1L is the heavier of the leading pair in
/// the right-hand run and the lighter in the mirrored one.
#[test]
fn curves_run_both_ways_and_the_outer_wheel_follows() {
    let dir = temp("turn");
    let p = plan(
        &dir,
        "turn = \"both\"",
        "[[condition]]\nname = \"a_tangent\"\ntrack = \"tangent.toml\"\nspeed_kmh = 60.0\nseeds = [1]\n\
         [[condition]]\nname = \"b_curve\"\ntrack = \"r400.toml\"\nspeed_kmh = 60.0\nstart_m = 150.0\n",
    );
    let out = dir.join("out");
    let m = dataset::generate(&p, &opts(&out), &|_| {}).unwrap();
    let mirrored: Vec<(String, u64, bool)> = m
        .runs
        .iter()
        .map(|r| (r.condition.clone(), r.seed, r.mirrored))
        .collect();
    assert_eq!(
        mirrored,
        vec![
            ("a_tangent".into(), 1, false), // a tangent is its own mirror image
            ("b_curve".into(), 1, true),
            ("b_curve".into(), 2, false),
        ]
    );
    let ds = DataSet::load(&out).unwrap();
    let idx = |seed: u64| {
        ds.runs
            .iter()
            .position(|r| r.condition == "b_curve" && r.seed == seed)
            .unwrap()
    };
    let (left, right) = (idx(1), idx(2));
    let dq = |run| mean(&ds, run, "w1l_force_z") - mean(&ds, run, "w1r_force_z");
    assert!(dq(right) > 3e3, "right-hand: 1L outer, ΔQ {}", dq(right));
    assert!(dq(left) < -3e3, "mirrored: 1L inner, ΔQ {}", dq(left));
    // Mirror images: the same load transfer either way, within the irregularity-free
    // model's asymmetries (wagon and profiles are symmetric).
    assert!(
        (dq(right) + dq(left)).abs() < 0.05 * dq(right),
        "{} {}",
        dq(right),
        dq(left)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A plan's `derailed = "drop"` leaves a derailing run out and lists it in the manifest with
/// where it left the rail; without it the generation stops, naming the run.
#[test]
fn a_derailing_run_is_dropped_where_the_plan_says_so() {
    let dir = temp("derail");
    // R 150 m without cant at 110 km/h: 6.2 m/s² unbalanced, far past any wagon's grip.
    let sharp = CURVE
        .replace("radius_m = 400.0", "radius_m = 150.0")
        .replace("cant_mm = 60.0", "cant_mm = 0.0");
    let conditions = "[[condition]]\nname = \"fast\"\ntrack = \"sharp.toml\"\nspeed_kmh = 110.0\nseeds = [1]\nduration_s = 2.0\n";
    std::fs::write(dir.join("sharp.toml"), &sharp).unwrap();
    let p = plan(&dir, "derailed = \"drop\"", conditions);
    let out = dir.join("out");
    let m = dataset::generate(&p, &opts(&out), &|_| {}).unwrap();
    assert!(m.runs.is_empty());
    assert_eq!(m.dropped.len(), 1);
    assert!(
        m.dropped[0].reason.contains("derailment at t ="),
        "{:?}",
        m.dropped[0]
    );
    assert!(!out.join("fast_seed1.npz").exists());
    let text = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(text.contains("\"dropped\""));
    let p = plan(&dir, "", conditions);
    let e = dataset::generate(&p, &opts(&dir.join("out2")), &|_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("fast (seed 1)") && e.contains("derailment"),
        "{e}"
    );
    // Anything else is refused, naming the key.
    std::fs::write(
        dir.join("bad.plan.toml"),
        format!(
            "vehicle = \"{}\"\nduration_s = 1.0\nderailed = \"ignore\"\n[[condition]]\nname = \"c\"\ntrack = \"sharp.toml\"\nspeed_kmh = 60.0\n",
            root().join("vehicles/c80.toml").display()
        ),
    )
    .unwrap();
    let e = Plan::load(&dir.join("bad.plan.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("derailed") && e.contains("drop"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `gauge_face = "lubricated"` gives the condition's wagon the lubricated flange friction,
/// and the contact uses it on the gauge face only: a wheel hard on its flange and yawed so
/// both patches slide keeps the tread patch's friction and carries no more than 0.15·N on
/// the flange patch.
#[test]
fn a_lubricated_gauge_face_lowers_the_flange_patch_friction_only() {
    let dir = temp("gauge");
    let p = plan(
        &dir,
        "",
        "[[condition]]\nname = \"c\"\ntrack = \"r400.toml\"\nspeed_kmh = 60.0\ngauge_face = \"lubricated\"\n",
    );
    assert_eq!(
        p.conditions[0].flange_friction,
        Some(railforce::plan::LUBRICATED_GAUGE_FACE)
    );
    let bad = std::fs::read_to_string(dir.join("line.plan.toml"))
        .unwrap()
        .replace("\"lubricated\"", "\"greasy\"");
    std::fs::write(dir.join("bad.plan.toml"), bad).unwrap();
    let e = Plan::load(&dir.join("bad.plan.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("gauge_face") && e.contains("lubricated"), "{e}");

    let v = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let table = v.contact.table();
    let geo = &v.contact.geometry;
    let patches = |flange_mu: f64, y: f64| {
        let model = railforce::contact::ContactModel {
            flange_friction: flange_mu,
            ..v.contact.model()
        };
        let mut w = WheelOnRail::rolling(Side::Left, 16.7, geo.nominal_radius, 0.0, 650.0);
        w.y = y;
        w.roll = table.lookup(w.y).roll;
        w.yaw = 0.05;
        w.height = height_for_load(table, &model, &w, 122.6e3);
        evaluate(table, &model, &w)
            .patches
            .into_iter()
            .flatten()
            .map(|p| (p.angle.abs(), p.normal, p.creep.x.hypot(p.creep.y)))
            .collect::<Vec<_>>()
    };
    // One patch on the tread (8 mm towards the flange, 9°) and one on the gauge face
    // (10.5 mm, 64°), each yawed so it slides.
    let one = |mu: f64, y: f64| {
        let ps = patches(mu, y);
        assert_eq!(ps.len(), 1, "{ps:?}");
        ps[0]
    };
    let (tread_dry, tread_lub) = (one(0.3, 8e-3), one(0.15, 8e-3));
    assert!(tread_dry.0 < GAUGE_FACE_ANGLE);
    assert_eq!(tread_dry, tread_lub, "the tread keeps its friction");
    let (fd, fl) = (one(0.3, 10.5e-3), one(0.15, 10.5e-3));
    assert!(fd.0 > GAUGE_FACE_ANGLE);
    // Saturated on the flange: no more than the friction allows (it falls with the slip
    // velocity under Polach 2005, so below 0.15·N), and well below the dry patch's.
    assert!(
        fl.2 <= 0.15 * fl.1 * 1.001,
        "lubricated flange patch {fl:?}"
    );
    assert!(
        fd.2 / fd.1 > 1.2 * fl.2 / fl.1,
        "dry {fd:?} vs lubricated {fl:?}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The shipped conditions keep to the regulation: no curve carries more than 150 mm of cant,
/// and conditions.md states each curve condition's excess or deficiency as
/// `11.8·V²/R − h`, rounded to the millimetre.
#[test]
fn cants_keep_to_the_regulation_and_their_balance_is_stated() {
    let doc = std::fs::read_to_string(root().join("assets/docs/conditions.md")).unwrap();
    let plan = Plan::load(&root().join("tracks/paper34.plan.toml")).unwrap();
    let mut stated = 0;
    for c in &plan.conditions {
        let spec = railforce::track::TrackSpec::load(&c.track).unwrap();
        for s in &spec.sections {
            if let railforce::track::SectionKind::Curve { radius, cant, .. } = s.kind {
                assert!(cant <= 0.150 + 1e-9, "{}: cant {cant} m", c.name);
                if c.name.starts_with("curve_") {
                    // `+ 0.0` turns a rounded −0 into +0.
                    let balance = (11.8 * c.speed_kmh.powi(2) / radius - cant * 1e3).round() + 0.0;
                    let row = format!(
                        "| {} | {:.0} | {:.0} | {:+.0} |",
                        c.name,
                        radius,
                        cant * 1e3,
                        balance
                    );
                    assert!(doc.contains(&row), "conditions.md lacks the row {row}");
                    stated += 1;
                }
            }
        }
    }
    assert_eq!(stated, 15);
}

/// The revised elements' keys are refused as their loaders promise, naming the file and key.
#[test]
fn revised_element_keys_are_checked() {
    let text = std::fs::read_to_string(root().join("vehicles/c80.toml")).unwrap();
    let dir = temp("keys");
    std::fs::copy(root().join("vehicles/c80.urdf"), dir.join("c80.urdf")).unwrap();
    let refuse = |edit: &dyn Fn(&str) -> String, key: &str, why: &str| {
        let p = dir.join("v.toml");
        std::fs::write(&p, edit(&text)).unwrap();
        let e = Vehicle::load(&p).unwrap_err().to_string();
        assert!(e.contains(key) && e.contains(why), "{key}: {e}");
    };
    refuse(
        &|t| t.replacen("statics = \"two_face\"", "statics = \"three_face\"", 1),
        "statics",
        "two_face",
    );
    refuse(
        &|t| t.replacen("statics = \"two_face\"", "statics = \"one_face\"", 1),
        "slope_friction",
        "frictionless slope",
    );
    refuse(
        &|t| t.replacen("slope_friction = 0.33", "slope_friction = 1.5", 1),
        "slope_friction",
        "locks the wedge",
    );
    refuse(
        &|t| {
            t.replacen(
                "loss_factor = [0.1, 0.1, 0.1]",
                "loss_factor = [0.1, 1.5, 0.1]",
                1,
            )
        },
        "loss_factor",
        "(0, 1)",
    );
    refuse(
        &|t| {
            t.replacen(
                "loss_factor = [0.1, 0.1, 0.1]",
                "loss_factor = [0.1, 0.1, 0.1]\ndamping = [1.0, 1.0, 1.0]",
                1,
            )
        },
        "loss_factor",
        "not both",
    );
    refuse(
        &|t| t.replacen("staging = \"potential\"", "staging = \"smooth\"", 1),
        "staging",
        "potential",
    );
    refuse(
        &|t| t.replacen("ks = 0.4", "ks = 1.2", 1),
        "contact.polach.ka",
        "ks ≤ ka",
    );
    refuse(
        &|t| t.replacen("creep_law = \"polach\"", "creep_law = \"fastsim\"", 1),
        "contact.polach",
        "creep_law = \"polach\"",
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The plan key `rail_support`: the plan's for every condition, a condition's own over it; a
/// data set of the curve on sleepers generates (at 0.2 ms, the step on sleepers) with the
/// wagon's weight on its wheels; a lumped track asked of a file without one, or an unknown
/// model, is refused naming the key.
#[test]
fn a_plan_puts_its_runs_on_sleepers() {
    let dir = temp("sleepers");
    let conditions = "[[condition]]\nname = \"c\"\ntrack = \"r400.toml\"\nspeed_kmh = 60.0\nstart_m = 150.0\nseeds = [1]\n\
         [[condition]]\nname = \"d\"\ntrack = \"r400.toml\"\nspeed_kmh = 60.0\nstart_m = 150.0\nseeds = [1]\nrail_support = \"rigid\"\n";
    let p = plan(&dir, "rail_support = \"discrete\"", conditions);
    assert_eq!(p.conditions[0].rail_support.as_deref(), Some("discrete"));
    assert_eq!(p.conditions[1].rail_support.as_deref(), Some("rigid"));
    let out = dir.join("out");
    let m = dataset::generate(&p, &opts(&out), &|_| {}).unwrap();
    assert_eq!(m.runs.len(), 2);
    let ds = DataSet::load(&out).unwrap();
    let q: f64 = ["w1l_force_z", "w1r_force_z", "w2l_force_z", "w2r_force_z"]
        .iter()
        .map(|c| mean(&ds, 0, c))
        .sum();
    let weight = Vehicle::load(&root().join("vehicles/c80.toml"))
        .unwrap()
        .mass()
        * 9.81
        / 2.0;
    assert!((q / weight - 1.0).abs() < 0.05, "{q} N against {weight} N");
    let p = plan(
        &dir,
        "rail_support = \"lumped\"",
        conditions
            .split("[[condition]]\nname = \"d\"")
            .next()
            .unwrap(),
    );
    let e = dataset::generate(&p, &opts(&dir.join("out2")), &|_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("c.rail_support") && e.contains("no lumped"),
        "{e}"
    );
    std::fs::write(
        dir.join("bad.plan.toml"),
        std::fs::read_to_string(dir.join("line.plan.toml"))
            .unwrap()
            .replace("\"lumped\"", "\"beams\""),
    )
    .unwrap();
    let e = Plan::load(&dir.join("bad.plan.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("rail_support") && e.contains("beams"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The plan key `roughness` (per plan, per condition, "none" to take it off) puts rail
/// roughness on a condition's rails: on a smooth tangent the leading wheel's load then varies
/// by more than 0.5 kN where it holds still without; the run's key records it; an unknown spectrum is refused by name.
#[test]
fn a_plan_puts_roughness_on_its_rails() {
    let dir = temp("roughness");
    let conditions = "[[condition]]\nname = \"c\"\ntrack = \"tangent.toml\"\nspeed_kmh = 60.0\nstart_m = 150.0\nseeds = [1]\n\
         [[condition]]\nname = \"d\"\ntrack = \"tangent.toml\"\nspeed_kmh = 60.0\nstart_m = 150.0\nseeds = [1]\nroughness = \"none\"\n";
    let p = plan(&dir, "roughness = \"cnossos_m\"", conditions);
    assert_eq!(p.conditions[0].roughness.as_deref(), Some("cnossos_m"));
    assert_eq!(p.conditions[1].roughness.as_deref(), Some("none"));
    let out = dir.join("out");
    let m = dataset::generate(&p, &opts(&out), &|_| {}).unwrap();
    assert_eq!(m.runs.len(), 2);
    let ds = DataSet::load(&out).unwrap();
    let sd = |run: usize| {
        let c = &ds.runs[run].columns[ds.channel("w1l_force_z").unwrap()];
        let m = c.iter().sum::<f64>() / c.len() as f64;
        (c.iter().map(|v| (v - m).powi(2)).sum::<f64>() / c.len() as f64).sqrt()
    };
    let (rough, smooth) = (sd(0), sd(1));
    assert!(
        rough > 500.0 && smooth < 0.1 * rough,
        "{rough} N against {smooth} N"
    );
    let manifest = std::fs::read_to_string(out.join("manifest.json")).unwrap();
    assert!(
        manifest.contains("\"roughness\": \"cnossos_m\""),
        "the manifest says so"
    );
    std::fs::write(
        dir.join("bad.plan.toml"),
        std::fs::read_to_string(dir.join("line.plan.toml"))
            .unwrap()
            .replace("\"cnossos_m\"", "\"rough\""),
    )
    .unwrap();
    let e = Plan::load(&dir.join("bad.plan.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("roughness") && e.contains("rough"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A plan narrowed to some seeds (the test seeds an experiment runs again) turns each kept run
/// as the whole plan does: `turn = "both"` counts in the plan file's seed list.
#[test]
fn a_narrowed_plan_turns_its_runs_as_the_whole_plan() {
    let dir = temp("narrowed");
    let p = plan(
        &dir,
        "turn = \"both\"",
        "[[condition]]\nname = \"t\"\ntrack = \"tangent.toml\"\nspeed_kmh = 60.0\n\
         [[condition]]\nname = \"c\"\ntrack = \"r400.toml\"\nspeed_kmh = 60.0\n",
    );
    for c in &p.conditions {
        let whole: Vec<bool> = [1, 2].iter().map(|&s| c.mirrored(s)).collect();
        assert_ne!(whole[0], whole[1], "both ways over the two seeds");
        let mut only = c.clone();
        only.only_seeds(&[2]);
        assert_eq!(only.seeds, vec![2]);
        assert_eq!(only.mirrored(2), whole[1], "{}", c.name);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
