//! Wheel and rail profiles.
//!
//! Internal convention for both: lateral coordinate `y` (m) positive toward the **field side**
//! (away from the flange / gauge face), `z` (m) positive **downward**: for a wheel, the increase
//! of the radius over the nominal rolling radius at the tape circle; for a rail, the depth below
//! the top of the rail. Profiles are stored on a uniform grid with first and second
//! derivatives, and read with cubic Hermite interpolation.

use crate::error::{Error, Result};
use std::path::Path;

/// Grid step of sampled profiles, m (0.02 mm).
const GRID_STEP: f64 = 2e-5;

/// A profile sampled on a uniform grid in `y`.
#[derive(Debug, Clone)]
pub struct Profile {
    /// Name for messages and reports.
    pub name: String,
    y0: f64,
    h: f64,
    z: Vec<f64>,
    dz: Vec<f64>,
    d2z: Vec<f64>,
}

impl Profile {
    /// Appends the bits of everything the contact geometry reads of this profile (its sampled
    /// shape, not its name): two profiles with equal fingerprints give the same contact.
    pub(crate) fn fingerprint(&self, out: &mut Vec<u64>) {
        out.extend([self.y0.to_bits(), self.h.to_bits(), self.z.len() as u64]);
        for v in [&self.z, &self.dz, &self.d2z] {
            out.extend(v.iter().map(|x| x.to_bits()));
        }
    }

    /// Samples `f(y) -> (z, dz/dy, d²z/dy²)` on `[y_min, y_max]`.
    pub fn from_fn(name: &str, y_min: f64, y_max: f64, f: impl Fn(f64) -> (f64, f64, f64)) -> Self {
        let n = crate::bounds::to_count(((y_max - y_min) / GRID_STEP).floor()) + 1;
        let (mut z, mut dz, mut d2z) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for i in 0..n {
            let (a, b, c) = f(y_min + i as f64 * GRID_STEP);
            z.push(a);
            dz.push(b);
            d2z.push(c);
        }
        Profile {
            name: name.to_string(),
            y0: y_min,
            h: GRID_STEP,
            z,
            dz,
            d2z,
        }
    }

    /// Builds a profile from points `(y, z)` in metres, `y` strictly increasing, through a
    /// natural cubic spline.
    pub fn from_points(name: &str, pts: &[(f64, f64)]) -> Result<Self> {
        let spline = CubicSpline::new(pts).map_err(Error::Domain)?;
        let (lo, hi) = (pts[0].0, pts[pts.len() - 1].0);
        Ok(Self::from_fn(name, lo, hi, |y| spline.eval(y)))
    }

    /// Lateral range covered, m.
    pub fn range(&self) -> (f64, f64) {
        (self.y0, self.y0 + (self.z.len() - 1) as f64 * self.h)
    }

    /// `(z, dz/dy, d²z/dy²)` at `y` (clamped to the range; outside it the profile continues
    /// with its end slope).
    #[inline]
    pub fn eval(&self, y: f64) -> (f64, f64, f64) {
        let (lo, hi) = self.range();
        if y < lo {
            return (self.z[0] + self.dz[0] * (y - lo), self.dz[0], 0.0);
        }
        if y > hi {
            let n = self.z.len() - 1;
            return (self.z[n] + self.dz[n] * (y - hi), self.dz[n], 0.0);
        }
        let u = (y - self.y0) / self.h;
        let i = (u as usize).min(self.z.len() - 2);
        let t = u - i as f64;
        let h = self.h;
        let (z0, z1, m0, m1) = (self.z[i], self.z[i + 1], self.dz[i] * h, self.dz[i + 1] * h);
        let t2 = t * t;
        let t3 = t2 * t;
        let z = (2.0 * t3 - 3.0 * t2 + 1.0) * z0
            + (t3 - 2.0 * t2 + t) * m0
            + (-2.0 * t3 + 3.0 * t2) * z1
            + (t3 - t2) * m1;
        let dz = ((6.0 * t2 - 6.0 * t) * z0
            + (3.0 * t2 - 4.0 * t + 1.0) * m0
            + (-6.0 * t2 + 6.0 * t) * z1
            + (3.0 * t2 - 2.0 * t) * m1)
            / h;
        let d2z = self.d2z[i] + t * (self.d2z[i + 1] - self.d2z[i]);
        (z, dz, d2z)
    }

    /// Returns a copy rotated by `angle` (rad) in the `y`–`z` plane about the origin, so that a
    /// rail leans its head toward the gauge side for a positive angle (inclination 1:40 is
    /// `atan(1/40)`): `(y, z) → (y·cos α + z·sin α, −y·sin α + z·cos α)`.
    pub fn rotated(&self, angle: f64) -> Result<Self> {
        let (s, c) = angle.sin_cos();
        let pts: Vec<(f64, f64)> = (0..self.z.len())
            .step_by(5)
            .map(|i| {
                let y = self.y0 + i as f64 * self.h;
                let z = self.z[i];
                (y * c + z * s, -y * s + z * c)
            })
            .collect();
        Self::from_points(&self.name, &pts)
    }

    /// Returns a copy shifted so that `(y, z)` becomes `(y − dy, z − dz)`.
    pub fn shifted(&self, dy: f64, dz: f64) -> Self {
        let mut p = self.clone();
        p.y0 -= dy;
        for z in &mut p.z {
            *z -= dz;
        }
        p
    }

    /// The point of least `z` (the top of a rail), by grid search and parabolic refinement.
    pub fn lowest_z(&self) -> (f64, f64) {
        let (i, _) = self
            .z
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .expect("profile has points");
        let y = self.y0 + i as f64 * self.h;
        // Newton on dz = 0 near the grid minimum.
        let mut yy = y;
        for _ in 0..5 {
            let (_, d1, d2) = self.eval(yy);
            if d2.abs() < 1e-12 {
                break;
            }
            yy = (yy - d1 / d2).clamp(y - self.h, y + self.h);
        }
        (yy, self.eval(yy).0)
    }

    /// The `y` where the profile reaches depth `z` on the side `y < y_from` nearest to
    /// `y_from` (e.g. the gauge point 14 mm below the rail top, gauge side negative).
    pub fn crossing_below(&self, y_from: f64, z: f64) -> Option<f64> {
        let start = crate::bounds::cell_clamped((y_from - self.y0) / self.h, self.z.len());
        for i in (0..start.min(self.z.len() - 1)).rev() {
            if (self.z[i] - z) * (self.z[i + 1] - z) <= 0.0 {
                // Bisection on the interpolant.
                let (mut a, mut b) = (
                    self.y0 + i as f64 * self.h,
                    self.y0 + (i + 1) as f64 * self.h,
                );
                for _ in 0..50 {
                    let m = 0.5 * (a + b);
                    if (self.eval(a).0 - z) * (self.eval(m).0 - z) <= 0.0 {
                        b = m;
                    } else {
                        a = m;
                    }
                }
                return Some(0.5 * (a + b));
            }
        }
        None
    }

    /// Profile curvature `z''/(1 + z'²)^{3/2}` at `y`, 1/m.
    pub fn curvature(&self, y: f64) -> f64 {
        let (_, d1, d2) = self.eval(y);
        d2 / (1.0 + d1 * d1).powf(1.5)
    }
}

/// Natural cubic spline through points with strictly increasing abscissae.
struct CubicSpline {
    x: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>, // second derivatives
}

impl CubicSpline {
    fn new(pts: &[(f64, f64)]) -> std::result::Result<Self, String> {
        let n = pts.len();
        if n < 4 {
            return Err(format!("a profile needs at least 4 points, got {n}"));
        }
        for (i, w) in pts.windows(2).enumerate() {
            if w[1].0 <= w[0].0 || w[1].0.is_nan() {
                return Err(format!(
                    "profile y is not strictly monotonic at point {} (y {} after {})",
                    i + 2,
                    w[1].0,
                    w[0].0
                ));
            }
        }
        let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
        // Tridiagonal system for the second derivatives (natural ends).
        let mut a = vec![0.0; n];
        let mut b = vec![1.0; n];
        let mut c = vec![0.0; n];
        let mut r = vec![0.0; n];
        for i in 1..n - 1 {
            let h0 = x[i] - x[i - 1];
            let h1 = x[i + 1] - x[i];
            a[i] = h0 / 6.0;
            b[i] = (h0 + h1) / 3.0;
            c[i] = h1 / 6.0;
            r[i] = (y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0;
        }
        for i in 1..n {
            let w = a[i] / b[i - 1];
            b[i] -= w * c[i - 1];
            r[i] -= w * r[i - 1];
        }
        let mut m = vec![0.0; n];
        m[n - 1] = r[n - 1] / b[n - 1];
        for i in (0..n - 1).rev() {
            m[i] = (r[i] - c[i] * m[i + 1]) / b[i];
        }
        Ok(CubicSpline { x, y, m })
    }

    fn eval(&self, t: f64) -> (f64, f64, f64) {
        let n = self.x.len();
        let i = self.x.partition_point(|&v| v <= t).clamp(1, n - 1) - 1;
        let h = self.x[i + 1] - self.x[i];
        let a = (self.x[i + 1] - t) / h;
        let b = (t - self.x[i]) / h;
        let (m0, m1, y0, y1) = (self.m[i], self.m[i + 1], self.y[i], self.y[i + 1]);
        let z = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let dz = (y1 - y0) / h + (-(3.0 * a * a - 1.0) * m0 + (3.0 * b * b - 1.0) * m1) * h / 6.0;
        let d2z = a * m0 + b * m1;
        (z, dz, d2z)
    }
}

/// The S1002 wheel (EN 13715) from its analytic definition (assets/docs/physics.md §4), over
/// `−69.5 mm ≤ y ≤ 60 mm` (the flange back's vertical tangent at −70 mm is left out).
pub fn s1002() -> Profile {
    Profile::from_fn("S1002", -69.5e-3, 60e-3, |y| {
        let (z, d1, d2) = s1002_mm(y * 1e3);
        (z * 1e-3, d1, d2 * 1e3)
    })
}

/// S1002 in mm: `(z, dz/dy, d²z/dy²)` at `y` (mm).
fn s1002_mm(y: f64) -> (f64, f64, f64) {
    // Circle arcs z = zc ± sqrt(R² − (y − yc)²).
    let arc = |zc: f64, sign: f64, r: f64, yc: f64| {
        let u = y - yc;
        let s = (r * r - u * u).max(1e-12).sqrt();
        (zc + sign * s, -sign * u / s, -sign * r * r / (s * s * s))
    };
    let poly = |c: &[f64]| {
        let (mut z, mut d1, mut d2) = (0.0, 0.0, 0.0);
        for (k, &ck) in c.iter().enumerate() {
            let k = k as i32;
            z += ck * y.powi(k);
            if k >= 1 {
                d1 += ck * k as f64 * y.powi(k - 1);
            }
            if k >= 2 {
                d2 += ck * (k * (k - 1)) as f64 * y.powi(k - 2);
            }
        }
        (z, d1, d2)
    };
    if y >= 32.15796 {
        (1.364323640 - 0.066666667 * y, -0.066666667, 0.0)
    } else if y >= -26.0 {
        poly(&[
            0.0,
            -3.358537058e-2,
            1.565681624e-3,
            -2.810427944e-5,
            5.844240864e-8,
            -1.562379023e-8,
            5.309217349e-15,
            -5.957839843e-12,
            2.646656573e-13,
        ])
    } else if y >= -35.0 {
        let (z, d1, d2) = poly(&[
            4.320221063e3,
            1.038384026e3,
            1.065501873e2,
            6.051367875,
            2.054332446e-1,
            4.169739389e-3,
            4.687195829e-5,
            2.252755540e-7,
        ]);
        (-z, -d1, -d2)
    } else if y >= -38.426669071 {
        arc(16.446, -1.0, 13.0, -26.210665)
    } else if y >= -39.764473993 {
        (-93.576667419 - 2.747477419 * y, -2.747477419, 0.0)
    } else if y >= -49.662510381 {
        arc(8.834924130, 1.0, 20.0, -58.558326413)
    } else if y >= -62.764705882 {
        arc(16.0, 1.0, 12.0, -55.0)
    } else {
        arc(9.519259302, 1.0, 20.5, -49.5)
    }
}

/// The 60 kg/m rail head (CHN60 / 60E1 family), upright (not inclined), from its arcs
/// (assets/docs/physics.md §4): crown R300 to |y| = 10.228 mm, R80 to 26.027 mm, R13 down to the 1:20 flank, flank
/// to 35 mm below the top. Symmetric about `y = 0`; `z` is the depth below the crown.
pub fn rail_60kg() -> Profile {
    // Each arc is tangent to the previous: its centre lies on the previous arc's normal.
    let (r1, r2, r3) = (300.0, 80.0, 13.0);
    let (y1, y2) = (10.228, 26.027);
    let c1 = (0.0, r1);
    let z_on = |c: (f64, f64), r: f64, y: f64| c.1 - (r * r - (y - c.0).powi(2)).sqrt();
    let p1 = (y1, z_on(c1, r1, y1));
    let c2 = (
        p1.0 + (c1.0 - p1.0) * r2 / r1,
        p1.1 + (c1.1 - p1.1) * r2 / r1,
    );
    let p2 = (y2, z_on(c2, r2, y2));
    let c3 = (
        p2.0 + (c2.0 - p2.0) * r3 / r2,
        p2.1 + (c2.1 - p2.1) * r3 / r2,
    );
    // Tangent point of R13 with the 1:20 flank (dz/dy = 20).
    let u3 = r3 * (400.0f64 / 401.0).sqrt();
    let y3 = c3.0 + u3;
    let z3 = z_on(c3, r3, y3);
    let depth = 35.0;
    let y4 = y3 + (depth - z3) / 20.0;
    let half = move |y: f64| -> (f64, f64, f64) {
        let arc = |c: (f64, f64), r: f64| {
            let u = y - c.0;
            let s = (r * r - u * u).max(1e-12).sqrt();
            (c.1 - s, u / s, r * r / (s * s * s))
        };
        if y <= y1 {
            arc(c1, r1)
        } else if y <= y2 {
            arc(c2, r2)
        } else if y <= y3 {
            arc(c3, r3)
        } else {
            (z3 + 20.0 * (y - y3), 20.0, 0.0)
        }
    };
    Profile::from_fn("60kg/m", -y4 * 1e-3, y4 * 1e-3, |y| {
        let ym = y * 1e3;
        let (z, d1, d2) = half(ym.abs());
        (z * 1e-3, d1 * ym.signum(), d2 * 1e3)
    })
}

/// A wheel profile by name (`s1002`) or from a file read with `opts` (see [`load`]).
/// A file's profile must rise toward the gauge side ([`super::Flange::check`]).
pub fn wheel_by_name_or_file(spec: &str, opts: LoadOptions) -> Result<Profile> {
    match spec.to_ascii_lowercase().as_str() {
        "s1002" => Ok(s1002()),
        _ => {
            let p = load(Path::new(spec), opts)?;
            super::Flange::check(&p).map_err(|message| Error::Parse {
                file: spec.into(),
                message,
            })?;
            Ok(p)
        }
    }
}

/// A rail profile by name (`60kg`, alias `chn60`, `60e1`, `uic60`: upright, to be inclined by
/// the caller) or from a file read with `opts` (see [`load`]).
pub fn rail_by_name_or_file(spec: &str, opts: LoadOptions) -> Result<Profile> {
    match spec.to_ascii_lowercase().as_str() {
        "60kg" | "chn60" | "60e1" | "uic60" => Ok(rail_60kg()),
        _ => load(Path::new(spec), opts),
    }
}

/// Options for reading a profile file.
#[derive(Debug, Clone, Copy, Default)]
pub struct LoadOptions {
    /// Mirror `y` after reading (on top of any flag in the file), to bring the field side to +y.
    pub mirror_y: bool,
}

/// Reads a profile from a file: SIMPACK `.prw`/`.prr`, MiniProf `.whl`/`.ban`/`.mpt` (by
/// extension; see `contact::miniprof`) or a 2-column text/CSV
/// file of `y, z` in mm (comments `#` or `!`, separators comma, semicolon, tab or spaces).
/// The result follows the internal convention only if the file does (field side +y, z down);
/// use [`LoadOptions::mirror_y`] otherwise.
pub fn load(path: &Path, opts: LoadOptions) -> Result<Profile> {
    let text = crate::io::read_text(path)?;
    parse(&text, path, opts)
}

/// Parses profile text as [`load`] reads a file; `path` gives the format (by extension), the
/// profile's name and the file named in errors.
pub fn parse(text: &str, path: &Path, opts: LoadOptions) -> Result<Profile> {
    let text = text.to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let mut pts = if ext == "prw" || ext == "prr" {
        parse_simpack(&text, path)?
    } else if super::miniprof::is_miniprof(&ext) {
        super::miniprof::parse(&text, path, ext == "whl")?
    } else {
        parse_columns(&text, path)?
    };
    if opts.mirror_y {
        for p in &mut pts {
            p.0 = -p.0;
        }
    }
    if pts.len() >= 2 && pts[0].0 > pts[pts.len() - 1].0 {
        pts.reverse();
    }
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Profile::from_points(&name, &pts).map_err(|e| match e {
        Error::Domain(m) => Error::Parse {
            file: path.to_path_buf(),
            message: m,
        },
        other => other,
    })
}

fn parse_columns(text: &str, path: &Path) -> Result<Vec<(f64, f64)>> {
    let mut pts = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        let line = line.split(['#', '!']).next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let cols: Vec<&str> = line
            .split([',', ';', '\t', ' '])
            .filter(|s| !s.is_empty())
            .collect();
        let parsed: Option<(f64, f64)> = match cols.as_slice() {
            [a, b, ..] => a.parse().ok().zip(b.parse().ok()),
            _ => None,
        };
        match parsed {
            Some((y, z)) => pts.push((y * 1e-3, z * 1e-3)),
            // A header line before any data is allowed.
            None if pts.is_empty() => continue,
            None => {
                return Err(Error::Parse {
                    file: path.to_path_buf(),
                    message: format!("line {}: expected two numbers (y, z in mm)", ln + 1),
                });
            }
        }
    }
    Ok(pts)
}

fn parse_simpack(text: &str, path: &Path) -> Result<Vec<(f64, f64)>> {
    let perr = |m: String| Error::Parse {
        file: path.to_path_buf(),
        message: m,
    };
    let mut in_block = false;
    let mut found_block = false;
    let (mut mirror_y, mut mirror_z, mut factor) = (false, false, 1000.0);
    let (mut shift_y, mut shift_z) = (0.0, 0.0);
    let mut pts = Vec::new();
    for (ln, raw) in text.lines().enumerate() {
        let line = raw.split('!').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if line.starts_with("point.begin") {
            in_block = true;
            found_block = true;
            continue;
        }
        if line.starts_with("point.end") {
            in_block = false;
            continue;
        }
        if in_block {
            let cols: Vec<f64> = line
                .split_whitespace()
                .map(|s| s.parse::<f64>())
                .collect::<std::result::Result<_, _>>()
                .map_err(|_| perr(format!("line {}: bad number in point block", ln + 1)))?;
            if cols.len() < 2 {
                return Err(perr(format!("line {}: a point needs y and z", ln + 1)));
            }
            pts.push((cols[0], cols[1]));
        } else if let Some((k, v)) = line.split_once('=') {
            let v = v.trim().trim_matches('\'');
            let num = || {
                v.parse::<f64>()
                    .map_err(|_| perr(format!("line {}: {} is not a number", ln + 1, k.trim())))
            };
            match k.trim() {
                "mirror.y" => mirror_y = num()? != 0.0,
                "mirror.z" => mirror_z = num()? != 0.0,
                "units.len.f" => factor = num()?,
                "shift.y" => shift_y = num()?,
                "shift.z" => shift_z = num()?,
                _ => {}
            }
        }
    }
    if !found_block {
        return Err(perr("no point.begin … point.end block".into()));
    }
    if !(factor.is_finite() && factor > 0.0) {
        return Err(perr(format!("units.len.f must be positive, got {factor}")));
    }
    // SIMPACK applies shift, then mirroring; the inversion flag only reverses the point order,
    // which does not matter here (points are sorted by y afterwards).
    Ok(pts
        .into_iter()
        .map(|(y, z)| {
            let (mut y, mut z) = (y + shift_y, z + shift_z);
            if mirror_y {
                y = -y;
            }
            if mirror_z {
                z = -z;
            }
            (y / factor, z / factor)
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn s1002_is_continuous_and_has_a_28mm_flange() {
        let p = s1002();
        // Section joints: value continuity to 0.01 mm.
        for yj in [
            32.15796,
            -26.0,
            -35.0,
            -38.426669071,
            -39.764473993,
            -49.662510381,
            -62.764705882,
        ] {
            let a = s1002_mm(yj - 1e-7).0;
            let b = s1002_mm(yj + 1e-7).0;
            assert!((a - b).abs() < 0.01, "jump {a} {b} at {yj}");
        }
        assert!(p.eval(0.0).0.abs() < 1e-12);
        let (lo, hi) = p.range();
        let tip = (0..1000)
            .map(|i| p.eval(lo + (hi - lo) * i as f64 / 999.0).0)
            .fold(f64::MIN, f64::max);
        assert!((tip - 0.028).abs() < 2e-4, "flange height {tip}");
    }

    #[test]
    fn rail_head_is_72_mm_wide_and_smooth() {
        let r = rail_60kg();
        let g = r.crossing_below(0.0, 0.014).unwrap();
        assert!(
            (2.0 * g.abs() - 0.072).abs() < 1e-3,
            "width at 14 mm {}",
            2.0 * g
        );
        // Slope continuity at the arc joints.
        for yj in [10.228e-3, 26.027e-3] {
            let (a, b) = (r.eval(yj - 1e-6).1, r.eval(yj + 1e-6).1);
            assert!((a - b).abs() < 1e-3);
        }
        assert!((r.curvature(0.0) - 1.0 / 0.3).abs() < 1e-3);
    }

    #[test]
    fn spline_rejects_bad_points() {
        assert!(Profile::from_points("x", &[(0.0, 0.0), (1.0, 0.0)]).is_err());
        let e = Profile::from_points("x", &[(0.0, 0.0), (1.0, 0.0), (0.5, 0.0), (2.0, 0.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("monotonic"), "{e}");
    }
}
