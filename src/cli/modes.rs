//! `railforce modes`: the linear stability of a vehicle against speed (root locus, damping,
//! named modes, linear critical speeds), a thin shell over `sim::modes`.

use anyhow::{Result, bail};
use clap::Args;
use railforce::report::svg::{Chart, Series};
use railforce::sim::modes::{
    Critical, FrictionLimit, ModesOptions, SpeedModes, critical_speeds, modes,
};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ModesArgs {
    /// Vehicle file (or a built-in name: c80, c80_empty, restrained_wheelset).
    #[arg(long, default_value = "vehicles/c80.toml")]
    vehicle: PathBuf,
    /// Speeds, km/h, as FROM:TO:STEP.
    #[arg(long, default_value = "20:200:5")]
    speeds: String,
    /// Amplitude of the contact's quasi-linearisation, mm: each wheelset's and rail's lateral
    /// position is stepped by ± this much, so the contact enters as its secant over it (the
    /// equivalent conicity at this amplitude, with the contact-angle and gravitational terms).
    #[arg(long, default_value_t = 3.0)]
    amplitude_mm: f64,
    /// Friction elements stuck (their stick springs), sliding (no friction force), both (two
    /// loci), equivalent (each by its describing function over the least damped mode's cycle
    /// with the first wheelset at --amplitude-mm: the friction of a limit cycle of that size)
    /// or all three.
    #[arg(long, default_value = "both", value_parser = ["stuck", "sliding", "both", "equivalent", "all"])]
    friction: String,
    /// Change the wheelsets' flange back-to-back distance by this many mm (S1002's conicity
    /// turns with it: +7 mm takes the C80's 1 353 mm to S1002's design 1 360 mm).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    flange_back_change_mm: f64,
    /// Wheel profile instead of the vehicle's: `s1002` or a file (2-column y,z in mm, or
    /// SIMPACK .prw), e.g. vehicles/profiles/worn_heavy_haul_wheel.csv.
    #[arg(long)]
    wheel_profile: Option<String>,
    /// Rail profile instead of the vehicle's: `60kg` or a file (2-column, or SIMPACK .prr),
    /// e.g. vehicles/profiles/worn_heavy_haul_rail.csv.
    #[arg(long)]
    rail_profile: Option<String>,
    /// Mirror the --rail-profile's y (MiniProf rails are measured with the field side to −y).
    #[arg(long)]
    mirror_rail_y: bool,
    /// Rail inclination 1:N of a --rail-profile (0 when it is already in track position).
    #[arg(long, default_value_t = 40.0, value_name = "N")]
    rail_inclination: f64,
    /// Flange back-to-back distance with a --wheel-profile/--rail-profile, mm [default: the
    /// vehicle's].
    #[arg(long)]
    flange_back_mm: Option<f64>,
    /// Rigid rails instead of the compliant rails of the paper's tracks (as Wickens' and
    /// Klingel's closed forms assume).
    #[arg(long)]
    rigid_rails: bool,
    /// Highest frequency of the modes reported, Hz.
    #[arg(long, default_value_t = 20.0)]
    max_frequency_hz: f64,
    /// Sweep the wheel–rail pairs the project carries instead of one: S1002 on 60 kg/m 1:40 at
    /// 1 353, 1 356 and 1 360 mm flange back and the worn heavy-haul pair at 1 347.4 mm, each
    /// in all three views (linear stuck and sliding, kink-and-coast, run-down); writes
    /// pairs.csv, pairs.json and pairs.svg (critical speed against conicity). About a minute.
    #[arg(long)]
    pairs: bool,
    /// Also the nonlinear view: kink-and-coast (from below the limit cycle, 6 mm kink, 2 m/s²)
    /// and the run-down of Iwnicki et al. (2015: kicked onto the limit cycle at the top
    /// speed, 1.5 m/s²) from the highest speed, their amplitudes against speed drawn as one
    /// bifurcation chart, and each critical speed and limit-cycle frequency beside the linear
    /// ones (about two minutes).
    #[arg(long)]
    nonlinear: bool,
    /// Output folder: modes.csv, modes.json, root_locus.svg, damping.svg (and with
    /// --nonlinear bifurcation.csv, bifurcation.svg).
    #[arg(long, default_value = "modes")]
    out: PathBuf,
}

pub fn run(args: ModesArgs) -> Result<()> {
    let mut vehicle = railforce::vehicle::Vehicle::load(&super::builtin::resolve(&args.vehicle)?)?;
    if args.wheel_profile.is_some() || args.rail_profile.is_some() {
        let geo = &vehicle.contact.geometry;
        let mirror = |m: bool| railforce::contact::profile::LoadOptions { mirror_y: m };
        let profile =
            |given: &Option<String>, own: &railforce::contact::Profile, wheel: bool| match given {
                None => Ok(own.clone()),
                Some(p) => {
                    let p = super::builtin::resolve(std::path::Path::new(p))
                        .map(|p| p.to_string_lossy().into_owned())
                        .unwrap_or_else(|_| p.clone());
                    if wheel {
                        railforce::contact::profile::wheel_by_name_or_file(&p, mirror(false))
                    } else {
                        railforce::contact::profile::rail_by_name_or_file(
                            &p,
                            mirror(args.mirror_rail_y),
                        )
                    }
                }
            };
        let wheel = profile(&args.wheel_profile, geo.wheel(), true)?;
        let rail = profile(&args.rail_profile, geo.rail(), false)?;
        let inclination = if args.rail_profile.is_none() || args.rail_inclination <= 0.0 {
            0.0 // the vehicle's rail is already inclined in its geometry
        } else {
            (1.0 / args.rail_inclination).atan()
        };
        let fb = args.flange_back_mm.map_or(geo.flange_back, |f| f * 1e-3);
        vehicle = vehicle.with_profile_pair(wheel, rail, inclination, fb)?;
    } else if let Some(f) = args.flange_back_mm {
        vehicle = vehicle.with_flange_back_changed(f * 1e-3 - vehicle.contact.geometry.flange_back);
    }
    let vehicle = vehicle.with_flange_back_changed(args.flange_back_change_mm * 1e-3);
    let mut spec = railforce::track::TrackSpec::load(&super::builtin::resolve(
        std::path::Path::new("tracks/tangent.toml"),
    )?)?;
    spec.irregularity = None;
    if args.rigid_rails {
        spec.rail_support = None;
    }
    let track = railforce::track::Track::new(spec, None);
    let speeds: Vec<f64> = super::contact::range(&args.speeds, "--speeds")?
        .into_iter()
        .map(|v| v / 3.6)
        .collect();
    if speeds.iter().any(|&v| v <= 0.0) {
        bail!("--speeds {}: every speed must be positive", args.speeds);
    }
    if args.pairs {
        return pairs(&vehicle, &track, &speeds, &args.out);
    }
    let limits: Vec<FrictionLimit> = match args.friction.as_str() {
        "stuck" => vec![FrictionLimit::Stuck],
        "sliding" => vec![FrictionLimit::Sliding],
        "equivalent" => vec![FrictionLimit::Equivalent],
        "all" => vec![
            FrictionLimit::Stuck,
            FrictionLimit::Sliding,
            FrictionLimit::Equivalent,
        ],
        _ => vec![FrictionLimit::Stuck, FrictionLimit::Sliding],
    };
    let amplitude = args.amplitude_mm * 1e-3;
    let conicity = vehicle.contact.table().equivalent_conicity(amplitude);
    eprintln!(
        "{}: {} speeds {:.0}–{:.0} km/h, contact quasi-linearised at {} mm (equivalent conicity {}), friction {}",
        vehicle.name,
        speeds.len(),
        speeds[0] * 3.6,
        speeds[speeds.len() - 1] * 3.6,
        args.amplitude_mm,
        conicity.map_or("—".into(), |l| format!("{l:.4}")),
        args.friction
    );
    std::fs::create_dir_all(&args.out)?;
    let mut csv = String::from(
        "friction,speed_kmh,rank,frequency_hz,damping_ratio,real_per_s,imag_rad_per_s,name,dominant_body,dominant_dof,dominant_share\n",
    );
    let mut json_limits = serde_json::Map::new();
    let mut locus = Vec::new();
    let mut damping = Vec::new();
    for limit in limits {
        let t0 = std::time::Instant::now();
        let sweep = modes(
            &vehicle,
            &track,
            &ModesOptions {
                speeds: speeds.clone(),
                amplitude,
                friction: limit,
                max_frequency: args.max_frequency_hz,
            },
        )?;
        let crit = critical_speeds(&sweep);
        eprintln!(
            "friction {}: {} speeds in {:.1} s",
            limit.name(),
            sweep.len(),
            t0.elapsed().as_secs_f64()
        );
        print_critical(limit, &crit);
        for s in &sweep {
            for (k, m) in s.modes.iter().enumerate() {
                csv += &format!(
                    "{},{:.1},{},{:.4},{:.5},{:.5},{:.5},{},{},{},{:.3}\n",
                    limit.name(),
                    s.speed_kmh,
                    k + 1,
                    m.frequency_hz,
                    m.damping_ratio,
                    m.real,
                    m.imag,
                    m.name,
                    m.dominant.0,
                    m.dominant.1,
                    m.dominant.2
                );
            }
        }
        charts(limit, &sweep, &crit, &mut locus, &mut damping);
        json_limits.insert(
            limit.name().into(),
            serde_json::json!({"critical": crit, "sweep": sweep}),
        );
    }
    let nonlinear = if args.nonlinear {
        Some(bifurcation(&vehicle, &track, &speeds, &args.out)?)
    } else {
        None
    };
    let json = serde_json::json!({
        "nonlinear": nonlinear,
        "vehicle": vehicle.name,
        "flange_back_m": vehicle.contact.geometry.flange_back,
        "amplitude_mm": args.amplitude_mm,
        "equivalent_conicity": conicity,
        "creep": "linear Kalker (the run's creep law replaced for the linearisation)",
        "track": "smooth tangent, compliant rails of tracks/tangent.toml",
        "limits": json_limits,
    });
    let write = |name: &str, text: &str| {
        railforce::io::write_atomic(&args.out.join(name), |w| w.write_all(text.as_bytes()))
    };
    write("modes.csv", &csv)?;
    write("modes.json", &(serde_json::to_string_pretty(&json)? + "\n"))?;
    let mut chart = Chart::new(
        "Root locus: eigenvalues from 20 to 200 km/h",
        "real part, 1/s (> 0 unstable)",
        "frequency, Hz",
        locus,
    );
    chart.size.1 = 520.0;
    write("root_locus.svg", &chart.to_svg())?;
    let mut chart = Chart::new(
        "Damping ratio of each family's least damped mode",
        "speed, km/h",
        "damping ratio",
        damping,
    );
    chart.size.1 = 460.0;
    write("damping.svg", &chart.to_svg())?;
    eprintln!(
        "wrote modes.csv, modes.json, root_locus.svg, damping.svg in {}",
        args.out.display()
    );
    Ok(())
}

fn print_critical(limit: FrictionLimit, crit: &[Critical]) {
    println!("friction {}:", limit.name());
    println!(
        "  {:<28} {:>18} {:>12} {:>14}",
        "mode family", "linear critical", "frequency", "least damping"
    );
    for c in crit {
        println!(
            "  {:<28} {:>18} {:>9.2} Hz {:>14.4}",
            c.name,
            c.speed_kmh
                .map_or("stable".to_string(), |v| format!("{v:.0} km/h")),
            c.frequency_hz,
            c.min_damping
        );
    }
}

/// The families that matter on a chart: hunting, sway, yaw (the rest are listed in the CSV).
fn charts(
    limit: FrictionLimit,
    sweep: &[SpeedModes],
    crit: &[Critical],
    locus: &mut Vec<Series>,
    damping: &mut Vec<Series>,
) {
    let mut names: Vec<&str> = crit.iter().map(|c| c.name.as_str()).collect();
    names.retain(|n| n.contains("hunting") || n.contains("sway") || n.contains("carbody yaw"));
    for name in names {
        let mut pts = Vec::new();
        let mut zeta = Vec::new();
        for s in sweep {
            let fam: Vec<_> = s.modes.iter().filter(|m| m.name == name).collect();
            for m in &fam {
                pts.push((m.real, m.frequency_hz));
            }
            if let Some(m) = fam
                .iter()
                .min_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio))
            {
                zeta.push((s.speed_kmh, m.damping_ratio));
            }
        }
        let label = format!("{name} ({})", limit.name());
        locus.push(Series::points(label.clone(), pts));
        damping.push(Series::line(label, zeta));
    }
}

/// Kink-and-coast and run-down from the highest speed of the sweep down to the lowest: the
/// leading wheelset's amplitude against speed for both branches (bifurcation.csv, .svg), and
/// each method's critical speed and limit-cycle frequency (printed, returned for the JSON).
fn bifurcation(
    vehicle: &railforce::vehicle::Vehicle,
    track: &railforce::track::Track,
    speeds: &[f64],
    out: &std::path::Path,
) -> Result<serde_json::Value> {
    let runs = railforce::sim::modes::nonlinear_views(vehicle, track, speeds)?;
    let mut csv = String::from("method,speed_kmh,amplitude_mm,frequency_hz\n");
    let mut series = Vec::new();
    let mut json = serde_json::Map::new();
    println!(
        "nonlinear, smooth tangent from {:.0} to {:.0} km/h:",
        speeds[speeds.len() - 1] * 3.6,
        (speeds[0] * 3.6).max(50.0)
    );
    for (name, run) in ["kink-and-coast", "run-down"].iter().zip(&runs) {
        for (v, a, f) in &run.blocks {
            csv += &format!("{name},{v:.2},{a:.3},{f:.3}\n");
        }
        series.push(Series::points(
            name.to_string(),
            run.blocks.iter().map(|b| (b.0, b.1)).collect(),
        ));
        println!(
            "  {name:<16} {}",
            match (run.critical_kmh, run.frequency_hz, run.cycle_kmh) {
                (Some(c), Some(f), Some(at)) => format!(
                    "hunting (≥ {:.1} mm) down to {c:.0} km/h, limit cycle {f:.2} Hz at {at:.0} km/h (the lowest speed it held its amplitude)",
                    railforce::sim::fidelity::HUNTING_AMPLITUDE * 1e3
                ),
                (Some(c), _, _) => format!("hunting down to {c:.0} km/h"),
                _ => match &run.derailed {
                    Some(m) => format!("derails: {m}"),
                    None => "no hunting".into(),
                },
            }
        );
        json.insert(name.to_string(), serde_json::to_value(run)?);
    }
    let write = |name: &str, text: &str| {
        railforce::io::write_atomic(&out.join(name), |w| w.write_all(text.as_bytes()))
    };
    write("bifurcation.csv", &csv)?;
    let mut chart = Chart::new(
        "Bifurcation: amplitude of the leading wheelset against speed, both branches",
        "speed, km/h",
        "half peak-to-peak lateral amplitude, mm",
        series,
    );
    chart.size.1 = 440.0;
    write("bifurcation.svg", &chart.to_svg())?;
    Ok(serde_json::Value::Object(json))
}

/// The built-in wheel–rail pairs, each in all three views ([`railforce::sim::modes::compare`]).
fn pairs(
    vehicle: &railforce::vehicle::Vehicle,
    track: &railforce::track::Track,
    speeds: &[f64],
    out: &std::path::Path,
) -> Result<()> {
    use railforce::contact::profile::{LoadOptions, load};
    let file = |p: &str| super::builtin::resolve(std::path::Path::new(p));
    let worn = vehicle.with_profile_pair(
        load(
            &file("vehicles/profiles/worn_heavy_haul_wheel.csv")?,
            LoadOptions::default(),
        )?,
        load(
            &file("vehicles/profiles/worn_heavy_haul_rail.csv")?,
            LoadOptions::default(),
        )?,
        0.0,
        1.3474,
    )?;
    let base = vehicle.contact.geometry.flange_back;
    let cases = [
        (
            "S1002 / 60 kg 1:40",
            vehicle.with_flange_back_changed(1.353 - base),
        ),
        (
            "S1002 / 60 kg 1:40",
            vehicle.with_flange_back_changed(1.356 - base),
        ),
        (
            "S1002 / 60 kg 1:40",
            vehicle.with_flange_back_changed(1.360 - base),
        ),
        ("worn heavy-haul (CONTACT test bank)", worn),
    ];
    std::fs::create_dir_all(out)?;
    let mut csv = String::from(
        "pair,flange_back_mm,conicity_3mm,stuck_kmh,stuck_mode,stuck_hz,sliding_kmh,sliding_mode,sliding_hz,kink_kmh,kink_hz,run_down_kmh,run_down_hz,run_down_sigma_y_rms_kn,run_down_sigma_y_limit_kn,kink_derails,run_down_derails\n",
    );
    let mut rows = Vec::new();
    let mut pts: [Vec<(f64, f64)>; 4] = Default::default();
    println!(
        "{}: {:<36} {:>8} {:>9} {:>24} {:>24} {:>16} {:>16}",
        vehicle.name,
        "pair",
        "flange",
        "λe 3 mm",
        "linear stuck",
        "linear sliding",
        "kink-and-coast",
        "run-down"
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.2}"));
    let derails = |n: &Option<railforce::sim::modes::Nonlinear>| {
        n.as_ref().is_some_and(|n| n.derailed.is_some())
    };
    for (name, v) in &cases {
        let t0 = std::time::Instant::now();
        let c = railforce::sim::modes::compare(v, track, speeds, true)?;
        let lin = |c: &Option<railforce::sim::modes::Critical>| match c {
            Some(c) => format!(
                "{:.0} km/h {:.2} Hz",
                c.speed_kmh.unwrap_or(f64::NAN),
                c.frequency_hz
            ),
            None => "damped".into(),
        };
        let non = |n: &Option<railforce::sim::modes::Nonlinear>| match n
            .as_ref()
            .and_then(|n| n.critical_kmh.map(|k| (k, n.frequency_hz)))
        {
            Some((k, f)) => format!(
                "{k:.0} km/h {}",
                f.map_or(String::new(), |f| format!("{f:.2} Hz"))
            ),
            None if derails(n) => "derails".into(),
            None => "none".into(),
        };
        println!(
            "  {:<36} {:>5.1} mm {:>9} {:>24} {:>24} {:>16} {:>16}   ({:.0} s)",
            name,
            c.flange_back_m * 1e3,
            c.conicity.map_or("—".into(), |l| format!("{l:.4}")),
            lin(&c.stuck),
            lin(&c.sliding),
            non(&c.kink_and_coast),
            non(&c.run_down),
            t0.elapsed().as_secs_f64(),
        );
        let en = |n: &Option<railforce::sim::modes::Nonlinear>| {
            n.as_ref().and_then(|n| n.running_stability_kn)
        };
        let kmh =
            |c: &Option<railforce::sim::modes::Critical>| c.as_ref().and_then(|c| c.speed_kmh);
        let hz = |c: &Option<railforce::sim::modes::Critical>| c.as_ref().map(|c| c.frequency_hz);
        let mode = |c: &Option<railforce::sim::modes::Critical>| {
            c.as_ref().map_or(String::new(), |c| c.name.clone())
        };
        let nk =
            |n: &Option<railforce::sim::modes::Nonlinear>| n.as_ref().and_then(|n| n.critical_kmh);
        let nf =
            |n: &Option<railforce::sim::modes::Nonlinear>| n.as_ref().and_then(|n| n.frequency_hz);
        csv += &format!(
            "{name},{:.1},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            c.flange_back_m * 1e3,
            c.conicity.map_or(String::new(), |l| format!("{l:.4}")),
            opt(kmh(&c.stuck)),
            mode(&c.stuck),
            opt(hz(&c.stuck)),
            opt(kmh(&c.sliding)),
            mode(&c.sliding),
            opt(hz(&c.sliding)),
            opt(nk(&c.kink_and_coast)),
            opt(nf(&c.kink_and_coast)),
            opt(nk(&c.run_down)),
            opt(nf(&c.run_down)),
            opt(en(&c.run_down).map(|e| e.0)),
            opt(en(&c.run_down).map(|e| e.1)),
            derails(&c.kink_and_coast),
            derails(&c.run_down),
        );
        if let Some(l) = c.conicity {
            for (k, v) in [
                kmh(&c.stuck),
                kmh(&c.sliding),
                nk(&c.kink_and_coast),
                nk(&c.run_down),
            ]
            .into_iter()
            .enumerate()
            {
                if let Some(v) = v {
                    pts[k].push((l, v));
                }
            }
        }
        rows.push(serde_json::json!({"pair": name, "comparison": c}));
    }
    let write = |name: &str, text: &str| {
        railforce::io::write_atomic(&out.join(name), |w| w.write_all(text.as_bytes()))
    };
    write("pairs.csv", &csv)?;
    write(
        "pairs.json",
        &(serde_json::to_string_pretty(
            &serde_json::json!({"vehicle": vehicle.name, "pairs": rows}),
        )? + "\n"),
    )?;
    let [a, b, c, d] = pts;
    let mut chart = Chart::new(
        format!(
            "{}: critical speed against equivalent conicity (3 mm)",
            vehicle.name
        ),
        "equivalent conicity at 3 mm",
        "critical speed, km/h (a pair without a point: stable 50–200 km/h)",
        vec![
            Series::points("linear, friction stuck", a),
            Series::points("linear, friction sliding", b),
            Series::points("kink-and-coast", c),
            Series::points("run-down", d),
        ],
    );
    chart.size.1 = 440.0;
    write("pairs.svg", &chart.to_svg())?;
    eprintln!(
        "wrote pairs.csv, pairs.json, pairs.svg in {}",
        out.display()
    );
    Ok(())
}
