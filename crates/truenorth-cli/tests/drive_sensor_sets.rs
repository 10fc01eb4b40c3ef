//! `truenorth drive` with the sensor sets real vehicles have: a vehicle speed or distance
//! with a yaw rate, a speed beside wheels (not used, and said so), a speed alone (refused:
//! nothing measures the heading).

mod common;

use common::{outcome, scratch};

/// A car at 10 m/s turning right at 0.05 rad/s for 20 s, at 10 Hz, as `header` and
/// `cells(t)` write it.
fn log(header: &str, cells: impl Fn(f64) -> String) -> String {
    let mut s = format!("{header}\n");
    for k in 0..=200 {
        let t = 0.1 * k as f64;
        s += &format!("{t},{}\n", cells(t));
    }
    s
}

#[test]
fn a_speed_or_a_distance_with_a_yaw_rate_draws_the_track() {
    let dir = scratch("drive_sets", "speed");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    for (name, text) in [
        ("speed", log("t_s,speed_mps,gyr_z", |_| "10,0.05".into())),
        (
            "dist",
            log("t_s,dist_m,gyr_z", |t| format!("{},0.05", 10.0 * t)),
        ),
    ] {
        let input = dir.join(format!("{name}.csv"));
        std::fs::write(&input, text).unwrap();
        let out = dir.join(format!("{name}-out.csv"));
        let o = common::succeeded(common::drive(&vehicle, &input, &out, &[]));
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(
            stderr.contains("sensors: speed + yaw rate"),
            "{name}: {stderr}"
        );
        let (_, rows) = common::table(&out, false);
        let last = rows.last().unwrap();
        // 200 m along an arc of 1 rad and radius 200 m.
        let (n, e) = (200.0 * 1f64.sin(), 200.0 * (1.0 - 1f64.cos()));
        assert!((last[1] - n).hypot(last[2] - e) < 1.0, "{name}: {last:?}");
        assert!(
            (last[3] - 1f64.to_degrees()).abs() < 0.1,
            "{name}: {last:?}"
        );
    }
}

#[test]
fn a_speed_beside_wheels_is_said_unused() {
    let dir = scratch("drive_sets", "unused");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    let input = dir.join("both.csv");
    let text = log("t_s,dist_l_m,dist_r_m,speed_mps,gyr_z", |t| {
        format!("{},{},10,0.0", 10.0 * t, 10.0 * t)
    });
    std::fs::write(&input, text).unwrap();
    let o = common::succeeded(common::drive(&vehicle, &input, &dir.join("o.csv"), &[]));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("`speed_mps` is not used"), "{stderr}");
}

#[test]
fn a_speed_alone_is_refused_with_what_to_add() {
    let dir = scratch("drive_sets", "alone");
    let vehicle = common::rear_vehicle(&dir, 1.6);
    let input = dir.join("speed.csv");
    std::fs::write(&input, log("t_s,speed_mps", |_| "10".into())).unwrap();
    let (ok, stderr) = outcome(&common::drive(&vehicle, &input, &dir.join("o.csv"), &[]));
    assert!(!ok);
    assert!(
        stderr.contains("nothing that measures the heading"),
        "{stderr}"
    );
    assert!(stderr.contains("gyr_z"), "{stderr}");
}
