//! Safety indices from identified forces (spec physics.md §7), with configurable limits whose
//! defaults are the commonly quoted Chinese values — secondary-source figures, labelled so:
//! derailment coefficient |Y|/Q ≤ 1.2 (allowable; 1.0 preferred), wheel unloading
//! ΔQ/Q̄ ≤ 0.65 (0.60 preferred), wheelset lateral force H ≤ 0.85·(10 + P_st/3) kN.

use super::Identified;
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
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            y_over_q: 1.2,
            unloading: 0.65,
            static_wheel_load_kn: 25_000.0 * crate::GRAVITY / 2.0 / 1000.0,
        }
    }
}

impl Limits {
    /// Wheelset lateral force limit `0.85·(10 + P_st/3)` kN, `P_st` the static axle load in kN.
    pub fn lateral_kn(&self) -> f64 {
        0.85 * (10.0 + 2.0 * self.static_wheel_load_kn / 3.0)
    }
}

/// One index's series and its exceedances.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IndexReport {
    /// Name, e.g. `Y/Q w1l`.
    pub name: String,
    /// The index alone: `Y/Q`, `ΔQ/Q̄` or `H (kN)`.
    pub index: String,
    /// Where: the wheel (`w1l`) or the wheelset (`wheelset 1`).
    pub place: String,
    /// Limit.
    pub limit: f64,
    /// Largest value and when.
    pub max: f64,
    /// Time of the largest value, s.
    pub max_time_s: f64,
    /// Intervals above the limit: (start s, end s, peak).
    pub exceedances: Vec<(f64, f64, f64)>,
    /// The series (same times as the identification).
    #[serde(skip)]
    pub series: Vec<f64>,
}

/// Wheel of a label name `w{n}{l|r}_force_{y|z}`: (`w1l`, `y`).
fn wheel_of(name: &str) -> Option<(&str, char)> {
    let (wheel, rest) = name.split_once('_')?;
    let comp = rest.strip_prefix("force_")?.chars().next()?;
    Some((wheel, comp))
}

/// Every index the identified targets allow: |Y|/Q where a wheel has both Y and Q, ΔQ/Q̄ where
/// it has Q, H where both wheels of a wheelset have Y.
pub fn indices(id: &Identified, limits: &Limits) -> Vec<IndexReport> {
    let find = |wheel: &str, comp: char| {
        id.targets
            .iter()
            .position(|t| wheel_of(t) == Some((wheel, comp)))
    };
    let col = |k: usize| -> Vec<f64> { id.values.iter().map(|v| v[k]).collect() };
    let mut out = Vec::new();
    let mut wheels: Vec<&str> = id
        .targets
        .iter()
        .filter_map(|t| wheel_of(t).map(|w| w.0))
        .collect();
    wheels.dedup();
    let q_bar = limits.static_wheel_load_kn * 1000.0;
    for w in &wheels {
        if let (Some(y), Some(q)) = (find(w, 'y'), find(w, 'z')) {
            let s = col(y)
                .iter()
                .zip(col(q))
                .map(|(y, q)| y.abs() / q.max(1.0))
                .collect();
            out.push(report("Y/Q", w, limits.y_over_q, s, &id.time));
        }
        if let Some(q) = find(w, 'z') {
            let s = col(q).iter().map(|q| (q_bar - q) / q_bar).collect();
            out.push(report("ΔQ/Q̄", w, limits.unloading, s, &id.time));
        }
    }
    for axle in 1..=4 {
        let (l, r) = (format!("w{axle}l"), format!("w{axle}r"));
        if let (Some(yl), Some(yr)) = (find(&l, 'y'), find(&r, 'y')) {
            let s = col(yl)
                .iter()
                .zip(col(yr))
                .map(|(a, b)| ((a + b) / 1000.0).abs())
                .collect();
            out.push(report(
                "H (kN)",
                &format!("wheelset {axle}"),
                limits.lateral_kn(),
                s,
                &id.time,
            ));
        }
    }
    out
}

fn report(index: &str, place: &str, limit: f64, series: Vec<f64>, time: &[f64]) -> IndexReport {
    let name = match index.strip_suffix(" (kN)") {
        Some(bare) => format!("{bare} {place} (kN)"),
        None => format!("{index} {place}"),
    };
    let (imax, &max) = series
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap_or((0, &f64::NAN));
    let mut exceedances = Vec::new();
    let mut open: Option<(usize, f64)> = None;
    for (i, &v) in series.iter().enumerate() {
        match (&mut open, v > limit) {
            (None, true) => open = Some((i, v)),
            (Some((_, peak)), true) => *peak = peak.max(v),
            (Some((s, peak)), false) => {
                exceedances.push((time[*s], time[i - 1], *peak));
                open = None;
            }
            (None, false) => {}
        }
    }
    if let Some((s, peak)) = open {
        exceedances.push((time[s], time[series.len() - 1], peak));
    }
    IndexReport {
        name,
        index: index.to_string(),
        place: place.to_string(),
        limit,
        max,
        max_time_s: time.get(imax).copied().unwrap_or(f64::NAN),
        exceedances,
        series,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_and_exceedances() {
        let id = Identified {
            targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
            time: vec![0.0, 0.005, 0.010, 0.015],
            values: vec![
                vec![10e3, 100e3],
                vec![130e3, 100e3],
                vec![-125e3, 100e3],
                vec![20e3, 30e3],
            ],
        };
        let r = indices(&id, &Limits::default());
        assert_eq!(r.len(), 2);
        assert_eq!(r[0].name, "Y/Q w1l");
        assert!((r[0].max - 1.3).abs() < 1e-12);
        assert_eq!(r[0].exceedances, vec![(0.005, 0.010, 1.3)]);
        let unl = &r[1];
        assert!((unl.max - (122.625 - 30.0) / 122.625).abs() < 1e-9);
        assert_eq!(unl.exceedances.len(), 1);
        assert!((Limits::default().lateral_kn() - 0.85 * (10.0 + 245.25 / 3.0)).abs() < 1e-9);
    }
}
