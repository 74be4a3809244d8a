//! `bench learn --against-torch`: PyTorch's CNN-BiLSTM against the engine in alternating
//! rounds on this machine, now: the same windows (21 channels × 20 steps, `sin(0.618·i)`),
//! the same training batch, inference in batches of 1 024, one thread each. PyTorch runs in
//! one Python process kept between rounds (assets/python/bench_torch.py `--serve`), so its
//! start and import are not timed.

use super::against::median;
use super::learn;
use anyhow::{Context, Result, bail};
use railforce::learn::neural::Architecture;
use railforce::learn::train::GradientEngine;
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread::JoinHandle;

const SCRIPT: &str = include_str!("../../../assets/python/bench_torch.py");
const NETS: &str = include_str!("../../../assets/python/railforce_nets.py");

/// The PyTorch side: a `bench_torch.py --serve` process.
pub struct Torch {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    /// Its standard error, read as it comes (so a full pipe never stalls it).
    stderr: Option<JoinHandle<String>>,
    version: String,
}

/// The last non-empty line of what a process wrote to standard error, as ` (line)`.
fn last_line(err: &str) -> String {
    err.lines()
        .rev()
        .find(|l| !l.trim().is_empty())
        .map(|l| format!(" ({})", l.trim()))
        .unwrap_or_default()
}

impl Torch {
    /// Starts PyTorch's side under `python` on the CPU for training batches of `batch`: an
    /// error naming the interpreter and the install line where it has no PyTorch.
    pub fn start(python: &str, batch: usize) -> Result<Self> {
        static STARTS: AtomicUsize = AtomicUsize::new(0);
        let dir = std::env::temp_dir().join(format!(
            "railforce-{}-torch-{}-{}",
            env!("CARGO_PKG_VERSION"),
            std::process::id(),
            STARTS.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::create_dir(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let started = Self::spawn(python, batch, &dir);
        std::fs::remove_dir_all(&dir).ok();
        started
    }

    fn spawn(python: &str, batch: usize, dir: &std::path::Path) -> Result<Self> {
        for (name, text) in [("bench_torch.py", SCRIPT), ("railforce_nets.py", NETS)] {
            std::fs::write(dir.join(name), text)
                .with_context(|| format!("writing {}", dir.join(name).display()))?;
        }
        let mut child = Command::new(python)
            .arg("-u")
            .arg(dir.join("bench_torch.py"))
            .args(["--serve", "--device", "cpu", "--threads", "1"])
            .args(["--batch", &batch.to_string()])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .with_context(|| {
                format!("starting {python} (give --python an interpreter with PyTorch)")
            })?;
        let stdin = child.stdin.take().expect("piped");
        let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
        let stderr = child.stderr.take();
        let drain = std::thread::spawn(move || {
            let mut err = String::new();
            if let Some(mut e) = stderr {
                std::io::Read::read_to_string(&mut e, &mut err).ok();
            }
            err
        });
        let mut line = String::new();
        let read = stdout.read_line(&mut line);
        let Some(version) = line.strip_prefix("ready ").filter(|_| read.is_ok()) else {
            // Whatever it printed instead, it is not the benchmark: stop it.
            drop(stdin);
            let _ = child.kill();
            let _ = child.wait();
            let last = last_line(&drain.join().unwrap_or_default());
            bail!(
                "{python} could not run the PyTorch benchmark{last}: install the CPU build with `{python} -m pip install torch --index-url https://download.pytorch.org/whl/cpu`, or name another interpreter with --python"
            );
        };
        let version = version.trim().to_string();
        Ok(Torch {
            child,
            stdin,
            stdout,
            stderr: Some(drain),
            version,
        })
    }

    /// One figure: `what` is `train` or `infer`.
    fn rate(&mut self, what: &str, a: Architecture, seconds: f64) -> Result<f64> {
        writeln!(self.stdin, "{what} {} {seconds}", a.name())?;
        self.stdin.flush()?;
        let mut line = String::new();
        if self.stdout.read_line(&mut line)? == 0 {
            let _ = self.child.wait();
            let err = self
                .stderr
                .take()
                .and_then(|h| h.join().ok())
                .unwrap_or_default();
            bail!(
                "the PyTorch process ended while timing {what}{}",
                last_line(&err)
            );
        }
        line.strip_prefix(what)
            .and_then(|v| v.trim().parse().ok())
            .with_context(|| format!("PyTorch answered {:?} to {what}", line.trim()))
    }
}

impl Drop for Torch {
    fn drop(&mut self) {
        let _ = writeln!(self.stdin, "quit");
        let _ = self.child.wait();
    }
}

/// Times `a` in railforce's fused engine and in PyTorch (started for `batch`), `rounds`
/// alternating rounds of `seconds` per figure (odd rounds railforce first, even rounds
/// PyTorch first), and prints each round, the medians and the ratios.
pub fn compare(
    mut torch: Torch,
    a: Architecture,
    batch: usize,
    rounds: usize,
    seconds: f64,
) -> Result<()> {
    println!(
        "same-run comparison with {} (railforce one thread): {}, 21 channels × 20 steps, training batch {batch} (forward + backward + Adam, dropout 0.2), inference in batches of 1024; {rounds} alternating rounds of {seconds} s a figure",
        torch.version,
        a.name()
    );
    println!(
        "{:>5} {:>10} {:>15} {:>13} {:>7} {:>15} {:>13} {:>7}",
        "round",
        "first",
        "railforce train",
        "PyTorch train",
        "ratio",
        "railforce infer",
        "PyTorch infer",
        "ratio"
    );
    let (mut train, mut infer) = (Vec::new(), Vec::new());
    for r in 0..rounds {
        let ours_first = r % 2 == 0;
        let mut figures = [[0.0; 2]; 2];
        for side in 0..2 {
            let ours = (side == 0) == ours_first;
            let t = if ours {
                learn::train_rate(a, GradientEngine::Fused, batch, seconds)?
            } else {
                torch.rate("train", a, seconds)?
            };
            let i = if ours {
                learn::infer_rate(a, seconds)
            } else {
                torch.rate("infer", a, seconds)?
            };
            figures[usize::from(!ours)] = [t, i];
        }
        let [[rt, ri], [pt, pi]] = figures;
        println!(
            "{:>5} {:>10} {rt:>15.0} {pt:>13.0} {:>6.2}× {ri:>15.0} {pi:>13.0} {:>6.2}×",
            r + 1,
            if ours_first { "railforce" } else { "PyTorch" },
            rt / pt,
            ri / pi
        );
        train.push([rt, pt]);
        infer.push([ri, pi]);
    }
    for (what, v) in [("training", &train), ("inference", &infer)] {
        let ratios: Vec<f64> = v.iter().map(|[a, b]| a / b).collect();
        let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ratios.iter().copied().fold(0.0, f64::max);
        println!(
            "{what}: railforce {:.0} windows/s, PyTorch {:.0} (medians); railforce/PyTorch {:.2}× (median of the rounds' ratios, {lo:.2}–{hi:.2}×)",
            median(&v.iter().map(|x| x[0]).collect::<Vec<_>>()),
            median(&v.iter().map(|x| x[1]).collect::<Vec<_>>()),
            median(&ratios)
        );
    }
    Ok(())
}
