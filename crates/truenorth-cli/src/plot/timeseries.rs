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
    const W: f64 = 900.0;
    const H: f64 = 420.0;
    const M: f64 = 60.0;
    let (x0, x1, y0, y1) =
        super::equal_axes::bounds(path, lines.iter().flat_map(|l| l.points.iter()))?;
    let (xs, ys) = ((x1 - x0).max(1e-12), (y1 - y0).max(1e-12) * 1.1);
    let yc = 0.5 * (y0 + y1);
    let sx = |x: f64| M + (x - x0) / xs * W;
    let sy = |y: f64| M + (yc + ys / 2.0 - y) / ys * H;
    let (w, h) = (W + 2.0 * M, H + 2.0 * M);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="13">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="16">{title}</text>"#,
        w / 2.0
    );
    for b in bands {
        let (a, c) = (sx(b.from.max(x0)), sx(b.to.min(x1)));
        let _ = writeln!(
            svg,
            r##"<rect x="{a:.1}" y="{M}" width="{:.1}" height="{H}" fill="#f2c14e" fill-opacity="0.35"/>"##,
            (c - a).max(0.5)
        );
    }
    let _ = writeln!(
        svg,
        r#"<rect x="{M}" y="{M}" width="{W}" height="{H}" fill="none" stroke="black"/>"#
    );
    let decimals = |span: f64| {
        if span >= 20.0 {
            0
        } else if span >= 2.0 {
            1
        } else {
            3
        }
    };
    let (dx, dy) = (decimals(xs), decimals(ys));
    for i in 0..=4 {
        let (x, y) = (
            x0 + xs * i as f64 / 4.0,
            yc - ys / 2.0 + ys * i as f64 / 4.0,
        );
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{x:.dx$}</text>"#,
            sx(x),
            M + H + 18.0
        );
        let _ = writeln!(
            svg,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="end">{y:.dy$}</text>"#,
            M - 6.0,
            sy(y) + 4.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" text-anchor="middle">{x_label}</text>"#,
        w / 2.0,
        h - 12.0
    );
    let _ = writeln!(
        svg,
        r#"<text x="16" y="{}" text-anchor="middle" transform="rotate(-90 16 {})">{y_label}</text>"#,
        h / 2.0,
        h / 2.0
    );
    for (i, l) in lines.iter().enumerate() {
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
                sx(x),
                sy(y)
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
    let _ = writeln!(svg, "</svg>");
    write_atomically(path, |f| Ok(f.write_all(svg.as_bytes())?))
}
