//! Reproduces every row of the official WMM2025 test values (NOAA NCEI / BGS, public
//! domain; copied into `tests/data/`, provenance in `tests/data/README.md`).
//!
//! Required: within 0.1 nT for X, Y, Z, H, F (and 0.1 nT/yr for their secular variation),
//! within 0.01° for I, D and GV (and 0.01°/yr for İ, Ḋ). The file rounds to 0.1 nT and
//! 0.01°, so a correct implementation stays within half of that. The worst deviation per
//! quantity is printed (`cargo test -p truenorth-geomag --test test_values -- --nocapture`).

use std::path::Path;

use truenorth_geomag::field_at_deg;

const NT_TOL: f64 = 0.1;
const DEG_TOL: f64 = 0.01;

/// Column names of the file (its `#` header, fields 5–19), with their tolerance.
const QUANTITIES: [(&str, f64); 15] = [
    ("X (nT)", NT_TOL),
    ("Y (nT)", NT_TOL),
    ("Z (nT)", NT_TOL),
    ("H (nT)", NT_TOL),
    ("F (nT)", NT_TOL),
    ("I (deg)", DEG_TOL),
    ("D (deg)", DEG_TOL),
    ("GV (deg)", DEG_TOL),
    ("Xdot (nT/yr)", NT_TOL),
    ("Ydot (nT/yr)", NT_TOL),
    ("Zdot (nT/yr)", NT_TOL),
    ("Hdot (nT/yr)", NT_TOL),
    ("Fdot (nT/yr)", NT_TOL),
    ("Idot (deg/yr)", DEG_TOL),
    ("Ddot (deg/yr)", DEG_TOL),
];

fn read_rows() -> Vec<Vec<f64>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/WMM2025_TEST_VALUES.txt");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            // "NaN" (the grid variation where it is undefined) parses as f64 NaN.
            l.split_whitespace()
                .map(|f| {
                    f.parse::<f64>()
                        .unwrap_or_else(|_| panic!("bad field `{f}` in `{l}`"))
                })
                .collect::<Vec<f64>>()
        })
        .collect()
}

#[test]
fn every_official_test_value_is_reproduced() {
    let rows = read_rows();
    assert_eq!(rows.len(), 12, "the WMM2025 test file has 12 rows");
    let mut worst = [0.0f64; QUANTITIES.len()];
    let mut failures = Vec::new();
    for row in &rows {
        assert_eq!(row.len(), 19, "19 fields per row: {row:?}");
        let (year, alt_km, lat, lon) = (row[0], row[1], row[2], row[3]);
        let f = field_at_deg(lat, lon, alt_km, year)
            .unwrap_or_else(|e| panic!("row {row:?} refused: {e}"));
        let sv = f.secular_variation;
        let ours = [
            f.x_nt,
            f.y_nt,
            f.z_nt,
            f.h_nt,
            f.f_nt,
            f.inclination_deg(),
            f.declination_deg(),
            f.grid_variation_deg().unwrap_or(f64::NAN),
            sv.x_nt_per_yr,
            sv.y_nt_per_yr,
            sv.z_nt_per_yr,
            sv.h_nt_per_yr,
            sv.f_nt_per_yr,
            sv.inclination_rad_per_yr.to_degrees(),
            sv.declination_rad_per_yr.to_degrees(),
        ];
        for (q, (&got, &want)) in ours.iter().zip(&row[4..]).enumerate() {
            let (name, tol) = QUANTITIES[q];
            if want.is_nan() {
                // Grid variation is undefined between 55° S and 55° N: we must say so too.
                if !got.is_nan() {
                    failures.push(format!("{name} at {row:?}: expected none, got {got}"));
                }
                continue;
            }
            let dev = (got - want).abs();
            worst[q] = worst[q].max(dev);
            // Written so that a NaN deviation fails too.
            if dev.is_nan() || dev > tol {
                failures.push(format!("{name} at {row:?}: {got} vs {want} (|Δ| = {dev})"));
            }
        }
    }
    println!(
        "worst deviation from the WMM2025 test values over {} rows:",
        rows.len()
    );
    for ((name, tol), w) in QUANTITIES.iter().zip(worst) {
        println!("  {name:<14} {w:.4}  (tolerance {tol})");
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
