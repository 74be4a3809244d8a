//! `railforce contact`: the contact of both wheels of a wheelset in a given state.

use anyhow::{Result, bail};
use clap::Args;
use railforce::contact::{
    CREEP_SPEED_FLOOR, ContactModel, CreepLaw, Material, QuasiStatic, Side, WheelsetGeometry,
    WheelsetState, profile,
};
use std::path::PathBuf;

/// Wheel, rail and wheelset description shared by contact commands.
#[derive(Debug, Args)]
pub struct WheelsetArgs {
    /// Wheel profile: `s1002` or a file (2-column y,z in mm, or SIMPACK .prw).
    #[arg(long, default_value = "s1002")]
    pub wheel: String,
    /// Rail profile: `60kg` (CHN60/60E1 head) or a file (2-column y,z in mm, or SIMPACK .prr).
    #[arg(long, default_value = "60kg")]
    pub rail: String,
    /// Mirror the wheel profile file's y (its field side to −y).
    #[arg(long)]
    pub mirror_wheel_y: bool,
    /// Mirror the rail profile file's y (MiniProf rails are measured with the field side to −y).
    #[arg(long)]
    pub mirror_rail_y: bool,
    /// Rail inclination 1:N (0 when the rail profile is already inclined).
    #[arg(long, default_value_t = 40.0, value_name = "N")]
    pub inclination: f64,
    /// Track gauge, mm.
    #[arg(long, default_value_t = 1435.0)]
    pub gauge_mm: f64,
    /// Flange back-to-back distance, mm (1353 Chinese wheelsets, 1360 the S1002 benchmark).
    #[arg(long, default_value_t = 1353.0)]
    pub flange_back_mm: f64,
    /// Nominal rolling radius at the tape circle, mm.
    #[arg(long, default_value_t = 420.0)]
    pub r0_mm: f64,
    /// Tape circle outside the flange back, mm (70 for S1002).
    #[arg(long, default_value_t = 70.0)]
    pub tape_offset_mm: f64,
}

impl WheelsetArgs {
    /// Builds the wheelset geometry.
    pub fn geometry(&self) -> Result<WheelsetGeometry> {
        if self.inclination < 0.0 {
            bail!(
                "--inclination must be 0 or positive, got {}",
                self.inclination
            );
        }
        let incl = if self.inclination > 0.0 {
            (1.0 / self.inclination).atan()
        } else {
            0.0
        };
        Ok(WheelsetGeometry::new(
            profile::wheel_by_name_or_file(
                &self.wheel,
                profile::LoadOptions {
                    mirror_y: self.mirror_wheel_y,
                },
            )?,
            profile::rail_by_name_or_file(
                &self.rail,
                profile::LoadOptions {
                    mirror_y: self.mirror_rail_y,
                },
            )?,
            incl,
            self.gauge_mm * 1e-3,
            self.flange_back_mm * 1e-3,
            self.tape_offset_mm * 1e-3,
            self.r0_mm * 1e-3,
        )?)
    }
}

#[derive(Debug, Args)]
pub struct ContactArgs {
    /// Vehicle file: use its wheel and rail profiles, gauge, contact table and contact settings
    /// (friction, creep law, material, damping), exactly what its runs compute. Without it the
    /// wheelset options below describe the contact.
    #[arg(long)]
    vehicle: Option<PathBuf>,
    #[command(flatten)]
    wheelset: WheelsetArgs,
    /// Lateral shift of the wheelset, mm (+ to the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = super::finite)]
    y_mm: f64,
    /// Yaw angle, mrad (+ turning left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = super::finite)]
    yaw_mrad: f64,
    /// Vertical load per wheel, kN: the wheelset height is found at which each wheel carries it
    /// [default: the --vehicle's static wheel load, else 122.6].
    #[arg(long)]
    load_kn: Option<f64>,
    /// Wheelset roll relative to the rail plane, mrad, beyond the rigid roll at this shift.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true, value_parser = super::finite)]
    extra_roll_mrad: f64,
    /// Forward speed, km/h.
    #[arg(long, default_value_t = 60.0)]
    speed_kmh: f64,
    /// Wheelset spin (angular velocity about the axle), rad/s [default: speed over the mean of
    /// the two wheels' rolling radii at this shift: the wheelset rolls, with no longitudinal
    /// creep when centred].
    #[arg(long, allow_hyphen_values = true)]
    spin: Option<f64>,
    /// Lateral velocity of the wheelset, m/s.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    lateral_velocity: f64,
    /// Yaw rate, rad/s.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw_rate: f64,
    /// Friction coefficient (without --vehicle).
    #[arg(long, default_value_t = 0.3)]
    mu: f64,
    /// Creep force law: polach, fastsim or linear (without --vehicle).
    #[arg(long, default_value = "polach")]
    law: String,
    /// Also print the equivalent conicity (EN 15302 integral method) for amplitudes 1–10 mm.
    #[arg(long)]
    conicity: bool,
    /// Sweep the lateral shift, mm, `FROM:TO:STEP` (e.g. `-12:12:0.5`), writing one row per
    /// state and wheel to --out (CSV, or JSON when the name ends in .json).
    #[arg(long, value_name = "FROM:TO:STEP", allow_hyphen_values = true)]
    sweep_y: Option<String>,
    /// Sweep the yaw angle, mrad, `FROM:TO:STEP` (with or without --sweep-y).
    #[arg(long, value_name = "FROM:TO:STEP", allow_hyphen_values = true)]
    sweep_yaw: Option<String>,
    /// Output of a sweep [default: contact_sweep.csv].
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The state the options describe at shift `y` and yaw `yaw` (m, rad).
fn state(args: &ContactArgs, y: f64, yaw: f64) -> WheelsetState {
    WheelsetState {
        y,
        yaw,
        extra_roll: args.extra_roll_mrad * 1e-3,
        speed: args.speed_kmh / 3.6,
        lateral_velocity: args.lateral_velocity,
        yaw_rate: args.yaw_rate,
        spin: args.spin,
    }
}

/// Parses `FROM:TO:STEP`.
pub(super) fn range(text: &str, what: &str) -> Result<Vec<f64>> {
    let parts: Vec<f64> = text
        .split(':')
        .map(|p| p.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| anyhow::anyhow!("{what} {text}: expected FROM:TO:STEP, e.g. -10:10:0.5"))?;
    let [a, b, step] = parts[..] else {
        bail!("{what} {text}: expected FROM:TO:STEP, e.g. -10:10:0.5");
    };
    if !(step > 0.0 && step.is_finite() && a.is_finite() && b.is_finite() && b >= a) {
        bail!("{what} {text}: FROM ≤ TO and STEP > 0");
    }
    let n = railforce::bounds::to_count(((b - a) / step + 1e-9).floor()) + 1;
    if n > 100_000 {
        bail!("{what} {text}: {n} points, more than 100 000");
    }
    Ok((0..n).map(|i| a + i as f64 * step).collect())
}

pub fn run(args: ContactArgs) -> Result<()> {
    let vehicle = match &args.vehicle {
        Some(p) => Some(railforce::vehicle::Vehicle::load(
            &super::builtin::resolve(p)?,
        )?),
        None => None,
    };
    let load_kn = args
        .load_kn
        .unwrap_or_else(|| vehicle.as_ref().map_or(122.6, |v| v.static_wheel_load_kn()));
    if !(load_kn > 0.0 && args.speed_kmh > 0.0 && args.mu > 0.0) {
        bail!("--load-kn, --speed-kmh and --mu must be positive");
    }
    let setup = match &vehicle {
        Some(v) => v.quasi_static(load_kn * 1e3),
        None => {
            let law = CreepLaw::parse(&args.law)
                .ok_or_else(|| anyhow::anyhow!("--law must be polach, fastsim or linear"))?;
            let geo = args.wheelset.geometry()?;
            QuasiStatic {
                table: geo.table(
                    railforce::vehicle::ContactSettings::TABLE_RANGE,
                    railforce::vehicle::ContactSettings::TABLE_STEP,
                ),
                model: ContactModel {
                    material: Material::STEEL,
                    friction: args.mu,
                    flange_friction: args.mu,
                    law,
                    damping_ratio: 0.05,
                },
                mass: 600.0,
                r0: geo.nominal_radius,
                load: load_kn * 1e3,
                flange_angle: 70f64.to_radians(),
            }
        }
    };
    let speed = args.speed_kmh / 3.6;
    if speed < CREEP_SPEED_FLOOR {
        eprintln!(
            "note: creepages are taken over {CREEP_SPEED_FLOOR} m/s below that speed, as in a run"
        );
    }
    if args.sweep_y.is_some() || args.sweep_yaw.is_some() {
        return sweep(&setup, &args);
    }
    let y = args.y_mm * 1e-3;
    let yaw = args.yaw_mrad * 1e-3;
    if y.abs() > railforce::vehicle::ContactSettings::TABLE_RANGE {
        anyhow::bail!(
            "--y-mm {}: a shift beyond the contact table (±{:.0} mm) puts the wheel off its rail: no contact to compute",
            args.y_mm,
            railforce::vehicle::ContactSettings::TABLE_RANGE * 1e3
        );
    }
    let st = setup.solve(&state(&args, y, yaw));
    println!(
        "wheelset y {:+.2} mm, yaw {:+.2} mrad → rigid roll {:+.4} mrad (+ {:+.3} given), centre height {:.3} mm",
        args.y_mm,
        args.yaw_mrad,
        st.roll * 1e3,
        args.extra_roll_mrad,
        st.height * 1e3
    );
    match args.spin {
        Some(s) => println!("spin {s:.4} rad/s (given)"),
        None => println!(
            "spin {:.4} rad/s: rolling at the mean rolling radius at this shift, {:.2} mm (--spin to set it)",
            st.spin,
            st.rolling_radius * 1e3
        ),
    }
    println!(
        "{:<11} {:>8} {:>8} {:>9} {:>8} {:>8} {:>6} {:>6} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "wheel",
        "approach",
        "track_y",
        "r_roll",
        "angle",
        "N",
        "a",
        "b",
        "p0",
        "xi_x",
        "xi_y",
        "spin",
        "Fx",
        "Fy",
        "Y",
        "Q"
    );
    println!(
        "{:<11} {:>8} {:>8} {:>9} {:>8} {:>8} {:>6} {:>6} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "", "um", "mm", "mm", "deg", "kN", "mm", "mm", "MPa", "", "", "1/m", "kN", "kN", "kN", "kN"
    );
    let limit = setup.nadal_limit();
    for wr in &st.wheels {
        let f = &wr.forces;
        let name = if wr.side == Side::Left {
            "left"
        } else {
            "right"
        };
        for (j, p) in f.patches.iter().enumerate() {
            let Some(p) = p else { continue };
            println!(
                "{:<11} {:>8.1} {:>8.1} {:>9.2} {:>8.3} {:>8.2} {:>6.2} {:>6.2} {:>7.0} {:>9.2e} {:>9.2e} {:>9.3} {:>8.2} {:>8.2} {:>8.2} {:>8.2}",
                format!("{name}{}", if j > 0 { " (2nd)" } else { "" }),
                wr.approach * 1e6,
                (y + p.point[1]) * 1e3,
                p.radius * 1e3,
                p.angle.to_degrees(),
                p.normal * 1e-3,
                p.ellipse.a * 1e3,
                p.ellipse.b * 1e3,
                p.ellipse.p0 * 1e-6,
                p.creepage.x,
                p.creepage.y,
                p.creepage.spin,
                p.creep.x * 1e-3,
                p.creep.y * 1e-3,
                p.force[1] * 1e-3,
                p.force[2] * 1e-3
            );
        }
        let yq = f.y_over_q();
        println!(
            "{:<11} wheel total Y {:+.2} kN, Q {:.2} kN, |Y|/Q {:.3} over {} patch(es)",
            "",
            f.force[1] * 1e-3,
            f.force[2] * 1e-3,
            yq,
            f.patches.iter().flatten().count()
        );
        if yq > limit {
            eprintln!(
                "warning: {name} wheel |Y|/Q {yq:.3} is beyond Nadal's flange-climb limit {limit:.3} (flange angle {:.0}°, μ {}): in a run this wheel would climb its flange",
                setup.flange_angle.to_degrees(),
                setup.model.friction
            );
        }
    }

    println!(
        "approach: of the wheelset centre below its rigid height; track_y: load centre of the patch (elastic strip contact, the simulator's)"
    );
    if args.conicity {
        println!("equivalent conicity (EN 15302 integral method):");
        for amp_mm in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
            match setup.table.equivalent_conicity(amp_mm * 1e-3) {
                Some(l) => println!("  amplitude {amp_mm:>4.1} mm: {l:.4}"),
                None => println!("  amplitude {amp_mm:>4.1} mm: no oscillation found"),
            }
        }
    }
    Ok(())
}

/// One row of a sweep.
#[derive(serde::Serialize)]
struct SweepRow {
    y_mm: f64,
    yaw_mrad: f64,
    wheel: &'static str,
    patches: usize,
    angle_deg: f64,
    rolling_radius_mm: f64,
    y_kn: f64,
    q_kn: f64,
    y_over_q: f64,
    fx_kn: f64,
    approach_um: f64,
    beyond_nadal: bool,
}

fn sweep(setup: &QuasiStatic, args: &ContactArgs) -> Result<()> {
    let ys = match &args.sweep_y {
        Some(r) => range(r, "--sweep-y")?,
        None => vec![args.y_mm],
    };
    let yaws = match &args.sweep_yaw {
        Some(r) => range(r, "--sweep-yaw")?,
        None => vec![args.yaw_mrad],
    };
    let limit = setup.nadal_limit();
    let range_mm = railforce::vehicle::ContactSettings::TABLE_RANGE * 1e3;
    if let Some(y) = ys.iter().find(|y| y.abs() > range_mm) {
        bail!("--sweep-y reaches {y} mm, beyond the contact table's ±{range_mm:.0} mm");
    }
    let mut rows = Vec::new();
    for &yaw in &yaws {
        for &y in &ys {
            let st = setup.solve(&state(args, y * 1e-3, yaw * 1e-3));
            for wr in &st.wheels {
                let f = &wr.forces;
                let yq = f.y_over_q();
                rows.push(SweepRow {
                    y_mm: y,
                    yaw_mrad: yaw,
                    wheel: if wr.side == Side::Left {
                        "left"
                    } else {
                        "right"
                    },
                    patches: f.patches.iter().flatten().count(),
                    angle_deg: f.main().map_or(f.rigid_angle, |p| p.angle).to_degrees(),
                    rolling_radius_mm: f.main().map_or(f.rigid_radius, |p| p.radius) * 1e3,
                    y_kn: f.force[1] * 1e-3,
                    q_kn: f.force[2] * 1e-3,
                    y_over_q: yq,
                    fx_kn: f.patches.iter().flatten().map(|p| p.creep.x).sum::<f64>() * 1e-3,
                    approach_um: wr.approach * 1e6,
                    beyond_nadal: yq > limit,
                });
            }
        }
    }
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("contact_sweep.csv"));
    let text = if out.extension().is_some_and(|e| e == "json") {
        serde_json::to_string_pretty(&serde_json::json!({
            "nadal_limit": limit,
            "flange_angle_deg": setup.flange_angle.to_degrees(),
            "friction": setup.model.friction,
            "speed_kmh": args.speed_kmh,
            "load_kn": setup.load * 1e-3,
            "rows": rows,
        }))?
    } else {
        let mut s = String::from(
            "y_mm,yaw_mrad,wheel,patches,angle_deg,rolling_radius_mm,y_kn,q_kn,y_over_q,fx_kn,approach_um,beyond_nadal\n",
        );
        for r in &rows {
            s += &format!(
                "{},{},{},{},{:.4},{:.4},{:.4},{:.4},{:.5},{:.4},{:.3},{}\n",
                r.y_mm,
                r.yaw_mrad,
                r.wheel,
                r.patches,
                r.angle_deg,
                r.rolling_radius_mm,
                r.y_kn,
                r.q_kn,
                r.y_over_q,
                r.fx_kn,
                r.approach_um,
                r.beyond_nadal
            );
        }
        s
    };
    railforce::io::write_atomic(&out, |w| w.write_all(text.as_bytes()))?;
    let climb = rows.iter().filter(|r| r.beyond_nadal).count();
    println!(
        "{} states × 2 wheels written to {}{}",
        ys.len() * yaws.len(),
        out.display(),
        if climb > 0 {
            format!("; {climb} wheel state(s) beyond Nadal's limit {limit:.3}")
        } else {
            String::new()
        }
    );
    if climb > 0 {
        eprintln!(
            "warning: {climb} wheel state(s) of the sweep lie beyond Nadal's flange-climb limit {limit:.3}"
        );
    }
    Ok(())
}
