//! The vehicle estimator on a real car as its CAN bus gives it: the smartLoc "Berlin
//! Potsdamer Platz" drive (`../shared/data/vehicle_smartloc_berlin/`: one vehicle speed and
//! the ESP's yaw rate at about 5 Hz, 283 s, 1.55 km, starting in motion, GNSS/INS truth).
//!
//! Beside it, plain integration on the same rows: the raw yaw rate (no bias: the car starts
//! in motion) times the speed's distance. The estimator measures the bias at each stop of
//! half a second or more, which plain integration does not. Both tracks are
//! compared with the truth after one rotation about the start, which is what a heading
//! relative to the start allows. Held: the fused track no worse than the plain one, and the
//! heading error beyond 3σ on at most 2 % of rows, never beyond 6σ. The figures:
//! `cargo test -p truenorth-fusion --test vehicle_smartloc -- --nocapture`.

use std::path::Path;

use truenorth_core::{HeadingEstimator, VehicleSample, angle_diff};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};

/// The reference course's own uncertainty, rad (1°): a ±1 s central difference of a
/// GNSS/INS track at 1 m/s or more, centimetres over two metres or more, and the
/// vehicle's sideslip, which turns the course away from the heading in a bend.
const COURSE_SIGMA_RAD: f64 = 0.017_453_292_519_943_295;

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    (header, rows)
}

fn col(header: &[String], name: &str) -> usize {
    header.iter().position(|h| h == name).unwrap()
}

#[test]
fn a_cars_speed_and_yaw_rate_never_worse_than_plain_integration() {
    let Some(dir) = truenorth_sim::shared_data::folder("vehicle_smartloc_berlin").unwrap() else {
        return;
    };
    let (h, drive) = read_csv(&dir.join("DRIVE.csv"));
    let (t_i, v_i, g_i) = (col(&h, "t_s"), col(&h, "speed_mps"), col(&h, "gyr_z"));
    let (rh, reference) = read_csv(&dir.join("REFERENCE.csv"));
    let (n_i, e_i, c_i) = (
        col(&rh, "north_m"),
        col(&rh, "east_m"),
        col(&rh, "course_deg"),
    );
    assert_eq!(
        drive.len(),
        reference.len(),
        "the two files share their time stamps"
    );

    // The speed integrated by the trapezoid rule, as `drive` integrates `speed_mps`.
    let mut dist = 0.0;
    let samples: Vec<VehicleSample> = drive
        .iter()
        .enumerate()
        .map(|(k, r)| {
            if k > 0 {
                let p = &drive[k - 1];
                dist += 0.5 * (r[v_i] + p[v_i]) * (r[t_i] - p[t_i]);
            }
            VehicleSample::at(r[t_i])
                .with_distance(dist)
                .with_gyro(r[g_i])
        })
        .collect();

    let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
    let estimates: Vec<_> = samples.iter().map(|s| nav.update(s).unwrap()).collect();
    // Plain integration of the raw rate.
    let (mut psi, mut north, mut east) = (0.0, 0.0, 0.0);
    let mut plain = vec![(0.0, 0.0, 0.0)];
    for k in 1..samples.len() {
        let (a, b) = (&samples[k - 1], &samples[k]);
        let psi_mid = psi + 0.25 * (a.gyr_z_rps.unwrap() + b.gyr_z_rps.unwrap()) * (b.t_s - a.t_s);
        psi += 0.5 * (a.gyr_z_rps.unwrap() + b.gyr_z_rps.unwrap()) * (b.t_s - a.t_s);
        let ds = b.dist_m.unwrap() - a.dist_m.unwrap();
        north += ds * psi_mid.cos();
        east += ds * psi_mid.sin();
        plain.push((psi, north, east));
    }

    let truth: Vec<(f64, f64)> = reference.iter().map(|r| (r[n_i], r[e_i])).collect();
    let fused_track: Vec<(f64, f64)> = estimates.iter().map(|e| (e.north_m, e.east_m)).collect();
    let plain_track: Vec<(f64, f64)> = plain.iter().map(|p| (p.1, p.2)).collect();
    let (fused_rms, fused_final) =
        truenorth_sim::rotated_track_errors(&fused_track, &truth).unwrap();
    let (plain_rms, plain_final) =
        truenorth_sim::rotated_track_errors(&plain_track, &truth).unwrap();
    let distance = dist;

    // Heading against the course over ground (moving rows only), after the one constant
    // offset a relative heading allows: the start heading, from the first second of course.
    let moving: Vec<usize> = (0..reference.len())
        .filter(|&k| reference[k][c_i].is_finite())
        .collect();
    let course = |k: usize| reference[k][c_i].to_radians();
    let offset = {
        let (s, c) = moving.iter().take(5).fold((0.0, 0.0), |(s, c), &k| {
            let d = course(k) - estimates[k].heading.rad();
            (s + d.sin(), c + d.cos())
        });
        s.atan2(c)
    };
    let (mut beyond, mut largest, mut sq, mut plain_sq) = (0usize, 0.0f64, 0.0, 0.0);
    for &k in &moving {
        let err = angle_diff(estimates[k].heading.rad() + offset, course(k));
        let sigma = estimates[k].heading_sigma_rad.hypot(COURSE_SIGMA_RAD);
        let z = err.abs() / sigma;
        beyond += usize::from(z > 3.0);
        largest = largest.max(z);
        sq += err * err;
        plain_sq += angle_diff(plain[k].0 + offset, course(k)).powi(2);
    }
    let share = beyond as f64 / moving.len() as f64;
    let n = moving.len() as f64;
    println!(
        "smartLoc Berlin, {distance:.0} m: fused {fused_rms:.1} m RMS, final {fused_final:.1} m ({:.2} %); plain {plain_rms:.1} m RMS, final {plain_final:.1} m ({:.2} %)",
        100.0 * fused_final / distance,
        100.0 * plain_final / distance
    );
    println!(
        "heading against the course: fused {:.2}° RMS, plain {:.2}° RMS; beyond 3σ {:.2} % of {} moving rows, largest {largest:.2}σ; final σ {:.1}°",
        (sq / n).sqrt().to_degrees(),
        (plain_sq / n).sqrt().to_degrees(),
        100.0 * share,
        moving.len(),
        estimates.last().unwrap().heading_sigma_rad.to_degrees()
    );
    // Never worse than plain integration. The estimator holds the heading at a standstill,
    // where plain integration follows the gyro, so a turn the gyro reads within five times
    // its noise at the ends of a stop (a CAN speed lags the yaw rate) is not followed:
    // before the bias was measured at the car's short stops that cost this drive 2.5 % of
    // its track error (0.37° over two stops). 5 % holds that with room for one drive's
    // noise; the hold is what keeps an unknown bias from turning a long stop into a turn.
    assert!(
        fused_rms <= 1.05 * plain_rms,
        "fused {fused_rms:.1} m vs plain {plain_rms:.1} m"
    );
    assert!(
        fused_final <= 1.05 * plain_final,
        "fused {fused_final:.1} m vs plain {plain_final:.1} m"
    );
    assert!(share <= 0.02, "{:.2} % beyond 3σ", 100.0 * share);
    assert!(largest < 6.0, "{largest:.2}σ");
}
