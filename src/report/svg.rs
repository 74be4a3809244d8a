//! SVG charts with no plotting dependency: line charts (training curves, force traces, R²
//! against SNR) and grouped bar charts with named categories (R² per condition, per model).
//! Both are sized for the report page (1 040 px wide by default) and carry their values as
//! hover titles on bars and points.

use super::escape::esc;
use std::fmt::Write as _;

/// One line (or set of points) of a line chart.
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points.
    pub points: Vec<(f64, f64)>,
    /// Draw the points only, with no line between them (reference values such as the paper's).
    pub points_only: bool,
}

impl Series {
    /// A line through `points`.
    pub fn line(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            points_only: false,
        }
    }

    /// Marked points with no line.
    pub fn points(label: impl Into<String>, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.into(),
            points,
            points_only: true,
        }
    }
}

/// A line chart.
pub struct Chart {
    /// Title.
    pub title: String,
    /// X axis label.
    pub x_label: String,
    /// Y axis label.
    pub y_label: String,
    /// Fixed y range, if any.
    pub y_range: Option<(f64, f64)>,
    /// Lines.
    pub series: Vec<Series>,
    /// Width and height, px.
    pub size: (f64, f64),
}

impl Chart {
    /// A line chart of the default size (1 040 × 400 px) with a free y range.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
        series: Vec<Series>,
    ) -> Self {
        Chart {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            y_range: None,
            series,
            size: (WIDTH, 400.0),
        }
    }
}

/// One group member of a bar chart: a value per category (`None`: no bar).
pub struct BarSeries {
    /// Legend label.
    pub label: String,
    /// Values in category order.
    pub values: Vec<Option<f64>>,
}

/// Grouped bars: one group per category, one bar per series, with the category names under
/// the axis (slanted when they would not fit).
pub struct BarChart {
    /// Title.
    pub title: String,
    /// Y axis label.
    pub y_label: String,
    /// Category names.
    pub categories: Vec<String>,
    /// Bars of each group.
    pub series: Vec<BarSeries>,
    /// Lowest value drawn: longer bars are cut there and marked (default: min(0, data), not
    /// below −1).
    pub floor: Option<f64>,
    /// Width, px (the height follows from the category names).
    pub width: f64,
}

/// A chart of a report.
pub enum Figure {
    /// Lines.
    Line(Chart),
    /// Grouped bars.
    Bars(BarChart),
    /// Horizontal ranked bars.
    Tornado(super::tornado::Tornado),
}

impl Figure {
    /// The SVG document.
    pub fn to_svg(&self) -> String {
        match self {
            Figure::Line(c) => c.to_svg(),
            Figure::Bars(b) => b.to_svg(),
            Figure::Tornado(t) => t.to_svg(),
        }
    }
}

impl From<Chart> for Figure {
    fn from(c: Chart) -> Self {
        Figure::Line(c)
    }
}

impl From<BarChart> for Figure {
    fn from(b: BarChart) -> Self {
        Figure::Bars(b)
    }
}

/// Default chart width, px (the report page is 1 100 px wide).
pub const WIDTH: f64 = 1040.0;
/// Right margin for the legend, px.
const LEGEND: f64 = 170.0;

const COLORS: [&str; 8] = [
    "#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf",
];

fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= n as f64)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + 1e-9 * span {
        // Snap to the step so that 0 prints as 0, not -0 or 1e-17.
        out.push((t / step).round() * step);
        t += step;
    }
    out
}

/// SVG header, white background and the title centred over the plot area.
fn open(w: f64, h: f64, title: &str, centre: f64) -> String {
    format!(
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/><text x="{centre}" y="20" text-anchor="middle" font-size="14" font-weight="bold">{}</text>"#,
        esc(title)
    )
}

/// Horizontal grid lines with y tick labels, the frame and the y label.
fn y_axis(s: &mut String, plot: (f64, f64, f64, f64), range: (f64, f64), label: &str) {
    let (l, t, r, b) = plot;
    let py = |y: f64| b - (y - range.0) / (range.1 - range.0) * (b - t);
    for ty in nice_ticks(range.0, range.1, 6) {
        let y = py(ty);
        let _ = write!(
            s,
            r##"<line x1="{l}" y1="{y:.1}" x2="{r}" y2="{y:.1}" stroke="#ddd"/><text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            l - 5.0,
            y + 4.0,
            fmt(ty)
        );
    }
    let _ = write!(
        s,
        r##"<rect x="{l}" y="{t}" width="{}" height="{}" fill="none" stroke="#444"/><text transform="translate(16,{}) rotate(-90)" text-anchor="middle">{}</text>"##,
        r - l,
        b - t,
        (b + t) / 2.0,
        esc(label)
    );
}

/// Legend entry `k` in the right margin.
fn legend(s: &mut String, x: f64, top: f64, k: usize, label: &str, dot: bool) {
    let c = COLORS[k % COLORS.len()];
    let ly = top + 14.0 + 18.0 * k as f64;
    if dot {
        let _ = write!(
            s,
            r#"<circle cx="{}" cy="{ly}" r="4" fill="{c}"/>"#,
            x + 20.0
        );
    } else {
        let _ = write!(
            s,
            r#"<line x1="{}" y1="{ly}" x2="{}" y2="{ly}" stroke="{c}" stroke-width="3"/>"#,
            x + 10.0,
            x + 30.0
        );
    }
    let _ = write!(
        s,
        r#"<text x="{}" y="{}">{}</text>"#,
        x + 35.0,
        ly + 4.0,
        esc(label)
    );
}

impl Chart {
    /// Renders the chart as an SVG document.
    pub fn to_svg(&self) -> String {
        let (w, h) = self.size;
        let (l, r, t, b) = (70.0, w - LEGEND, 36.0, h - 50.0);
        let finite = |p: &&(f64, f64)| p.0.is_finite() && p.1.is_finite();
        let (mut x0, mut x1, mut y0, mut y1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &(x, y) in self
            .series
            .iter()
            .flat_map(|s| s.points.iter())
            .filter(finite)
        {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        if !x0.is_finite() {
            (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
        }
        if x1 - x0 < 1e-12 {
            x1 = x0 + 1.0;
        }
        let (y0, y1) = match self.y_range {
            Some(range) => range,
            None => {
                let span = (y1 - y0).max(1e-12);
                (y0 - 0.04 * span, y1 + 0.04 * span)
            }
        };
        let px = |x: f64| l + (x - x0) / (x1 - x0) * (r - l);
        let py = |y: f64| b - (y.clamp(y0, y1) - y0) / (y1 - y0) * (b - t);
        let mut s = open(w, h, &self.title, (l + r) / 2.0);
        y_axis(&mut s, (l, t, r, b), (y0, y1), &self.y_label);
        for tx in nice_ticks(x0, x1, 10) {
            let x = px(tx);
            let _ = write!(
                s,
                r##"<line x1="{x:.1}" y1="{t}" x2="{x:.1}" y2="{b}" stroke="#eee"/><text x="{x:.1}" y="{}" text-anchor="middle">{}</text>"##,
                b + 16.0,
                fmt(tx)
            );
        }
        let _ = write!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            (l + r) / 2.0,
            h - 12.0,
            esc(&self.x_label)
        );
        for (k, se) in self.series.iter().enumerate() {
            let c = COLORS[k % COLORS.len()];
            let pts: Vec<&(f64, f64)> = se.points.iter().filter(finite).collect();
            if !se.points_only {
                let d: Vec<String> = pts
                    .iter()
                    .map(|&&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
                    .collect();
                let _ = write!(
                    s,
                    r#"<polyline fill="none" stroke="{c}" stroke-width="1.5" points="{}"/>"#,
                    d.join(" ")
                );
            }
            if se.points_only || pts.len() <= 40 {
                let radius = if se.points_only { 4.5 } else { 2.5 };
                for &&(x, y) in &pts {
                    let _ = write!(
                        s,
                        r#"<circle cx="{:.1}" cy="{:.1}" r="{radius}" fill="{c}"><title>{}: {}, {}</title></circle>"#,
                        px(x),
                        py(y),
                        esc(&se.label),
                        fmt(x),
                        fmt(y)
                    );
                }
            }
            legend(&mut s, r, t, k, &se.label, se.points_only);
        }
        s.push_str("</svg>\n");
        s
    }
}

impl BarChart {
    /// Renders the chart as an SVG document.
    pub fn to_svg(&self) -> String {
        let n = self.categories.len().max(1);
        let w = self.width;
        let (l, r, t) = (70.0, w - LEGEND, 36.0);
        let slot = (r - l) / n as f64;
        let longest = self
            .categories
            .iter()
            .map(|c| c.chars().count())
            .max()
            .unwrap_or(0) as f64;
        // Names fit flat when a slot holds them (≈ 6.5 px per character at 12 px); otherwise
        // they are slanted at 45°, which needs 0.71 × their length below the axis.
        let slanted = longest * 6.5 > slot;
        let below = if slanted {
            24.0 + longest * 6.5 * 0.71
        } else {
            30.0
        };
        let b = t + 300.0;
        let h = b + below;
        let values = || self.series.iter().flat_map(|s| s.values.iter().flatten());
        let lo_data = values().copied().fold(0.0f64, f64::min);
        let hi_data = values().copied().fold(0.0f64, f64::max);
        let y0 = self.floor.unwrap_or(lo_data.max(-1.0)).min(0.0);
        let y1 = if hi_data > y0 {
            hi_data + 0.04 * (hi_data - y0)
        } else {
            y0 + 1.0
        };
        let py = |y: f64| b - (y.clamp(y0, y1) - y0) / (y1 - y0) * (b - t);
        let mut s = open(w, h, &self.title, (l + r) / 2.0);
        y_axis(&mut s, (l, t, r, b), (y0, y1), &self.y_label);
        let m = self.series.len().max(1) as f64;
        let bar = 0.8 * slot / m;
        for (i, cat) in self.categories.iter().enumerate() {
            let x = l + slot * i as f64;
            for (k, se) in self.series.iter().enumerate() {
                let Some(v) = se.values.get(i).copied().flatten() else {
                    continue;
                };
                let c = COLORS[k % COLORS.len()];
                let bx = x + 0.1 * slot + bar * k as f64;
                let (ya, yb) = (py(v.max(0.0)), py(v.min(0.0)));
                let _ = write!(
                    s,
                    r#"<rect x="{bx:.1}" y="{ya:.1}" width="{:.1}" height="{:.1}" fill="{c}"><title>{} — {}: {}</title></rect>"#,
                    (bar - 1.0).max(1.0),
                    (yb - ya).max(0.5),
                    esc(cat),
                    esc(&se.label),
                    fmt(v)
                );
                if v < y0 {
                    // Cut at the floor: say so with the value.
                    let _ = write!(
                        s,
                        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle" font-size="9" fill="{c}">{}</text>"#,
                        bx + bar / 2.0,
                        b - 4.0,
                        fmt(v)
                    );
                }
            }
            let cx = x + slot / 2.0;
            if slanted {
                let _ = write!(
                    s,
                    r#"<text x="{cx:.1}" y="{}" text-anchor="end" transform="rotate(-45 {cx:.1} {})">{}</text>"#,
                    b + 14.0,
                    b + 14.0,
                    esc(cat)
                );
            } else {
                let _ = write!(
                    s,
                    r#"<text x="{cx:.1}" y="{}" text-anchor="middle">{}</text>"#,
                    b + 18.0,
                    esc(cat)
                );
            }
        }
        if y0 < 0.0 {
            let _ = write!(
                s,
                r##"<line x1="{l}" y1="{0:.1}" x2="{r}" y2="{0:.1}" stroke="#444"/>"##,
                py(0.0)
            );
        }
        for (k, se) in self.series.iter().enumerate() {
            let c = COLORS[k % COLORS.len()];
            let ly = t + 14.0 + 18.0 * k as f64;
            let _ = write!(
                s,
                r#"<rect x="{}" y="{}" width="20" height="10" fill="{c}"/><text x="{}" y="{}">{}</text>"#,
                r + 10.0,
                ly - 5.0,
                r + 35.0,
                ly + 4.0,
                esc(&se.label)
            );
        }
        s.push_str("</svg>\n");
        s
    }
}

fn fmt(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 10_000.0 || v.abs() < 0.001 {
        format!("{v:.1e}")
    } else {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_print_zero_as_zero() {
        let t = nice_ticks(-1.0, 1.0, 8);
        assert!(
            t.iter()
                .any(|&v| v == 0.0 && v.is_sign_positive() || fmt(v) == "0")
        );
        assert!(t.iter().all(|&v| fmt(v) != "-0"));
    }

    #[test]
    fn bars_name_their_categories_and_values() {
        let b = BarChart {
            title: "R² per condition".into(),
            y_label: "test R²".into(),
            categories: vec!["curve_r400_v60".into(), "tangent_v80".into()],
            series: vec![
                BarSeries {
                    label: "FQ (ours)".into(),
                    values: vec![Some(0.8), Some(-3.0)],
                },
                BarSeries {
                    label: "FQ (paper)".into(),
                    values: vec![Some(0.9542), None],
                },
            ],
            floor: None,
            width: WIDTH,
        };
        let s = b.to_svg();
        assert!(s.contains("curve_r400_v60") && s.contains("tangent_v80"));
        assert!(s.contains("FQ (paper): 0.954"));
        // −3 is below the floor of −1: cut and labelled.
        assert!(s.contains(">-3</text>"));
        // The frame, three bars, two legend keys.
        assert_eq!(s.matches("<rect x=").count(), 1 + 3 + 2);
    }
}
