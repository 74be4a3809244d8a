//! Safety indices from a force series, identified or true (assets/docs/physics.md §7), with
//! configurable limits whose defaults are the commonly quoted Chinese values — secondary-source
//! figures, labelled so:
//! derailment coefficient |Y|/Q ≤ 1.2 (allowable; 1.0 preferred), wheel unloading
//! ΔQ/Q̄ ≤ 0.65 (0.60 preferred), wheelset lateral force H ≤ 0.85·(10 + P_st/3) kN, and a
//! time criterion: an excursion above a limit counts when it lasts at least 50 ms (shorter
//! impacts are reported as brief, not as exceedances).
//!
//! One [`Monitor`] evaluates them sample by sample: the batch report ([`indices`]) and the
//! streaming identification run the same code.

use super::ForceSeries;
use crate::sensors::RATE_HZ;
use serde::{Deserialize, Serialize};

/// Limits and the static load they refer to.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// |Y|/Q limit.
    pub y_over_q: f64,
    /// ΔQ/Q̄ limit.
    pub unloading: f64,
    /// Static wheel load Q̄, kN (C80: 25 t axle → 122.6 kN).
    pub static_wheel_load_kn: f64,
    /// Shortest excursion above a limit that counts as an exceedance, s.
    #[serde(default = "default_min_duration")]
    pub min_duration_s: f64,
    /// α of the wheelset lateral force limit `α·(10 + P_st/3)` kN.
    #[serde(default = "default_lateral_alpha")]
    pub lateral_alpha: f64,
}

impl Limits {
    /// The limits of the criteria's `[chinese]` table with the static wheel load
    /// `static_wheel_load_kn` (what `identify`, `validate identify` and `assess` judge by
    /// unless told otherwise).
    pub fn from_criteria(criteria: &crate::assess::Criteria, static_wheel_load_kn: f64) -> Self {
        let c = &criteria.chinese;
        Limits {
            y_over_q: c.derailment,
            unloading: c.unloading,
            static_wheel_load_kn,
            min_duration_s: c.min_duration_s,
            lateral_alpha: c.lateral_alpha,
        }
    }
}

fn default_lateral_alpha() -> f64 {
    0.85
}

fn default_min_duration() -> f64 {
    DEFAULT_MIN_DURATION_S
}

/// Default time criterion, s: 50 ms, the duration below which a lateral impact is not read as
/// a derailment risk in the commonly quoted reading of GB 5599 (secondary source).
pub const DEFAULT_MIN_DURATION_S: f64 = 0.05;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            y_over_q: 1.2,
            unloading: 0.65,
            static_wheel_load_kn: 25_000.0 * crate::GRAVITY / 2.0 / 1000.0,
            min_duration_s: DEFAULT_MIN_DURATION_S,
            lateral_alpha: default_lateral_alpha(),
        }
    }
}

impl Limits {
    /// Refuses a limit no judgement can use: a non-positive or non-finite index limit or
    /// static wheel load (ΔQ/Q̄ would divide by it), or a negative time criterion.
    pub fn check(&self) -> crate::error::Result<()> {
        for (what, v) in [
            ("the Y/Q limit", self.y_over_q),
            ("the ΔQ/Q̄ limit", self.unloading),
            ("the static wheel load Q̄ (kN)", self.static_wheel_load_kn),
            ("the lateral force limit's α", self.lateral_alpha),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(crate::error::Error::Domain(format!(
                    "{what} is {v}: give a positive number"
                )));
            }
        }
        if !(self.min_duration_s.is_finite() && self.min_duration_s >= 0.0) {
            return Err(crate::error::Error::Domain(format!(
                "the time criterion is {} s: give a duration ≥ 0",
                self.min_duration_s
            )));
        }
        Ok(())
    }

    /// Wheelset lateral force limit `α·(10 + P_st/3)` kN (α = 0.85 by default), `P_st` the
    /// static axle load in kN.
    pub fn lateral_kn(&self) -> f64 {
        self.lateral_alpha * (10.0 + 2.0 * self.static_wheel_load_kn / 3.0)
    }
}

/// One index's summary and its exceedances.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IndexReport {
    /// Name, e.g. `Y/Q w1l`.
    pub name: String,
    /// The index alone: `Y/Q`, `ΔQ/Q̄` or `H (kN)`.
    pub index: String,
    /// Where: the wheel (`w1l`) or the wheelset (`wheelset 1`).
    pub place: String,
    /// ASCII column name in output files (`y_over_q_w1l`, `unloading_w1l`, `h_wheelset1_kn`).
    pub column: String,
    /// Limit.
    pub limit: f64,
    /// Largest value.
    pub max: f64,
    /// Time of the largest value, s (on the sample grid).
    pub max_time_s: f64,
    /// Excursions above the limit lasting at least the time criterion: (start s, end s, peak).
    pub exceedances: Vec<(f64, f64, f64)>,
    /// Excursions above the limit shorter than the time criterion (not exceedances).
    pub brief_excursions: usize,
    /// The series (same times as the identification; empty when streamed).
    #[serde(skip)]
    pub series: Vec<f64>,
}

/// Wheel of a label name `w{n}{l|r}_force_{y|z}`: (`w1l`, `y`).
fn wheel_of(name: &str) -> Option<(&str, char)> {
    let (wheel, rest) = name.split_once('_')?;
    let comp = rest.strip_prefix("force_")?.chars().next()?;
    Some((wheel, comp))
}

/// How one index is computed from a row of identified forces (N).
#[derive(Debug, Clone, Copy)]
enum Formula {
    /// |Y|/Q of a wheel (Q floored at 1 N).
    YOverQ { y: usize, q: usize },
    /// (Q̄ − Q)/Q̄.
    Unloading { q: usize, q_bar: f64 },
    /// |Y_l + Y_r| in kN.
    Lateral { yl: usize, yr: usize },
}

impl Formula {
    fn value(self, row: &[f64]) -> f64 {
        match self {
            Formula::YOverQ { y, q } => row[y].abs() / row[q].max(1.0),
            Formula::Unloading { q, q_bar } => (q_bar - row[q]) / q_bar,
            Formula::Lateral { yl, yr } => ((row[yl] + row[yr]) / 1000.0).abs(),
        }
    }
}

/// Running state of one index.
struct Track {
    report: IndexReport,
    formula: Formula,
    /// Open excursion: start time, last time above, peak.
    open: Option<(f64, f64, f64)>,
}

/// Evaluates every index the targets allow, one sample at a time.
pub struct Monitor {
    tracks: Vec<Track>,
    min_duration: f64,
    keep_series: bool,
}

/// A time on the 200 Hz sample grid (no float noise such as 15.764999999989637).
pub fn on_grid(t: f64) -> f64 {
    (t * RATE_HZ).round() / RATE_HZ
}

impl Monitor {
    /// Every index the targets allow: |Y|/Q where a wheel has both Y and Q, ΔQ/Q̄ where it
    /// has Q, H where both wheels of a wheelset have Y. `keep_series` keeps every value (the
    /// batch report); a stream keeps only the summary.
    pub fn new(targets: &[String], limits: &Limits, keep_series: bool) -> Self {
        let find = |wheel: &str, comp: char| {
            targets
                .iter()
                .position(|t| wheel_of(t) == Some((wheel, comp)))
        };
        let mut wheels: Vec<&str> = Vec::new();
        for w in targets.iter().filter_map(|t| wheel_of(t).map(|w| w.0)) {
            if !wheels.contains(&w) {
                wheels.push(w);
            }
        }
        let q_bar = limits.static_wheel_load_kn * 1000.0;
        let mut defs: Vec<(&str, String, String, f64, Formula)> = Vec::new();
        for w in &wheels {
            if let (Some(y), Some(q)) = (find(w, 'y'), find(w, 'z')) {
                defs.push((
                    "Y/Q",
                    w.to_string(),
                    format!("y_over_q_{w}"),
                    limits.y_over_q,
                    Formula::YOverQ { y, q },
                ));
            }
            if let Some(q) = find(w, 'z') {
                defs.push((
                    "ΔQ/Q̄",
                    w.to_string(),
                    format!("unloading_{w}"),
                    limits.unloading,
                    Formula::Unloading { q, q_bar },
                ));
            }
        }
        for axle in 1..=4 {
            let (l, r) = (format!("w{axle}l"), format!("w{axle}r"));
            if let (Some(yl), Some(yr)) = (find(&l, 'y'), find(&r, 'y')) {
                defs.push((
                    "H (kN)",
                    format!("wheelset {axle}"),
                    format!("h_wheelset{axle}_kn"),
                    limits.lateral_kn(),
                    Formula::Lateral { yl, yr },
                ));
            }
        }
        let tracks = defs
            .into_iter()
            .map(|(index, place, column, limit, formula)| Track {
                report: IndexReport {
                    name: match index.strip_suffix(" (kN)") {
                        Some(bare) => format!("{bare} {place} (kN)"),
                        None => format!("{index} {place}"),
                    },
                    index: index.to_string(),
                    place,
                    column,
                    limit,
                    max: f64::NEG_INFINITY,
                    max_time_s: f64::NAN,
                    exceedances: Vec::new(),
                    brief_excursions: 0,
                    series: Vec::new(),
                },
                formula,
                open: None,
            })
            .collect();
        Monitor {
            tracks,
            min_duration: limits.min_duration_s,
            keep_series,
        }
    }

    /// ASCII column names of the indices, in order.
    pub fn columns(&self) -> Vec<&str> {
        self.tracks
            .iter()
            .map(|t| t.report.column.as_str())
            .collect()
    }

    /// Evaluates one row of forces (N, target order) at time `t`; returns the index values.
    pub fn push(&mut self, t: f64, row: &[f64]) -> Vec<f64> {
        let t = on_grid(t);
        let dt = 1.0 / RATE_HZ;
        let min = self.min_duration;
        self.tracks
            .iter_mut()
            .map(|tr| {
                let v = tr.formula.value(row);
                let r = &mut tr.report;
                if v > r.max || r.max_time_s.is_nan() {
                    r.max = v;
                    r.max_time_s = t;
                }
                if self.keep_series {
                    r.series.push(v);
                }
                match (&mut tr.open, v > r.limit) {
                    (None, true) => tr.open = Some((t, t, v)),
                    (Some((_, last, peak)), true) => {
                        *last = t;
                        *peak = peak.max(v);
                    }
                    (Some(_), false) => close(r, tr.open.take(), dt, min),
                    (None, false) => {}
                }
                v
            })
            .collect()
    }

    /// The reports (open excursions closed at the last sample).
    pub fn finish(mut self) -> Vec<IndexReport> {
        let dt = 1.0 / RATE_HZ;
        for tr in &mut self.tracks {
            close(&mut tr.report, tr.open.take(), dt, self.min_duration);
        }
        self.tracks.into_iter().map(|t| t.report).collect()
    }
}

/// Files an excursion as an exceedance when it lasted at least `min` (its samples span
/// `last − start + dt`), else as brief.
fn close(r: &mut IndexReport, open: Option<(f64, f64, f64)>, dt: f64, min: f64) {
    if let Some((start, last, peak)) = open {
        if last - start + dt >= min - 1e-9 {
            r.exceedances.push((start, last, peak));
        } else {
            r.brief_excursions += 1;
        }
    }
}

/// Every index of an identification with its whole series (see [`Monitor::new`]).
pub fn indices(id: &ForceSeries, limits: &Limits) -> Vec<IndexReport> {
    let mut m = Monitor::new(&id.targets, limits, true);
    for (t, row) in id.time.iter().zip(&id.values) {
        m.push(*t, row);
    }
    m.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_exceedances() {
        let id = ForceSeries {
            targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
            time: vec![0.0, 0.005, 0.010, 0.015],
            values: vec![
                vec![10e3, 100e3],
                vec![130e3, 100e3],
                vec![-125e3, 100e3],
                vec![20e3, 30e3],
            ],
        };
        let mut limits = Limits {
            min_duration_s: 0.0,
            ..Limits::default()
        };
        let r = indices(&id, &limits);
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].name, "Y/Q w1l");
        assert_eq!(r[0].column, "y_over_q_w1l");
        assert_eq!(r[1].column, "unloading_w1l");
        assert!((r[0].max - 1.3).abs() < 1e-12);
        assert_eq!(r[0].exceedances, vec![(0.005, 0.010, 1.3)]);
        let unl = &r[1];
        assert!((unl.max - (122.625 - 30.0) / 122.625).abs() < 1e-9);
        assert_eq!(unl.exceedances.len(), 1);
        assert!((Limits::default().lateral_kn() - 0.85 * (10.0 + 245.25 / 3.0)).abs() < 1e-9);
        // With the 50 ms time criterion the 10 ms excursion is brief, not an exceedance.
        limits.min_duration_s = 0.05;
        let r = indices(&id, &limits);
        assert!(r[0].exceedances.is_empty());
        assert_eq!(r[0].brief_excursions, 1);
    }

    /// A planted Y/Q pulse longer than the time criterion is an exceedance, a shorter one is
    /// not; times come out on the sample grid.
    #[test]
    fn time_criterion_on_planted_pulses() {
        let n = 200;
        let time: Vec<f64> = (0..n).map(|i| 3.0 + i as f64 * 0.005 + 1e-12).collect();
        let values = (0..n)
            .map(|i| {
                // 12 samples (60 ms) at 1.5 from 0.1 s, 6 samples (30 ms) from 0.5 s.
                let y = if (20..32).contains(&i) || (100..106).contains(&i) {
                    150e3
                } else {
                    20e3
                };
                vec![y, 100e3]
            })
            .collect();
        let id = ForceSeries {
            targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
            time,
            values,
        };
        let r = &indices(&id, &Limits::default())[0];
        assert_eq!(r.exceedances.len(), 1);
        assert_eq!(r.brief_excursions, 1);
        let (a, b, peak) = r.exceedances[0];
        assert_eq!((a, b), (3.1, 3.155));
        assert!((peak - 1.5).abs() < 1e-12);
        assert_eq!(r.max_time_s, 3.1);
    }

    #[test]
    fn both_wheels_of_a_wheelset_give_h() {
        let targets: Vec<String> = ["w1l_force_y", "w1r_force_y", "w1l_force_z", "w1r_force_z"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        let m = Monitor::new(&targets, &Limits::default(), false);
        assert_eq!(
            m.columns(),
            [
                "y_over_q_w1l",
                "unloading_w1l",
                "y_over_q_w1r",
                "unloading_w1r",
                "h_wheelset1_kn"
            ]
        );
    }
}
