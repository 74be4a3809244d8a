//! `railforce simulate`: one run of a vehicle on a track.

use anyhow::{Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use railforce::dataset::{Format, write_run};
use railforce::sim::{Simulation, output, wheel_name};
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::Vehicle;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SimulateArgs {
    /// Vehicle file (TOML naming its URDF).
    #[arg(long, default_value = "vehicles/c80.toml")]
    vehicle: PathBuf,
    /// Track file.
    #[arg(long)]
    track: PathBuf,
    /// Running speed, km/h.
    #[arg(long, default_value_t = 60.0)]
    speed_kmh: f64,
    /// Recorded duration after settling, s.
    #[arg(long, default_value_t = 60.0)]
    duration: f64,
    /// Irregularity seed (overrides the track file's).
    #[arg(long)]
    seed: Option<u64>,
    /// The rails' support, over the track file's `[rail_support]`: `rigid`; `lumped` (a rail
    /// mass on springs under each wheel: the file's); `discrete` (rails as beams on sleepers,
    /// ballast and subgrade, Zhai's parameters unless the file gives its own; a step costs
    /// about 2.2 times the lumped track's at the same step and runs at 0.1 ms, faster than
    /// 60 km/h at 1.67 mm of travel a step: some 17 times slower than the lumped track at its
    /// own step; the default integrator only).
    #[arg(long, value_parser = railforce::track::RAIL_SUPPORT_MODELS)]
    rail_support: Option<String>,
    /// Rail roughness below the irregularities, over the track file's `[roughness]`:
    /// `iso3095` (EN ISO 3095's limit, ground rail), `cnossos_m` (an average network) or
    /// `none`; down to 0.1 m through the contact filter. The step then follows it (62.5 µs).
    #[arg(long, value_parser = ["iso3095", "cnossos_m", "none"])]
    roughness: Option<String>,
    /// Output file, its format by its extension: `.csv`, `.parquet` (what `generate` writes) or
    /// `.npz`; a `.meta.json` file is written beside it.
    #[arg(long, default_value = "run.csv")]
    out: PathBuf,
    /// Settling time before recording, s (not written out).
    #[arg(long, default_value_t = 3.0)]
    settle: f64,
    /// Integration step, s (default: the integrator's own, 5/6 ms linearly implicit Hertz,
    /// 0.5 ms linearly implicit, 0.2 ms semi-implicit or Heun). A step longer than the
    /// integrator holds for this vehicle (0.895 / 0.689 / 0.531 / 0.254 ms for the C80 on tangent at 80 km/h) is
    /// refused before the run.
    #[arg(long)]
    dt: Option<f64>,
    /// Integrator (default: linearly-implicit-hertz): `linearly-implicit-hertz` (the wheel–rail
    /// damping and the contact's Hertz spring, each wheelset with its rail masses, and the
    /// side frames' pad damping taken implicitly: accurate at 5/6 ms, `railforce bench step`), `linearly-implicit` (the
    /// damping alone: 0.5 ms, for data sets made with it), `semi-implicit` (explicit in every
    /// force: 0.2 ms) or `heun` (second order, two force evaluations a step, explicit: a
    /// reference for small steps).
    #[arg(long, value_parser = railforce::sim::Integrator::NAMES)]
    integrator: Option<String>,
    /// Report a derailment but keep running (default: stop with an error).
    #[arg(long)]
    keep_going: bool,
    /// The train around the wagon: `none` (the wagon alone, its speed held by the vehicle
    /// file's `[hauling]`), a built-in consist (`daqin_10kt`, `daqin_20kt`, `_empty` for
    /// either unloaded) or a consist file. The train's driver holds --speed-kmh by notches;
    /// its couplers pull and push the carbody at their pivots and height, at the angle the
    /// neighbours stand on the track. Records `coupler_front_force`, `coupler_rear_force`
    /// (N, + tension), `coupler_front_yaw`, `coupler_rear_yaw` (rad).
    #[arg(long, default_value = "none")]
    consist: String,
    /// The wagon's place in the train, as a fraction of its length from the head (0 to 1;
    /// default: the consist file's `position`).
    #[arg(long, requires = "consist")]
    position: Option<f64>,
}

pub fn run(args: SimulateArgs) -> Result<()> {
    let command_start = std::time::Instant::now();
    let request = railforce::sim::RunRequest {
        speed_kmh: args.speed_kmh,
        duration: args.duration,
        settle: args.settle,
        stepping: railforce::sim::Stepping::chosen(args.integrator.as_deref(), args.dt),
        stop_on_derailment: !args.keep_going,
    };
    let cfg = super::with_flags(request.config(), "--speed-kmh, --duration, --settle, --dt")?;
    let format = args
        .out
        .extension()
        .and_then(|e| e.to_str())
        .and_then(|e| Format::parse(&e.to_ascii_lowercase()));
    let Some(format) = format else {
        bail!(
            "--out {}: the extension names the format; use .csv, .parquet or .npz",
            args.out.display()
        );
    };
    let mut args = args;
    args.vehicle = super::builtin::resolve(&args.vehicle)?;
    args.track = super::builtin::resolve(&args.track)?;
    let vehicle = Vehicle::load(&args.vehicle)?;
    let flange = railforce::contact::Flange::of(vehicle.contact.geometry.wheel());
    if flange.is_flangeless() {
        eprintln!(
            "note: the wheel profile {} has no flange (it rises {:.1} mm above its tape circle): the wheels cannot flange, and the derailment watch reads a climb of 90 % of that height (a cone for textbook checks, or a file cut short?)",
            vehicle.contact.geometry.wheel().name,
            flange.height * 1e3
        );
    }
    let mut spec = TrackSpec::load(&args.track)?;
    if let Some(m) = &args.rail_support {
        spec.set_rail_model(m)?;
    }
    if let Some(r) = &args.roughness {
        spec.set_roughness(r)?;
    }
    let track = Track::new(spec, args.seed);
    let mut cfg = cfg;
    cfg.dt = request
        .stepping
        .step_on(track.spec(), &vehicle, cfg.speed)?;
    let dt = cfg.dt;
    if dt < request.stepping.dt
        && let Some((_, why)) =
            railforce::sim::Stepping::limit_on(track.spec(), &vehicle, cfg.speed)
    {
        eprintln!("note: step {:.4} ms: {why}", dt * 1e3);
    }
    cfg.train = railforce::sim::hitch::TrainSetup::resolve(
        &args.consist,
        args.position,
        std::path::Path::new("."),
        "--consist",
    )?;
    let mut sim = Simulation::new(&vehicle, &track, cfg)?;
    let train_meta = sim.hitch().map(|h| {
        let t = h.train();
        serde_json::json!({
            "consist": args.consist,
            "position": args.position,
            "name": t.consist().name,
            "vehicles": t.consist().vehicles.len(),
            "wagon_index": t.wagon_index(),
            "mass_t": t.consist().mass() * 1e-3,
        })
    });
    let meta = serde_json::json!({
        "train": train_meta,
        "tool": format!("railforce {}", env!("CARGO_PKG_VERSION")),
        "vehicle": {"file": args.vehicle, "hash_fnv1a": railforce::dataset::file_hash(&args.vehicle)?, "name": vehicle.name},
        "track": {"file": args.track, "hash_fnv1a": railforce::dataset::file_hash(&args.track)?, "name": track.spec().name, "rail_support": track.spec().rail_model(), "roughness": track.spec().short_waves.and_then(|w| w.roughness).map(|r| r.spectrum.name())},
        "seed": track.irregularities().map(|i| i.spec().seed),
        "speed_kmh": args.speed_kmh,
        "duration_s": args.duration,
        "settle_s": args.settle,
        "integration_step_s": dt,
        "integrator": request.stepping.integrator.name(),
        "sampling_rate_hz": sim.config().output_rate,
        "anti_alias": format!("8th-order Butterworth low-pass at {} Hz at the integration rate, then decimation", sim.config().cutoff),
        "frame": "track frame: x along the running direction, y to the left, z up",
        "forces": "forces of the rail on the wheel in the track frame: force_y = Y (+ left), force_z = Q (+ up); wheels 1L..4R numbered from the front, left/right facing the running direction",
        "accelerations": vehicle.accelerometers.describe(),
        "accelerometers": vehicle.accelerometers.name(),
        "labels": {"FL": "w1l_force_y", "FQ": "w1l_force_z"},
        "conventions_note": "EN names: Y lateral, Q vertical (Chinese standards: Q lateral, P vertical)",
    });
    let bar = ProgressBar::new(1000);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% eta {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message(format!(
        "simulating {} s on {}",
        args.duration,
        track.spec().name
    ));
    let progress = |f: f64| bar.set_position((f * 1000.0) as u64);
    // One writer for every format, the data sets' (CSV bytes as `run_to_csv` writes them).
    let summary = output::record(&mut sim, progress).and_then(|rec| {
        write_run(&args.out, &rec, format, false)?;
        output::write_meta(&args.out, &meta, &rec)
    });
    bar.finish_and_clear();
    let summary = summary?;
    println!(
        "wrote {} ({} rows at {} Hz) and {}",
        args.out.display(),
        summary.rows,
        sim.config().output_rate,
        output::meta_path(&args.out).display()
    );
    println!(
        "simulated {:.1} s (+{:.1} s settling) in {:.2} s: {:.1}× real time (step {} ms); the whole command {:.2} s (files read, contact table built or read from the cache, output written)",
        summary.simulated,
        args.settle,
        summary.wall,
        summary.real_time_factor,
        dt * 1e3,
        command_start.elapsed().as_secs_f64()
    );
    print!("peak |Y/Q|:");
    for (k, p) in summary.peak_y_over_q.iter().enumerate() {
        print!(" {} {:.3}", wheel_name(k), p);
    }
    println!();
    print!("mean Q (kN):");
    for (k, (_, q)) in summary.mean_yq.iter().enumerate() {
        print!(" {} {:.1}", wheel_name(k), q * 1e-3);
    }
    println!();
    if let Some(h) = sim.hitch() {
        let t = h.train();
        println!(
            "train {}: wagon {} of {}; the train ran at {:.1} km/h at the end{}",
            t.consist().name,
            t.wagon_index() + 1,
            t.consist().vehicles.len(),
            t.speed() * 3.6,
            if t.speed_not_held_s() > 0.0 {
                format!(
                    "; its locomotives could not hold {} km/h for {:.1} s (the train slowed, as it would)",
                    args.speed_kmh,
                    t.speed_not_held_s()
                )
            } else {
                String::new()
            }
        );
    }
    println!("to watch it: {}", super::view::hint(&args.out, None));
    Ok(())
}
