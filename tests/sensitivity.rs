//! `railforce sensitivity`: refusals naming the file and key, a small screening end to end
//! (every copy on its base's irregularities, a stop never reached has no effect, the same seed
//! gives the same bytes, a rerun resumes).

use crate::common::{railforce_in, scratch, succeed};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn tiny_plan(dir: &Path) -> PathBuf {
    let p = dir.join("tiny.plan.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"tiny\"\nvehicle = \"{}\"\nduration_s = 0.3\nseeds = [1]\n\
             [[condition]]\nname = \"t\"\ntrack = \"{}\"\nspeed_kmh = 80.0\n",
            root().join("vehicles/c80.toml").display(),
            root().join("tracks/tangent.toml").display()
        ),
    )
    .unwrap();
    p
}

fn study(dir: &Path, estimates: &str, out: &str) -> std::process::Output {
    let e = dir.join("e.estimates.toml");
    std::fs::write(&e, estimates).unwrap();
    railforce_in(dir)
        .args([
            "sensitivity",
            "--trajectories",
            "2",
            "--settle",
            "0.2",
            "--jobs",
            "2",
        ])
        .arg("--plan")
        .arg(tiny_plan(dir))
        .arg("--estimates")
        .arg(&e)
        .arg("--out")
        .arg(dir.join(out))
        .output()
        .unwrap()
}

/// An estimate without a range, without a source, or with a range an element's loader
/// refuses at one end is refused before any run, naming the file and the key.
#[test]
fn an_estimate_without_a_range_or_source_or_beyond_its_bounds_is_refused() {
    let dir = scratch("sens-refuse");
    let key = "[estimate.\"vehicle.contact.friction\"]\n";
    for (body, says) in [
        ("one_of = [0.2, 0.3]\nsource = \"s\"\n", "no range"),
        ("uniform = [0.2, 0.3]\n", "no source"),
        (
            "uniform = [0.3, 0.3]\nsource = \"s\"\n",
            "no range: a study samples lo < hi",
        ),
        (
            "uniform = [-0.1, 0.3]\nsource = \"s\"\n",
            "an end of its range",
        ),
    ] {
        let out = study(&dir, &format!("{key}{body}"), "out");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{body}");
        assert!(
            err.contains("e.estimates.toml")
                && err.contains("estimate.\"vehicle.contact.friction\"")
                && err.contains(says),
            "{body}: {err}"
        );
        assert!(
            !dir.join("out/morris/data").exists(),
            "no run before the check"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two estimates, two trajectories: 7 runs on one track. The gibs' clearance is never taken
/// up in 0.3 s on a tangent, so it has no effect at all; the nests' stiffness moves FQ.
#[test]
fn a_small_screening_ranks_what_acts_and_repeats_itself() {
    let dir = scratch("sens-run");
    let estimates = "name = \"e\"\n\
        [estimate.\"vehicle.lateral_stop.clearance_m\"]\nuniform = [0.015, 0.02]\nsource = \"estimate\"\n\
        [estimate.\"vehicle.spring_nest.outer_stiffness\"]\nuniform = [0.8, 1.2]\nscale = true\n\
        with = [\"vehicle.spring_nest.inner_stiffness\"]\nsource = \"estimate ±20 %\"\n";
    let out = study(&dir, estimates, "a");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let m: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("a/morris/data/manifest.json")).unwrap(),
    )
    .unwrap();
    let runs = m["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 7);
    let seeds: std::collections::BTreeSet<u64> = runs
        .iter()
        .map(|r| r["realisation_seed"].as_u64().unwrap())
        .collect();
    assert_eq!(
        seeds.len(),
        1,
        "every copy shares its base's irregularities"
    );
    let csv = std::fs::read_to_string(dir.join("a/morris/measures.csv")).unwrap();
    let mu_star = |key: &str, output: &str| -> f64 {
        csv.lines()
            .find(|l| l.contains(&format!(",{key},{output},")))
            .and_then(|l| l.split(',').nth(5)?.parse().ok())
            .unwrap_or_else(|| panic!("{key} {output} in\n{csv}"))
    };
    for o in ["fl_mean", "fl_std", "fq_mean", "fq_std", "fq_p9985"] {
        assert_eq!(mu_star("vehicle.lateral_stop.clearance_m", o), 0.0, "{o}");
    }
    assert!(mu_star("vehicle.spring_nest.outer_stiffness", "fq_std") > 0.0);
    let ranked = std::fs::read_to_string(dir.join("a/morris/ranked_t.csv")).unwrap();
    let first = ranked.lines().nth(1).unwrap();
    assert!(
        first.starts_with("1,vehicle.spring_nest.outer_stiffness,"),
        "{ranked}"
    );
    assert!(dir.join("a/morris/tornado_t.svg").is_file() && dir.join("a/index.html").is_file());
    // The same seed, the same bytes; a rerun into the same folder runs nothing.
    let out = study(&dir, estimates, "b");
    assert!(out.status.success());
    assert_eq!(
        csv,
        std::fs::read_to_string(dir.join("b/morris/measures.csv")).unwrap()
    );
    let again = succeed(
        railforce_in(&dir)
            .args(["sensitivity", "--trajectories", "2", "--settle", "0.2"])
            .arg("--plan")
            .arg(tiny_plan(&dir))
            .arg("--estimates")
            .arg(dir.join("e.estimates.toml"))
            .arg("--out")
            .arg(dir.join("a")),
    );
    assert!(
        String::from_utf8_lossy(&again.stderr).contains("0 generated, 7 already done"),
        "{}",
        String::from_utf8_lossy(&again.stderr)
    );
    let _ = std::fs::remove_dir_all(&dir);
}
