//! The assessment criteria file (`vehicles/assessment.toml`): filters, windows, percentiles
//! and limits, each table with the source it was taken from. The built-in default is that
//! file; users pass their own with the same keys.

use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The built-in criteria (the project's `vehicles/assessment.toml`).
pub const DEFAULT: &str = include_str!("../../vehicles/assessment.toml");

/// Low-pass filter of the forces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Filter {
    /// Cut-off, Hz.
    pub lowpass_hz: f64,
    /// Butterworth order (even), run forward and backward.
    pub order: usize,
    /// Where it comes from.
    pub source: String,
}

/// Sliding mean over track distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlidingMean {
    /// Window length, m.
    pub window_m: f64,
    /// Step between window centres, m.
    pub step_m: f64,
    /// Where it comes from.
    pub source: String,
}

/// Percentiles, %.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Percentiles {
    /// F1.
    pub low: f64,
    /// F2, the value assessed.
    pub high: f64,
    /// F0 of the quasi-static values (50: the median).
    pub quasi_static: f64,
    /// Where it comes from.
    pub source: String,
}

/// A single limit and its source.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct YOverQ {
    /// (Y/Q)2m limit.
    pub limit: f64,
    /// Where it comes from.
    pub source: String,
}

/// Track-shifting force limit `α·(10 + 2·Q0/3)` kN.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackShift {
    /// α.
    pub alpha: f64,
    /// Where it comes from.
    pub source: String,
}

/// Vertical force limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vertical {
    /// Qlim − Q0, kN.
    pub q_max_over_static_kn: f64,
    /// Qqst limit, kN.
    pub q_qst_kn: f64,
    /// Where it comes from.
    pub source: String,
}

/// Quasi-static lateral force limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LateralQuasiStatic {
    /// Yqst limit, kN.
    pub y_qst_kn: f64,
    /// Where it comes from.
    pub source: String,
}

/// The Chinese derailment criteria.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Chinese {
    /// |Y|/Q limit.
    pub derailment: f64,
    /// ΔQ/Q̄ limit.
    pub unloading: f64,
    /// α of H ≤ α·(10 + P_st/3) kN.
    pub lateral_alpha: f64,
    /// Time criterion, s.
    pub min_duration_s: f64,
    /// Where it comes from.
    pub source: String,
}

/// In-train coupler force (runs in a train).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Coupler {
    /// Largest coupler force, tension or compression, kN.
    pub limit_kn: f64,
    /// Where it comes from.
    pub source: String,
}

/// Ride index.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ride {
    /// Sperling Wz limit (vertical and lateral).
    pub wz_limit: f64,
    /// Spectral band of the index, Hz.
    pub band_hz: [f64; 2],
    /// Shortest record assessed, s.
    pub min_seconds: f64,
    /// Where it comes from.
    pub source: String,
}

/// Running stability on ΣY.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stability {
    /// Half width of the band around the dominant frequency, Hz.
    pub band_half_width_hz: f64,
    /// Sliding rms window, m.
    pub window_m: f64,
    /// Step between windows, m.
    pub step_m: f64,
    /// Limit as a share of the track-shifting limit (ΣY)lim.
    pub limit_ratio: f64,
    /// Where it comes from.
    pub source: String,
}

/// Carbody accelerations (running behaviour).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CarbodyAcceleration {
    /// Band, Hz.
    pub band_hz: [f64; 2],
    /// Lateral limit of max(|F1|, |F2|), m/s².
    pub lateral_limit: f64,
    /// Vertical limit, m/s².
    pub vertical_limit: f64,
    /// Where it comes from.
    pub source: String,
}

/// Every criterion of an assessment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Criteria {
    /// What the set is.
    pub name: String,
    /// Force filter.
    pub filter: Filter,
    /// Sliding mean.
    pub sliding_mean: SlidingMean,
    /// Percentiles.
    pub percentiles: Percentiles,
    /// (Y/Q)2m.
    pub y_over_q: YOverQ,
    /// (ΣY)2m.
    pub track_shift: TrackShift,
    /// Q and Qqst.
    pub vertical: Vertical,
    /// Yqst.
    pub lateral_quasi_static: LateralQuasiStatic,
    /// |Y|/Q, ΔQ/Q̄, H with a time criterion.
    pub chinese: Chinese,
    /// Ride index from the carbody accelerations (absent: not assessed).
    pub ride: Option<Ride>,
    /// Coupler force of a run in a train (absent: not assessed).
    #[serde(default)]
    pub coupler: Option<Coupler>,
    /// Running stability (absent: not assessed).
    pub stability: Option<Stability>,
    /// Carbody accelerations (absent: not assessed).
    pub carbody_acceleration: Option<CarbodyAcceleration>,
}

impl Criteria {
    /// The built-in set.
    pub fn builtin() -> Self {
        Self::parse(DEFAULT, Path::new("vehicles/assessment.toml"))
            .expect("the built-in criteria parse")
    }

    /// Reads and checks a criteria file.
    pub fn load(path: &Path) -> Result<Self> {
        Self::parse(&crate::io::read_text(path)?, path)
    }

    /// Parses and checks criteria text (`path` names it in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let c: Criteria = crate::io::parse_toml(text, path)?;
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Error::config(
                    path,
                    field,
                    format!("must be positive, got {v}"),
                ))
            }
        };
        positive("filter.lowpass_hz", c.filter.lowpass_hz)?;
        if c.filter.lowpass_hz >= 100.0 {
            return Err(Error::config(
                path,
                "filter.lowpass_hz",
                format!(
                    "{} Hz is not below the 100 Hz Nyquist frequency of 200 Hz data",
                    c.filter.lowpass_hz
                ),
            ));
        }
        if !(2..=12).contains(&c.filter.order) || c.filter.order % 2 == 1 {
            return Err(Error::config(
                path,
                "filter.order",
                format!("an even order from 2 to 12, got {}", c.filter.order),
            ));
        }
        positive("sliding_mean.window_m", c.sliding_mean.window_m)?;
        positive("sliding_mean.step_m", c.sliding_mean.step_m)?;
        for (f, v) in [
            ("percentiles.low", c.percentiles.low),
            ("percentiles.high", c.percentiles.high),
            ("percentiles.quasi_static", c.percentiles.quasi_static),
        ] {
            if !(0.0..=100.0).contains(&v) {
                return Err(Error::config(
                    path,
                    f,
                    format!("a percentage from 0 to 100, got {v}"),
                ));
            }
        }
        positive("y_over_q.limit", c.y_over_q.limit)?;
        positive("track_shift.alpha", c.track_shift.alpha)?;
        positive(
            "vertical.q_max_over_static_kn",
            c.vertical.q_max_over_static_kn,
        )?;
        positive("vertical.q_qst_kn", c.vertical.q_qst_kn)?;
        positive(
            "lateral_quasi_static.y_qst_kn",
            c.lateral_quasi_static.y_qst_kn,
        )?;
        positive("chinese.derailment", c.chinese.derailment)?;
        positive("chinese.unloading", c.chinese.unloading)?;
        positive("chinese.lateral_alpha", c.chinese.lateral_alpha)?;
        if let Some(k) = &c.coupler {
            positive("coupler.limit_kn", k.limit_kn)?;
        }
        if let Some(r) = &c.ride {
            positive("ride.wz_limit", r.wz_limit)?;
            positive("ride.min_seconds", r.min_seconds)?;
            if !(r.band_hz[0] > 0.0 && r.band_hz[1] > r.band_hz[0]) {
                return Err(Error::config(
                    path,
                    "ride.band_hz",
                    "two frequencies, low < high",
                ));
            }
        }
        if let Some(a) = &c.carbody_acceleration {
            positive("carbody_acceleration.lateral_limit", a.lateral_limit)?;
            positive("carbody_acceleration.vertical_limit", a.vertical_limit)?;
            if !(a.band_hz[0] > 0.0 && a.band_hz[1] > a.band_hz[0]) {
                return Err(Error::config(
                    path,
                    "carbody_acceleration.band_hz",
                    "two frequencies, low < high",
                ));
            }
        }
        if let Some(st) = &c.stability {
            positive("stability.band_half_width_hz", st.band_half_width_hz)?;
            positive("stability.window_m", st.window_m)?;
            positive("stability.step_m", st.step_m)?;
            positive("stability.limit_ratio", st.limit_ratio)?;
        }
        if !(c.chinese.min_duration_s.is_finite() && c.chinese.min_duration_s >= 0.0) {
            return Err(Error::config(
                path,
                "chinese.min_duration_s",
                "a duration ≥ 0",
            ));
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_builtin_set_parses_and_cites_every_table() {
        let c = Criteria::builtin();
        assert_eq!(c.sliding_mean.window_m, 2.0);
        assert_eq!(c.percentiles.high, 99.85);
        for s in [
            &c.filter.source,
            &c.sliding_mean.source,
            &c.percentiles.source,
            &c.y_over_q.source,
            &c.track_shift.source,
            &c.vertical.source,
            &c.lateral_quasi_static.source,
            &c.chinese.source,
            &c.ride.as_ref().unwrap().source,
            &c.coupler.as_ref().unwrap().source,
            &c.stability.as_ref().unwrap().source,
            &c.carbody_acceleration.as_ref().unwrap().source,
        ] {
            assert!(s.len() > 20, "{s}");
        }
        let bad = DEFAULT.replace("order = 4", "order = 3");
        let e = Criteria::parse(&bad, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.toml") && e.contains("filter.order"), "{e}");
        let bad = DEFAULT.replace("[filter]", "[filter]\ncolour = 1");
        let e = Criteria::parse(&bad, Path::new("x.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("colour"), "{e}");
    }
}
