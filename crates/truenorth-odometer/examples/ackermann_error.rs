//! Measures how far US 4,788,645 eq. 14 (the patent's effective front track) is from the
//! exact rigid-body Ackermann geometry, and how far its look-up table is from the formula.
//!
//! `cargo run -p truenorth-odometer --example ackermann_error`
//!
//! Vehicle: wheelbase B = 2.7 m, nominal front track T_F = 1.55 m (a mid-size car). Kingpin
//! offset p = 0.10 m, i.e. Pitman-arm ratio P = 2p/T_F = 0.129: the patent's "approx. 1/8"
//! (which would be p = 0.097 m on this track), and the order of the kingpin-to-wheel-centre
//! distance of a conventional front suspension. The other columns show p = 0 and the patent's
//! other figure, P = 1/3 (p = 0.258 m, an implausibly long arm, kept for comparison).

use truenorth_odometer::{
    AckermannGeometry, AckermannParams, EffectiveTrack, EffectiveTrackTable, PatentAckermannTrack,
};

/// Wheelbase, m.
pub const WHEELBASE_M: f64 = 2.7;
/// Nominal front track, m.
pub const TRACK_M: f64 = 1.55;
/// Kingpin offset of the main column, m.
pub const KINGPIN_OFFSET_M: f64 = 0.10;

/// One row of the table.
#[derive(Debug, Clone, Copy)]
pub struct Row {
    /// Curvature ratio ΔD/AD.
    pub c: f64,
    /// Rear-axle-centre turn radius for the main vehicle, m (None past its peak).
    pub radius_m: Option<f64>,
    /// Inner front wheel steer angle, degrees.
    pub inner_steer_deg: Option<f64>,
    /// Exact T_E, m.
    pub exact_m: Option<f64>,
    /// Patent T_E, m (None past the formula's c_max).
    pub patent_m: Option<f64>,
    /// (patent − exact)/exact for p = 0.10 m, p = 0 and P = 1/3.
    pub rel: [Option<f64>; 3],
}

fn car(p: f64) -> AckermannParams {
    AckermannParams {
        wheelbase_m: WHEELBASE_M,
        track_m: TRACK_M,
        kingpin_offset_m: p,
    }
}

/// The offsets of the three error columns, m.
pub fn offsets_m() -> [f64; 3] {
    [KINGPIN_OFFSET_M, 0.0, TRACK_M / 6.0]
}

/// Relative error of the patent formula at ratio `c` for kingpin offset `p`.
pub fn relative_error(p: f64, c: f64) -> Option<f64> {
    let g = AckermannGeometry::new(car(p)).ok()?;
    let f = PatentAckermannTrack::from_params(&car(p)).ok()?;
    let exact = g.effective_track_m(c).ok()?;
    let patent = f.effective_track_m(c).ok()?;
    Some((patent - exact) / exact)
}

/// The ratios tabulated: 0 to just below the formula's limit.
pub fn ratios() -> Vec<f64> {
    let c_max = PatentAckermannTrack::from_params(&car(KINGPIN_OFFSET_M))
        .map(|f| f.max_ratio())
        .unwrap_or(0.28);
    let mut v: Vec<f64> = (0..=13).map(|i| 0.02 * i as f64).collect();
    v.extend([0.27, 0.275, 0.28, 0.283, c_max]);
    v
}

/// The table for the main vehicle.
pub fn table() -> Vec<Row> {
    let g = AckermannGeometry::new(car(KINGPIN_OFFSET_M)).ok();
    let f = PatentAckermannTrack::from_params(&car(KINGPIN_OFFSET_M)).ok();
    ratios()
        .into_iter()
        .map(|c| {
            let k = g.and_then(|g| g.curvature_from_ratio(c).ok());
            let exact_m = g.and_then(|g| g.effective_track_m(c).ok());
            let patent_m = f.and_then(|f| f.effective_track_m(c).ok());
            let offs = offsets_m();
            Row {
                c,
                radius_m: k.map(|k| 1.0 / k),
                inner_steer_deg: k.and_then(|k| {
                    g.and_then(|g| g.steer_angles_rad(k).ok())
                        .map(|(_, r)| r.to_degrees())
                }),
                exact_m,
                patent_m,
                rel: [
                    relative_error(offs[0], c),
                    relative_error(offs[1], c),
                    relative_error(offs[2], c),
                ],
            }
        })
        .collect()
}

/// Largest |table − formula| / formula over `n` evenly spaced ratios in `[lo, hi]`.
pub fn table_error<const N: usize>(lo: f64, hi: f64, n: usize) -> f64 {
    let Ok(f) = PatentAckermannTrack::from_params(&car(KINGPIN_OFFSET_M)) else {
        return f64::NAN;
    };
    let Ok(t) = EffectiveTrackTable::<N>::build(&f, f.max_ratio()) else {
        return f64::NAN;
    };
    (0..=n)
        .map(|i| lo + (hi - lo) * i as f64 / n as f64)
        .filter_map(|c| {
            let a = f.effective_track_m(c).ok()?;
            let b = t.effective_track_m(c).ok()?;
            Some(((b - a) / a).abs())
        })
        .fold(0.0, f64::max)
}

fn opt(x: Option<f64>, prec: usize) -> String {
    x.map_or_else(|| "—".to_string(), |v| format!("{v:.prec$}"))
}

fn sci(x: Option<f64>) -> String {
    x.map_or_else(|| "—".to_string(), |v| format!("{v:+.2e}"))
}

/// Prints the tables.
pub fn print() {
    let g = AckermannGeometry::new(car(KINGPIN_OFFSET_M)).ok();
    let f = PatentAckermannTrack::from_params(&car(KINGPIN_OFFSET_M)).ok();
    println!(
        "B = {WHEELBASE_M} m, T_F = {TRACK_M} m, p = {KINGPIN_OFFSET_M} m (P = 2p/T_F = {:.4})",
        2.0 * KINGPIN_OFFSET_M / TRACK_M
    );
    println!(
        "patent c_max = {:.4}; exact geometry peaks at c = {:.4} (rear-axle radius {:.2} m)",
        f.map_or(f64::NAN, |f| f.max_ratio()),
        g.map_or(f64::NAN, |g| g.peak_ratio()),
        g.map_or(f64::NAN, |g| 1.0 / g.peak_curvature_per_m()),
    );
    println!();
    println!(
        "| c = ΔD/AD | R rear (m) | inner steer (°) | T_E exact (m) | T_E patent (m) | rel. error p=0.10 | heading error on 90° (°) | rel. error p=0 | rel. error P=1/3 |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in table() {
        let heading = r.rel[0].map(|e| 90.0 * (1.0 / (1.0 + e) - 1.0));
        println!(
            "| {:.4} | {} | {} | {} | {} | {} | {} | {} | {} |",
            r.c,
            opt(r.radius_m.filter(|x| x.is_finite()), 2),
            opt(r.inner_steer_deg, 1),
            opt(r.exact_m, 4),
            opt(r.patent_m, 4),
            sci(r.rel[0]),
            opt(heading, 3),
            sci(r.rel[1]),
            sci(r.rel[2]),
        );
    }
    let c_max = f.map_or(f64::NAN, |f| f.max_ratio());
    println!();
    println!(
        "look-up table (uniform in c, linear interpolation) vs the formula, max relative error:"
    );
    println!("| entries | c ≤ 0.5 c_max | c ≤ 0.9 c_max | c ≤ c_max |");
    println!("|---|---|---|---|");
    for (n, e) in [
        (
            16,
            [
                table_error::<16>(0.0, 0.5 * c_max, 4000),
                table_error::<16>(0.0, 0.9 * c_max, 4000),
                table_error::<16>(0.0, c_max, 4000),
            ],
        ),
        (
            64,
            [
                table_error::<64>(0.0, 0.5 * c_max, 4000),
                table_error::<64>(0.0, 0.9 * c_max, 4000),
                table_error::<64>(0.0, c_max, 4000),
            ],
        ),
        (
            256,
            [
                table_error::<256>(0.0, 0.5 * c_max, 4000),
                table_error::<256>(0.0, 0.9 * c_max, 4000),
                table_error::<256>(0.0, c_max, 4000),
            ],
        ),
    ] {
        println!("| {n} | {:.2e} | {:.2e} | {:.2e} |", e[0], e[1], e[2]);
    }
}

#[allow(dead_code)]
fn main() {
    print();
}
