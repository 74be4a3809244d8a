//! Out-of-round wheels: a wheel flat and a polygon (`[[wheel_defect]]` in a vehicle file, read
//! here). On a flat rail the wheel's centre follows the rolling circle over its tread: with the
//! radius changed by Δr(u) along the tread, the centre sits at
//! `h(s) = max_u [Δr(s + u) − u²/(2R)]` over R (the wheel touches where its surface is lowest),
//! so a dip more concave than the wheel is convex is bridged, the wheel pivoting about its
//! edges. Under a single-point contact that path lowers the wheel as a rail lower by it would,
//! so the run adds h to the rail's height under that wheel, once per turn.
//!
//! - A new flat of length L is a chord, `d = R − √(R² − L²/4) ≈ L²/(8R)` deep,
//!   `Δr(u) = −d + u²/(2R)` for |u| ≤ L/2: the centre drops by d and its path's slope jumps by
//!   about L/R at the flat's centre (the impact). AAR Rule 68 condemns a slid flat of 2½ in
//!   (63.5 mm).
//! - A rounded (worn) flat of the same depth over a longer L_r:
//!   `Δr(u) = −(d/2)·(1 + cos(2πu/L_r))` for |u| ≤ L_r/2.
//! - A polygon of order n and amplitude a: `Δr(θ) = a·cos(nθ)`; orders 1–5, the 3rd dominant
//!   on solid wheels (Nielsen & Johansson, Proc IMechE F 214, 2000).

use crate::error::{Error, Result};
use serde::Deserialize;
use std::f64::consts::PI;
use std::path::Path;

/// `[[wheel_defect]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct WheelDefectFile {
    wheel: String,
    flat_length_mm: Option<f64>,
    flat_depth_mm: Option<f64>,
    flat_rounded_length_mm: Option<f64>,
    polygon_order: Option<u32>,
    polygon_amplitude_mm: Option<f64>,
}

/// Grid step of a wheel's path over one turn, m.
const PATH_STEP: f64 = 2.5e-4;

/// A flat on a wheel's tread.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flat {
    /// Length of the flat's chord, m.
    pub length: f64,
    /// Depth, m.
    pub depth: f64,
    /// Length along the tread of a rounded (worn) flat of the same depth, m; None for a new
    /// flat (a chord).
    pub rounded: Option<f64>,
}

impl Flat {
    /// The radius's change `u` metres along the tread from the flat's centre (|u| within half
    /// a turn), m.
    fn radius_change(&self, u: f64, radius: f64) -> f64 {
        match self.rounded {
            // A chord; a depth given under the chord's leaves the flat shorter, never proud.
            None if u.abs() <= 0.5 * self.length => (-self.depth + u * u / (2.0 * radius)).min(0.0),
            Some(lr) if u.abs() <= 0.5 * lr => {
                -0.5 * self.depth * (1.0 + (2.0 * PI * u / lr).cos())
            }
            _ => 0.0,
        }
    }
}

/// One out-of-round wheel.
#[derive(Debug, Clone, PartialEq)]
pub struct WheelDefect {
    /// The wheel (0 → 1L, 1 → 1R, …).
    pub wheel: usize,
    /// A flat, if any.
    pub flat: Option<Flat>,
    /// A polygon's order and amplitude (m).
    pub polygon: Option<(u32, f64)>,
    /// Nominal rolling radius, m.
    radius: f64,
    /// The centre's path over one turn on the grid `−PATH_STEP, 0, PATH_STEP, …` (two points
    /// beyond each end for the cubic), m.
    path: Vec<f64>,
}

impl WheelDefect {
    /// A wheel of nominal radius `radius` (m) with a flat and a polygon, its path computed.
    pub fn new(wheel: usize, flat: Option<Flat>, polygon: Option<(u32, f64)>, radius: f64) -> Self {
        let turn = 2.0 * PI * radius;
        let n = ((turn / PATH_STEP).round() as usize).max(16);
        let h = turn / n as f64;
        // The tread's radius change at every grid point of one turn (the flat's centre at 0).
        let dr: Vec<f64> = (0..n)
            .map(|i| {
                let u = i as f64 * h;
                let u = u - turn * (u / turn).round();
                let flat = flat.map_or(0.0, |f| f.radius_change(u, radius));
                let poly = polygon.map_or(0.0, |(k, a)| a * (k as f64 * u / radius).cos());
                flat + poly
            })
            .collect();
        // The rolling circle's reach: where u²/(2R) exceeds the deepest change twice over.
        let deepest = dr.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let reach = ((4.0 * deepest * radius).sqrt() / h).ceil() as usize + 1;
        let centre = |i: usize| {
            (0..=2 * reach)
                .map(|j| {
                    let off = j as isize - reach as isize;
                    let t = (i as isize + off).rem_euclid(n as isize) as usize;
                    let u = off as f64 * h;
                    dr[t] - u * u / (2.0 * radius)
                })
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let path = (0..n + 3).map(|i| centre((i + n - 1) % n)).collect();
        WheelDefect {
            wheel,
            flat,
            polygon,
            radius,
            path,
        }
    }

    /// How far the wheel's centre is lowered (≤ 0 over a flat) and its rate per metre rolled,
    /// after `rolled` metres (the flat's centre and the polygon's first peak at 0). A run passes
    /// the wheelset's track position, so the flat strikes at every 2πR along the track, from
    /// the start: out-of-roundness is not faded in as the rails' short waves are.
    pub fn radius_change(&self, rolled: f64) -> (f64, f64) {
        let n = self.path.len() - 3;
        let turn = 2.0 * PI * self.radius;
        let h = turn / n as f64;
        let u = rolled.rem_euclid(turn) / h;
        let i = (u.floor() as usize).min(n - 1);
        crate::dsp::catmull_rom(&self.path, i + 1, u - i as f64, h)
    }
}

/// The depth of a flat of length `len` on a wheel of radius `radius`, m.
pub fn flat_depth(len: f64, radius: f64) -> f64 {
    radius - (radius * radius - 0.25 * len * len).sqrt()
}

/// The defects a vehicle file lists, every key checked against `radius` (m) and the
/// `wheelsets` named in its contact.
pub(super) fn bind(
    path: &Path,
    rows: &[WheelDefectFile],
    radius: f64,
    wheelsets: usize,
) -> Result<Vec<WheelDefect>> {
    let mut out: Vec<WheelDefect> = Vec::new();
    for (i, r) in rows.iter().enumerate() {
        let err =
            |key: &str, msg: String| Error::config(path, format!("wheel_defect[{i}].{key}"), msg);
        let wheel = super::parse_wheel(&r.wheel, wheelsets).ok_or_else(|| {
            err(
                "wheel",
                format!("\"{}\" is not a wheel: use 1L … {wheelsets}R", r.wheel),
            )
        })?;
        if out.iter().any(|d| d.wheel == wheel) {
            return Err(err("wheel", format!("{} is listed twice", r.wheel)));
        }
        let flat = match (
            r.flat_length_mm,
            r.flat_depth_mm.or(r.flat_rounded_length_mm),
        ) {
            (None, None) => None,
            (None, Some(_)) => {
                return Err(err(
                    "flat_length_mm",
                    "a flat's depth or rounded length needs its length".into(),
                ));
            }
            (Some(l), _) => {
                let depth = r.flat_depth_mm;
                let len = l * 1e-3;
                if !(len.is_finite() && len > 0.0 && len <= 0.5 * radius) {
                    return Err(err(
                        "flat_length_mm",
                        format!(
                            "must be above 0 and at most {:.0} mm, got {l}",
                            0.5e3 * radius
                        ),
                    ));
                }
                let d = depth.map_or(flat_depth(len, radius), |d| d * 1e-3);
                if !(d.is_finite() && d > 0.0 && d <= flat_depth(len, radius) * 1.000_001) {
                    return Err(err(
                        "flat_depth_mm",
                        format!(
                            "must be above 0 and at most the chord's {:.3} mm, got {}",
                            flat_depth(len, radius) * 1e3,
                            d * 1e3
                        ),
                    ));
                }
                let rounded = match r.flat_rounded_length_mm {
                    None => None,
                    Some(lr) if lr.is_finite() && lr >= l && lr <= 0.5e3 * radius => {
                        Some(lr * 1e-3)
                    }
                    Some(lr) => {
                        return Err(err(
                            "flat_rounded_length_mm",
                            format!(
                                "must be at least flat_length_mm ({l}) and at most {:.0} mm, got {lr}",
                                0.5e3 * radius
                            ),
                        ));
                    }
                };
                Some(Flat {
                    length: len,
                    depth: d,
                    rounded,
                })
            }
        };
        let polygon = match (r.polygon_order, r.polygon_amplitude_mm) {
            (None, None) => None,
            (Some(n), Some(a)) => {
                if !(1..=40).contains(&n) {
                    return Err(err("polygon_order", format!("must be 1 to 40, got {n}")));
                }
                if !(a.is_finite() && a > 0.0 && a <= 5.0) {
                    return Err(err(
                        "polygon_amplitude_mm",
                        format!("must be above 0 and at most 5 mm, got {a}"),
                    ));
                }
                Some((n, a * 1e-3))
            }
            _ => {
                return Err(err(
                    "polygon_order",
                    "a polygon needs both polygon_order and polygon_amplitude_mm".into(),
                ));
            }
        };
        if flat.is_none() && polygon.is_none() {
            return Err(err("wheel", "names no flat and no polygon".into()));
        }
        out.push(WheelDefect::new(wheel, flat, polygon, radius));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flats_depth_is_its_chords() {
        // excitation spec: 0.48 mm for 40 mm and 0.74 mm for 50 mm at R 0.42 m.
        assert!((flat_depth(0.040, 0.42) * 1e3 - 0.476).abs() < 0.005);
        assert!((flat_depth(0.050, 0.42) * 1e3 - 0.744).abs() < 0.005);
        assert!((flat_depth(0.050, 0.42) / (0.05f64.powi(2) / (8.0 * 0.42)) - 1.0).abs() < 1e-3);
    }

    fn flat(rounded: Option<f64>) -> Flat {
        Flat {
            length: 0.05,
            depth: flat_depth(0.05, 0.42),
            rounded,
        }
    }

    #[test]
    fn over_a_new_flat_the_centre_drops_its_depth_and_pivots_about_its_edges() {
        let (r, turn) = (0.42, 2.0 * PI * 0.42);
        let d = WheelDefect::new(0, Some(flat(None)), None, r);
        // At the flat's centre the wheel stands on its chord: the centre is d lower.
        assert!((d.radius_change(3.0 * turn).0 + flat_depth(0.05, r)).abs() < 2e-6);
        assert_eq!(d.radius_change(0.5 * turn).0, 0.0);
        // Pivoting about the edge behind (a circle of radius R about it), the centre is at
        // −(L/2 + s)²/(2R) for −L/2 < s < 0: its slope −(L/2 + s)/R, turning over at 0.
        let before = d.radius_change(-2e-3).1;
        assert!(
            (before / (-(0.025 - 0.002) / r) - 1.0).abs() < 0.02,
            "{before}"
        );
        assert!(d.radius_change(2e-3).1 > 0.0);
        // Never below the tread's own change (the circle cannot reach deeper).
        for i in 0..400 {
            let u = -0.05 + i as f64 * 2.5e-4;
            assert!(
                d.radius_change(u).0 >= flat(None).radius_change(u, r) - 1e-7,
                "{u}"
            );
        }
    }

    #[test]
    fn a_gentle_change_is_followed_as_it_is_and_its_rate_is_its_derivative() {
        let r = 0.42;
        let turn = 2.0 * PI * r;
        // A third-order polygon of 0.1 mm curves far less than the wheel: followed exactly.
        let poly = WheelDefect::new(0, None, Some((3, 0.1e-3)), r);
        assert!((poly.radius_change(turn / 3.0).0 - 0.1e-3).abs() < 1e-9);
        // A rounded flat 0.74 mm deep over 200 mm: its curvature is under 1/R, followed.
        let rounded = WheelDefect::new(0, Some(flat(Some(0.2))), Some((3, 0.1e-3)), r);
        assert!((rounded.radius_change(0.0).0 - (-flat_depth(0.05, r) + 0.1e-3)).abs() < 1e-8);
        let h = 1e-6;
        for s in [0.01, 0.05, 1.0, 2.0 * turn + 0.013] {
            let fd = (rounded.radius_change(s + h).0 - rounded.radius_change(s - h).0) / (2.0 * h);
            assert!(
                (fd - rounded.radius_change(s).1).abs() < 1e-5,
                "at {s}: {fd}"
            );
        }
    }

    #[test]
    fn a_new_flat_shallower_than_its_chord_never_stands_proud() {
        let f = Flat {
            length: 0.05,
            depth: 0.3e-3,
            rounded: None,
        };
        for i in 0..=100 {
            let u = -0.025 + i as f64 * 5e-4;
            assert!(f.radius_change(u, 0.42) <= 0.0, "{u}");
        }
        let d = WheelDefect::new(0, Some(f), None, 0.42);
        assert!((d.radius_change(0.0).0 + 0.3e-3).abs() < 1e-6);
        assert!(d.radius_change(0.03).0 <= 1e-12);
    }

    fn rows(text: &str) -> Result<Vec<WheelDefect>> {
        #[derive(Deserialize)]
        struct T {
            wheel_defect: Vec<WheelDefectFile>,
        }
        let t: T = toml::from_str(text).unwrap();
        bind(Path::new("v.toml"), &t.wheel_defect, 0.42, 4)
    }

    #[test]
    fn a_vehicle_files_rows_are_read_and_bad_ones_refused() {
        let d = rows("[[wheel_defect]]\nwheel = \"2R\"\nflat_length_mm = 50\n").unwrap();
        assert_eq!(d[0].wheel, 3);
        assert!((d[0].flat.unwrap().depth - flat_depth(0.05, 0.42)).abs() < 1e-15);
        for (bad, key) in [
            (
                "wheel = \"5L\"\nflat_length_mm = 50",
                "wheel_defect[0].wheel",
            ),
            ("wheel = \"1L\"", "wheel_defect[0].wheel"),
            (
                "wheel = \"1L\"\nflat_length_mm = -1",
                "wheel_defect[0].flat_length_mm",
            ),
            (
                "wheel = \"1L\"\nflat_length_mm = 50\nflat_depth_mm = 2",
                "wheel_defect[0].flat_depth_mm",
            ),
            (
                "wheel = \"1L\"\npolygon_order = 3",
                "wheel_defect[0].polygon_order",
            ),
        ] {
            let e = rows(&format!("[[wheel_defect]]\n{bad}\n"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(key) && e.contains("v.toml"), "{bad}: {e}");
        }
    }
}
