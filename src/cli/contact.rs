//! `railforce contact`: the contact of both wheels of a wheelset in a given state.

use anyhow::{Result, bail};
use clap::Args;
use railforce::contact::{
    CreepLaw, Material, Side, WheelsetGeometry, WheelsetMotion, profile, split_load, wheel_force,
};

/// Wheel, rail and wheelset description shared by contact commands.
#[derive(Debug, Args)]
pub struct WheelsetArgs {
    /// Wheel profile: `s1002` or a file (2-column y,z in mm, or SIMPACK .prw).
    #[arg(long, default_value = "s1002")]
    pub wheel: String,
    /// Rail profile: `60kg` (CHN60/60E1 head) or a file (2-column y,z in mm, or SIMPACK .prr).
    #[arg(long, default_value = "60kg")]
    pub rail: String,
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
            profile::wheel_by_name_or_file(&self.wheel)?,
            profile::rail_by_name_or_file(&self.rail)?,
            incl,
            self.gauge_mm * 1e-3,
            self.flange_back_mm * 1e-3,
            0.070,
            self.r0_mm * 1e-3,
        )?)
    }
}

#[derive(Debug, Args)]
pub struct ContactArgs {
    #[command(flatten)]
    wheelset: WheelsetArgs,
    /// Lateral shift of the wheelset, mm (+ to the left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    y_mm: f64,
    /// Yaw angle, mrad (+ turning left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw_mrad: f64,
    /// Normal load per wheel, kN.
    #[arg(long, default_value_t = 122.6)]
    load_kn: f64,
    /// Forward speed, km/h.
    #[arg(long, default_value_t = 60.0)]
    speed_kmh: f64,
    /// Wheelset spin (angular velocity about the axle), rad/s [default: speed / r0, pure
    /// rolling at the nominal radius].
    #[arg(long, allow_hyphen_values = true)]
    spin: Option<f64>,
    /// Lateral velocity of the wheelset, m/s.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    lateral_velocity: f64,
    /// Yaw rate, rad/s.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw_rate: f64,
    /// Friction coefficient.
    #[arg(long, default_value_t = 0.3)]
    mu: f64,
    /// Creep force law: polach, fastsim or linear.
    #[arg(long, default_value = "polach")]
    law: String,
    /// Also print the equivalent conicity (EN 15302 integral method) for amplitudes 1–10 mm.
    #[arg(long)]
    conicity: bool,
}

pub fn run(args: ContactArgs) -> Result<()> {
    let law = CreepLaw::parse(&args.law)
        .ok_or_else(|| anyhow::anyhow!("--law must be polach, fastsim or linear"))?;
    if !(args.load_kn > 0.0 && args.speed_kmh > 0.0 && args.mu > 0.0) {
        bail!("--load-kn, --speed-kmh and --mu must be positive");
    }
    let geo = args.wheelset.geometry()?;
    let state = geo.solve(args.y_mm * 1e-3, args.yaw_mrad * 1e-3);
    let speed = args.speed_kmh / 3.6;
    let motion = WheelsetMotion {
        spin: args.spin.unwrap_or(speed / geo.nominal_radius),
        lateral_velocity: args.lateral_velocity,
        yaw_rate: args.yaw_rate,
        yaw: args.yaw_mrad * 1e-3,
        ..WheelsetMotion::rolling(speed, geo.nominal_radius)
    };
    let material = Material::STEEL;
    let centre = [0.0, state.y, state.z];
    println!(
        "wheelset y {:+.2} mm, yaw {:+.2} mrad → roll {:+.4} mrad, centre height {:.3} mm",
        args.y_mm,
        args.yaw_mrad,
        state.roll * 1e3,
        state.z * 1e3
    );
    println!(
        "{:<11} {:>8} {:>8} {:>8} {:>9} {:>8} {:>6} {:>6} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "wheel",
        "wheel_y",
        "rail_y",
        "track_y",
        "r_roll",
        "angle",
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
        "{:<11} {:>8} {:>8} {:>8} {:>9} {:>8} {:>6} {:>6} {:>7} {:>9} {:>9} {:>9} {:>8} {:>8} {:>8} {:>8}",
        "", "mm", "mm", "mm", "mm", "deg", "mm", "mm", "MPa", "", "", "1/m", "kN", "kN", "kN", "kN"
    );
    for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        let main = state.wheels[k];
        let load = args.load_kn * 1e3;
        let (n_main, n_second) = match &state.secondary[k] {
            Some(sec) => split_load(&main.hertz, &sec.hertz, sec.gap, load, &material),
            None => (load, 0.0),
        };
        let mut contacts = vec![(main, n_main, "")];
        if let Some(sec) = state.secondary[k] {
            contacts.push((sec, n_second, " (2nd)"));
        }
        for (c, n, tag) in contacts {
            let f = wheel_force(
                side, &c, centre, state.roll, &motion, n, args.mu, &material, law,
            );
            let name = format!("{}{tag}", if k == 0 { "left" } else { "right" });
            println!(
                "{:<11} {:>8.2} {:>8.2} {:>8.1} {:>9.2} {:>8.3} {:>6.2} {:>6.2} {:>7.0} {:>9.2e} {:>9.2e} {:>9.3} {:>8.2} {:>8.2} {:>8.2} {:>8.2}",
                name,
                c.wheel_y * 1e3,
                c.rail_y * 1e3,
                c.point[1] * 1e3,
                c.rolling_radius * 1e3,
                c.angle.to_degrees(),
                f.ellipse.a * 1e3,
                f.ellipse.b * 1e3,
                f.ellipse.p0 * 1e-6,
                f.creepage.x,
                f.creepage.y,
                f.creepage.spin,
                f.creep.x * 1e-3,
                f.creep.y * 1e-3,
                f.force[1] * 1e-3,
                f.force[2] * 1e-3
            );
            if c.gap > 0.0 {
                println!(
                    "       second contact {:.3} mm above the first",
                    c.gap * 1e3
                );
            }
        }
    }
    println!(
        "wheel_y: on the wheel profile from the tape circle (+ field side); rail_y: from the gauge point (+ field side)"
    );
    if args.conicity {
        let table = geo.table(15e-3, 1e-4);
        println!("equivalent conicity (EN 15302 integral method):");
        for amp_mm in [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
            match table.equivalent_conicity(amp_mm * 1e-3) {
                Some(l) => println!("  amplitude {amp_mm:>4.1} mm: {l:.4}"),
                None => println!("  amplitude {amp_mm:>4.1} mm: no oscillation found"),
            }
        }
    }
    Ok(())
}
