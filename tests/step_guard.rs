//! The step guard against the runs themselves: the longest step it finds for an integrator is
//! where the nonlinear runs begin to burst, and a run past it is refused before it starts.

use railforce::sim::modes::{check_step, guard, longest_step};
use railforce::sim::{Integrator, SimConfig, Simulation};
use railforce::track::Track;
use railforce::vehicle::Vehicle;
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn config(dt: f64, integrator: Integrator) -> SimConfig {
    SimConfig {
        speed: 80.0 / 3.6,
        dt,
        integrator,
        duration: 0.5,
        settle: 1.5,
        ..SimConfig::default()
    }
}

/// The C80 on the shipped tangent (rails on their lumped supports) at 80 km/h, default
/// integrator: the 5/6 ms step holds every stiff mode; 1 ms grows the side frames' pitch on
/// their pads; the longest step the guard finds (0.895 ms) lies between the runs' own
/// boundary — 0.87 ms runs clean, 0.9 ms chatters until the watch stops it — and the guard's
/// message names the mode and the step.
#[test]
fn the_guard_finds_the_step_where_runs_burst() {
    let vehicle = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let hertz = Integrator::LinearlyImplicitHertz;
    let sim = |dt: f64| Simulation::new(&vehicle, &track, config(dt, hertz)).unwrap();

    let default = check_step(&sim(5.0 / 6.0 * 1e-3)).unwrap();
    assert!(!default.bursts(), "{default:?}");
    let coarse = check_step(&sim(1e-3)).unwrap();
    assert!(coarse.bursts() && coarse.growth > 1.5, "{coarse:?}");
    assert!(coarse.mode.name.contains("sideframe"), "{:?}", coarse.mode);

    let longest = longest_step(&sim(1e-3)).unwrap().unwrap();
    assert!(longest > 0.87e-3 && longest < 0.9e-3, "{longest}");

    // The runs themselves, stepped past the guard (the watch alone sees them).
    let mut holds = sim(0.87e-3);
    holds.settle().expect("0.87 ms runs");
    let mut bursts = sim(0.9e-3);
    let e = bursts.settle().unwrap_err().to_string();
    assert!(e.contains("chatters"), "{e}");

    // Through the run's entry the guard refuses it first, naming what and how far.
    let e = guard(&sim(0.9e-3)).unwrap_err().to_string();
    assert!(
        e.contains("0.900 ms step cannot follow")
            && e.contains("sideframe")
            && e.contains("longest step that holds it here is 0.89"),
        "{e}"
    );
    let mut run = sim(0.9e-3);
    let e = railforce::sim::output::record(&mut run, |_| {})
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(e.contains("cannot follow"), "{e}");
}

/// The explicit step (semi-implicit Euler) holds the side frames' pads to a much shorter step
/// than the Hertz integrator, which solves them in their damping: the guard's longest step for
/// it is shorter, and its default 0.2 ms passes.
#[test]
fn the_explicit_step_is_held_shorter() {
    let vehicle = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let semi = Integrator::SemiImplicit;
    let ok = Simulation::new(&vehicle, &track, config(2e-4, semi)).unwrap();
    assert!(!check_step(&ok).unwrap().bursts());
    let coarse = Simulation::new(&vehicle, &track, config(1e-3, semi)).unwrap();
    let longest = longest_step(&coarse).unwrap().unwrap();
    assert!(longest > 2e-4 && longest < 0.85e-3, "{longest}");
}

/// Every integrator's own step lies inside the longest step the guard finds for it (release:
/// four bisections), with the margins physics.md §6 quotes: 0.895 / 0.689 / 0.531 / 0.254 ms
/// against 5/6, 0.5, 0.2 and 0.2 ms.
#[test]
#[ignore = "release: four bisections of simulated steps per integrator"]
fn every_integrators_own_step_is_held() {
    let vehicle = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let limits = railforce::sim::modes::step_limits(&vehicle, &track, 80.0 / 3.6).unwrap();
    assert_eq!(limits.len(), 4);
    for l in limits {
        let quoted = match l.integrator {
            Integrator::LinearlyImplicitHertz => 0.895e-3,
            Integrator::LinearlyImplicit => 0.689e-3,
            Integrator::SemiImplicit => 0.531e-3,
            Integrator::Heun => 0.254e-3,
        };
        assert!(l.holds(), "{l:?}");
        let longest = l.longest.unwrap();
        assert!(
            (longest / quoted - 1.0).abs() < 0.01,
            "{l:?} against the quoted {quoted}"
        );
    }
}

/// The guard works on copies: a run it has looked at steps to the same bits as one it has not
/// (the same seed gives the same bytes).
#[test]
fn the_guard_leaves_the_run_as_it_was() {
    let vehicle = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let track = Track::load(&root().join("tracks/curve_r400.toml")).unwrap();
    let cfg = config(5.0 / 6.0 * 1e-3, Integrator::LinearlyImplicitHertz);
    let mut looked = Simulation::new(&vehicle, &track, cfg.clone()).unwrap();
    let mut plain = Simulation::new(&vehicle, &track, cfg).unwrap();
    guard(&looked).unwrap();
    for _ in 0..200 {
        looked.step().unwrap();
        plain.step().unwrap();
    }
    assert_eq!(looked.states(), plain.states());
    assert_eq!(looked.rails(), plain.rails());
    assert_eq!(looked.wheels, plain.wheels);
}

/// The pads bound the default step (physics.md §2): the side frames' pitch on them grows as
/// their stiffness's square root, so pads (0.895/0.833)² ≈ 1.15 times the file's reach the
/// default step's limit. The fleet's stiffest pads (1.1 ×) pass the guard; 1.2 × (which
/// chattered in every screening run) are refused before they run, and the guard's longest step
/// for them falls by about √1.2 (release: two bisections).
#[test]
#[ignore = "release: two bisections of simulated steps per pad stiffness"]
fn the_pads_bound_the_default_step() {
    use railforce::vehicle::elements::Element;
    let track = Track::load(&root().join("tracks/tangent.toml")).unwrap();
    let with_pads = |factor: f64| {
        let mut v = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
        for e in &mut v.elements {
            if let Element::ShearPad(p) = e {
                p.stiffness *= factor;
            }
        }
        v
    };
    let hertz = Integrator::LinearlyImplicitHertz;
    let default = 5.0 / 6.0 * 1e-3;
    let fleet = with_pads(1.1);
    let sim = Simulation::new(&fleet, &track, config(default, hertz)).unwrap();
    assert!(!check_step(&sim).unwrap().bursts());
    let stiff = with_pads(1.2);
    let sim = Simulation::new(&stiff, &track, config(default, hertz)).unwrap();
    let c = check_step(&sim).unwrap();
    assert!(c.bursts() && c.mode.name.contains("sideframe"), "{c:?}");
    let nominal = Vehicle::load(&root().join("vehicles/c80.toml")).unwrap();
    let at = |v: &Vehicle| {
        let s = Simulation::new(v, &track, config(1e-3, hertz)).unwrap();
        longest_step(&s).unwrap().unwrap()
    };
    let ratio = at(&nominal) / at(&stiff);
    assert!((ratio / 1.2f64.sqrt() - 1.0).abs() < 0.05, "{ratio}");
}
