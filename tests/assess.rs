//! Assessment statistics against signals with known answers, and a quiet run that passes.

use railforce::assess::{Criteria, RunForces, Span, WheelSeries, assess};

/// A synthetic run at 10 m/s sampled at 200 Hz over `len` metres, one wheelset, forces from
/// `y(s)` and `q(s)` (N) on both wheels (the right wheel's Y mirrored).
fn run(len: f64, y: impl Fn(f64, usize) -> f64, q: impl Fn(f64, usize) -> f64) -> RunForces {
    let n = (len / 0.05) as usize + 1;
    let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
    let s: Vec<f64> = (0..n).map(|i| i as f64 * 0.05).collect();
    let wheel = |name: &str, sign: f64| WheelSeries {
        wheel: name.into(),
        y: s.iter().enumerate().map(|(i, &x)| sign * y(x, i)).collect(),
        q: s.iter().enumerate().map(|(i, &x)| q(x, i)).collect(),
    };
    RunForces {
        time: time.clone(),
        s: s.clone(),
        wheels: vec![wheel("w1l", 1.0), wheel("w1r", -1.0)],
        carbody: None,
        couplers: None,
    }
}

/// Zero-mean pseudo-noise, symmetric, ±amp.
fn noise(i: usize, amp: f64) -> f64 {
    let h = (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11;
    amp * (2.0 * (h as f64 / (1u64 << 53) as f64) - 1.0)
}

fn spans() -> Vec<Span> {
    vec![
        Span {
            name: "tangent".into(),
            radius_m: None,
            from_m: 0.0,
            to_m: 100.0,
        },
        Span {
            name: "curve R 400 m".into(),
            radius_m: Some(400.0),
            from_m: 100.0,
            to_m: 300.0,
        },
    ]
}

fn value(
    a: &railforce::assess::Assessment,
    section: &str,
    quantity: &str,
    place: &str,
) -> (f64, bool) {
    let r = a
        .rows
        .iter()
        .find(|r| r.section == section && r.quantity == quantity && r.place == place)
        .unwrap_or_else(|| panic!("{section} {quantity} {place}"));
    (r.value, r.pass)
}

#[test]
fn quasi_static_levels_are_the_medians_over_the_curve() {
    let r = run(
        300.0,
        |s, i| {
            if s >= 100.0 {
                30e3 + noise(i, 8e3)
            } else {
                noise(i, 8e3)
            }
        },
        |_, i| 110e3 + noise(i + 7, 10e3),
    );
    let a = assess(&r, &spans(), &Criteria::builtin(), 122.6).unwrap();
    let (yqst, pass) = value(&a, "curve R 400 m", "Yqst", "w1l");
    assert!((yqst - 30.0).abs() < 0.5, "Yqst {yqst} kN");
    assert!(pass, "30 kN is within 60 kN");
    let (qqst, _) = value(&a, "curve R 400 m", "Qqst", "w1r");
    assert!((qqst - 110.0).abs() < 0.5, "Qqst {qqst} kN");
    // Quasi-static values belong to curves only.
    assert!(
        !a.rows
            .iter()
            .any(|r| r.section == "tangent" && r.quantity == "Yqst")
    );
    // ΣY of a mirrored pair is zero.
    let (sum, _) = value(&a, "curve R 400 m", "(ΣY)2m", "wheelset 1");
    assert!(sum < 1e-6, "{sum}");
}

#[test]
fn a_quiet_run_passes_every_criterion() {
    // Static loads, no lateral force: a wagon at rest on smooth track.
    let r = run(50.0, |_, _| 0.0, |_, _| 122.6e3);
    let a = assess(&r, &[], &Criteria::builtin(), 122.6).unwrap();
    assert!(a.rows.len() >= 8, "{}", a.rows.len());
    assert!(
        a.failures().count() == 0,
        "{:?}",
        a.failures().collect::<Vec<_>>()
    );
    assert!(a.markdown().contains("secondary"), "sources cited");
}

/// A Y/Q of 1.0 held over 3 m fails the 2 m sliding-mean criterion (0.8); held over 0.4 m the
/// sliding mean dilutes it to a fifth and it passes, though its peak is the same.
#[test]
fn planted_y_over_q_plateaus_long_and_short() {
    let q = |_: f64, _: usize| 100e3;
    let long = run(
        60.0,
        |s, _| {
            if (30.0..33.0).contains(&s) {
                100e3
            } else {
                0.0
            }
        },
        q,
    );
    let short = run(
        60.0,
        |s, _| {
            if (30.0..30.4).contains(&s) {
                100e3
            } else {
                0.0
            }
        },
        q,
    );
    let c = Criteria::builtin();
    let a = assess(&long, &[], &c, 122.6).unwrap();
    let (v, pass) = value(&a, "whole run", "(Y/Q)2m", "w1l");
    assert!(!pass && v > 0.95, "long plateau: {v}");
    let a = assess(&short, &[], &c, 122.6).unwrap();
    let (v, pass) = value(&a, "whole run", "(Y/Q)2m", "w1l");
    assert!(pass && v < 0.3, "short plateau: {v}");
}

#[test]
fn identify_output_is_read_like_a_simulated_run() {
    let n = 2001;
    let col = |f: &dyn Fn(usize) -> f64| (0..n).map(f).collect::<Vec<f64>>();
    let cols = vec![
        ("time_s".to_string(), col(&|i| i as f64 * 0.005)),
        ("s_m".to_string(), col(&|i| i as f64 * 0.05)),
        ("w1l_force_y_N".to_string(), col(&|_| 5e3)),
        ("w1l_force_z_N".to_string(), col(&|_| 120e3)),
        ("y_over_q_w1l".to_string(), col(&|_| 0.04)),
    ];
    let r = RunForces::from_columns("identified.csv", &cols).unwrap();
    assert_eq!(r.wheels.len(), 1);
    assert_eq!(r.wheels[0].wheel, "w1l");
    let e = RunForces::from_columns("x.csv", &cols[..1])
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.csv") && e.contains("s_m"), "{e}");
}

/// The C80 simulated on smooth tangent track at walking pace passes every criterion.
#[test]
fn a_slow_run_on_smooth_track_passes() {
    use railforce::sim::{SimConfig, Simulation, output};
    use railforce::track::{Track, TrackSpec};
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let v = railforce::vehicle::Vehicle::load(&root.join("vehicles/c80.toml")).unwrap();
    let mut spec = TrackSpec::load(&root.join("tracks/tangent.toml")).unwrap();
    spec.irregularity = None;
    spec.rail_support = None;
    let track = Track::new(spec, None);
    let cfg = SimConfig {
        speed: 10.0 / 3.6,
        duration: 1.0,
        settle: 0.2,
        ..SimConfig::default()
    };
    let mut sim = Simulation::new(&v, &track, cfg).unwrap();
    let rec = output::record(&mut sim, |_| {}).unwrap();
    let cols: Vec<(String, Vec<f64>)> = rec
        .names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.clone(), rec.column(i)))
        .collect();
    let r = RunForces::from_columns("smooth run", &cols).unwrap();
    assert_eq!(r.wheels.len(), 8);
    let a = assess(&r, &[], &Criteria::builtin(), 122.6).unwrap();
    assert!(
        a.failures().count() == 0,
        "{:?}",
        a.failures().collect::<Vec<_>>()
    );
    let (q, _) = value(&a, "whole run", "Q", "w1l");
    assert!((q - 122.6).abs() < 5.0, "static wheel load: {q} kN");
    assert!(
        r.carbody.is_some(),
        "the run records the carbody accelerations"
    );
}

/// A wheelset hunting at 1.5 Hz: ΣY of amplitude A has a sliding rms of A/√2 over 100 m;
/// 40 kN passes the stability limit (half the track-shifting limit, 39 kN), 70 kN fails.
#[test]
fn planted_hunting_is_caught_by_the_stability_criterion() {
    let hunt = |amp: f64| {
        let mut r = run(300.0, |_, _| 0.0, |_, _| 122.6e3);
        r.wheels[0].y = r
            .time
            .iter()
            .map(|t| amp * (2.0 * std::f64::consts::PI * 1.5 * t).sin())
            .collect();
        let a = assess(&r, &[], &Criteria::builtin(), 122.6).unwrap();
        value(&a, "whole run", "(ΣY)rms", "wheelset 1")
    };
    let (rms, pass) = hunt(40e3);
    assert!((rms - 40.0 / 2f64.sqrt()).abs() < 1.0 && pass, "{rms}");
    let (rms, pass) = hunt(70e3);
    assert!((rms - 70.0 / 2f64.sqrt()).abs() < 1.5 && !pass, "{rms}");
}

/// Carbody accelerations: a 2 m/s² sine at 3 Hz lies in the 0.4–10 Hz band and reads 2 m/s²
/// (within the 3 m/s² lateral limit); gravity and a 0.1 Hz sway are outside it; 4 m/s²
/// laterally fails. The ride index of the same motion is its Sperling value.
#[test]
fn carbody_accelerations_in_their_band() {
    let with = |amp: f64| {
        let mut r = run(300.0, |_, _| 0.0, |_, _| 122.6e3);
        let w = 2.0 * std::f64::consts::PI;
        let y: Vec<f64> = r
            .time
            .iter()
            .map(|t| amp * (w * 3.0 * t).sin() + 1.0 * (w * 0.1 * t).sin())
            .collect();
        let z: Vec<f64> = r.time.iter().map(|_| 9.81).collect();
        r.carbody = Some([y, z]);
        assess(&r, &[], &Criteria::builtin(), 122.6).unwrap()
    };
    let a = with(2.0);
    let (ay, pass) = value(&a, "whole run", "ÿ* lateral (0.4–10 Hz)", "carbody");
    assert!((ay - 2.0).abs() < 0.05 && pass, "{ay}");
    let (az, _) = value(&a, "whole run", "z̈* vertical (0.4–10 Hz)", "carbody");
    assert!(
        az < 1e-6,
        "gravity is not an acceleration of the ride: {az}"
    );
    let (_, pass) = value(&with(4.0), "whole run", "ÿ* lateral (0.4–10 Hz)", "carbody");
    assert!(!pass);
    // Sperling by hand: A = 2/9.81 g at 3 Hz, lateral F = 0.8·3² = 7.2 (the 0.1 Hz sway is
    // below the 0.5 Hz band): 7.08·(A³·7.2/3)^0.1 = 4.797, beyond the freight 4.25.
    let (wz, pass) = value(&a, "whole run", "Wz lateral", "carbody");
    let by_hand = 7.08 * ((2.0f64 / 9.81).powi(3) * 7.2 / 3.0).powf(0.1);
    assert!((wz - by_hand).abs() < 0.01 && !pass, "{wz} vs {by_hand}");
}

/// Identified forces with intervals: a constant ±δ on Q moves the 99.85 % Q by exactly δ
/// (a percentile shifts with a constant), the intervals hold the value, the probability of
/// exceeding a limit grows with δ and is (1 − coverage)/2 where the high end meets the limit.
#[test]
fn statistics_of_identified_forces_carry_their_intervals() {
    use railforce::assess::interval::{WheelBand, assess_with_bands, normal_quantile};
    let r = run(
        300.0,
        |x, i| 20e3 * (x / 300.0) + noise(i, 3e3),
        |_, i| 110e3 + noise(i + 7, 10e3),
    );
    let band = |dy: f64, dq: f64| -> Vec<WheelBand> {
        r.wheels
            .iter()
            .map(|w| WheelBand {
                y: [
                    w.y.iter().map(|v| v - dy).collect(),
                    w.y.iter().map(|v| v + dy).collect(),
                ],
                q: [
                    w.q.iter().map(|v| v - dq).collect(),
                    w.q.iter().map(|v| v + dq).collect(),
                ],
            })
            .collect()
    };
    let c = Criteria::builtin();
    let plain = assess(&r, &spans(), &c, 110.0).unwrap();
    let a = assess_with_bands(&r, &band(2e3, 5e3), &spans(), &c, 110.0, 0.9).unwrap();
    assert_eq!(a.rows, plain.rows, "the values are the plain assessment's");
    assert_eq!(a.intervals.len(), a.rows.len());
    for (row, b) in a.rows.iter().zip(&a.intervals) {
        assert!(b.low <= row.value && row.value <= b.high, "{row:?} {b:?}");
        assert!((0.0..=1.0).contains(&b.exceedance));
    }
    let q = a
        .rows
        .iter()
        .position(|r| r.section == "tangent" && r.quantity == "Q" && r.place == "w1l")
        .unwrap();
    assert!((a.intervals[q].high - a.rows[q].value - 5.0).abs() < 1e-6);
    assert!((a.rows[q].value - a.intervals[q].low - 5.0).abs() < 1e-6);
    // Zero-width bands: the statistic is known, nothing within its limit can exceed it.
    let exact = assess_with_bands(&r, &band(0.0, 0.0), &spans(), &c, 110.0, 0.9).unwrap();
    for (row, b) in exact.rows.iter().zip(&exact.intervals) {
        assert_eq!((b.low, b.high), (row.value, row.value));
        assert_eq!(b.exceedance, if row.pass { 0.0 } else { 1.0 });
    }
    // Wider bands, likelier exceedance; where the high end meets the limit, (1 − 0.9)/2.
    let wide = assess_with_bands(&r, &band(2e3, 40e3), &spans(), &c, 110.0, 0.9).unwrap();
    assert!(wide.intervals[q].exceedance > a.intervals[q].exceedance);
    let to_limit = (a.rows[q].limit - a.rows[q].value) * 1e3;
    let meet = assess_with_bands(&r, &band(2e3, to_limit), &spans(), &c, 110.0, 0.9).unwrap();
    assert!(
        (meet.intervals[q].exceedance - 0.05).abs() < 1e-4,
        "{:?}",
        meet.intervals[q]
    );
    assert!((normal_quantile(0.95) - 1.6449).abs() < 1e-4);
    // The report says what the intervals are.
    assert!(a.markdown().contains("P(exceed)") && a.table().csv().contains("p_exceed"));
}

/// identify's bound columns are read with the forces; one bound without the other is named.
#[test]
fn bound_columns_are_read_and_checked() {
    use railforce::assess::interval::bands_from_columns;
    let col = |n: &str, v: f64| (n.to_string(), vec![v; 400]);
    let time = (
        "time_s".to_string(),
        (0..400).map(|i| i as f64 * 0.005).collect(),
    );
    let s = (
        "s_m".to_string(),
        (0..400).map(|i| i as f64 * 0.05).collect(),
    );
    let mut cols = vec![
        time,
        s,
        col("w1l_force_y_N", 1e3),
        col("w1l_force_z_N", 1e5),
    ];
    let r = RunForces::from_columns("x.csv", &cols).unwrap();
    assert_eq!(bands_from_columns("x.csv", &cols, &r).unwrap(), None);
    cols.push(col("w1l_force_y_lo_N", 0.5e3));
    let e = bands_from_columns("x.csv", &cols, &r)
        .unwrap_err()
        .to_string();
    assert!(e.contains("x.csv") && e.contains("w1l_force_y_hi_N"), "{e}");
    cols.push(col("w1l_force_y_hi_N", 2e3));
    cols.push(col("w1l_force_z_lo_N", 0.9e5));
    cols.push(col("w1l_force_z_hi_N", 0.95e5));
    let e = bands_from_columns("x.csv", &cols, &r)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("w1l_force_z") && e.contains("around the value"),
        "{e}"
    );
}
