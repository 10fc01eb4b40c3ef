//! The fixes' delay check on simulated drives with a real receiver's habits
//! (`truenorth_sim::log_drive::GnssConfig`: 1–10 Hz, stamped 50–500 ms after the epoch with
//! jitter and a share of later fixes, course noise, urban canyons with multipath jumps,
//! outages, frozen fixes, the antenna 0.5–2.5 m ahead of the axle): the delay found against
//! the one each drive's fixes were stamped with, less the lead the antenna's course has on
//! the heading in a turn (lever arm over speed: a course at the antenna turns before the
//! axle's), and the same fixes stamped 2 s later still (another clock, a logger's queue).
//!
//! Run: `cargo test --release -p truenorth-checks --test course_lag_drives -- --nocapture`.

use truenorth_checks::CourseLagCheck;
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

/// The warning rule of `truenorth drive`: the assumed 0.1 s refuted at 5σ and more than
/// 0.45 s (three times its 0.15 s spread) from the delay found.
fn warned(check: &CourseLagCheck) -> bool {
    let refuted = check.excess_at(0.1).is_some_and(|e| e > 25.0);
    refuted && check.lag().is_some_and(|l| (l.lag_s - 0.1).abs() > 0.45)
}

#[test]
fn the_delay_is_found_on_drives_with_a_real_receivers_habits() {
    let (mut found, mut z2, mut warned_on_time, mut warned_late, mut drives) =
        (0, Vec::new(), 0, 0, 0);
    let kind = VehicleKind::RearWheelCar;
    {
        for seed in 0..10 {
            let config = LogDriveConfig::new(seed, kind, SensorSet::WHEELS_GYRO).with_gnss();
            let d = LogDrive::new(config).unwrap();
            let samples = d.vehicle_samples();
            // The delay the fixes were stamped with: the median of stamp less epoch.
            let mut delays: Vec<f64> = samples
                .iter()
                .zip(&d.measured)
                .filter_map(|(s, m)| Some(s.t_s - m.gnss?.epoch_s))
                .filter(|x| x.is_finite() && x.abs() < 5.0)
                .collect();
            delays.sort_by(f64::total_cmp);
            let delay = delays[delays.len() / 2];
            // The antenna ahead of the axle: its course leads the heading by lever/speed.
            let lever = d.gnss.as_ref().map_or(0.0, |g| g.lever_arm_m[0]);
            let inv_v: Vec<f64> = d
                .truth
                .iter()
                .filter(|t| t.speed_mps > 3.0)
                .map(|t| 1.0 / t.speed_mps)
                .collect();
            let lead = lever * inv_v.iter().sum::<f64>() / inv_v.len().max(1) as f64;
            drives += 1;
            for (extra_s, late) in [(0.0, false), (2.0, true)] {
                let mut check = Box::new(CourseLagCheck::new());
                let rows = if late {
                    d.samples_with_fixes_late(extra_s)
                } else {
                    samples.clone()
                };
                rows.iter().for_each(|s| check.push(s));
                let said = warned(&check);
                if late {
                    warned_late += usize::from(said);
                } else {
                    warned_on_time += usize::from(said);
                }
                let Some(l) = check.lag() else {
                    println!(
                        "{kind:?} seed {seed} (+{extra_s} s): no delay told ({} pairs)",
                        check.pairs
                    );
                    continue;
                };
                let truth = delay + extra_s - lead;
                let z = (l.lag_s - truth) / l.sigma_s;
                println!(
                    "{kind:?} seed {seed} (+{extra_s} s): stamped {:.3} s late, lead {lead:.3} s, found {:.3} ± {:.3} s ({} pairs, misfit {:.2}), {z:+.2}σ{}",
                    delay + extra_s,
                    l.lag_s,
                    l.sigma_s,
                    l.pairs,
                    l.misfit,
                    if said { ", said" } else { "" }
                );
                found += 1;
                z2.push(z * z);
            }
        }
    }
    let rms_z = (z2.iter().sum::<f64>() / z2.len().max(1) as f64).sqrt();
    println!(
        "{drives} drives: a delay told {found} of {} times, RMS z {rms_z:.2}; said on time {warned_on_time}, said 2 s late {warned_late}",
        2 * drives
    );
    assert!(
        found >= 2 * drives * 3 / 4,
        "a delay told on {found} of {}",
        2 * drives
    );
    // The σ holds: every delay within 4σ of the truth, their RMS near one.
    assert!(
        z2.iter().all(|z2| *z2 < 16.0),
        "a delay beyond 4σ of the truth"
    );
    assert!(rms_z < 2.0, "the delays' σ too small: RMS z {rms_z:.2}");
    assert_eq!(
        warned_on_time, 0,
        "fixes stamped 50-500 ms late were said late"
    );
    assert!(
        warned_late >= drives * 3 / 4,
        "fixes 2 s late said on {warned_late} of {drives} drives"
    );
}
