//! Vertical profile: constant gradients joined by parabolic vertical curves.
//!
//! Each grade change at `s_i` (the point of vertical intersection) from gradient `g₋` to `g₊`
//! is rounded by a parabola of radius `R_v` over `s_i ± T`, `T = R_v·|g₊ − g₋|/2`, tangent to
//! both grades (the usual railway design rule).

/// A grade change: from `at` on, the gradient is `gradient` (rise over run, positive uphill in
/// the running direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grade {
    /// Point of vertical intersection, m along the track.
    pub at: f64,
    /// Gradient after the change (dimensionless: 0.02 = 20 ‰).
    pub gradient: f64,
    /// Radius of the vertical curve rounding the change, m (`inf` for none).
    pub vertical_curve_radius: f64,
}

/// The vertical profile of a track.
#[derive(Debug, Clone)]
pub struct VerticalProfile {
    start_elevation: f64,
    grades: Vec<Grade>,
    /// Elevation of the unrounded polyline at each grade point.
    polyline_z: Vec<f64>,
}

impl VerticalProfile {
    /// A level profile at the given elevation.
    pub fn level(elevation: f64) -> Self {
        Self::new(
            elevation,
            vec![Grade {
                at: 0.0,
                gradient: 0.0,
                vertical_curve_radius: f64::INFINITY,
            }],
        )
    }

    /// Builds a profile from grade changes sorted by `at`, the first at 0.
    pub fn new(start_elevation: f64, grades: Vec<Grade>) -> Self {
        let mut polyline_z = Vec::with_capacity(grades.len());
        let mut z = start_elevation;
        for (i, g) in grades.iter().enumerate() {
            if i > 0 {
                z += grades[i - 1].gradient * (g.at - grades[i - 1].at);
            }
            polyline_z.push(z);
        }
        VerticalProfile {
            start_elevation,
            grades,
            polyline_z,
        }
    }

    /// Grade changes.
    pub fn grades(&self) -> &[Grade] {
        &self.grades
    }

    /// Elevation at the start, m.
    pub fn start_elevation(&self) -> f64 {
        self.start_elevation
    }

    /// The span `[s_i − T, s_i + T]` of each grade change's vertical curve (`None` for the first
    /// grade and for changes without rounding).
    pub fn rounding_zones(&self) -> Vec<Option<(f64, f64)>> {
        self.grades
            .iter()
            .enumerate()
            .map(|(i, g)| {
                let t = self.half_length(i);
                (t > 0.0).then_some((g.at - t, g.at + t))
            })
            .collect()
    }

    fn half_length(&self, i: usize) -> f64 {
        if i == 0 {
            return 0.0;
        }
        let g = &self.grades[i];
        let dg = g.gradient - self.grades[i - 1].gradient;
        if g.vertical_curve_radius.is_finite() && dg != 0.0 {
            0.5 * g.vertical_curve_radius * dg.abs()
        } else {
            0.0
        }
    }

    /// Elevation `z`, gradient `dz/ds` and vertical curvature `d²z/ds²` (1/m, positive in a
    /// sag) at `s`.
    pub fn at(&self, s: f64) -> (f64, f64, f64) {
        // Polyline through the grade points.
        let i = self.grades.partition_point(|g| g.at <= s).max(1) - 1;
        let g = self.grades[i];
        let mut z = self.polyline_z[i] + g.gradient * (s - g.at);
        let mut slope = g.gradient;
        let mut curv = 0.0;
        // Parabolic rounding of the changes whose zone contains s (zones do not overlap, so at
        // most one applies; check the neighbours of i).
        for j in i.saturating_sub(1)..(i + 2).min(self.grades.len()) {
            let t = self.half_length(j);
            if t <= 0.0 {
                continue;
            }
            let gj = self.grades[j];
            let s0 = gj.at - t;
            if s <= s0 || s >= gj.at + t {
                continue;
            }
            let dg = gj.gradient - self.grades[j - 1].gradient;
            let u = s - s0;
            // Parabola minus the kinked polyline: dg·u²/(4T) − dg·max(0, s − s_j).
            let past = (s - gj.at).max(0.0);
            z += dg * u * u / (4.0 * t) - dg * past;
            slope += dg * u / (2.0 * t) - if s > gj.at { dg } else { 0.0 };
            curv = dg / (2.0 * t);
        }
        (z, slope, curv)
    }
}
