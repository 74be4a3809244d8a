//! A tornado chart: one horizontal bar per parameter, longest on top, each bar one or more
//! measures side by side (a sensitivity study's μ* of FL and FQ), with the values written at
//! the bar ends.

use super::escape::esc;
use std::fmt::Write;

/// Horizontal bars, ranked as given (the caller sorts).
pub struct Tornado {
    /// Title.
    pub title: String,
    /// The value axis' label (`μ*, kN over the range`).
    pub x_label: String,
    /// Parameter names, top to bottom.
    pub rows: Vec<String>,
    /// The measures: a legend label and one value per row.
    pub series: Vec<(String, Vec<f64>)>,
}

const COLORS: [&str; 4] = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"];

impl Tornado {
    /// Renders the chart as an SVG document (width 1 040 px; the height follows the rows).
    pub fn to_svg(&self) -> String {
        let longest = self
            .rows
            .iter()
            .map(|r| r.chars().count())
            .max()
            .unwrap_or(0) as f64;
        // ≈ 6.5 px per character at 12 px.
        let l = (longest * 6.5 + 20.0).clamp(120.0, 520.0);
        let (w, t) = (1040.0, 40.0);
        let r = w - 90.0;
        let per = self.series.len().max(1) as f64;
        let row_h = 8.0 + 11.0 * per;
        let b = t + row_h * self.rows.len().max(1) as f64;
        let h = b + 60.0;
        let max = self
            .series
            .iter()
            .flat_map(|s| s.1.iter())
            .filter(|v| v.is_finite())
            .fold(0.0_f64, |a, v| a.max(v.abs()));
        let max = if max > 0.0 { max } else { 1.0 };
        let x = |v: f64| l + (r - l) * (v.abs() / max).min(1.0);
        let mut s = format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="12"><rect width="{w}" height="{h}" fill="white"/><text x="{}" y="20" font-size="14" text-anchor="middle">{}</text>"#,
            w / 2.0,
            esc(&self.title)
        );
        for (i, name) in self.rows.iter().enumerate() {
            let y0 = t + row_h * i as f64;
            let _ = write!(
                s,
                r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
                l - 6.0,
                y0 + row_h / 2.0 + 4.0,
                esc(name)
            );
            for (k, (_, values)) in self.series.iter().enumerate() {
                let Some(&v) = values.get(i) else { continue };
                if !v.is_finite() {
                    continue;
                }
                let y = y0 + 4.0 + 11.0 * k as f64;
                let c = COLORS[k % COLORS.len()];
                let _ = write!(
                    s,
                    r#"<rect x="{l}" y="{y}" width="{:.1}" height="10" fill="{c}"/><text x="{:.1}" y="{}" font-size="10">{}</text>"#,
                    x(v) - l,
                    x(v) + 3.0,
                    y + 9.0,
                    fmt(v)
                );
            }
        }
        let _ = write!(
            s,
            r##"<line x1="{l}" y1="{t}" x2="{l}" y2="{b}" stroke="#333"/><line x1="{l}" y1="{b}" x2="{r}" y2="{b}" stroke="#333"/><text x="{}" y="{}" text-anchor="middle">{}</text>"##,
            (l + r) / 2.0,
            b + 20.0,
            esc(&self.x_label)
        );
        for (k, (label, _)) in self.series.iter().enumerate() {
            let lx = l + 160.0 * k as f64;
            let c = COLORS[k % COLORS.len()];
            let _ = write!(
                s,
                r#"<rect x="{lx}" y="{}" width="14" height="10" fill="{c}"/><text x="{}" y="{}">{}</text>"#,
                b + 34.0,
                lx + 18.0,
                b + 43.0,
                esc(label)
            );
        }
        s.push_str("</svg>\n");
        s
    }
}

fn fmt(v: f64) -> String {
    if v.abs() >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bars_scale_with_their_values_and_every_row_is_named() {
        let t = Tornado {
            title: "t".into(),
            x_label: "kN".into(),
            rows: vec!["a".into(), "b".into()],
            series: vec![("FQ".into(), vec![4.0, 1.0])],
        };
        let svg = t.to_svg();
        let widths: Vec<f64> = svg
            .split("<rect x=")
            .skip(1)
            .filter_map(|p| p.split("width=\"").nth(1)?.split('"').next()?.parse().ok())
            .collect();
        assert_eq!(widths.len(), 3, "{svg}");
        assert!((widths[0] / widths[1] - 4.0).abs() < 1e-6, "{widths:?}");
        assert!(svg.contains(">a<") && svg.contains(">b<"));
    }
}
