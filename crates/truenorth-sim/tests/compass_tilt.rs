//! The compass on a tilting body: a steady roll in a circle turns a level-assumed compass's
//! heading by up to `atan(tan(dip)·sin(roll))`, grades pitch the body, and without the tilt a
//! perfect compass reads the heading exactly.

use truenorth_sim::{
    Habit, LogDrive, LogDriveConfig, SensorSet, Span, TiltConfig, VehicleKind, VehicleTruth,
};

/// A circling car with a perfect compass (no iron, no noise, no disturbances).
fn circling(seed: u64) -> LogDriveConfig {
    let mut c = LogDriveConfig::real_circling_car(seed);
    c.compass.hard_iron = Span::fixed(0.0);
    c.compass.soft_iron_ratio = Span::fixed(1.0);
    c.compass.noise = Span::fixed(0.0);
    c.compass.disturbances = false;
    c
}

/// The compass's heading error at each reading, rad, and the truth there.
fn heading_errors(d: &LogDrive) -> Vec<(f64, [f64; 2], VehicleTruth)> {
    let times: Vec<f64> = d.measured.iter().filter_map(|m| m.compass_s).collect();
    let truth = truenorth_sim::simulate_at(&d.route, d.heading0_rad, &times).unwrap();
    d.rows
        .iter()
        .zip(&d.measured)
        .filter_map(|(r, m)| Some((r.mag?, m.compass_tilt_rad.unwrap_or([0.0; 2]))))
        .zip(truth)
        .map(|((m, tilt), t)| {
            let err = (-m.y).atan2(m.x) - (t.heading_rad - d.errors.declination_rad);
            (truenorth_core::wrap_pi(err), tilt, t)
        })
        .collect()
}

#[test]
fn a_steady_roll_turns_the_heading_by_the_vertical_field() {
    for seed in 0..3 {
        let mut c = circling(seed);
        c.tilt = Some(TiltConfig {
            camber_pct: Span::fixed(0.0),
            grade_pct: Span::fixed(0.0),
            ..TiltConfig::for_car()
        });
        let d = LogDrive::new(c).unwrap();
        let e = &d.errors;
        let body = e.tilt.unwrap();
        let errors = heading_errors(&d);
        let (_, [roll, _], t) = errors[errors.len() / 2];
        // Out of the turn by the roll gradient.
        let lateral = t.speed_mps * t.yaw_rate_rps / truenorth_core::STANDARD_GRAVITY_MPS2;
        assert!((roll + body.roll_rad_per_g * lateral).abs() < 1e-12);
        // The worst error round the circle, from the field seen through a roll φ: the
        // compass reads atan2(H sin ψ cos φ − Z sin φ, H cos ψ) for a heading ψ.
        let z_over_h = e.dip_rad.tan();
        let worst_model = (0..3600)
            .map(|k| {
                let psi = f64::from(k).to_radians() / 10.0;
                let read = (psi.sin() * roll.cos() - z_over_h * roll.sin()).atan2(psi.cos());
                truenorth_core::wrap_pi(read - psi).abs()
            })
            .fold(0.0, f64::max);
        let worst = errors.iter().map(|x| x.0.abs()).fold(0.0, f64::max);
        assert!(
            (worst - worst_model).abs() < 0.02 * worst_model + 1e-4,
            "{} vs {}",
            worst.to_degrees(),
            worst_model.to_degrees()
        );
        // A degree of roll, two to four of heading at these dips.
        let per_degree = worst / roll.abs();
        assert!((1.1..4.0).contains(&per_degree), "{per_degree}");
    }
}

#[test]
fn without_the_tilt_a_perfect_compass_reads_the_heading() {
    let d = LogDrive::new(circling(1).without(Habit::CompassTilt)).unwrap();
    assert!(d.errors.tilt.is_none());
    assert!(heading_errors(&d).iter().all(|x| x.0.abs() < 1e-9));
}

#[test]
fn grades_pitch_the_body_and_the_camber_rolls_it() {
    let mut c = LogDriveConfig::new(2, VehicleKind::RearWheelCar, SensorSet::GYRO_COMPASS);
    c.motion.length_m = 6000.0;
    c.tilt = Some(TiltConfig {
        pitch_deg_per_g: Span::fixed(0.0),
        roll_deg_per_g: Span::fixed(0.0),
        grade_length_m: Span::fixed(100.0),
        ..TiltConfig::for_car()
    });
    let d = LogDrive::new(c).unwrap();
    let body = d.errors.tilt.unwrap();
    let tilts: Vec<[f64; 2]> = d
        .measured
        .iter()
        .filter_map(|m| m.compass_tilt_rad)
        .collect();
    assert!(tilts.iter().all(|t| (t[0] - body.camber_rad).abs() < 1e-12));
    let pitch_sd = (tilts.iter().map(|t| t[1] * t[1]).sum::<f64>() / tilts.len() as f64).sqrt();
    // Some 60 correlation lengths of grade: its spread within a quarter.
    let expect = body.grade_sigma.atan();
    assert!(
        (pitch_sd / expect - 1.0).abs() < 0.25,
        "{pitch_sd} vs {expect}"
    );
}

#[test]
fn the_dip_keeps_the_total_field_on_the_earth() {
    for seed in 0..40 {
        let d = LogDrive::new(LogDriveConfig {
            motion: truenorth_sim::MotionConfig {
                length_m: 50.0,
                ..truenorth_sim::MotionConfig::for_car()
            },
            ..LogDriveConfig::new(seed, VehicleKind::RearWheelCar, SensorSet::GYRO_COMPASS)
        })
        .unwrap();
        let e = &d.errors;
        let total = e.field_ut / e.dip_rad.cos();
        assert!(
            total <= 67.0 + 1e-9 && e.dip_rad.to_degrees() <= 75.0,
            "{total}"
        );
    }
}
