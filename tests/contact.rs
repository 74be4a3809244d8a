//! Contact model against closed forms and the CONTACT reference data in assets/reference.

use railforce::contact::profile::{self, LoadOptions, Profile};
use railforce::contact::validate::{self, ProfileSource, Reference};
use railforce::contact::{Side, WheelsetGeometry};
use std::path::{Path, PathBuf};

/// The reference data: the copies in the repository (`assets/reference/`, origin and licence
/// in its README), read from disk here; the binary embeds the same files.
fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/reference")
}

#[test]
fn manchester_a22_with_benchmark_profiles_within_tolerance() {
    let dir = reference_dir();
    let rows =
        validate::manchester_a22(&Reference::Dir(dir.clone()), ProfileSource::Benchmark).unwrap();
    assert_eq!(rows.len(), 42, "21 cases × 2 wheels");
    for r in &rows {
        assert!(
            r.passes(),
            "case {} {:?}: position {:.3} vs {:.3} mm, angle {:.3} vs {:.3}°",
            r.case,
            r.side,
            r.position.0 * 1e3,
            r.position.1 * 1e3,
            r.angle.0.to_degrees(),
            r.angle.1.to_degrees()
        );
        // Roll within 5 % of the reference or 0.02 mrad.
        assert!(
            (r.roll.0 - r.roll.1).abs() < 2e-5 + 0.05 * r.roll.1.abs(),
            "{r:?}"
        );
    }
    // The jump to flange contact on the right wheel at 6.5 mm: contact angle beyond 60°.
    let flange = rows
        .iter()
        .find(|r| r.case == 14 && r.side == Side::Right)
        .unwrap();
    assert!(flange.angle.0.abs() > 60f64.to_radians());
    let before = rows
        .iter()
        .find(|r| r.case == 13 && r.side == Side::Right)
        .unwrap();
    assert!(before.angle.0.abs() < 30f64.to_radians());
}

#[test]
fn analytic_profiles_match_the_benchmark_files() {
    let dir = reference_dir();
    // Wheel: the analytic S1002 against the benchmark's sampled S1002.
    let bench = profile::load(
        &dir.join("profiles/MBench_S1002_v3.prw"),
        LoadOptions::default(),
    )
    .unwrap();
    let ours = profile::s1002();
    let mut worst: f64 = 0.0;
    for i in 0..=1150 {
        let y = -55e-3 + i as f64 * 1e-4;
        worst = worst.max((bench.eval(y).0 - ours.eval(y).0).abs());
    }
    assert!(worst < 0.05e-3, "S1002 deviates {:.4} mm", worst * 1e3);
    // Rail: both mounted the same way (top at 0, gauge point at 0) over the running surface.
    let geo = |rail: Profile, incl: f64| {
        WheelsetGeometry::new(profile::s1002(), rail, incl, 1.435, 1.36, 0.07, 0.46).unwrap()
    };
    let b = geo(
        profile::load(
            &dir.join("profiles/MBench_UIC60_v3.prr"),
            LoadOptions::default(),
        )
        .unwrap(),
        0.0,
    );
    let o = geo(profile::rail_60kg(), (1.0f64 / 40.0).atan());
    let mut worst: f64 = 0.0;
    for i in 0..=600 {
        let y = 2e-3 + i as f64 * 1e-4; // from the gauge corner to 62 mm field-ward
        worst = worst.max((b.rail().eval(y).0 - o.rail().eval(y).0).abs());
    }
    assert!(worst < 0.1e-3, "rail deviates {:.4} mm", worst * 1e3);
}

#[test]
fn creep_curve_polach_and_fastsim_against_contact() {
    let rows = validate::tractcurv(&Reference::Builtin).unwrap();
    assert_eq!(rows.len(), 60);
    for r in &rows {
        assert!(
            r.passes(),
            "{} at ξ {}: {:.4} vs {:.4}",
            r.method,
            r.creepage,
            r.force.0,
            r.force.1
        );
    }
    // At small creepage both follow the linear theory (within 3 %).
    for r in rows.iter().filter(|r| r.creepage <= 1e-5) {
        assert!((r.force.0 / r.force.1 - 1.0).abs() < 0.03, "{r:?}");
    }
}

/// A conical wheel (conicity λ) on rails with a circular crown of radius R. Under a shift y
/// the wheelset rolls by φ = Δr/(2b) (b half the contact spacing, both wheels touching); the
/// roll moves the wheels' lowest points sideways by r0·φ and, by tilting the cones, the contact
/// along each crown by R·φ. Hence Δr = 2λ(y + (r0 + R)·φ) = 2λy·b/(b − λ(r0 + R)): an
/// effective conicity λ·b/(b − λ(r0 + R)), which is also the equivalent conicity.
#[test]
fn conical_wheel_on_round_rail_matches_closed_form() {
    let lambda = 0.05;
    let wheel = Profile::from_fn("cone", -60e-3, 60e-3, |y| (-lambda * y, -lambda, 0.0));
    let r = 0.03;
    let rail = Profile::from_fn("round", -29e-3, 29e-3, |y| {
        let s = (r * r - y * y).sqrt();
        (r - s, y / s, r * r / (s * s * s))
    });
    let geo = WheelsetGeometry::new(wheel, rail, 0.0, 1.435, 1.36, 0.07, 0.42).unwrap();
    let centred = geo.solve(0.0, 0.0);
    assert!(centred.roll.abs() < 1e-9);
    for k in 0..2 {
        assert!((centred.wheels[k].angle - lambda.atan()).abs() < 1e-4);
        // Flat-tread wheel: no lateral curvature; the rail's is 1/R at the contact.
        assert!(centred.wheels[k].wheel_curvature.abs() < 1e-9);
        assert!((centred.wheels[k].rail_curvature * r - 1.0).abs() < 0.01);
    }
    let b = 0.5 * (centred.wheels[0].point[1] - centred.wheels[1].point[1]);
    let r0 = centred.wheels[0].rolling_radius;
    let effective = lambda * b / (b - lambda * (r0 + r));
    for y in [-4e-3, -1e-3, 2e-3, 5e-3] {
        let s = geo.solve(y, 0.0);
        let dr = s.wheels[0].rolling_radius - s.wheels[1].rolling_radius;
        assert!(
            (dr / (2.0 * effective * y) - 1.0).abs() < 0.001,
            "y {y}: Δr {dr} vs {}",
            2.0 * effective * y
        );
        assert!(
            (s.roll / (dr / (2.0 * b)) - 1.0).abs() < 0.01,
            "roll {}",
            s.roll
        );
        // The wheel with the larger radius is on the side the wheelset moved to.
        assert_eq!(dr > 0.0, y > 0.0);
    }
    let table = geo.table(8e-3, 2e-4);
    for amp in [2e-3, 4e-3] {
        let le = table.equivalent_conicity(amp).unwrap();
        assert!((le / effective - 1.0).abs() < 0.01, "λe({amp}) = {le}");
    }
    // Table lookup between grid points agrees with a direct solve.
    let (direct, looked) = (geo.solve(1.23e-3, 0.0), table.lookup(1.23e-3));
    assert!((direct.roll - looked.roll).abs() < 1e-7);
    assert!((direct.wheels[0].rolling_radius - looked.wheels[0].rolling_radius).abs() < 1e-7);
}

#[test]
fn s1002_on_60kg_conicity_grows_toward_flange_contact() {
    // The C80's default pair: S1002 on 60 kg/m at 1:40, gauge 1435 mm, back-to-back 1353 mm.
    let geo = WheelsetGeometry::new(
        profile::s1002(),
        profile::rail_60kg(),
        (1.0f64 / 40.0).atan(),
        1.435,
        1.353,
        0.07,
        0.42,
    )
    .unwrap();
    let table = geo.table(10e-3, 2e-4);
    let l2 = table.equivalent_conicity(2e-3).unwrap();
    let l6 = table.equivalent_conicity(6e-3).unwrap();
    assert!(l2 > 0.01 && l2 < 0.5, "λe(2 mm) {l2}");
    assert!(l6 > l2, "λe(6 mm) {l6} ≤ λe(2 mm) {l2}");
    // Δr is odd in y for symmetric profiles.
    for y in [1e-3, 3e-3, 7e-3] {
        assert!((table.delta_r(y) + table.delta_r(-y)).abs() < 1e-6);
    }
}

#[test]
fn flange_back_sets_the_s1002_conicity() {
    // S1002 is drawn for a 1 360 mm flange back; at the Chinese 1 353 mm each wheel sits
    // 3.5 mm further out on its nearly flat tread, so the new-profile pair is almost
    // cylindrical (assets/docs/validation.md: the hunting order depends on it).
    let conicity = |back: f64| {
        let geo = WheelsetGeometry::new(
            profile::s1002(),
            profile::rail_60kg(),
            (1.0f64 / 40.0).atan(),
            1.435,
            back,
            0.07,
            0.42,
        )
        .unwrap();
        geo.table(12e-3, 2e-4).equivalent_conicity(3e-3).unwrap()
    };
    let (chinese, design) = (conicity(1.353), conicity(1.360));
    assert!(
        chinese > 0.01 && chinese < 0.03,
        "λe(3 mm) at 1 353 mm: {chinese}"
    );
    assert!(
        design > 0.12 && design < 0.25,
        "λe(3 mm) at 1 360 mm: {design}"
    );
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("railforce-prof-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn profile_files_load_and_bad_ones_fail_clearly() {
    // Two-column CSV with a header, in mm.
    let p = write(
        "cone.csv",
        "y_mm,z_mm\n-30,1.5\n-10,0.5\n10,-0.5\n30,-1.5\n",
    );
    let prof = profile::load(&p, LoadOptions::default()).unwrap();
    assert!((prof.eval(0.0).0).abs() < 1e-9 && (prof.eval(20e-3).0 + 1e-3).abs() < 1e-9);
    // Decreasing y is accepted (reversed); mirroring flips the slope.
    let p = write("rev.txt", "30 -1.5\n10 -0.5\n-10 0.5\n-30 1.5\n");
    let m = profile::load(&p, LoadOptions { mirror_y: true }).unwrap();
    assert!((m.eval(20e-3).0 - 1e-3).abs() < 1e-9);
    let cases = [
        ("few.csv", "0,0\n1,0\n", "at least 4 points"),
        ("nonmono.csv", "0,0\n1,0\n0.5,0\n2,0\n3,0\n", "monotonic"),
        ("text.csv", "0,0\n1,0\nabc\n", "line 3"),
        (
            "noblock.prw",
            "header.begin\n type = 1\nheader.end\n",
            "point.begin",
        ),
        (
            "badnum.prr",
            "spline.begin\n point.begin\n 1.0 x\n point.end\n",
            "bad number",
        ),
    ];
    for (name, text, want) in cases {
        let p = write(name, text);
        let e = profile::load(&p, LoadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(e.contains(name) && e.contains(want), "{name}: {e}");
    }
}

/// The worn heavy-haul pair carried in `vehicles/profiles/` (converted from CONTACT's test
/// bank, the originals unchanged in `assets/reference/profiles/`) reads as the SIMPACK files
/// it came from: the wheel is the `.prw` shifted 70 mm to its tape line, the rail the `.prr`
/// less the under-turned corners of its head, which the SIMPACK reader refuses naming the file
/// and the point (its y turns back).
#[test]
fn worn_heavy_haul_pair_equals_its_simpack_originals() {
    use railforce::contact::profile::{LoadOptions, load};
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let wheel_csv = load(
        &root.join("vehicles/profiles/worn_heavy_haul_wheel.csv"),
        LoadOptions::default(),
    )
    .unwrap();
    let wheel_prw = load(
        &root.join("assets/reference/profiles/worn_high_mileage.prw"),
        LoadOptions::default(),
    )
    .unwrap();
    let (lo, hi) = wheel_csv.range();
    let n = 200;
    for i in 0..=n {
        let y = lo + (hi - lo) * i as f64 / n as f64;
        let (a, b) = (wheel_csv.eval(y).0, wheel_prw.eval(y + 0.070).0);
        assert!((a - b).abs() < 1e-9, "wheel at y {y}: {a} vs {b}");
    }
    let err = load(
        &root.join("assets/reference/profiles/site_b_hr.prr"),
        LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("site_b_hr.prr") && err.contains("not strictly monotonic at point"),
        "{err}"
    );
    let rail = load(
        &root.join("vehicles/profiles/worn_heavy_haul_rail.csv"),
        LoadOptions::default(),
    )
    .unwrap();
    // The crown is at the file's z = 0, 16.4 mm to the field side of its origin.
    let (y_top, z_top) = rail.lowest_z();
    assert!(
        (y_top - 0.0164).abs() < 1e-3 && z_top.abs() < 1e-6,
        "{y_top} {z_top}"
    );
}

/// MiniProf files read as CONTACT reads them: the benchmark's UIC60 rail in the regular format,
/// mirrored as CONTACT's example mirrors it, equals its SIMPACK copy; a measured wheel in the old format keeps its
/// flange and tread past a glitch at the flange tip and gives a conicity on that rail; a jump,
/// metres and a profile that turns back near the top are refused naming the file and line.
#[test]
fn miniprof_files_read_as_contact_reads_them() {
    use railforce::contact::profile::{LoadOptions, load, parse};
    let refdir =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("assets/reference/profiles");
    // MiniProf rails are measured with the field side to −y: mirrored, as CONTACT's own
    // benchmark example reads this file (examples/python_mbench.py, mirror_y = 1).
    let ban = load(
        &refdir.join("MBench_UIC60_v3.ban"),
        LoadOptions { mirror_y: true },
    )
    .unwrap();
    let prr = load(&refdir.join("MBench_UIC60_v3.prr"), LoadOptions::default()).unwrap();
    // Both put the top at their lowest z; compare the shapes relative to it.
    let ((yb, zb), (yp, zp)) = (ban.lowest_z(), prr.lowest_z());
    for k in -25..=25 {
        let d = k as f64 * 1e-3;
        let (a, b) = (ban.eval(yb + d).0 - zb, prr.eval(yp + d).0 - zp);
        assert!((a - b).abs() < 0.05e-3, "rail at {d}: {a} vs {b}");
    }
    let wheel = load(&refdir.join("Car7216_0001r.whl"), LoadOptions::default()).unwrap();
    let (lo, hi) = wheel.range();
    assert!(lo < -0.05 && hi > 0.05, "flange and tread kept: {lo}..{hi}");
    let geo = railforce::contact::WheelsetGeometry::new(wheel, prr, 0.0, 1.435, 1.360, 0.070, 0.42)
        .unwrap();
    let table = geo.table(0.02, 1e-4);
    let l = table.equivalent_conicity(3e-3).unwrap();
    assert!(l > 0.0 && l < 1.0, "{l}");
    // Bad files.
    let text = std::fs::read_to_string(refdir.join("MBench_UIC60_v3.ban")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let first_data = lines.iter().position(|l| l.trim().is_empty()).unwrap() + 1;
    let mut jump = lines.clone();
    let moved = format!(
        "{} 99.0",
        lines[first_data + 40].split_whitespace().next().unwrap()
    );
    jump[first_data + 40] = &moved;
    let e = parse(
        &jump.join("\n"),
        std::path::Path::new("j.ban"),
        LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("j.ban") && e.contains("line") && e.contains("jump"),
        "{e}"
    );
    let metres: String = (0..40)
        .map(|i| {
            format!(
                "{} {}\n",
                -0.03 + i as f64 * 0.0015,
                0.001 * (i as f64 - 20.0).powi(2) / 400.0
            )
        })
        .collect();
    let e = parse(
        &format!("ColumnDef=X,Y\n\n{metres}"),
        std::path::Path::new("m.ban"),
        LoadOptions::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("m.ban") && e.contains("millimetres"), "{e}");
}
