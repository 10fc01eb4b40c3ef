//! A minimal SVG plot of quantities over time (independent x and y scales, lines, shaded
//! time bands), for the orientation figures.

use std::fmt::Write as _;
use std::path::Path;

use crate::io::{CliResult, write_atomically};

/// One line: (t, value) points joined in order.
pub struct Line<'a> {
    /// Legend label.
    pub label: &'a str,
    /// CSS colour.
    pub colour: &'a str,
    /// (t, value) points.
    pub points: Vec<(f64, f64)>,
}

/// A shaded interval of time.
pub struct Band {
    /// Start, in the x unit.
    pub from: f64,
    /// End, in the x unit.
    pub to: f64,
}

/// Most points drawn per line: longer lines are thinned evenly (a plot 900 px wide shows no
/// more).
const MAX_POINTS: usize = 4000;

/// Writes the plot to `path` (whole or not at all).
pub fn write_timeseries(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    lines: &[Line],
    bands: &[Band],
) -> CliResult {
    let (x0, x1, y0, y1) =
        super::equal_axes::bounds(path, lines.iter().flat_map(|l| l.points.iter()))?;
    let view = View {
        x0,
        x1,
        xs: (x1 - x0).max(1e-12),
        ys: (y1 - y0).max(1e-12) * 1.1,
        yc: 0.5 * (y0 + y1),
    };
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{HEIGHT}" viewBox="0 0 {WIDTH} {HEIGHT}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="16">{title}</text>"#,
        WIDTH / 2.0
    );
    shade(&mut svg, &view, bands);
    let _ = writeln!(
        svg,
        r#"<rect x="{M}" y="{M}" width="{W}" height="{H}" fill="none" stroke="black"/>"#
    );
    axes(&mut svg, &view, x_label, y_label);
    for (i, l) in lines.iter().enumerate() {
        draw_line(&mut svg, &view, i, l);
    }
    let _ = writeln!(svg, "</svg>");
    write_atomically(path, |f| Ok(f.write_all(svg.as_bytes())?))
}

/// Width of the plot area, px.
const W: f64 = 900.0;
/// Height of the plot area, px.
const H: f64 = 420.0;
/// Margin around it for labels, px.
const M: f64 = 60.0;
/// Size of the whole figure, px.
const WIDTH: f64 = W + 2.0 * M;
/// Height of the whole figure, px.
const HEIGHT: f64 = H + 2.0 * M;

/// The data shown: x from `x0` to `x1` (span `xs`), y centred on `yc` with span `ys`.
struct View {
    x0: f64,
    x1: f64,
    xs: f64,
    ys: f64,
    yc: f64,
}

impl View {
    /// Pixel column of data `x`.
    fn sx(&self, x: f64) -> f64 {
        M + (x - self.x0) / self.xs * W
    }

    /// Pixel row of data `y` (up is up).
    fn sy(&self, y: f64) -> f64 {
        M + (self.yc + self.ys / 2.0 - y) / self.ys * H
    }
}

/// The shaded time bands, clipped to the view.
fn shade(svg: &mut String, view: &View, bands: &[Band]) {
    for b in bands {
        let (a, c) = (view.sx(b.from.max(view.x0)), view.sx(b.to.min(view.x1)));
        let _ = writeln!(
            svg,
            r##"<rect x="{a:.1}" y="{M}" width="{:.1}" height="{H}" fill="#f2c14e" fill-opacity="0.35"/>"##,
            (c - a).max(0.5)
        );
    }
}

/// Five labelled values on each axis (decimals by the span shown) and the axis titles.
fn axes(svg: &mut String, view: &View, x_label: &str, y_label: &str) {
    let decimals = |span: f64| {
        if span >= 20.0 {
            0
        } else if span >= 2.0 {
            1
        } else {
            3
        }
    };
    let (dx, dy) = (decimals(view.xs), decimals(view.ys));
    for i in 0..=4 {
        let (x, y) = (
            view.x0 + view.xs * i as f64 / 4.0,
            view.yc - view.ys / 2.0 + view.ys * i as f64 / 4.0,
        );
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{x:.dx$}</text>"#,
            view.sx(x),
            M + H + 18.0
        );
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{y:.dy$}</text>"#,
            M - 6.0,
            view.sy(y) + 4.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_label}</text>"#,
        WIDTH / 2.0,
        HEIGHT - 12.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{y_label}</text>"#,
        HEIGHT / 2.0,
        HEIGHT / 2.0
    );
}

/// Line `i`: its points joined (thinned to [`MAX_POINTS`], the pen lifted over non-finite
/// ones) and its legend entry.
fn draw_line(svg: &mut String, view: &View, i: usize, l: &Line) {
    let step = l.points.len().div_ceil(MAX_POINTS).max(1);
    let mut d = String::new();
    let mut pen_up = true;
    for &(x, y) in l.points.iter().step_by(step) {
        if !(x.is_finite() && y.is_finite()) {
            pen_up = true;
            continue;
        }
        let _ = write!(
            d,
            "{}{:.1},{:.1} ",
            if pen_up { "M" } else { "L" },
            view.sx(x),
            view.sy(y)
        );
        pen_up = false;
    }
    let _ = writeln!(
        svg,
        r#"<path d="{d}" fill="none" stroke="{}" stroke-width="1.2"/>"#,
        l.colour
    );
    let ly = M + 16.0 + 18.0 * i as f64;
    let _ = writeln!(
        svg,
        r#"<line x1="{:.1}" y1="{ly:.1}" x2="{:.1}" y2="{ly:.1}" stroke="{}" stroke-width="3"/><text x="{:.1}" y="{:.1}">{}</text>"#,
        M + 10.0,
        M + 30.0,
        l.colour,
        M + 36.0,
        ly + 4.0,
        l.label
    );
}
