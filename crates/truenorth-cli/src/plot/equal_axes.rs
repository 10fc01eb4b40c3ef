//! A minimal SVG scatter/line plot writer for the demo's figures (no plotting dependency:
//! the figures are a handful of point sets on equal axes).

use std::fmt::Write as _;
use std::path::Path;

use crate::io::{CliError, CliResult};

/// One data series: points drawn as dots or joined as a line.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// CSS colour.
    pub colour: &'a str,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// How the points are drawn.
    pub style: Style,
}

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A dot per point (readings).
    Dots,
    /// Joined, last point back to the first (a fitted curve).
    Closed,
    /// Joined from first to last (a track).
    Open,
}

/// The smallest and largest finite x and y of `points`, as (x0, x1, y0, y1); an error
/// naming `path` if there is no finite point.
pub(super) fn bounds<'a>(
    path: &Path,
    points: impl Iterator<Item = &'a (f64, f64)>,
) -> CliResult<(f64, f64, f64, f64)> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in points.filter(|p| p.0.is_finite() && p.1.is_finite()) {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return Err(CliError::file(path, "nothing to plot"));
    }
    Ok((x0, x1, y0, y1))
}

/// Writes an equal-axes plot of `series` to `path`.
pub fn write_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    series: &[Series],
) -> CliResult {
    let (x0, x1, y0, y1) = bounds(path, series.iter().flat_map(|s| s.points.iter()))?;
    // Equal scales on both axes so that a circle looks like a circle.
    let view = View {
        span: (x1 - x0).max(y1 - y0).max(1e-12) * 1.1,
        cx: 0.5 * (x0 + x1),
        cy: 0.5 * (y0 + y1),
    };
    let mut svg = String::new();
    frame(&mut svg, title, x_label, y_label);
    ticks(&mut svg, &view);
    zero_axes(&mut svg, &view);
    for (k, s) in series.iter().enumerate() {
        draw_series(&mut svg, &view, k, s);
    }
    svg.push_str("</svg>\n");
    std::fs::write(path, svg).map_err(|e| CliError::file(path, format!("cannot write: {e}")))
}

/// Side of the square plot area, px.
const SIZE: f64 = 560.0;
/// Margin around it for labels, px.
const MARGIN: f64 = 60.0;
/// Width (and height) of the whole figure, px.
const WIDTH: f64 = SIZE + 2.0 * MARGIN;

/// The square of data shown: its centre and side, in data units.
struct View {
    span: f64,
    cx: f64,
    cy: f64,
}

impl View {
    /// Pixel column of data `x`.
    fn sx(&self, x: f64) -> f64 {
        MARGIN + (x - self.cx + self.span / 2.0) / self.span * SIZE
    }

    /// Pixel row of data `y` (up is up).
    fn sy(&self, y: f64) -> f64 {
        MARGIN + (self.cy + self.span / 2.0 - y) / self.span * SIZE
    }
}

/// The SVG header, background, title, axis labels and plot border.
fn frame(svg: &mut String, title: &str, x_label: &str, y_label: &str) {
    let w = WIDTH;
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{w}" viewBox="0 0 {w} {w}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="16">{title}</text>"#,
        w / 2.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_label}</text>"#,
        w / 2.0,
        w - 15.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="18" y="{}" text-anchor="middle" transform="rotate(-90 18 {})">{y_label}</text>"#,
        w / 2.0,
        w / 2.0
    );
    let _ = writeln!(
        svg,
        r##"<rect x="{MARGIN}" y="{MARGIN}" width="{SIZE}" height="{SIZE}" fill="none" stroke="#888"/>"##
    );
}

/// Tick marks and labels at round values (1, 2 or 5 times a power of ten), about six per
/// axis.
fn ticks(svg: &mut String, view: &View) {
    let step = nice_step(view.span / 6.0);
    for (lo, vertical) in [
        (view.cx - view.span / 2.0, true),
        (view.cy - view.span / 2.0, false),
    ] {
        let mut v = (lo / step).ceil() * step;
        while v <= lo + view.span {
            let label = format!("{}", (v / step).round() * step);
            if vertical {
                let px = view.sx(v);
                let _ = writeln!(
                    svg,
                    r##"<line x1="{px:.1}" y1="{0}" x2="{px:.1}" y2="{1}" stroke="#888"/>"##,
                    MARGIN + SIZE,
                    MARGIN + SIZE + 5.0
                );
                let _ = writeln!(
                    svg,
                    r#"<text x="{px:.1}" y="{}" text-anchor="middle" font-size="11">{label}</text>"#,
                    MARGIN + SIZE + 18.0
                );
            } else {
                let px = view.sy(v);
                let _ = writeln!(
                    svg,
                    r##"<line x1="{0}" y1="{px:.1}" x2="{MARGIN}" y2="{px:.1}" stroke="#888"/>"##,
                    MARGIN - 5.0
                );
                let _ = writeln!(
                    svg,
                    r#"<text x="{}" y="{:.1}" text-anchor="end" font-size="11">{label}</text>"#,
                    MARGIN - 8.0,
                    px + 4.0
                );
            }
            v += step;
        }
    }
}

/// Axes through zero when zero is in view.
fn zero_axes(svg: &mut String, view: &View) {
    let half = view.span / 2.0;
    if (view.cx - half..view.cx + half).contains(&0.0) {
        let _ = writeln!(
            svg,
            r##"<line x1="{0}" y1="{MARGIN}" x2="{0}" y2="{1}" stroke="#ccc"/>"##,
            view.sx(0.0),
            MARGIN + SIZE
        );
    }
    if (view.cy - half..view.cy + half).contains(&0.0) {
        let _ = writeln!(
            svg,
            r##"<line x1="{MARGIN}" y1="{0}" x2="{1}" y2="{0}" stroke="#ccc"/>"##,
            view.sy(0.0),
            MARGIN + SIZE
        );
    }
}

/// Series `k`: its points (dots, or a line open or closed) and its legend entry.
fn draw_series(svg: &mut String, view: &View, k: usize, s: &Series) {
    if s.style != Style::Dots {
        let pts: Vec<String> = s
            .points
            .iter()
            .map(|&(x, y)| format!("{:.1},{:.1}", view.sx(x), view.sy(y)))
            .collect();
        let _ = writeln!(
            svg,
            r#"<{} points="{}" fill="none" stroke="{}" stroke-width="2"/>"#,
            if s.style == Style::Closed {
                "polygon"
            } else {
                "polyline"
            },
            pts.join(" "),
            s.colour
        );
    } else {
        for &(x, y) in &s.points {
            let _ = writeln!(
                svg,
                r#"<circle cx="{:.1}" cy="{:.1}" r="1.6" fill="{}"/>"#,
                view.sx(x),
                view.sy(y),
                s.colour
            );
        }
    }
    let ly = MARGIN + 18.0 + 18.0 * k as f64;
    let _ = writeln!(
        svg,
        r#"<rect x="{}" y="{}" width="12" height="12" fill="{}"/>"#,
        MARGIN + 10.0,
        ly - 10.0,
        s.colour
    );
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{ly}">{}</text>"#,
        MARGIN + 28.0,
        s.label
    );
}

/// The round step (1, 2 or 5 × 10ⁿ) nearest above `raw`.
fn nice_step(raw: f64) -> f64 {
    let p = 10f64.powf(raw.max(1e-300).log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * p)
}
