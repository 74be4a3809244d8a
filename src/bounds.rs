//! Declared ranges: the one validation layer every number read from a file passes.
//!
//! Every TOML input (vehicle, track, plan with its `[vary]` draws, criteria, channel map,
//! consist) goes through [`check_toml`] when [`crate::io::parse_toml`] reads it: each number
//! must be finite, and a field whose name declares its unit (`length_m`, `speed_kmh`,
//! `cant_mm`, …) must lie within that unit's physical range ([`UNITS`]). The vehicle's force
//! elements add tighter bounds of their own through [`element_bound`] (a width within an
//! element below a metre, a stiffness below 10¹² N/m). Loaders keep their field-specific
//! checks (a radius above zero, a percentile below 100); this layer is what no loader can
//! forget.
//!
//! Indices computed from floats go through [`index_of`] or [`count_of`], which refuse a
//! non-finite or out-of-range value by the quantity's name instead of wrapping to a huge
//! index.

use crate::error::{Error, Result};
use std::path::Path;

/// The physical range of a number by the unit its field's name ends with (the most specific
/// suffix first): lower bound, upper bound, what it measures. A value beyond them is a typing
/// error or a unit slip (a track 1 000 km long, a speed of 10⁵ km/h), never a railway.
pub const UNITS: [(&str, f64, f64, &str); 19] = [
    ("_ns_per_m", 0.0, 1e9, "a damping, N·s/m"),
    ("_n_per_m", 0.0, 1e12, "a stiffness, N/m"),
    ("_kmh", 0.0, 400.0, "a speed, km/h"),
    ("_mm", -1e3, 1e3, "a length, mm"),
    ("_m", -1e6, 1e6, "a length or position, m"),
    ("_m_s", 0.0, 1e4, "a speed, m/s"),
    ("_s", 0.0, 1e6, "a duration, s"),
    ("_hz", 0.0, 1e6, "a frequency, Hz"),
    ("_permille", -100.0, 100.0, "a gradient, ‰"),
    ("_kg", 0.0, 1e7, "a mass, kg"),
    ("_t", 0.0, 1e5, "a mass, t"),
    ("_kn", -1e5, 1e5, "a force, kN"),
    ("_n", -1e8, 1e8, "a force, N"),
    ("_deg", -360.0, 360.0, "an angle, degrees"),
    ("_pa", 0.0, 1e13, "a pressure or modulus, Pa"),
    ("_kpa", 0.0, 1e5, "a pressure, kPa"),
    ("friction", 0.0, 2.0, "a friction coefficient"),
    ("poisson", 0.0, 0.5, "a Poisson's ratio"),
    ("fraction", 0.0, 1.0, "a fraction"),
];

/// The declared range of `field` (its last dotted part, without an array index), if its
/// name declares one.
pub fn unit_range(field: &str) -> Option<(f64, f64, &'static str)> {
    let name = last_name(field);
    UNITS
        .iter()
        .find(|(suffix, ..)| name.ends_with(suffix))
        .map(|&(_, lo, hi, what)| (lo, hi, what))
}

fn last_name(field: &str) -> &str {
    let name = field.rsplit('.').next().unwrap_or(field);
    name.split('[').next().unwrap_or(name)
}

/// Checks every number of a parsed TOML document: finite, and within its unit's range
/// where the field's name declares one. The error names the file and the dotted field
/// (`section[3].length_m`).
pub fn check_toml(table: &toml::Table, path: &Path) -> Result<()> {
    fn walk(v: &toml::Value, field: &str, path: &Path) -> Result<()> {
        match v {
            toml::Value::Table(t) => {
                for (k, x) in t {
                    let f = if field.is_empty() {
                        k.clone()
                    } else {
                        format!("{field}.{k}")
                    };
                    walk(x, &f, path)?;
                }
                Ok(())
            }
            toml::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, &format!("{field}[{i}]"), path)?;
                }
                Ok(())
            }
            toml::Value::Float(x) => check_value(path, field, *x),
            toml::Value::Integer(i) => check_value(path, field, *i as f64),
            _ => Ok(()),
        }
    }
    for (k, v) in table {
        walk(v, k, path)?;
    }
    Ok(())
}

/// Checks one number read at `field` of `path`: finite, and within its unit's range.
pub fn check_value(path: &Path, field: &str, v: f64) -> Result<()> {
    if !v.is_finite() {
        return Err(Error::config(
            path,
            field,
            format!("must be a finite number, got {v}"),
        ));
    }
    // A varied key's draw (`{ uniform = [...] }`) carries factors, not the field's unit.
    if field.contains(".vary.") || field.starts_with("vary.") {
        return Ok(());
    }
    match unit_range(field) {
        Some((lo, hi, what)) if !(lo..=hi).contains(&v) => Err(Error::config(
            path,
            field,
            format!(
                "{} is outside the physical range of {what}: [{lo}, {hi}]",
                show(v)
            ),
        )),
        _ => Ok(()),
    }
}

/// A number as a message shows it: exponent form when very large or very small.
pub fn show(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e7).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The bounds a vehicle's force elements are held to, by what the field's name says it is
/// (the most specific suffix first): the largest magnitude and what it measures. The C80's
/// stiffest element, a pad, is 2·10⁸ N/m; its largest dimension within an element, 0.76 m.
const ELEMENT_BOUNDS: [(&str, f64, &str); 13] = [
    ("width_m", 1.0, "a width, m"),
    ("flange_back_m", 2.0, "a flange-back spacing, m"),
    ("radius_m", 2.0, "a radius, m"),
    ("gauge_m", 2.0, "a gauge, m"),
    ("_m", 1.0, "a length within an element, m"),
    (
        "stiffness",
        1e12,
        "a stiffness, N/m (N·m/rad for a rotation)",
    ),
    ("damping", 1e9, "a damping, N·s/m (N·m·s/rad)"),
    ("friction", 2.0, "a friction coefficient"),
    ("young_pa", 1e13, "a Young's modulus, Pa"),
    ("preload_n", 1e7, "a force, N"),
    ("ratio", 10.0, "a ratio"),
    ("proportional", 1e4, "a controller gain, 1/s"),
    ("integral", 1e6, "a controller gain, 1/s²"),
];

/// The bound of a vehicle element's `field` (its last dotted part), if it declares one: the
/// largest magnitude and what it measures.
pub fn element_bound(field: &str) -> Option<(f64, &'static str)> {
    let name = last_name(field);
    ELEMENT_BOUNDS
        .iter()
        .find(|(suffix, _, _)| name.ends_with(suffix))
        .map(|&(_, max, what)| (max, what))
}

/// The largest index or count [`count_of`] accepts: no grid, table or histogram of the
/// project comes near it, and a value beyond it is a unit slip or a runaway state.
pub const MAX_COUNT: usize = 1 << 32;

/// The index of the cell holding `x` (already in cells: `x = (value − origin) / step`),
/// floored: an error naming `what` if `x` is not finite or not in `[0, len)`.
pub fn index_of(x: f64, len: usize, what: &str) -> Result<usize> {
    if x.is_finite() && x >= 0.0 && x < len as f64 {
        Ok(x as usize)
    } else {
        Err(Error::Domain(format!(
            "{what}: {x} is not a cell of a grid of {len} (non-finite or out of range)"
        )))
    }
}

/// A count computed from a float (`duration / dt` rounded, `length / step` …), rounded to
/// the nearest integer: an error naming `what` if it is not finite, negative or beyond
/// [`MAX_COUNT`].
pub fn count_of(x: f64, what: &str) -> Result<usize> {
    let r = x.round();
    if r.is_finite() && r >= 0.0 && r <= MAX_COUNT as f64 {
        Ok(r as usize)
    } else {
        Err(Error::Domain(format!(
            "{what}: {x} is not a count (non-finite, negative or beyond {MAX_COUNT})"
        )))
    }
}

/// A count or index computed from an already rounded float, total: a non-finite or negative
/// `x` is 0 and a huge one [`MAX_COUNT`]. For counts from values a loader has already held
/// to their declared ranges (a step, a duration, a grid spacing), where an error has no one
/// to reach; a count from a file's own numbers goes through [`count_of`].
#[inline]
pub fn to_count(x: f64) -> usize {
    if x.is_finite() && x > 0.0 {
        x.min(MAX_COUNT as f64) as usize
    } else {
        0
    }
}

/// The cell of `x` (in cells) clamped into `[0, len − 1]`, with a non-finite `x` at cell 0:
/// the total form for lookups on the step's hot path, which never see a non-finite state
/// (the simulation checks the state before any lookup) but must never index out of bounds.
#[inline]
pub fn cell_clamped(x: f64, len: usize) -> usize {
    debug_assert!(len > 0);
    // `as` saturates (NaN → 0, −x → 0, +∞ → usize::MAX).
    (x as usize).min(len.saturating_sub(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_by_unit_and_errors_by_name() {
        let p = Path::new("t.toml");
        assert!(check_value(p, "section[2].length_m", 200.0).is_ok());
        let e = check_value(p, "section[2].length_m", 1e308).unwrap_err();
        assert!(e.to_string().contains("section[2].length_m"), "{e}");
        assert!(check_value(p, "speed_kmh", -1.0).is_err());
        assert!(check_value(p, "cant_mm", f64::NAN).is_err());
        // `_n_per_m` is a stiffness, not a length (`_m`).
        assert!(check_value(p, "x.lateral_stiffness_n_per_m", 4e7).is_ok());
        // Draw factors are not in the key's unit.
        assert!(check_value(p, "vary.\"a.length_m\".uniform[0]", 1e7).is_ok());
        let t: toml::Table = toml::from_str("a = 1.0\n[b]\nc_kmh = 900.0").unwrap();
        let e = check_toml(&t, p).unwrap_err().to_string();
        assert!(e.contains("b.c_kmh") && e.contains("t.toml"), "{e}");
    }

    #[test]
    fn indices_are_checked() {
        assert_eq!(index_of(2.7, 3, "x").unwrap(), 2);
        assert!(index_of(3.0, 3, "x").is_err());
        assert!(
            index_of(f64::NAN, 3, "grid of q")
                .unwrap_err()
                .to_string()
                .contains("grid of q")
        );
        assert!(index_of(-0.1, 3, "x").is_err());
        assert_eq!(count_of(4.6, "n").unwrap(), 5);
        assert!(count_of(f64::INFINITY, "n").is_err());
        assert!(count_of(-2.0, "n").is_err());
        assert_eq!(to_count(f64::NAN), 0);
        assert_eq!(to_count(1e300), MAX_COUNT);
        assert_eq!(cell_clamped(f64::NAN, 4), 0);
        assert_eq!(cell_clamped(1e300, 4), 3);
        assert_eq!(cell_clamped(-5.0, 4), 0);
    }
}
