//! Short waves: rail roughness, weld dips and out-of-round wheels reach the wheel loads, the
//! step follows them (or a step too coarse is refused with the reason), and the label wheel's
//! FQ read by band holds at that step against one ten times finer.

use railforce::sim::step_study::{BANDS, band_rms};
use railforce::sim::{Integrator, MAX_STEP_SHORT_WAVES, SimConfig, Simulation, Stepping, fidelity};
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::{Flat, Vehicle, WheelDefect, wheel_defect::flat_depth};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A new 50 mm flat on 1L.
fn new_flat() -> WheelDefect {
    let flat = Flat {
        length: 0.05,
        depth: flat_depth(0.05, 0.42),
        rounded: None,
    };
    WheelDefect::new(0, Some(flat), None, 0.42)
}

fn c80() -> Vehicle {
    Vehicle::load(&root().join("vehicles/c80.toml")).unwrap()
}

/// The shipped tangent with `extra` tables appended (roughness, welds).
fn tangent_with(extra: &str) -> TrackSpec {
    let text = std::fs::read_to_string(root().join("tracks/tangent.toml")).unwrap();
    TrackSpec::parse(
        &format!("{text}\n{extra}\n"),
        Path::new("tangent_short.toml"),
    )
    .unwrap()
}

#[test]
fn the_step_follows_the_shortest_wave_and_a_coarser_given_step_is_refused() {
    let v = c80();
    let plain = tangent_with("");
    assert!(Stepping::limit_on(&plain, &v, 27.8).is_none());
    assert_eq!(
        Stepping::default().step_on(&plain, &v, 27.8).unwrap(),
        5e-3 / 6.0
    );

    let rough = tangent_with("[roughness]\nspectrum = \"cnossos_m\"");
    assert_eq!(
        Stepping::default().step_on(&rough, &v, 27.8).unwrap(),
        MAX_STEP_SHORT_WAVES
    );
    // 20 mm waves at 100 km/h pass at 1.39 kHz: 20 steps a period, a whole fraction of 5 ms.
    let fine = tangent_with("[roughness]\nspectrum = \"iso3095\"\nmin_wavelength_m = 0.02");
    let dt = Stepping::default().step_on(&fine, &v, 100.0 / 3.6).unwrap();
    assert!(dt * 20.0 * (100.0 / 3.6 / 0.02) <= 1.0 + 1e-9, "{dt}");
    assert!((5e-3 / dt - (5e-3 / dt).round()).abs() < 1e-9);

    let e = Stepping::chosen(None, Some(5e-3 / 6.0))
        .step_on(&rough, &v, 27.8)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tangent") && e.contains("0.0625 ms") && e.contains("short waves"),
        "{e}"
    );

    // A flat wheel on smooth rails: half its 50 mm at 100 km/h.
    let mut flat = c80();
    flat.wheel_defects.push(new_flat());
    let dt = Stepping::default()
        .step_on(&plain, &flat, 100.0 / 3.6)
        .unwrap();
    assert!(dt < MAX_STEP_SHORT_WAVES && dt * 20.0 * (100.0 / 3.6 / 0.025) <= 1.0 + 1e-9);
}

/// Each wheel's largest Q over `seconds` at 80 km/h on `spec`, at the step the run takes.
fn peak_loads(v: &Vehicle, spec: TrackSpec, seconds: f64) -> Vec<f64> {
    let speed = 80.0 / 3.6;
    let dt = Stepping::default().step_on(&spec, v, speed).unwrap();
    let track = Track::new(spec, None);
    let cfg = SimConfig {
        speed,
        start: Some(100.0),
        settle: 1.0,
        duration: seconds,
        dt,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(v, &track, cfg).unwrap();
    sim.settle().unwrap();
    let mut peak = vec![0.0f64; sim.wheels.len()];
    for _ in 0..(seconds / dt).round() as usize {
        sim.step().unwrap();
        for (p, w) in peak.iter_mut().zip(&sim.wheels) {
            *p = p.max(w.q);
        }
    }
    peak
}

/// A new 50 mm flat on 1L strikes: its peak load well above the static 122.5 kN and above
/// every round wheel's, on either track. A 0.3 mm dip over 1 m passes at 22 Hz at 80 km/h, below P2, so it loads the
/// wheels quasi-statically by about the unsprung and rail masses under one times the dip's
/// largest curvature: (600 + 250) kg × (d/2)·(2πV/L)² = 2.5 kN (their mean within 30 %).
#[test]
#[ignore = "release: cargo test --release -- --ignored"]
fn a_flat_strikes_and_a_weld_dip_loads_every_wheel() {
    let mut smooth = tangent_with("");
    smooth.irregularity = None;
    let mut flat = c80();
    flat.wheel_defects.push(new_flat());
    let q = peak_loads(&flat, smooth.clone(), 1.0);
    let others = q[1..].iter().copied().fold(0.0, f64::max);
    assert!(q[0] > 1.5 * 122.5e3 && q[0] > 1.3 * others, "{q:?}");
    // P1 sees the rail's mass near the wheel: the lumped track's 250 kg (the whole basin's,
    // right below 20 Hz) strikes harder than a beam's. Measured at 80 km/h: 840 against 382 kN.
    let mut beams = smooth.clone();
    beams.set_rail_model("discrete").unwrap();
    let on_beams = peak_loads(&flat, beams, 1.0)[0];
    assert!(
        on_beams > 1.5 * 122.5e3 && on_beams < 0.75 * q[0],
        "{on_beams} against {}",
        q[0]
    );

    let mut welded = tangent_with("[welds]\nspacing_m = 10.0\nfirst_m = 115.0");
    welded.irregularity = None;
    let (round, weld) = (
        peak_loads(&c80(), smooth, 2.0),
        peak_loads(&c80(), welded, 2.0),
    );
    let (d, l, v) = (0.3e-3, 1.0, 80.0 / 3.6);
    let want = 850.0 * 0.5 * d * (2.0 * std::f64::consts::PI * v / l).powi(2);
    let rise: Vec<f64> = round.iter().zip(&weld).map(|(a, b)| b - a).collect();
    let mean = rise.iter().sum::<f64>() / rise.len() as f64;
    // Measured: +3.1 / 2.2 / 1.4 / 2.3 kN by wheelset (the bogie's side frame pitches over
    // the dip), a mean 10 % under the closed form.
    assert!((mean / want - 1.0).abs() < 0.3, "{rise:?} against {want}");
    assert!(rise.iter().all(|r| *r > 0.4 * want), "{rise:?}");
}

/// The label wheel's FQ by band (0–20, 20–50, 50–100 Hz) at the short-wave step is within 3 %
/// of a step ten times finer on a CNOSSOS-rough class-5 tangent at 100 km/h (physics.md §3.4).
#[test]
#[ignore = "release: cargo test --release -- --ignored"]
fn fq_by_band_holds_at_the_short_wave_step() {
    let v = c80();
    let spec = tangent_with("[roughness]\nspectrum = \"cnossos_m\"");
    let track = Track::new(spec, None);
    let run = |dt| {
        let cfg = SimConfig {
            speed: 100.0 / 3.6,
            duration: 6.0,
            settle: 2.0,
            dt,
            integrator: Integrator::LinearlyImplicitHertz,
            ..SimConfig::default()
        };
        let rec = fidelity::run_with(&v, &track, cfg).unwrap();
        band_rms(&fidelity::column(&rec, "w1l_force_z").unwrap(), 200.0)
    };
    let (coarse, fine) = (run(MAX_STEP_SHORT_WAVES), run(MAX_STEP_SHORT_WAVES / 10.0));
    for ((a, b), band) in coarse.iter().zip(&fine).zip(BANDS) {
        assert!((a / b - 1.0).abs() < 0.03, "{band:?} Hz: {a} against {b}");
    }
    // The short waves put power where the step matters: the 20–50 Hz band over 2 kN.
    assert!(fine[1] > 2e3, "{fine:?}");
}

/// Roughness down to 20 mm passes at 1.4 kHz at 100 km/h, near P1: the run steps fine enough
/// for it and low-passes before the 200 Hz record, so the record holds no alias. Its 0–20 Hz
/// band is within 2 % of the same rails drawn down to 0.1 m only, and its power above 60 Hz
/// under 0.5 % of its variance.
#[test]
#[ignore = "release: cargo test --release -- --ignored"]
fn p1_stays_out_of_the_record() {
    let v = c80();
    let run = |min: f64| {
        let spec = tangent_with(&format!(
            "[roughness]\nspectrum = \"iso3095\"\nmin_wavelength_m = {min}"
        ));
        let speed = 100.0 / 3.6;
        let dt = Stepping::default().step_on(&spec, &v, speed).unwrap();
        let cfg = SimConfig {
            speed,
            duration: 6.0,
            settle: 2.0,
            dt,
            ..SimConfig::default()
        };
        let track = Track::new(spec, None);
        let mut sim = Simulation::new(&v, &track, cfg).unwrap();
        let rec = railforce::sim::output::record(&mut sim, |_| {}).unwrap();
        let q = fidelity::column(&rec, "w1l_force_z").unwrap();
        (
            band_rms(&q, 200.0),
            fidelity::power_above(&q, 200.0, 60.0),
            dt,
        )
    };
    let (short, above, dt) = run(0.02);
    let (long, _, _) = run(0.1);
    assert!(dt < 4e-5, "{dt}");
    assert!(
        (short[0] / long[0] - 1.0).abs() < 0.02,
        "{short:?} against {long:?}"
    );
    assert!(above < 0.005, "power above 60 Hz: {above}");
}
