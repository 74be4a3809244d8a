//! The train coupled to the 3-D wagon: the couplers' angle in a steady curve against its
//! closed form, the direction of their pull, the run's train channels and the consist's
//! refusals through the command line.

use railforce::sim::hitch::TrainSetup;
use railforce::sim::{SimConfig, Simulation};
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::Vehicle;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The mean coupler angles (front, rear) and forces over `seconds` in the middle of the R 800 m
/// curve without irregularities, the wagon at `position` in `consist`.
fn steady_curve(consist: &str, position: f64, speed_kmh: f64, seconds: f64) -> [f64; 4] {
    let vehicle = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let mut spec = TrackSpec::load(&root().join("tracks/curve_r800.toml")).unwrap();
    spec.irregularity = None;
    let track = Track::new(spec, None);
    let cfg = SimConfig {
        speed: speed_kmh / 3.6,
        start: Some(500.0),
        settle: 10.0,
        train: TrainSetup::resolve(consist, Some(position), &root(), "consist").unwrap(),
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(&vehicle, &track, cfg).unwrap();
    sim.settle().unwrap();
    let steps = (seconds / sim.config().dt).round() as usize;
    let mut sum = [0.0; 4];
    for _ in 0..steps {
        sim.step().unwrap();
        let r = sim.hitch().unwrap().readings;
        for (s, x) in sum
            .iter_mut()
            .zip([r[0].yaw, r[1].yaw, r[0].force, r[1].force])
        {
            *s += x / steps as f64;
        }
    }
    sum
}

/// In a steady curve both couplers swing inward, each by L/(2R) for identical neighbours (L
/// the cars' centre spacing, 12 m for C80s): the pair's lateral pull is F·L/R, inward under
/// tension. Right-hand curve: inward is to the right (negative angles).
#[test]
fn couplers_swing_inward_by_the_closed_form_in_a_steady_curve() {
    let [front, rear, f_front, f_rear] = steady_curve("daqin_10kt", 0.5, 60.0, 1.0);
    let want = -12.0 / 800.0;
    let got = front + rear;
    eprintln!(
        "ψ_front + ψ_rear = {:.3} mrad against L/R = {:.3} mrad; forces {:.1} / {:.1} kN",
        got * 1e3,
        want * 1e3,
        f_front * 1e-3,
        f_rear * 1e-3
    );
    assert!(
        ((got - want) / want).abs() < 0.02,
        "ψ_front + ψ_rear = {:.3} mrad, closed form L/R = {:.3} mrad (front {:.3}, rear {:.3})",
        got * 1e3,
        want * 1e3,
        front * 1e3,
        rear * 1e3
    );
    // The wagon mid-train on a level curve at constant speed: both couplers in tension.
    assert!(f_front > 0.0 && f_rear > 0.0, "{f_front} {f_rear}");
}

/// A consist naming an unknown vehicle, a wagon outside the train or a negative mass is
/// refused by `simulate`, naming the file and the field.
#[test]
fn bad_consists_are_refused_naming_file_and_field() {
    let dir = crate::common::scratch("consist");
    let good = std::fs::read_to_string(root().join("vehicles/daqin_10kt.consist.toml")).unwrap();
    let cases: Vec<(String, Vec<&str>, &str)> = vec![
        (good.clone(), vec!["--position", "1.5"], "position"),
        (
            good.replacen("position = ", "position = 7.0 #", 1),
            vec![],
            "position",
        ),
    ];
    for (i, (text, extra, field)) in cases.into_iter().enumerate() {
        let f = dir.join(format!("c{i}.consist.toml"));
        std::fs::write(&f, text).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
            .current_dir(&dir)
            .args(["simulate", "--track"])
            .arg(root().join("tracks/tangent.toml"))
            .args(["--duration", "0.1", "--consist"])
            .arg(&f)
            .args(&extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "case {i} was accepted");
        assert!(
            err.contains(field) && (err.contains(".consist.toml") || err.contains("--consist")),
            "case {i}: {err}"
        );
    }
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
        .args([
            "simulate",
            "--duration",
            "0.1",
            "--consist",
            "nowhere",
            "--track",
        ])
        .arg(root().join("tracks/tangent.toml"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("nowhere") && err.contains("daqin_20kt"),
        "{err}"
    );
}

/// `assess` reports each coupler's largest force per section of a run in a train, against the
/// 2 250 kN limit the criteria cite, and `view` carries the couplers to draw; nothing of
/// couplers for a wagon alone.
#[test]
fn assess_reports_the_coupler_force_of_a_run_in_a_train() {
    let dir = crate::common::scratch("assess-train");
    let bin = env!("CARGO_BIN_EXE_railforce");
    let track = root().join("tracks/curve_r800.toml");
    for (consist, want) in [("daqin_10kt", true), ("none", false)] {
        let run = dir.join(format!("{consist}.csv"));
        crate::common::succeed(
            std::process::Command::new(bin)
                .args([
                    "simulate",
                    "--duration",
                    "8",
                    "--consist",
                    consist,
                    "--track",
                ])
                .arg(&track)
                .arg("--out")
                .arg(&run),
        );
        let adir = dir.join(format!("a_{consist}"));
        crate::common::succeed(
            std::process::Command::new(bin)
                .arg("assess")
                .arg(&run)
                .arg("--out")
                .arg(&adir),
        );
        crate::common::succeed(std::process::Command::new(bin).arg("view").arg(&run));
        let html = std::fs::read_to_string(run.with_extension("view.html")).unwrap();
        assert_eq!(html.contains("\"couplers\":{\"force\""), want);
        let csv = std::fs::read_to_string(adir.join("assessment.csv")).unwrap();
        let rows: Vec<&str> = csv
            .lines()
            .filter(|l| l.contains("coupler force"))
            .collect();
        if want {
            // Front and rear in each section of the run's own track (from its .meta.json).
            let sections: std::collections::BTreeSet<&str> = csv
                .lines()
                .skip(1)
                .filter_map(|l| l.split(',').next())
                .collect();
            assert!(sections.len() > 1, "{csv}");
            assert_eq!(rows.len(), 2 * sections.len(), "{csv}");
            for r in rows {
                assert!(r.contains("2250"), "{r}");
            }
        } else {
            assert!(rows.is_empty(), "{csv}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A plan mixing a wagon alone and a wagon in a train makes one data set with one set of
/// channels: the run alone records the couplers as zeros (it has none), the other its forces.
#[test]
fn a_plan_mixing_trains_and_wagons_alone_records_one_set_of_channels() {
    let dir = crate::common::scratch("mixed");
    let plan = dir.join("mixed.plan.toml");
    std::fs::write(
        &plan,
        format!(
            "name = \"mixed\"\nvehicle = \"{v}\"\nduration_s = 0.5\nseeds = [1]\n\
             [[condition]]\nname = \"alone\"\ntrack = \"{t}\"\nspeed_kmh = 60.0\n\
             [[condition]]\nname = \"train\"\ntrack = \"{t}\"\nspeed_kmh = 60.0\nconsist = \"daqin_10kt\"\nposition = 0.5\n",
            v = root().join("vehicles/c80.toml").display(),
            t = root().join("tracks/tangent.toml").display()
        ),
    )
    .unwrap();
    crate::common::succeed(
        std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
            .args(["generate", "--plan"])
            .arg(&plan)
            .arg("--out")
            .arg(dir.join("data"))
            .args(["--format", "csv", "--settle", "0.5"]),
    );
    let col = |file: &str, name: &str| -> Vec<f64> {
        let text = std::fs::read_to_string(dir.join("data").join(file)).unwrap();
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let k = head
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("{file}: no {name}"));
        lines
            .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
            .collect()
    };
    assert!(
        col("alone_seed1.csv", "coupler_front_force")
            .iter()
            .all(|&f| f == 0.0)
    );
    assert!(
        col("train_seed1.csv", "coupler_front_force")
            .iter()
            .all(|&f| f > 0.0)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A fleet may draw the wagon's place in its train (`[vary] position`) and the mass of its
/// train's wagons (`consist_mass`, a factor): each run records its draws; drawn for a
/// condition in no train, the plan is refused naming the key.
#[test]
fn a_plan_draws_the_wagons_place_in_its_train() {
    let dir = crate::common::scratch("varypos");
    let plan = |consist: &str| {
        let mass = if consist.is_empty() {
            ""
        } else {
            "consist_mass = { uniform = [0.6, 1.0], scale = true }\n"
        };
        format!(
            "name = \"v\"\nvehicle = \"{v}\"\nduration_s = 0.3\nseeds = [1, 2, 3]\n{consist}\
             [vary]\nposition = {{ uniform = [0.1, 0.9] }}\n{mass}\
             [[condition]]\nname = \"c\"\ntrack = \"{t}\"\nspeed_kmh = 60.0\n",
            v = root().join("vehicles/c80.toml").display(),
            t = root().join("tracks/tangent.toml").display()
        )
    };
    let generate = |text: String| {
        let p = dir.join("v.plan.toml");
        std::fs::write(&p, text).unwrap();
        let _ = std::fs::remove_dir_all(dir.join("data"));
        std::process::Command::new(env!("CARGO_BIN_EXE_railforce"))
            .args(["generate", "--plan"])
            .arg(&p)
            .arg("--out")
            .arg(dir.join("data"))
            .args(["--settle", "0.2"])
            .output()
            .unwrap()
    };
    let out = generate(plan("consist = \"daqin_10kt\"\n"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("data/manifest.json")).unwrap())
            .unwrap();
    let places: Vec<f64> = m["runs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["position"].as_f64().unwrap())
        .collect();
    assert_eq!(places.len(), 3);
    assert!(places.iter().all(|p| (0.1..=0.9).contains(p)), "{places:?}");
    assert!(
        places[0] != places[1] && places[1] != places[2],
        "{places:?}"
    );
    for r in m["runs"].as_array().unwrap() {
        let f = r["draws"]["consist_mass"]["scale"]
            .as_f64()
            .unwrap_or(f64::NAN);
        assert!((0.6..=1.0).contains(&f), "{}", r["draws"]);
    }
    let out = generate(plan(""));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("vary.\"position\"") && err.contains("no train"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
