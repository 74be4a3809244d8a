//! Recorded signals: the paper's 21 sensor channels, the true forces of every wheel, and the
//! same kinds of signals for every body, low-pass filtered at the integration rate and
//! decimated to the output rate, streamed to a CSV file written atomically, with a metadata
//! file beside it.
//!
//! Accelerations are what the vehicle file's accelerometers read ([`Accelerometers`]): the
//! specific force `a − g` (default) or the kinematic acceleration `a`, in body axes; for
//! wheelsets, which spin, in the axes of the local track frame (an axle-box accelerometer).
//!
//! [`Accelerometers`]: crate::vehicle::Accelerometers

use super::Simulation;
use super::filter::Lowpass;
use super::profile::StepProfile;
use crate::error::{Error, Result};
use crate::sensors::{PAPER_CHANNELS, PAPER_UNITS};
use crate::vehicle::Accelerometers;
use nalgebra::Vector3;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use crate::sensors::VEHICLE_MASS;

use super::channels::{BODY_SIGNALS, WHEEL_SIGNALS};

/// Filters and decimates the signals of a simulation.
pub struct Recorder {
    names: Vec<String>,
    units: Vec<&'static str>,
    /// Every channel but time and position, filtered together.
    filters: crate::dsp::FilterBank,
    every: usize,
    count: usize,
    row: Vec<f64>,
    paper: bool,
    /// Each body's ten values of the step (kept to spare an allocation a step).
    bodies: Vec<[f64; 10]>,
    /// With profiling on: time spent in each part of [`Recorder::sample`], per sample.
    profile: Option<StepProfile>,
}

impl Recorder {
    /// Channels for this simulation's vehicle.
    pub fn new(sim: &Simulation) -> Self {
        let v = sim.vehicle();
        let paper = v.sensors.is_some();
        let (names, units): (Vec<String>, Vec<&'static str>) =
            super::channels::channels_of(v, sim.records_couplers())
                .into_iter()
                .map(|c| (c.name, c.unit))
                .unzip();
        let cfg = sim.config();
        let every = crate::bounds::to_count((1.0 / (cfg.output_rate * cfg.dt)).round().max(1.0));
        let n = names.len();
        Recorder {
            names,
            units,
            filters: Lowpass::new(cfg.cutoff, 1.0 / cfg.dt).bank(n - 2),
            every,
            count: 0,
            row: vec![0.0; n],
            paper,
            bodies: Vec::with_capacity(sim.states().len()),
            profile: None,
        }
    }

    /// Turns the timing of [`Recorder::sample`]'s parts on (cleared) or off.
    pub fn set_profiling(&mut self, on: bool) {
        self.profile = on.then(StepProfile::default);
    }

    /// With profiling on: each part of a sample, mean µs and calls per sample
    /// ([`StepProfile::per_step`]; `clock_ns`, the clock's cost per part, taken off).
    pub fn profile(&self, clock_ns: f64) -> Vec<(String, f64, f64)> {
        self.profile
            .as_ref()
            .map(|p| p.per_step(clock_ns))
            .unwrap_or_default()
    }

    /// Channel names, in column order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Units of the channels.
    pub fn units(&self) -> &[&'static str] {
        &self.units
    }

    /// Takes the signals of the current step; returns a decimated row when one is due.
    /// The first call initialises the filters to the current values (no start transient).
    pub fn sample(&mut self, sim: &mut Simulation) -> Option<&[f64]> {
        let mut clock = self.profile.is_some().then(Instant::now);
        // Adds the time since the last reading to `part` (profiling only).
        let mut lap = |profile: &mut Option<StepProfile>, part: &str| {
            if let (Some(t), Some(p)) = (clock.as_mut(), profile.as_mut()) {
                let now = Instant::now();
                p.add(part, now - *t);
                *t = now;
            }
        };
        sim.refresh_frames();
        lap(
            &mut self.profile,
            "every body's track frame (every 10th step)",
        );
        let sim = &*sim;
        signals(sim, self.paper, &mut self.bodies, &mut self.row);
        if self.count == 0 {
            self.filters.hold(&self.row[2..]);
        }
        lap(&mut self.profile, "the channels computed");
        self.filters.step(&mut self.row[2..]);
        lap(&mut self.profile, "the low-pass filter bank");
        if let Some(p) = self.profile.as_mut() {
            p.steps += 1;
        }
        let due = self.count.is_multiple_of(self.every);
        self.count += 1;
        if !due {
            return None;
        }
        // Time and position are not filtered: read only for the rows written (the
        // position is four projections onto the centre line).
        self.row[0] = sim.time();
        self.row[1] = sim.centre_s();
        Some(&self.row[..])
    }
}

/// Computes all channels of the current step into `out` (same order as the names).
fn signals(sim: &Simulation, paper: bool, body_vals: &mut Vec<[f64; 10]>, out: &mut [f64]) {
    let v = sim.vehicle();
    let states = sim.states();
    // World z is up: a body at rest has a = 0 and reads a − g = +g·e_z as specific force.
    let g = match v.accelerometers {
        Accelerometers::Kinematic => Vector3::zeros(),
        Accelerometers::SpecificForce => Vector3::new(0.0, 0.0, crate::GRAVITY),
    };
    body_vals.clear();
    for (i, st) in states.iter().enumerate() {
        let f = &sim.frames()[i];
        let spec_force = sim.accelerations[i] + g;
        let is_ws = v.contact.wheelsets.contains(&i);
        let m = st.matrix();
        let axes = if is_ws { f.axes } else { m };
        let a = axes.transpose() * spec_force;
        let w = axes.transpose() * st.angular_velocity;
        let rel = f.to_local(&(st.position - f.origin));
        let rot_rel = f.axes.transpose() * m;
        let y_axis = rot_rel.column(1);
        body_vals.push([
            a.x,
            a.y,
            a.z,
            w.x,
            w.y,
            w.z,
            rel.y,
            rel.z,
            crate::angle::asin(y_axis.z),
            crate::angle::atan2(-y_axis.x, y_axis.y),
        ]);
    }
    // Time and position (columns 0 and 1) are set by the caller when a row is due.
    let mut k = 2;
    let mut put = |x: f64| {
        out[k] = x;
        k += 1;
    };
    if let Some(sl) = &v.sensors {
        let ws_pos = v
            .contact
            .wheelsets
            .iter()
            .position(|&w| w == sl.wheelset)
            .unwrap_or(0);
        let wl = &sim.wheels[2 * ws_pos];
        // The angle of attack and the creepages are those of the label wheel (1L: the paper's).
        let lw = &sim.wheels[sl.label_wheel];
        let (fl, fr, bo, cb, ws) = (
            &body_vals[sl.frame_left],
            &body_vals[sl.frame_right],
            &body_vals[sl.bolster],
            &body_vals[sl.carbody],
            &body_vals[sl.wheelset],
        );
        for x in [
            fl[1],
            fr[1],
            fl[2],
            fr[2],
            bo[1],
            bo[2],
            ws[1],
            ws[2],
            wl.y_centre,
            wl.yaw,
            wl.roll,
            cb[3],
            cb[4],
            cb[5],
            ws[3],
            ws[4],
            ws[5],
            lw.yaw - lw.rail_slope,
            lw.creepage.y,
            lw.creepage.x,
            lw.creepage.spin,
        ] {
            put(x);
        }
    }
    for (w, (rail_y, rail_z)) in sim.wheels.iter().zip(sim.rail_heads()) {
        for x in [
            w.y,
            w.q,
            w.normal,
            w.angle,
            w.creepage.x,
            w.creepage.y,
            w.creepage.spin,
            rail_y,
            rail_z,
        ] {
            put(x);
        }
    }
    for b in body_vals.iter() {
        for &x in b {
            put(x);
        }
    }
    for e in &v.elements {
        // Elements without gauges (wedges, stops, bracing) are not measured at all.
        let axes = e.gauge_axes();
        if axes.is_empty() {
            continue;
        }
        if let Some(d) = e.deflection(states) {
            for &axis in axes {
                put(d[axis]);
            }
        }
    }
    // What the wagon weighs (a weighbridge, or the consist list): known, not sensed.
    put(v.mass() * 1e-3);
    if sim.records_couplers() {
        // A wagon alone in a data set of trains: no coupler, no force, no angle.
        let [f, r] = sim.hitch().map(|h| h.readings).unwrap_or_default();
        for x in [f.force, r.force, f.yaw, r.yaw] {
            put(x);
        }
    }
    let _ = paper;
}

/// What a finished run reports.
#[derive(Debug, Clone, Default)]
pub struct RunSummary {
    /// Rows written.
    pub rows: usize,
    /// Simulated time recorded, s.
    pub simulated: f64,
    /// Wall time of the whole run (settling included), s.
    pub wall: f64,
    /// Simulated time (settling included) over wall time.
    pub real_time_factor: f64,
    /// Peak |Y/Q| per wheel over the recorded part.
    pub peak_y_over_q: Vec<f64>,
    /// Mean Y and Q per wheel over the recorded part, N.
    pub mean_yq: Vec<(f64, f64)>,
    /// Output file.
    pub out: PathBuf,
}

/// A recorded run held in memory: channel names and units, and rows of values.
#[derive(Debug, Clone)]
pub struct Recording {
    /// Channel names.
    pub names: Vec<String>,
    /// Units.
    pub units: Vec<&'static str>,
    /// Rows at the output rate.
    pub rows: Vec<Vec<f64>>,
    /// What the run reports.
    pub summary: RunSummary,
}

impl Recording {
    /// One column by index.
    pub fn column(&self, i: usize) -> Vec<f64> {
        self.rows.iter().map(|r| r[i]).collect()
    }

    /// Refuses a recording that holds a non-finite value, naming the column, the row and the
    /// file it was to be written to: no writer puts NaN or infinity in a file.
    pub fn check_finite(&self, path: &Path) -> Result<()> {
        for (r, row) in self.rows.iter().enumerate() {
            if let Some(c) = row.iter().position(|v| !v.is_finite()) {
                return Err(Error::Domain(format!(
                    "{}: not written: column {} holds {} at row {} (t = {:.4} s)",
                    path.display(),
                    self.names.get(c).map_or("?", |n| n.as_str()),
                    row[c],
                    r + 1,
                    row.first().copied().unwrap_or(f64::NAN)
                )));
            }
        }
        Ok(())
    }

    /// Writes the rows as CSV with a header line.
    pub fn write_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        self.write_csv_as(w, &[])
    }

    /// CSV with the columns flagged in `single` (by index; missing: false) printed at float32
    /// precision (the shortest text that reads back as the same f32).
    pub fn write_csv_as(&self, w: &mut dyn Write, single: &[bool]) -> std::io::Result<()> {
        writeln!(w, "{}", self.names.join(","))?;
        for row in &self.rows {
            for (k, x) in row.iter().enumerate() {
                if k > 0 {
                    w.write_all(b",")?;
                }
                if single.get(k).copied().unwrap_or(false) {
                    write!(w, "{:e}", *x as f32)?;
                } else {
                    write!(w, "{x:.7e}")?;
                }
            }
            w.write_all(b"\n")?;
        }
        Ok(())
    }
}

/// Runs a simulation: refuses a step its integrator cannot hold ([`super::modes::guard`]),
/// settles, then records `duration` seconds in memory (about 0.4 MB per
/// simulated second for the C80's 244 columns). `progress` receives the fraction done.
pub fn record(sim: &mut Simulation, mut progress: impl FnMut(f64)) -> Result<Recording> {
    let t0 = std::time::Instant::now();
    super::modes::guard(sim)?;
    sim.settle()?;
    let mut rec = Recorder::new(sim);
    let duration = sim.config().duration;
    let n_wheels = sim.wheels.len();
    let mut peak = vec![0.0f64; n_wheels];
    let mut sums = vec![(0.0, 0.0); n_wheels];
    // Each wheel's recorded Y and Q columns, found by name.
    let column = |name: String| rec.names().iter().position(|n| *n == name);
    let yq_cols: Vec<Option<(usize, usize)>> = (0..n_wheels)
        .map(|k| {
            let w = super::wheel_name(k).to_ascii_lowercase();
            column(format!("w{w}_force_y")).zip(column(format!("w{w}_force_z")))
        })
        .collect();
    let static_load =
        sim.vehicle().mass() * crate::GRAVITY / sim.vehicle().contact.wheelsets.len() as f64 / 2.0;
    let total_steps = crate::bounds::count_of(duration / sim.config().dt, "steps of the run")?;
    let mut rows = Vec::with_capacity((duration * sim.config().output_rate) as usize + 1);
    for steps in 0..=total_steps {
        if steps > 0 {
            sim.step()?;
        }
        for (k, wr) in sim.wheels.iter().enumerate() {
            sums[k].0 += wr.y;
            sums[k].1 += wr.q;
        }
        if let Some(row) = rec.sample(&mut *sim) {
            if row.iter().any(|x| !x.is_finite()) {
                return Err(Error::Domain(format!(
                    "non-finite signal at t = {:.4} s: nothing is written",
                    sim.time()
                )));
            }
            // Y/Q from the recorded (filtered) forces, where the wheel carries at least 10 %
            // of its static load (Y/Q of an unloaded wheel means nothing).
            for (p, cols) in peak.iter_mut().zip(&yq_cols) {
                if let Some((y, q)) = cols.map(|(y, q)| (row[y], row[q]))
                    && q > 0.1 * static_load
                {
                    *p = p.max((y / q).abs());
                }
            }
            rows.push(row.to_vec());
        }
        if steps % 2000 == 1999 {
            progress(steps as f64 / total_steps.max(1) as f64);
        }
    }
    let wall = t0.elapsed().as_secs_f64();
    let n = (total_steps + 1) as f64;
    Ok(Recording {
        names: rec.names().to_vec(),
        units: rec.units().to_vec(),
        summary: RunSummary {
            rows: rows.len(),
            simulated: duration,
            wall,
            real_time_factor: (duration + sim.config().settle) / wall,
            peak_y_over_q: peak,
            mean_yq: sums.iter().map(|&(y, q)| (y / n, q / n)).collect(),
            out: PathBuf::new(),
        },
        rows,
    })
}

/// Runs a simulation and writes it to a CSV file (temporary file, renamed when complete) with
/// `<out>.meta.json` beside it.
pub fn run_to_csv(
    sim: &mut Simulation,
    out: &Path,
    meta: &serde_json::Value,
    progress: impl FnMut(f64),
) -> Result<RunSummary> {
    let recording = record(sim, progress)?;
    recording.check_finite(out)?;
    crate::io::write_atomic(out, |w| recording.write_csv(w))?;
    write_meta(out, meta, &recording)
}

/// Writes `<out>.meta.json` for a recording written to `out`: `meta` with the channels (name,
/// unit), the row count and the wall time added; returns the run's summary naming `out`.
pub fn write_meta(
    out: &Path,
    meta: &serde_json::Value,
    recording: &Recording,
) -> Result<RunSummary> {
    let mut meta = meta.clone();
    if let Some(m) = meta.as_object_mut() {
        m.insert(
            "channels".into(),
            recording
                .names
                .iter()
                .zip(&recording.units)
                .map(|(n, u)| serde_json::json!({"name": n, "unit": u}))
                .collect(),
        );
        m.insert("rows".into(), recording.rows.len().into());
        m.insert("wall_time_s".into(), recording.summary.wall.into());
    }
    crate::io::check_json_finite(&meta, &meta_path(out))?;
    crate::io::write_atomic(&meta_path(out), |w| {
        serde_json::to_writer_pretty(&mut *w, &meta).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })?;
    let mut summary = recording.summary.clone();
    summary.out = out.to_path_buf();
    Ok(summary)
}

/// `run.csv` → `run.meta.json`.
pub fn meta_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "run".into());
    out.with_file_name(format!("{stem}.meta.json"))
}

/// The SI unit of a recorded channel from its name, by the same tables the recorder names its
/// channels with (`time_s`, `s_m`, the paper's 21, `w<wheel>_<signal>`, `<body>_<signal>`, the
/// suspension gauges); a `_noisy` copy has its channel's unit; `None` for a name it never
/// records.
pub fn unit_of(name: &str) -> Option<&'static str> {
    let n = crate::sensors::clean_name(name);
    match n {
        "time_s" => return Some("s"),
        "s_m" => return Some("m"),
        VEHICLE_MASS => return Some("t"),
        _ => {}
    }
    if let Some(k) = PAPER_CHANNELS.iter().position(|c| *c == n) {
        return Some(PAPER_UNITS[k]);
    }
    let wheel = n.len() > 4
        && n.starts_with('w')
        && n.as_bytes()[1].is_ascii_digit()
        && matches!(n.as_bytes()[2], b'l' | b'r')
        && n.as_bytes()[3] == b'_';
    if wheel && let Some((_, u, _)) = WHEEL_SIGNALS.iter().find(|(s, _, _)| &n[4..] == *s) {
        return Some(u);
    }
    if let Some((_, u, _)) = BODY_SIGNALS.iter().find(|(s, _, _)| {
        n.len() > s.len() + 1 && n.ends_with(s) && n.as_bytes()[n.len() - s.len() - 1] == b'_'
    }) {
        return Some(u);
    }
    crate::sensors::DEFLECTION_PREFIXES
        .iter()
        .any(|p| n.starts_with(p))
        .then_some("m")
}
