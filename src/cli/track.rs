//! `railforce track`.

use anyhow::{Context, Result};
use clap::Args;
use railforce::track::{Channel, SectionKind, Track, TrackSpec, Turn, check};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct TrackArgs {
    /// Track file (TOML), e.g. tracks/curve_r400.toml, or a built-in name: curve_r400.
    file: PathBuf,
    /// Write geometry and rail irregularities to this CSV file.
    #[arg(long, value_name = "CSV")]
    out: Option<PathBuf>,
    /// Sampling step of the CSV export, m.
    #[arg(long, default_value_t = 0.25, value_name = "M")]
    step: f64,
    /// Check the irregularities against the FRA PSD: print sample vs formula RMS per channel
    /// and write the Welch PSD beside the formula to CSV; the rails' roughness, where the file
    /// has it, by third-octave band against its spectrum.
    #[arg(long)]
    psd: bool,
    /// Where `--psd` writes its CSV.
    #[arg(long, value_name = "CSV", default_value = "psd.csv")]
    psd_out: PathBuf,
    /// Irregularity seed (overrides the file's `irregularity.seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// With --seed: the rails of the data-set run of this condition name and seed (a plan's
    /// runs draw their irregularities from both, so every condition has its own).
    #[arg(long, value_name = "NAME", requires = "seed")]
    condition: Option<String>,
}

pub fn run(args: TrackArgs) -> Result<()> {
    let spec = TrackSpec::load(&super::builtin::resolve(&args.file)?)?;
    let seed = match (&args.condition, args.seed) {
        (Some(name), Some(seed)) => Some(railforce::dataset::realisation_seed(name, seed)),
        _ => args.seed,
    };
    let track = Track::new(spec, seed);
    print_summary(&track);
    if let Some(out) = &args.out {
        track
            .write_csv(out, args.step)
            .with_context(|| format!("exporting {} every --step m", args.file.display()))?;
        println!("wrote {} (every {} m)", out.display(), args.step);
        if let Some(w) = &track.spec().short_waves {
            let shortest = w.shortest_wavelength();
            if args.step > 0.25 * shortest {
                println!(
                    "note: the rails' short waves reach {:.0} mm; every {} m reads them aliased: give --step {} or less",
                    shortest * 1e3,
                    args.step,
                    0.25 * shortest
                );
            }
        }
    }
    if args.psd {
        print_roughness(&track);
        let irr = track.irregularities().with_context(|| {
            format!(
                "{}: --psd needs an [irregularity] table in the track file",
                args.file.display()
            )
        })?;
        let sp = irr.spec();
        println!(
            "\nIrregularity RMS, {}, band {}–{} m, seed {}, over {:.0} m:",
            match sp.spectrum {
                railforce::track::Spectrum::Fra => format!("FRA class {}", sp.class.number),
                s => format!("spectrum {}", s.name()),
            },
            sp.min_wavelength,
            sp.max_wavelength,
            sp.seed,
            track.length()
        );
        println!(
            "  {:<12} {:>14} {:>15} {:>10}",
            "channel", "sample RMS mm", "formula RMS mm", "deviation"
        );
        for c in check::rms_checks(irr, track.length()) {
            println!(
                "  {:<12} {:>14.3} {:>15.3} {:>+9.1}%",
                c.channel.name(),
                c.sample_rms * 1e3,
                c.formula_rms * 1e3,
                100.0 * c.deviation()
            );
        }
        let [raw_min, raw_max, raw_rms] = irr.gauge_before_limit();
        let g = irr.channel_samples(Channel::Gauge);
        let rms = (g.iter().map(|v| v * v).sum::<f64>() / g.len() as f64).sqrt();
        let (lo, hi) = sp.gauge_limits;
        println!(
            "  gauge held within {:+.1} / {:+.1} mm (49 CFR 213.53, class {}) by a soft limit (knee at 75 %): \
             synthesised {:+.1} to {:+.1} mm, RMS {:.2} mm → {:+.1} to {:+.1} mm, RMS {:.2} mm",
            lo * 1e3,
            hi * 1e3,
            sp.class.number,
            raw_min * 1e3,
            raw_max * 1e3,
            raw_rms * 1e3,
            g.iter().cloned().fold(f64::INFINITY, f64::min) * 1e3,
            g.iter().cloned().fold(f64::NEG_INFINITY, f64::max) * 1e3,
            rms * 1e3
        );
        let two_pi = 2.0 * std::f64::consts::PI;
        let (w_lo, w_hi) = (two_pi / sp.max_wavelength, two_pi / sp.min_wavelength);
        let cmp = check::psd_comparison(irr, track.length());
        cmp.write_csv(&args.psd_out, w_lo, w_hi)?;
        println!("  Welch / formula power per octave of the band:");
        print!("  {:<18}", "octave (m)");
        for ch in Channel::ALL {
            print!(" {:>11}", ch.name());
        }
        println!();
        for o in cmp.octave_ratios(w_lo, w_hi) {
            print!(
                "  {:<18}",
                format!("{:.1}–{:.1}", two_pi / o.hi, two_pi / o.lo)
            );
            for r in o.ratio {
                print!(" {r:>11.3}");
            }
            println!();
        }
        println!(
            "wrote {} ({} Welch segments)",
            args.psd_out.display(),
            cmp.segments
        );
    }
    Ok(())
}

fn print_summary(track: &Track) {
    let spec = track.spec();
    println!(
        "{} — {:.1} m, gauge {} m, rail spacing {} m",
        spec.name,
        track.length(),
        spec.gauge,
        spec.rail_spacing
    );
    if !spec.description.is_empty() {
        println!("  {}", spec.description);
    }
    for (i, sec) in spec.sections.iter().enumerate() {
        let what = match sec.kind {
            SectionKind::Tangent => "tangent".to_string(),
            SectionKind::Transition => "transition (clothoid, linear cant ramp)".to_string(),
            SectionKind::Curve { radius, cant, turn } => {
                let v_eq = sec.balance_speed(spec.rail_spacing).unwrap_or(0.0);
                format!(
                    "curve {} R {radius} m, cant {:.0} mm, balance speed {:.1} km/h",
                    match turn {
                        Turn::Left => "left",
                        Turn::Right => "right",
                    },
                    cant * 1e3,
                    v_eq * 3.6
                )
            }
        };
        println!("  [{i}] {:>8.1}–{:<8.1} m  {what}", sec.start, sec.end());
    }
    let grades = spec.profile.grades();
    if grades.len() > 1 || grades[0].gradient != 0.0 {
        for g in grades {
            let rv = if g.vertical_curve_radius.is_finite() {
                format!(", vertical curve R {} m", g.vertical_curve_radius)
            } else {
                String::new()
            };
            println!("  grade from {:.1} m: {:+.1} ‰{rv}", g.at, g.gradient * 1e3);
        }
    } else {
        println!("  level");
    }
    match &spec.irregularity {
        Some(irr) => println!(
            "  irregularities: FRA class {}, wavelengths {}–{} m, seed {}",
            irr.class.number, irr.min_wavelength, irr.max_wavelength, irr.seed
        ),
        None => println!("  no irregularities (smooth track)"),
    }
    if let Some(w) = &spec.short_waves {
        if let Some(r) = w.roughness {
            println!(
                "  rail roughness: {}, wavelengths {}–{} m, contact filter {}",
                r.spectrum.name(),
                r.min_wavelength,
                r.max_wavelength,
                if r.contact_filter { "on" } else { "off" }
            );
        }
        if let Some(d) = w.welds {
            println!(
                "  weld dips every {} m from {} m: {} mm over {} m (gradient {:.2} mrad)",
                d.spacing,
                d.first,
                d.depth * 1e3,
                d.length,
                d.gradient() * 1e3
            );
        }
        if let Some(j) = w.joints {
            println!(
                "  dipped joints every {} m from {} m: 2α {:.1} mrad, {:.2} mm deep over {} m",
                j.spacing,
                j.first,
                j.angle * 1e3,
                j.depth() * 1e3,
                j.length
            );
        }
    }
}

/// The rails' drawn roughness by third-octave band against its spectrum (1 dB); the count of
/// bands outside.
fn print_roughness(track: &Track) -> usize {
    let Some(w) = track.short_waves() else {
        return 0;
    };
    let bands = check::roughness_bands(w, track.length());
    if bands.is_empty() {
        return 0;
    }
    println!("  drawn roughness by third-octave band against the spectrum (dB re 1 µm, ±1 dB):");
    let mut misses = 0;
    for b in &bands {
        let ok = (b.drawn_db - b.expected_db).abs() <= 1.0;
        misses += usize::from(!ok);
        println!(
            "  {} {} rail, {:>6.1} mm: {:>6.2} against {:>6.2}",
            if ok { "pass" } else { "MISS" },
            if b.side == 0 { "left " } else { "right" },
            b.wavelength * 1e3,
            b.drawn_db,
            b.expected_db
        );
    }
    misses
}

/// `railforce validate track`: the discrete track's checks (the file's parameters, else the
/// default set), measured against expected; an error on a miss.
pub fn validate_discrete(track: Option<&std::path::Path>) -> Result<()> {
    let mut misses = 0;
    let p = match track {
        None => railforce::track::discrete::DiscreteSupport::default(),
        Some(t) => {
            let mut spec = TrackSpec::load(&super::builtin::resolve(t)?)?;
            if spec.short_waves.is_some_and(|w| w.roughness.is_some()) {
                println!("{}: rail roughness", spec.name);
                misses += print_roughness(&Track::new(spec.clone(), None));
            }
            spec.set_rail_model("discrete")?;
            spec.discrete_rails.context("set above")?
        }
    };
    println!(
        "rails on discrete sleepers: {} bays of {} m, β {:.3} /m (Winkler, the seat's chain over the spacing)",
        p.bays,
        p.spacing,
        p.beta()
    );
    for c in railforce::track::discrete::checks(&p) {
        let ok = c.passes();
        misses += usize::from(!ok);
        println!(
            "  {} {}: {:.4} {} against {:.4} (±{:.0} %)",
            if ok { "pass" } else { "MISS" },
            c.name,
            c.measured,
            c.unit,
            c.expected,
            100.0 * c.tolerance
        );
    }
    anyhow::ensure!(misses == 0, "{misses} track check(s) missed");
    Ok(())
}
