//! One section of track assessed, one function per criterion: the wheels' sliding (Y/Q)2m,
//! Q, Yqst and Qqst; the wheelsets' track-shifting (ΣY)2m and running stability; the Chinese
//! criteria with their time criterion; the carbody's accelerations and Sperling's ride index.
//! Each appends its rows in a fixed order, so a report reads the same run after run.

use super::criteria::Criteria;
use super::safety::{Limits, indices};
use super::statistics::{self, sliding_mean};
use super::{ForceSeries, Row, RunForces, Span, WheelSeries, ride};
use crate::dsp::percentile;

/// A section's rows of the run, its filtered wheel forces and the criteria.
pub(super) struct Section<'a> {
    run: &'a RunForces,
    wheels: &'a [WheelSeries],
    span: &'a Span,
    c: &'a Criteria,
    q0_kn: f64,
    fs: f64,
    /// Rows of the run inside the section.
    idx: Vec<usize>,
    /// Distance covered by the section's rows, m.
    covered: f64,
    /// Track position of those rows, m.
    s: Vec<f64>,
}

impl<'a> Section<'a> {
    /// The section, or `None` when it holds less than one full sliding window.
    pub(super) fn new(
        run: &'a RunForces,
        wheels: &'a [WheelSeries],
        span: &'a Span,
        c: &'a Criteria,
        q0_kn: f64,
        fs: f64,
    ) -> Option<Self> {
        let idx: Vec<usize> = (0..run.s.len())
            .filter(|&i| run.s[i] >= span.from_m && run.s[i] < span.to_m)
            .collect();
        let covered = idx.last().map_or(0.0, |&l| run.s[l] - run.s[idx[0]]);
        if idx.len() < 2 || covered < c.sliding_mean.window_m {
            return None;
        }
        let s = idx.iter().map(|&i| run.s[i]).collect();
        Some(Section {
            run,
            wheels,
            span,
            c,
            q0_kn,
            fs,
            idx,
            covered,
            s,
        })
    }

    fn pick(&self, v: &[f64]) -> Vec<f64> {
        self.idx.iter().map(|&i| v[i]).collect()
    }

    #[allow(clippy::too_many_arguments)]
    fn row(
        &self,
        quantity: &str,
        place: &str,
        value: f64,
        limit: f64,
        unit: &str,
        statistic: String,
        criterion: &str,
    ) -> Row {
        Row {
            section: self.span.name.clone(),
            quantity: quantity.into(),
            place: place.into(),
            value,
            limit,
            unit: unit.into(),
            statistic,
            pass: value <= limit,
            criterion: criterion.into(),
        }
    }

    /// Both ends of the sliding means' distribution: the larger in magnitude is assessed.
    fn two_sided(&self, x: &[f64]) -> f64 {
        let (win, step) = (self.c.sliding_mean.window_m, self.c.sliding_mean.step_m);
        let m: Vec<f64> = sliding_mean(&self.s, x, win, step)
            .into_iter()
            .map(|p| p.1)
            .collect();
        let pct = &self.c.percentiles;
        percentile(&m, pct.low)
            .abs()
            .max(percentile(&m, pct.high).abs())
    }

    fn sliding_words(&self) -> String {
        let (win, step) = (self.c.sliding_mean.window_m, self.c.sliding_mean.step_m);
        let pct = &self.c.percentiles;
        format!(
            "max(|F1|, |F2|) of the {win} m sliding mean every {step} m, F1 = {} %, F2 = {} %",
            pct.low, pct.high
        )
    }

    /// Per wheel: (Y/Q)2m, Q's upper percentile, and over a curve Yqst and Qqst.
    pub(super) fn wheel_statistics(&self, rows: &mut Vec<Row>) {
        let c = self.c;
        let pct = &c.percentiles;
        for w in self.wheels {
            let (y, q) = (self.pick(&w.y), self.pick(&w.q));
            let yq: Vec<f64> = y.iter().zip(&q).map(|(a, b)| a / b.max(1.0)).collect();
            rows.push(self.row(
                "(Y/Q)2m",
                &w.wheel,
                self.two_sided(&yq),
                c.y_over_q.limit,
                "-",
                self.sliding_words(),
                "y_over_q",
            ));
            rows.push(self.row(
                "Q",
                &w.wheel,
                percentile(&q, pct.high) / 1000.0,
                self.q0_kn + c.vertical.q_max_over_static_kn,
                "kN",
                format!(
                    "F2 = {} % of the filtered force; limit Q0 + {} kN",
                    pct.high, c.vertical.q_max_over_static_kn
                ),
                "vertical",
            ));
            if self.span.radius_m.is_some() {
                let f0 = pct.quasi_static;
                rows.push(self.row(
                    "Yqst",
                    &w.wheel,
                    percentile(&y, f0).abs() / 1000.0,
                    c.lateral_quasi_static.y_qst_kn,
                    "kN",
                    format!("|F0 = {f0} %| of the filtered force over the curve"),
                    "lateral_quasi_static",
                ));
                rows.push(self.row(
                    "Qqst",
                    &w.wheel,
                    percentile(&q, f0) / 1000.0,
                    c.vertical.q_qst_kn,
                    "kN",
                    format!("F0 = {f0} % of the filtered force over the curve"),
                    "vertical",
                ));
            }
        }
    }

    /// ΣY = Y_l + Y_r (kN) of every wheelset with both wheels, once for both criteria.
    pub(super) fn axle_sums(&self) -> Vec<(usize, Vec<f64>)> {
        let wheels = self.wheels;
        (1..=wheels.len())
            .filter_map(|axle| {
                let find = |side: char| wheels.iter().find(|w| w.wheel == format!("w{axle}{side}"));
                let (l, r) = (find('l')?, find('r')?);
                let sum = self
                    .idx
                    .iter()
                    .map(|&i| (l.y[i] + r.y[i]) / 1000.0)
                    .collect();
                Some((axle, sum))
            })
            .collect()
    }

    /// The track-shifting force (ΣY)2m of every wheelset against α·(10 + 2·Q0/3).
    pub(super) fn track_shift(&self, axle_sums: &[(usize, Vec<f64>)], rows: &mut Vec<Row>) {
        let c = self.c;
        for (axle, sum) in axle_sums {
            rows.push(self.row(
                "(ΣY)2m",
                &format!("wheelset {axle}"),
                self.two_sided(sum),
                c.track_shift.alpha * (10.0 + 2.0 * self.q0_kn / 3.0),
                "kN",
                format!(
                    "{}; limit α·(10 + 2·Q0/3), α = {}",
                    self.sliding_words(),
                    c.track_shift.alpha
                ),
                "track_shift",
            ));
        }
    }

    /// Running stability: ΣY around its dominant frequency, as a sliding rms over distance.
    pub(super) fn running_stability(&self, axle_sums: &[(usize, Vec<f64>)], rows: &mut Vec<Row>) {
        let c = self.c;
        let Some(st) = &c.stability else {
            return;
        };
        if self.covered < st.window_m {
            return;
        }
        for (axle, sum) in axle_sums {
            let Some(f0) = statistics::dominant_frequency(sum, self.fs, 0.5, c.filter.lowpass_hz)
            else {
                continue;
            };
            let band = statistics::band_pass(
                sum,
                self.fs,
                f0 - st.band_half_width_hz,
                f0 + st.band_half_width_hz,
                c.filter.order,
            );
            let sq: Vec<f64> = band.iter().map(|v| v * v).collect();
            let rms = sliding_mean(&self.s, &sq, st.window_m, st.step_m)
                .into_iter()
                .map(|p| p.1.sqrt())
                .fold(0.0f64, f64::max);
            rows.push(self.row(
                "(ΣY)rms",
                &format!("wheelset {axle}"),
                rms,
                st.limit_ratio * c.track_shift.alpha * (10.0 + 2.0 * self.q0_kn / 3.0),
                "kN",
                format!(
                    "largest sliding rms over {} m every {} m of ΣY band-passed at f0 = {f0:.2} Hz ± {} Hz; limit {}·(ΣY)lim",
                    st.window_m, st.step_m, st.band_half_width_hz, st.limit_ratio
                ),
                "stability",
            ));
        }
    }

    /// The Chinese criteria with their time criterion, through the one safety monitor.
    pub(super) fn chinese(&self, rows: &mut Vec<Row>) {
        let c = self.c;
        let wheels = self.wheels;
        let id = ForceSeries {
            targets: wheels
                .iter()
                .flat_map(|w| {
                    [
                        format!("{}_force_y", w.wheel),
                        format!("{}_force_z", w.wheel),
                    ]
                })
                .collect(),
            time: self.pick(&self.run.time),
            values: self
                .idx
                .iter()
                .map(|&i| wheels.iter().flat_map(|w| [w.y[i], w.q[i]]).collect())
                .collect(),
        };
        let limits = Limits {
            y_over_q: c.chinese.derailment,
            unloading: c.chinese.unloading,
            static_wheel_load_kn: self.q0_kn,
            min_duration_s: c.chinese.min_duration_s,
            lateral_alpha: c.chinese.lateral_alpha,
        };
        for r in indices(&id, &limits) {
            let quantity = match r.index.as_str() {
                "Y/Q" => "Y/Q (time criterion)".to_string(),
                "H (kN)" => "H".to_string(),
                other => other.to_string(),
            };
            rows.push(Row {
                section: self.span.name.clone(),
                quantity,
                place: r.place.clone(),
                value: r.max,
                limit: r.limit,
                unit: if r.index == "H (kN)" { "kN" } else { "-" }.into(),
                statistic: format!(
                    "largest filtered value; fails only above the limit for ≥ {:.0} ms ({} exceedance(s), {} shorter)",
                    c.chinese.min_duration_s * 1000.0,
                    r.exceedances.len(),
                    r.brief_excursions
                ),
                pass: r.exceedances.is_empty(),
                criterion: "chinese".into(),
            });
        }
    }

    /// The carbody's accelerations band-passed, both ends of their distribution.
    pub(super) fn carbody_acceleration(&self, rows: &mut Vec<Row>) {
        let c = self.c;
        let (Some(ca), Some(acc)) = (&c.carbody_acceleration, &self.run.carbody) else {
            return;
        };
        let pct = &c.percentiles;
        for (k, (name, limit)) in [
            ("ÿ* lateral (0.4–10 Hz)", ca.lateral_limit),
            ("z̈* vertical (0.4–10 Hz)", ca.vertical_limit),
        ]
        .into_iter()
        .enumerate()
        {
            let band = statistics::band_pass(
                &acc[k],
                self.fs,
                ca.band_hz[0],
                ca.band_hz[1],
                c.filter.order,
            );
            let band = self.pick(&band);
            let v = percentile(&band, pct.low)
                .abs()
                .max(percentile(&band, pct.high).abs());
            rows.push(self.row(
                name,
                "carbody",
                v,
                limit,
                "m/s²",
                format!(
                    "max(|F1|, |F2|) of the acceleration band-passed {}–{} Hz, F1 = {} %, F2 = {} %",
                    ca.band_hz[0], ca.band_hz[1], pct.low, pct.high
                ),
                "carbody_acceleration",
            ));
        }
    }

    /// Sperling's ride index Wz of the carbody, lateral and vertical.
    pub(super) fn ride(&self, rows: &mut Vec<Row>) {
        let (Some(r), Some(acc)) = (&self.c.ride, &self.run.carbody) else {
            return;
        };
        if (self.idx.len() as f64 / self.fs) < r.min_seconds {
            return;
        }
        for (k, (dir, name)) in [
            (ride::Direction::Lateral, "Wz lateral"),
            (ride::Direction::Vertical, "Wz vertical"),
        ]
        .into_iter()
        .enumerate()
        {
            let wz = ride::sperling(
                &self.pick(&acc[k]),
                self.fs,
                dir,
                (r.band_hz[0], r.band_hz[1]),
            );
            rows.push(self.row(
                name,
                "carbody",
                wz,
                r.wz_limit,
                "-",
                format!(
                    "Sperling over the section's spectrum, {}–{} Hz",
                    r.band_hz[0], r.band_hz[1]
                ),
                "ride",
            ));
        }
    }

    /// The largest coupler force of a run in a train, each coupler, against the criteria's
    /// limit (unfiltered: the draft gears' peaks are the load).
    pub(super) fn couplers(&self, rows: &mut Vec<Row>) {
        let (Some(k), Some(f)) = (&self.c.coupler, &self.run.couplers) else {
            return;
        };
        for (series, place) in f.iter().zip(["front coupler", "rear coupler"]) {
            let peak = self
                .pick(series)
                .into_iter()
                .fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m });
            rows.push(self.row(
                "coupler force",
                place,
                peak.abs() * 1e-3,
                k.limit_kn,
                "kN",
                format!(
                    "largest |force| over the section ({} kN, {})",
                    crate::bounds::show((peak * 1e-3 * 10.0).round() / 10.0),
                    if peak >= 0.0 {
                        "tension"
                    } else {
                        "compression"
                    }
                ),
                "coupler",
            ));
        }
    }
}
