//! `bench simulate --against OTHER`: this binary and another railforce binary timed in
//! alternate rounds on the same run, so that whatever else a shared machine does falls on
//! both alike; the ratio of their medians is this build's speed-up (speed as a ratio against a
//! reference measured in the same run).

use anyhow::{Context, Result, bail};
use std::path::Path;
use std::process::Command;

/// The real-time factors that a `bench simulate` printed, physics only and with all channels
/// (the lines `physics only: … X× real time` and `with all channels: … Y× real time …`, which
/// the other binary must print too; one without them is refused). Real time, not µs per step:
/// the two binaries may step at different steps (their own defaults).
fn parse(stdout: &str) -> Option<(f64, f64)> {
    let number = |key: &str| -> Option<f64> {
        let line = stdout.lines().find(|l| l.trim_start().starts_with(key))?;
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = words
            .windows(2)
            .position(|w| w[0].ends_with('×') && w[1] == "real")?;
        words[at].trim_end_matches('×').parse().ok()
    };
    Some((number("physics only:")?, number("with all channels:")?))
}

/// One measurement by the other binary: `bench simulate --repeat 1` with `args`.
pub fn other_once(bin: &Path, args: &[String]) -> Result<(f64, f64)> {
    let out = Command::new(bin)
        .args(["bench", "simulate", "--repeat", "1"])
        .args(args)
        .output()
        .with_context(|| format!("--against {}: cannot run it", bin.display()))?;
    if !out.status.success() {
        bail!(
            "--against {}: its bench simulate failed: {}",
            bin.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    parse(&String::from_utf8_lossy(&out.stdout)).with_context(|| {
        format!(
            "--against {}: its output has no 'physics only:' and 'with all channels:' lines (is it a railforce binary?)",
            bin.display()
        )
    })
}

/// Median of `v` (not empty).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The real-time factors come from the two lines, whatever surrounds them.
    #[test]
    fn reads_the_two_lines_of_a_bench_simulate() {
        let out = "simulation benchmark: C80 …\n  physics only:        11.49 µs per step (slowest 12.88),  43.5× real time\n  with all channels:   13.32 µs per step,  37.5× real time (recording costs 16 %)\n";
        assert_eq!(parse(out), Some((43.5, 37.5)));
        assert_eq!(parse("physics only: 1 µs\n"), None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
