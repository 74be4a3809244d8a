//! Where a result comes from: the commit of the code that measured it, the clock, and the
//! processor time a part took beside its wall time (how busy the cores were).

/// Seconds since 1970-01-01 UTC (0 when the clock is before it).
pub(super) fn unix_now() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

/// The commit of the source tree this binary was built from (`git rev-parse HEAD` in it, with
/// `-modified` when tracked files differ from it), or "unknown" where that tree is gone: the
/// results snapshot names the code that measured it.
pub(super) fn source_commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .arg("-C")
            .arg(env!("CARGO_MANIFEST_DIR"))
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "HEAD"]) {
        Some(h) if !h.is_empty() => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty { format!("{h}-modified") } else { h }
        }
        _ => "unknown".into(),
    }
}

/// Processor seconds this process has used so far: user and system time of every thread,
/// and of the children it waited for (`getrusage`); `None` where the platform does not say.
/// A part's CPU time over its wall time is how many cores it kept busy.
pub(super) fn cpu_seconds() -> Option<f64> {
    #[cfg(unix)]
    {
        let used = |who| {
            let mut u = std::mem::MaybeUninit::<libc::rusage>::zeroed();
            // SAFETY: getrusage fills the struct it is handed and reads nothing else.
            let rc = unsafe { libc::getrusage(who, u.as_mut_ptr()) };
            (rc == 0).then(|| {
                // SAFETY: zero-initialised, then written by a successful call.
                let u = unsafe { u.assume_init() };
                let t = |tv: libc::timeval| tv.tv_sec as f64 + tv.tv_usec as f64 * 1e-6;
                t(u.ru_utime) + t(u.ru_stime)
            })
        };
        Some(used(libc::RUSAGE_SELF)? + used(libc::RUSAGE_CHILDREN).unwrap_or(0.0))
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The machine in words: the processor's model name (`/proc/cpuinfo`, where there is one) and
/// the cores the run had, e.g. "AMD EPYC, 2 cores". Timings from different machines sit side
/// by side in a merged snapshot, so each part names its own.
pub(super) fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            (t.lines())
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, m)| m.split_whitespace().collect::<Vec<_>>().join(" "))
        })
        .filter(|m| !m.is_empty())
        .unwrap_or_else(|| std::env::consts::ARCH.to_string());
    format!("{model}, {} cores", cores())
}

/// The cores this machine offers the run (1 where it cannot say).
pub(super) fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

#[cfg(test)]
mod tests {
    /// Work costs CPU time: the clock read grows while a thread computes. (The spin waits on
    /// the CPU clock itself, so a busy machine only makes it take longer.)
    #[test]
    #[cfg(unix)]
    fn cpu_time_grows_with_work() {
        let a = super::cpu_seconds().expect("getrusage on unix");
        let t = std::time::Instant::now();
        let mut x = 1.0f64;
        let mut b = a;
        while b - a < 0.1 && t.elapsed().as_secs_f64() < 10.0 {
            for _ in 0..100_000 {
                x = std::hint::black_box(x * 1.000_000_1 + 1e-9);
            }
            b = super::cpu_seconds().expect("getrusage on unix");
        }
        assert!(
            b - a >= 0.1,
            "spun 10 s of wall time, CPU grew {:.3} s",
            b - a
        );
        assert!(x.is_finite());
    }
}
