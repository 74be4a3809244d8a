//! `bench step`: the same run at several integration steps against a finer one.

use anyhow::Result;
use railforce::sim::Integrator;
use railforce::sim::step_study::step_study;
use railforce::track::{Track, TrackSpec};
use std::path::{Path, PathBuf};

/// What `bench step` compares.
#[derive(Debug, clap::Args)]
pub struct StepArgs {
    /// Vehicle file.
    #[arg(long, default_value = "vehicles/c80.toml")]
    vehicle: PathBuf,
    /// Track file.
    #[arg(long, default_value = "tracks/curve_r400.toml")]
    track: PathBuf,
    /// Speed, km/h.
    #[arg(long, default_value_t = 60.0)]
    speed_kmh: f64,
    /// Simulated seconds per run (after 3 s settling).
    #[arg(long, default_value_t = 15.0)]
    seconds: f64,
    /// Reference step, s.
    #[arg(long, default_value_t = 5e-5)]
    reference: f64,
    /// Steps compared with it, s, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "2.5e-4,5e-4,7.142857142857143e-4,8.333333333333333e-4"
    )]
    steps: Vec<f64>,
    /// Take the rails as rigid (drop the track file's `[rail_support]`): separates the
    /// rail masses' part in the step limit from the vehicle's.
    #[arg(long, conflicts_with = "rail_support")]
    rigid_rails: bool,
    /// The rails' support over the track file's (`rigid`, `lumped`, `discrete`; as
    /// `simulate --rail-support`). On rails on sleepers the reference must be
    /// `--reference-integrator linearly-implicit-hertz` (the only integrator they run with).
    #[arg(long, value_parser = railforce::track::RAIL_SUPPORT_MODELS)]
    rail_support: Option<String>,
    /// Integrator of the compared steps (default: the default integrator, linearly implicit
    /// with the contact's Hertz spring).
    #[arg(long, value_parser = Integrator::NAMES)]
    integrator: Option<String>,
    /// Integrator of the reference (default semi-implicit: at 0.05 ms, a quarter of its own
    /// step, the yardstick every default step is held to within 1 %).
    #[arg(long, default_value = "semi-implicit", value_parser = Integrator::NAMES)]
    reference_integrator: String,
}

pub fn run(args: &StepArgs) -> Result<()> {
    let integrator = railforce::sim::Stepping::chosen(args.integrator.as_deref(), None).integrator;
    let reference_integrator =
        Integrator::parse(&args.reference_integrator).expect("checked by clap");
    let (vehicle, track): (&Path, &Path) = (&args.vehicle, &args.track);
    let (speed_kmh, seconds, reference) = (args.speed_kmh, args.seconds, args.reference);
    let (steps, rigid_rails) = (&args.steps, args.rigid_rails);
    if cfg!(debug_assertions) {
        eprintln!("warning: debug build; use `cargo run --release -- bench step`");
    }
    let v = railforce::vehicle::Vehicle::load(&super::super::builtin::resolve(vehicle)?)?;
    let mut spec = TrackSpec::load(&super::super::builtin::resolve(track)?)?;
    if rigid_rails {
        spec.set_rail_model("rigid")?;
    }
    if let Some(m) = &args.rail_support {
        spec.set_rail_model(m)?;
    }
    let rails = match spec.rail_model() {
        "rigid" => "rigid rails",
        "lumped" => "compliant rails, lumped",
        _ => "rails on discrete sleepers",
    };
    let tr = Track::new(spec, None);
    let s = step_study(
        &v,
        &tr,
        speed_kmh / 3.6,
        seconds,
        (reference, reference_integrator),
        steps,
        integrator,
    )?;
    println!(
        "step study ({}): {} on {} ({rails}), {speed_kmh} km/h, {seconds} s after 3 s settling, one thread",
        integrator.name(),
        v.name,
        tr.spec().name
    );
    println!(
        "  reference {:.4} ms ({}): {:.2} s wall; FL, FQ power above 40 Hz {:.2} %, {:.2} %",
        s.reference_dt * 1e3,
        s.reference_integrator.name(),
        s.reference_wall_s,
        100.0 * s.reference_high[0],
        100.0 * s.reference_high[1]
    );
    let [b0, b1, b2] = s.reference_fq_bands.map(|b| b * 1e-3);
    println!(
        "  reference FQ rms by band: 0–20 Hz {b0:.2} kN, 20–50 Hz {b1:.2} kN, 50–100 Hz {b2:.2} kN (the record's 50 Hz low-pass in the last)"
    );
    println!(
        "  {:>8} {:>9} {:>9} {:>12} {:>10} {:>11} {:>16} {:>22}",
        "step ms",
        "wall s",
        "speed-up",
        "Y/Q rms %",
        "Q sd %",
        "FL sd %",
        "> 40 Hz FL/FQ %",
        "FQ 0–20/20–50/50–100 %"
    );
    for t in &s.trials {
        let head = format!(
            "  {:>8.3} {:>9.2} {:>8.2}×",
            t.dt * 1e3,
            t.wall_s,
            s.reference_wall_s / t.wall_s.max(1e-9)
        );
        match &t.outcome {
            Err(e) => {
                println!("  {:>8.3}  stopped: {e}", t.dt * 1e3);
                continue;
            }
            Ok(d) => println!(
                "{head} {:>12.2} {:>10.2} {:>11.2} {:>8.2} / {:<5.2} {:>8.2} / {:.2} / {:.2}",
                100.0 * d.yq_rms,
                100.0 * d.q_sd,
                100.0 * d.label_y_sd,
                100.0 * d.high[0],
                100.0 * d.high[1],
                100.0 * d.fq_bands[0],
                100.0 * d.fq_bands[1],
                100.0 * d.fq_bands[2]
            ),
        }
    }
    println!(
        "  (largest relative difference from the reference over the eight wheels; the default step is held to ≤ 1 %, each FQ band to ≤ 3 %)"
    );
    Ok(())
}
