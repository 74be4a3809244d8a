//! `railforce validate contact`: the contact model against CONTACT's Manchester benchmark
//! and tractcurv creep curve.

use anyhow::{Result, bail};
use railforce::contact::Side;
use railforce::contact::validate::{self as cv, ProfileSource};

/// Prints measured against reference; an error on a missed tolerance.
pub(super) fn run(dir: &cv::Reference) -> Result<()> {
    println!("reference data: {}", dir.describe());
    let mut misses = 0;
    for (source, gate) in [
        (ProfileSource::Benchmark, true),
        (ProfileSource::Analytic, false),
    ] {
        let rows = cv::manchester_a22(dir, source)?;
        println!(
            "\nManchester benchmark A-2.2, {} profiles{}",
            match source {
                ProfileSource::Benchmark => "the benchmark's own S1002/UIC60",
                ProfileSource::Analytic => "railforce's analytic S1002 / 60 kg/m at 1:40",
            },
            if gate { "" } else { " (informative)" }
        );
        println!(
            "{:>4} {:>6} {:>5} {:>10} {:>10} {:>7} {:>8} {:>8} {:>6} {:>10} {:>10}  ok",
            "case",
            "wheel",
            "y mm",
            "ycp mm",
            "ref",
            "Δ mm",
            "δ deg",
            "ref",
            "Δ°",
            "roll mrad",
            "ref"
        );
        let (mut worst_p, mut worst_a) = (0.0f64, 0.0f64);
        for r in &rows {
            let dp = r.position.0 - r.position.1;
            let da = (r.angle.0 - r.angle.1).to_degrees();
            worst_p = worst_p.max(dp.abs());
            worst_a = worst_a.max(da.abs());
            let ok = r.passes();
            if gate && !ok {
                misses += 1;
            }
            println!(
                "{:>4} {:>6} {:>5.1} {:>10.3} {:>10.3} {:>+7.3} {:>8.3} {:>8.3} {:>+6.2} {:>10.4} {:>10.4}  {}",
                r.case,
                if r.side == Side::Left {
                    "left"
                } else {
                    "right"
                },
                r.y * 1e3,
                r.position.0 * 1e3,
                r.position.1 * 1e3,
                dp * 1e3,
                r.angle.0.to_degrees(),
                r.angle.1.to_degrees(),
                da,
                r.roll.0 * 1e3,
                r.roll.1 * 1e3,
                if ok {
                    "yes"
                } else if gate {
                    "MISS"
                } else {
                    "miss (info)"
                }
            );
        }
        println!(
            "worst: position {:.3} mm (tolerance {} mm), angle {:.2}° (tolerance 2°)",
            worst_p * 1e3,
            cv::POSITION_TOLERANCE * 1e3,
            worst_a
        );
    }
    let rows = cv::tractcurv(dir)?;
    println!("\nCreep curve (tractcurv: Fn 106.7 kN, a/b 0.5, μ 0.33), Fx/(μ·Fn)");
    println!(
        "{:<13} {:>9} {:>9} {:>9} {:>8}  ok",
        "method", "ξx", "ours", "ref", "Δ"
    );
    let mut worst = [0.0f64; 2];
    for r in &rows {
        let d = r.force.0 - r.force.1;
        let k = usize::from(r.method == "fastsim");
        worst[k] = worst[k].max(d.abs());
        if !r.passes() {
            misses += 1;
        }
        println!(
            "{:<13} {:>9.5} {:>9.4} {:>9.4} {:>+8.4}  {}",
            if k == 1 { "fastsim" } else { "polach/exact" },
            r.creepage,
            r.force.0,
            r.force.1,
            d,
            if r.passes() { "yes" } else { "MISS" }
        );
    }
    println!(
        "worst: Polach vs exact {:.4} μFn (target 0.03, gate {}), FASTSIM vs FASTSIM {:.4} μFn (gate {})",
        worst[0],
        cv::POLACH_TOLERANCE,
        worst[1],
        cv::FASTSIM_TOLERANCE
    );
    if misses > 0 {
        bail!("{misses} comparison(s) outside tolerance");
    }
    println!("\nall gated comparisons within tolerance");
    Ok(())
}
