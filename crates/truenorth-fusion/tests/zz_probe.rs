//! probe
use truenorth_core::{HeadingEstimator, angle_diff};
use truenorth_fusion::vehicle::nav_filter::*;
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

#[test]
fn probe() {
    let seed: u64 = std::env::var("SEED")
        .map(|s| s.parse().unwrap())
        .unwrap_or(0);
    let set = if std::env::var("DIST").is_ok() {
        SensorSet::WHEELS
    } else {
        SensorSet::WHEEL_SPEEDS
    };
    let d = LogDrive::new(LogDriveConfig::new(
        seed,
        VehicleKind::Differential,
        set.with_compass(),
    ))
    .unwrap();
    println!(
        "truth: lag {:.3} odo lat {:.3} compass lat {:.3} track {:?}",
        d.errors.wheel_lag_s,
        d.errors.odometry_clock.latency_s,
        d.errors.compass_clock.latency_s,
        d.vehicle.wheels
    );
    let c = VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(SensorPriors::for_wheels(&d.vehicle.wheels)),
        ..VehicleConfig::default()
    };
    let mut nav = VehicleEstimator::new(c).unwrap();
    let psi0 = d.truth[0].heading_rad;
    let mut next = 0.0;
    for (k, s) in d.vehicle_samples().iter().enumerate() {
        let e = nav.update(s).unwrap();
        let f = nav.filter();
        if s.t_s >= next {
            next += 10.0;
            let reference = if e.status.heading_absolute {
                d.truth[k].heading_rad - d.errors.declination_rad
            } else {
                d.truth[k].heading_rad - psi0
            };
            let err = angle_diff(e.heading.rad(), reference).to_degrees();
            println!(
                "t {:6.1} err {:7.2} σ {:5.2} abs {} used {} dist {} tr {:6.3}±{:.3} diff {:7.4}±{:.4} cb {:6.2}±{:.2} rate {:6.3} truth {:6.3}",
                s.t_s,
                err,
                e.heading_sigma_rad.to_degrees(),
                u8::from(e.status.heading_absolute),
                u8::from(e.status.compass_used),
                u8::from(e.status.compass_disturbed),
                f.x[TRACK_SCALE],
                f.sigma(TRACK_SCALE),
                f.x[WHEEL_DIFF],
                f.sigma(WHEEL_DIFF),
                f.x[COMPASS_BIAS].to_degrees(),
                f.sigma(COMPASS_BIAS).to_degrees(),
                0.0,
                d.truth[k].yaw_rate_rps
            );
        }
    }
}
