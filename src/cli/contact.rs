//! `railforce contact`: the contact of both wheels of a wheelset in a given state.

use anyhow::{Result, bail};
use clap::Args;
use railforce::contact::{
    CREEP_SPEED_FLOOR, ContactModel, CreepLaw, Material, Side, WheelOnRail, WheelsetGeometry,
    evaluate, height_for_load, profile,
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
            profile::wheel_by_name_or_file(&self.wheel)?,
            profile::rail_by_name_or_file(&self.rail)?,
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
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    y_mm: f64,
    /// Yaw angle, mrad (+ turning left).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    yaw_mrad: f64,
    /// Vertical load per wheel, kN: the wheelset height is found at which each wheel carries it
    /// [default: the --vehicle's static wheel load, else 122.6].
    #[arg(long)]
    load_kn: Option<f64>,
    /// Wheelset roll relative to the rail plane, mrad, beyond the rigid roll at this shift.
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    extra_roll_mrad: f64,
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
    /// Friction coefficient (without --vehicle).
    #[arg(long, default_value_t = 0.3)]
    mu: f64,
    /// Creep force law: polach, fastsim or linear (without --vehicle).
    #[arg(long, default_value = "polach")]
    law: String,
    /// Also print the equivalent conicity (EN 15302 integral method) for amplitudes 1–10 mm.
    #[arg(long)]
    conicity: bool,
}

pub fn run(args: ContactArgs) -> Result<()> {
    let vehicle = match &args.vehicle {
        Some(p) => Some(railforce::vehicle::Vehicle::load(
            &super::builtin::resolve(p)?,
        )?),
        None => None,
    };
    let load_kn = args.load_kn.unwrap_or_else(|| {
        vehicle.as_ref().map_or(122.6, |v| {
            v.mass() * railforce::GRAVITY / (2 * v.contact.wheelsets.len()) as f64 * 1e-3
        })
    });
    if !(load_kn > 0.0 && args.speed_kmh > 0.0 && args.mu > 0.0) {
        bail!("--load-kn, --speed-kmh and --mu must be positive");
    }
    let (geo, model, mass) = match &vehicle {
        Some(v) => (
            v.contact.geometry.clone(),
            v.contact.model(),
            0.5 * v.bodies[v.contact.wheelsets[0]].mass,
        ),
        None => {
            let law = CreepLaw::parse(&args.law)
                .ok_or_else(|| anyhow::anyhow!("--law must be polach, fastsim or linear"))?;
            let model = ContactModel {
                material: Material::STEEL,
                friction: args.mu,
                law,
                damping_ratio: 0.05,
            };
            (args.wheelset.geometry()?, model, 600.0)
        }
    };
    let table = match &vehicle {
        Some(v) => v.contact.table().clone(),
        None => geo.table(
            railforce::vehicle::ContactSettings::TABLE_RANGE,
            railforce::vehicle::ContactSettings::TABLE_STEP,
        ),
    };
    let y = args.y_mm * 1e-3;
    let yaw = args.yaw_mrad * 1e-3;
    let rigid = table.lookup(y);
    let speed = args.speed_kmh / 3.6;
    if speed < CREEP_SPEED_FLOOR {
        eprintln!(
            "note: creepages are taken over {CREEP_SPEED_FLOOR} m/s below that speed, as in a run"
        );
    }
    println!(
        "wheelset y {:+.2} mm, yaw {:+.2} mrad → rigid roll {:+.4} mrad (+ {:+.3} given), centre height {:.3} mm",
        args.y_mm,
        args.yaw_mrad,
        rigid.roll * 1e3,
        args.extra_roll_mrad,
        rigid.z * 1e3
    );
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
    for side in [Side::Left, Side::Right] {
        let mut w = WheelOnRail::rolling(side, speed, geo.nominal_radius, 0.0, mass);
        w.y = y;
        w.yaw = yaw;
        w.roll = rigid.roll + args.extra_roll_mrad * 1e-3;
        w.velocity = [
            speed * yaw.cos() - args.lateral_velocity * yaw.sin(),
            speed * yaw.sin() + args.lateral_velocity * yaw.cos(),
            0.0,
        ];
        let spin = args.spin.unwrap_or(speed / geo.nominal_radius);
        w.angular_velocity = [-spin * yaw.sin(), spin * yaw.cos(), args.yaw_rate];
        w.height = height_for_load(&table, &model, &w, load_kn * 1e3);
        let f = evaluate(&table, &model, &w);
        let name = if side == Side::Left { "left" } else { "right" };
        for (j, p) in f.patches.iter().enumerate() {
            let Some(p) = p else { continue };
            println!(
                "{:<11} {:>8.1} {:>8.1} {:>9.2} {:>8.3} {:>8.2} {:>6.2} {:>6.2} {:>7.0} {:>9.2e} {:>9.2e} {:>9.3} {:>8.2} {:>8.2} {:>8.2} {:>8.2}",
                format!("{name}{}", if j > 0 { " (2nd)" } else { "" }),
                (rigid.z - w.height) * 1e6,
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
        println!(
            "{:<11} wheel total Y {:+.2} kN, Q {:.2} kN over {} patch(es)",
            "",
            f.force[1] * 1e-3,
            f.force[2] * 1e-3,
            f.patches.iter().flatten().count()
        );
    }
    println!(
        "approach: of the wheelset centre below its rigid height; track_y: load centre of the patch (elastic strip contact, the simulator's)"
    );
    if args.conicity {
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
