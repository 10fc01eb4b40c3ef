//! `truenorth drive` on a real car's CAN data as it comes: the smartLoc "Berlin Potsdamer
//! Platz" drive (`../shared/data/vehicle_smartloc_berlin/DRIVE.csv`, `t_s,speed_mps,gyr_z`
//! at about 5 Hz, starting in motion; GNSS/INS truth in `REFERENCE.csv`).
//!
//! The command's track is compared with the truth after one rotation about the start (its
//! heading is relative to the start: the car has no compass), beside plain integration of
//! the same columns computed here (the raw yaw rate times the speed's distance). Held: the
//! command's track no worse than plain integration's beyond what holding the heading at a
//! standstill costs (see `truenorth-fusion/tests/vehicle_smartloc.rs`, which holds the
//! library's figures), its heading σ kept against the reference's course, its sensors
//! named, and what the set cannot tell said.
//! `cargo test -p truenorth-cli --test smartloc -- --nocapture` prints the figures.

mod common;

use common::scratch;

#[test]
fn a_cars_speed_and_yaw_rate_as_they_come() {
    let Some(dir) = truenorth_sim::shared_data::folder("vehicle_smartloc_berlin").unwrap() else {
        return;
    };
    let work = scratch("smartloc", "drive");
    let vehicle = common::rear_vehicle(&work, 1.6);
    let out = work.join("out.csv");
    let o = common::succeeded(common::drive(
        &vehicle,
        &dir.join("DRIVE.csv"),
        &out,
        &["--extra", "sigma"],
    ));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("sensors: speed + yaw rate"), "{stderr}");
    assert!(stderr.contains("warning: no north"), "{stderr}");
    assert!(stderr.contains("warning: no gyro gain"), "{stderr}");

    let (_, rows) = common::table(&out, false);
    let (h, drive) = common::table(&dir.join("DRIVE.csv"), false);
    let (rh, reference) = common::table(&dir.join("REFERENCE.csv"), true);
    let col = |h: &[String], n: &str| h.iter().position(|x| x == n).unwrap();
    let (t_i, v_i, g_i) = (col(&h, "t_s"), col(&h, "speed_mps"), col(&h, "gyr_z"));
    let (n_i, e_i) = (col(&rh, "north_m"), col(&rh, "east_m"));
    assert_eq!(rows.len(), drive.len());

    let (mut psi, mut north, mut east, mut dist) = (0.0, 0.0, 0.0, 0.0);
    let mut plain = vec![(0.0, 0.0)];
    for k in 1..drive.len() {
        let (a, b) = (&drive[k - 1], &drive[k]);
        let dt = b[t_i] - a[t_i];
        let mid = psi + 0.25 * (a[g_i] + b[g_i]) * dt;
        psi += 0.5 * (a[g_i] + b[g_i]) * dt;
        let ds = 0.5 * (a[v_i] + b[v_i]) * dt;
        dist += ds;
        north += ds * mid.cos();
        east += ds * mid.sin();
        plain.push((north, east));
    }
    let truth: Vec<(f64, f64)> = reference.iter().map(|r| (r[n_i], r[e_i])).collect();
    let fused: Vec<(f64, f64)> = rows.iter().map(|r| (r[1], r[2])).collect();
    let (f_rms, f_final) = truenorth_sim::rotated_track_errors(&fused, &truth).unwrap();
    let (p_rms, p_final) = truenorth_sim::rotated_track_errors(&plain, &truth).unwrap();
    println!(
        "smartLoc Berlin through `drive`, {dist:.0} m: {f_rms:.1} m RMS, final {f_final:.1} m ({:.2} %); plain integration {p_rms:.1} m RMS, final {p_final:.1} m ({:.2} %)",
        100.0 * f_final / dist,
        100.0 * p_final / dist
    );
    // The heading against the reference's course (both relative to the start), on rows where
    // the car moves fast enough for the course to be the heading (over 2 m/s): its σ is a
    // promise, so few rows beyond 3σ (2 %, room for a course's own noise) and none beyond 6σ.
    let c_i = col(&rh, "course_deg");
    let (mut moving, mut beyond3, mut worst) = (0usize, 0usize, 0.0f64);
    for ((r, d), t) in rows.iter().zip(&drive).zip(&reference) {
        if d[v_i] < 2.0 {
            continue;
        }
        let truth = t[c_i] - reference[0][c_i];
        let err = (r[3] - truth + 540.0).rem_euclid(360.0) - 180.0;
        let z = err.abs() / r[4];
        moving += 1;
        beyond3 += usize::from(z > 3.0);
        worst = worst.max(z);
    }
    let share = beyond3 as f64 / moving as f64;
    println!(
        "heading on {moving} moving rows: {:.1} % beyond 3σ, worst {worst:.1}σ",
        100.0 * share
    );
    assert!(share <= 0.02, "{:.1} % beyond 3σ", 100.0 * share);
    assert!(worst < 6.0, "worst {worst:.1}σ");
    // The tolerance of `truenorth-fusion/tests/vehicle_smartloc.rs`: what the heading held at
    // a standstill can cost, with room for the noise of one drive.
    assert!(f_rms <= 1.05 * p_rms, "{f_rms:.1} m vs {p_rms:.1} m");
    assert!(
        f_final <= 1.05 * p_final,
        "{f_final:.1} m vs {p_final:.1} m"
    );
}
