//! Assessment of a run as acceptance engineers read it: the forces low-pass filtered, then
//! EN 14363 / UIC 518-style statistics — (Y/Q)2m and (ΣY)2m as sliding means over 2 m of
//! track in steps of 0.5 m with their 0.15 % and 99.85 % percentiles, Q's 99.85 %, the
//! quasi-static Yqst and Qqst as medians over curves — and the Chinese derailment criteria
//! with their time criterion, per wheel (or wheelset) and per section of track, each against
//! its limit from the criteria file ([`criteria`]), which cites where every number comes from.
//!
//! Works on a simulated run (forces named `w1l_force_y`) and on `identify` output
//! (`w1l_force_y_N`) alike: the same statistics of true and identified forces.

mod compare;
pub mod criteria;
pub mod interval;
mod ride;
pub mod safety;
mod section;
mod statistics;

use crate::dsp::{Butterworth, percentile};
use crate::error::{Error, Result};
use crate::track::{SectionKind, TrackSpec};
pub use compare::{StatCheck, compare};
pub use criteria::Criteria;
use section::Section;
use serde::Serialize;

/// A series of wheel–rail forces in time: the label time and one series per target, in N —
/// what `identify` writes and the truth of a simulated run alike, so both are judged by the
/// same statistics and indices.
#[derive(Debug, Clone, PartialEq)]
pub struct ForceSeries {
    /// Target names (label channels).
    pub targets: Vec<String>,
    /// Time of each value, s (for identification, the label step of its window).
    pub time: Vec<f64>,
    /// Values `[n][targets]`, N.
    pub values: Vec<Vec<f64>>,
}

/// Y and Q of one wheel over a run, N.
#[derive(Debug, Clone)]
pub struct WheelSeries {
    /// Wheel name (`w1l`).
    pub wheel: String,
    /// Lateral force Y.
    pub y: Vec<f64>,
    /// Vertical force Q.
    pub q: Vec<f64>,
}

/// The forces of a run with time and track position.
#[derive(Debug, Clone)]
pub struct RunForces {
    /// Time, s.
    pub time: Vec<f64>,
    /// Track position of the vehicle, m.
    pub s: Vec<f64>,
    /// Every wheel with both forces, in column order.
    pub wheels: Vec<WheelSeries>,
    /// Carbody lateral and vertical accelerations, m/s², where the run has them (the ride
    /// index).
    pub carbody: Option<[Vec<f64>; 2]>,
    /// Front and rear coupler forces, N (+ tension), where the run was in a train.
    pub couplers: Option<[Vec<f64>; 2]>,
}

impl RunForces {
    /// From named columns: `time_s`, `s_m` and `w{n}{l|r}_force_{y|z}` (a trailing `_N`, as
    /// `identify` writes, is accepted). Errors name `source` and what is missing.
    pub fn from_columns(source: &str, cols: &[(String, Vec<f64>)]) -> Result<Self> {
        let find = |name: &str| {
            cols.iter()
                .find(|(n, _)| n == name || n.strip_suffix("_N") == Some(name))
                .map(|(_, v)| v.clone())
        };
        let time =
            find("time_s").ok_or_else(|| Error::Domain(format!("{source}: no time_s column")))?;
        let s = find("s_m").ok_or_else(|| {
            Error::Domain(format!(
                "{source}: no s_m column: the sliding means are over track distance (simulate, generate and identify write s_m)"
            ))
        })?;
        if time.len() < 2 {
            return Err(Error::Domain(format!(
                "{source}: {} row(s): a run to assess needs at least two",
                time.len()
            )));
        }
        let mut wheels = Vec::new();
        for (name, _) in cols {
            let base = name.strip_suffix("_N").unwrap_or(name);
            // A wheel with one of its two forces would drop out of every index unnoticed.
            let (wheel, other) =
                match (base.strip_suffix("_force_y"), base.strip_suffix("_force_z")) {
                    (Some(w), _) => (w, "force_z"),
                    (_, Some(w)) => (w, "force_y"),
                    _ => continue,
                };
            let Some(paired) = find(&format!("{wheel}_{other}")) else {
                return Err(Error::Domain(format!(
                    "{source}: column {name} has no {wheel}_{other} beside it: a wheel is assessed on both its forces"
                )));
            };
            if other == "force_z" {
                wheels.push(WheelSeries {
                    wheel: wheel.to_string(),
                    y: find(base).unwrap_or_default(),
                    q: paired,
                });
            }
        }
        if wheels.is_empty() {
            return Err(Error::Domain(format!(
                "{source}: no wheel with both forces (columns w1l_force_y and w1l_force_z, or with _N)"
            )));
        }
        let named: Vec<(String, &Vec<f64>)> = [("time_s".to_string(), &time), ("s_m".into(), &s)]
            .into_iter()
            .chain(wheels.iter().flat_map(|w| {
                [
                    (format!("{}_force_y", w.wheel), &w.y),
                    (format!("{}_force_z", w.wheel), &w.q),
                ]
            }))
            .collect();
        for (what, v) in named {
            if let Some(r) = v.iter().position(|x| !x.is_finite()) {
                return Err(Error::Domain(format!(
                    "{source}: column {what}, row {}: not a finite number",
                    r + 1
                )));
            }
        }
        let carbody = find("carbody_acc_y")
            .zip(find("carbody_acc_z"))
            .map(|(y, z)| [y, z]);
        if let Some(r) = carbody
            .iter()
            .flat_map(|c| c.iter())
            .find_map(|v| v.iter().position(|x| !x.is_finite()))
        {
            return Err(Error::Domain(format!(
                "{source}: carbody acceleration, row {}: not a finite number",
                r + 1
            )));
        }
        let couplers = find("coupler_front_force")
            .zip(find("coupler_rear_force"))
            .map(|(f, r)| [f, r]);
        if let Some(r) = couplers
            .iter()
            .flat_map(|c| c.iter())
            .find_map(|v| v.iter().position(|x| !x.is_finite()))
        {
            return Err(Error::Domain(format!(
                "{source}: coupler force, row {}: not a finite number",
                r + 1
            )));
        }
        Ok(RunForces {
            time,
            s,
            wheels,
            carbody,
            couplers,
        })
    }
}

/// A stretch of track assessed on its own.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Span {
    /// Name (`tangent`, `curve R 400 m`, `transition`, `whole run`).
    pub name: String,
    /// Radius of a curve, m.
    pub radius_m: Option<f64>,
    /// From, m.
    pub from_m: f64,
    /// To, m.
    pub to_m: f64,
}

/// The sections of a track, in order.
pub fn spans(track: &TrackSpec) -> Vec<Span> {
    track
        .sections
        .iter()
        .map(|sec| {
            let (name, radius_m) = match sec.kind {
                SectionKind::Tangent => ("tangent".to_string(), None),
                SectionKind::Transition => ("transition".to_string(), None),
                SectionKind::Curve { radius, .. } => {
                    (format!("curve R {radius:.0} m"), Some(radius))
                }
            };
            Span {
                name: format!("{name} ({:.0}–{:.0} m)", sec.start, sec.end()),
                radius_m,
                from_m: sec.start,
                to_m: sec.end(),
            }
        })
        .collect()
}

/// One assessed quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// Section of track.
    pub section: String,
    /// Quantity (`(Y/Q)2m`, `(ΣY)2m`, `Q`, `Yqst`, `Qqst`, `Y/Q (50 ms)`, `ΔQ/Q̄`, `H`).
    pub quantity: String,
    /// Wheel or wheelset.
    pub place: String,
    /// Statistic compared with the limit (described in `statistic`).
    pub value: f64,
    /// Limit.
    pub limit: f64,
    /// Unit of value and limit (`-` for ratios).
    pub unit: String,
    /// How the value is computed.
    pub statistic: String,
    /// Within the limit.
    pub pass: bool,
    /// Criteria table the limit comes from (its `source` cites it).
    pub criterion: String,
}

/// The assessment of a run.
#[derive(Debug, Clone, Serialize)]
pub struct Assessment {
    /// Static wheel load Q0, kN.
    pub static_wheel_load_kn: f64,
    /// Criteria used (with their sources).
    pub criteria: Criteria,
    /// Every quantity per section and place.
    pub rows: Vec<Row>,
    /// Coverage of the identified forces' intervals the statistics' intervals come from
    /// (identified forces with bounds, [`interval::assess_with_bands`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub coverage: Option<f64>,
    /// Per row, the statistic's interval and the probability its limit is exceeded (empty
    /// without bounds).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub intervals: Vec<interval::RowInterval>,
}

/// Assesses a run given as named columns (a `simulate` or `generate` run, or `identify`'s
/// output): with each statistic's interval where the columns carry identified forces' bounds
/// (`w1l_force_y_lo_N` …, at `coverage`), else plainly. `source` names the data in messages.
pub fn assess_columns(
    source: &str,
    cols: &[(String, Vec<f64>)],
    spans: &[Span],
    criteria: &Criteria,
    q0_kn: f64,
    coverage: f64,
) -> Result<Assessment> {
    let run = RunForces::from_columns(source, cols)?;
    match interval::bands_from_columns(source, cols, &run)? {
        Some(b) => interval::assess_with_bands(&run, &b, spans, criteria, q0_kn, coverage),
        None => assess(&run, spans, criteria, q0_kn),
    }
}

/// Samples per second of a time column (median step).
fn rate(time: &[f64]) -> f64 {
    let steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    1.0 / percentile(&steps, 50.0)
}

/// Assesses `run` over `spans` (empty: the whole run as one) against `criteria`, with static
/// wheel load `q0_kn`: each section by every criterion in turn (`section`: one function per
/// criterion).
pub fn assess(
    run: &RunForces,
    spans: &[Span],
    criteria: &Criteria,
    q0_kn: f64,
) -> Result<Assessment> {
    let fs = rate(&run.time);
    if !(fs.is_finite() && fs > 2.0 * criteria.filter.lowpass_hz) {
        return Err(Error::Domain(format!(
            "sampling rate {fs:.1} Hz is too low for the {} Hz filter",
            criteria.filter.lowpass_hz
        )));
    }
    let lp = Butterworth::lowpass(criteria.filter.order, criteria.filter.lowpass_hz, fs);
    let wheels: Vec<WheelSeries> = run
        .wheels
        .iter()
        .map(|w| WheelSeries {
            wheel: w.wheel.clone(),
            y: lp.filtfilt(&w.y),
            q: lp.filtfilt(&w.q),
        })
        .collect();
    let whole = [Span {
        name: "whole run".into(),
        radius_m: None,
        from_m: f64::NEG_INFINITY,
        to_m: f64::INFINITY,
    }];
    let spans = if spans.is_empty() { &whole[..] } else { spans };
    let win = criteria.sliding_mean.window_m;
    let mut rows = Vec::new();
    for span in spans {
        let Some(sec) = Section::new(run, &wheels, span, criteria, q0_kn, fs) else {
            continue;
        };
        sec.wheel_statistics(&mut rows);
        let axle_sums = sec.axle_sums();
        sec.track_shift(&axle_sums, &mut rows);
        sec.running_stability(&axle_sums, &mut rows);
        sec.chinese(&mut rows);
        sec.carbody_acceleration(&mut rows);
        sec.ride(&mut rows);
        sec.couplers(&mut rows);
    }
    if rows.is_empty() {
        return Err(Error::Domain(format!(
            "no section holds {win} m of the run: nothing to assess"
        )));
    }
    Ok(Assessment {
        static_wheel_load_kn: q0_kn,
        criteria: criteria.clone(),
        rows,
        coverage: None,
        intervals: Vec::new(),
    })
}

impl Assessment {
    /// Rows outside their limit.
    pub fn failures(&self) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(|r| !r.pass)
    }

    /// The table (section, quantity, place, value, limit, unit, verdict, criterion; with
    /// intervals, then the statistic's low and high end and the probability of exceeding the
    /// limit).
    pub fn table(&self) -> crate::report::table::Table {
        let mut head = vec![
            "section",
            "quantity",
            "place",
            "value",
            "limit",
            "unit",
            "verdict",
            "criterion",
        ];
        if !self.intervals.is_empty() {
            head.extend(["low", "high", "P(exceed)"]);
        }
        let mut t = crate::report::table::Table::new(&head);
        for (i, r) in self.rows.iter().enumerate() {
            let mut row = vec![
                r.section.clone(),
                r.quantity.clone(),
                r.place.clone(),
                format!("{:.4}", r.value),
                format!("{:.4}", r.limit),
                r.unit.clone(),
                if r.pass { "pass" } else { "FAIL" }.into(),
                r.criterion.clone(),
            ];
            if let Some(b) = self.intervals.get(i) {
                row.extend([
                    format!("{:.4}", b.low),
                    format!("{:.4}", b.high),
                    format!("{:.4}", b.exceedance),
                ]);
            }
            t.push(row);
        }
        t
    }

    /// Markdown: the table, then each criterion's source.
    pub fn markdown(&self) -> String {
        let c = &self.criteria;
        let mut s = format!(
            "# Assessment ({})\n\nStatic wheel load Q0 = {:.1} kN. Forces low-pass filtered at {} Hz (Butterworth order {}, zero phase). {} of {} quantities within their limits.\n\n",
            c.name,
            self.static_wheel_load_kn,
            c.filter.lowpass_hz,
            c.filter.order,
            self.rows.iter().filter(|r| r.pass).count(),
            self.rows.len()
        );
        if let Some(c) = self.coverage {
            s += &format!(
                "Identified forces with their {:.0} % intervals: each statistic is recomputed with every wheel's Y and Q at the bounds (low and high: the smallest and largest over the four corners), and P(exceed) is the probability that the true statistic exceeds its limit, taking the statistic's error as normal with its central {:.0} % interval reaching the high end (an estimate: the errors of one run are taken to move together).\n\n",
                100.0 * c,
                100.0 * c
            );
        }
        s += &self.table().markdown();
        s += "\n## Sources\n\n";
        for (k, src) in [
            ("filter", &c.filter.source),
            ("sliding_mean", &c.sliding_mean.source),
            ("percentiles", &c.percentiles.source),
            ("y_over_q", &c.y_over_q.source),
            ("track_shift", &c.track_shift.source),
            ("vertical", &c.vertical.source),
            ("lateral_quasi_static", &c.lateral_quasi_static.source),
            ("chinese", &c.chinese.source),
        ] {
            s += &format!("- `{k}`: {src}\n");
        }
        if let Some(r) = &c.ride {
            s += &format!("- `ride`: {}\n", r.source);
        }
        if let Some(st) = &c.stability {
            s += &format!("- `stability`: {}\n", st.source);
        }
        if let Some(a) = &c.carbody_acceleration {
            s += &format!("- `carbody_acceleration`: {}\n", a.source);
        }
        s
    }
}

impl RunForces {
    /// From identified (or true) forces at the label times and the track position at those
    /// times.
    pub fn from_identified(id: &ForceSeries, s: Vec<f64>) -> Result<Self> {
        let cols: Vec<(String, Vec<f64>)> = [
            ("time_s".to_string(), id.time.clone()),
            ("s_m".to_string(), s),
        ]
        .into_iter()
        .chain(
            id.targets
                .iter()
                .enumerate()
                .map(|(k, t)| (t.clone(), id.values.iter().map(|v| v[k]).collect())),
        )
        .collect();
        Self::from_columns("identified forces", &cols)
    }
}
