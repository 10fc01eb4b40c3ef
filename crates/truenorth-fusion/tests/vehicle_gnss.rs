//! The vehicle estimator with satellite fixes, on simulated drives with a real receiver's
//! habits (time-correlated error, outages, urban canyons with multipath jumps, frozen and
//! late fixes, the antenna off the axle: `truenorth_sim::log_drive::GnssConfig`).

use truenorth_core::{HeadingEstimator, NavEstimate, angle_diff};
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_geomag::LocalTangentPlane;
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

fn config(d: &LogDrive) -> VehicleConfig {
    VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(SensorPriors::for_wheels(&d.vehicle.wheels)),
        ..VehicleConfig::default()
    }
}

/// Each estimate's position in the simulator's plane (the truth's), once referred to the
/// fixes.
fn in_truth_plane(d: &LogDrive, nav: &VehicleEstimator, e: &NavEstimate) -> Option<(f64, f64)> {
    let (lat, lon) = nav.gnss_origin()?;
    let ours = LocalTangentPlane::new(lat, lon, 0.0).ok()?;
    let g = ours.to_geodetic(e.north_m, e.east_m, 0.0).ok()?;
    let [n, e, _] = d.plane?.from_geodetic(&g);
    Some((n, e))
}

#[test]
fn fixes_hold_the_track() {
    for (kind, set) in [
        (VehicleKind::RearWheelCar, SensorSet::WHEELS_GYRO),
        (VehicleKind::RearWheelCar, SensorSet::SPEED_YAW),
        (VehicleKind::SkidSteer, SensorSet::WHEELS_GYRO),
    ] {
        for seed in 0..3 {
            let d = LogDrive::new(LogDriveConfig::new(seed, kind, set).with_gnss()).unwrap();
            let mut nav = VehicleEstimator::new(config(&d)).unwrap();
            let (mut sq, mut n, mut beyond, mut hsq, mut hn, mut hbeyond) =
                (0.0, 0usize, 0usize, 0.0, 0usize, 0usize);
            for (s, t) in d.vehicle_samples().iter().zip(&d.truth) {
                let e = nav.update(s).unwrap();
                if !nav.gnss_aligned() {
                    continue;
                }
                if let Some((pn, pe)) = in_truth_plane(&d, &nav, &e) {
                    let (dn, de) = (pn - t.north_m, pe - t.east_m);
                    sq += dn * dn + de * de;
                    n += 1;
                    let c = e.position_cov_m2;
                    let det = c[(0, 0)] * c[(1, 1)] - c[(0, 1)] * c[(1, 0)];
                    let d2 = (c[(1, 1)] * dn * dn - 2.0 * c[(0, 1)] * dn * de
                        + c[(0, 0)] * de * de)
                        / det;
                    beyond += usize::from(d2 > 11.83);
                }
                let err = angle_diff(
                    e.heading.rad() + nav.gnss_declination_rad().unwrap(),
                    t.heading_rad,
                );
                hsq += err * err;
                hn += 1;
                hbeyond += usize::from(err.abs() > 3.0 * e.heading_sigma_rad);
            }
            let c = nav.gnss_counts();
            println!(
                "{kind:?} {set:?} seed {seed}: {:.0} m; position RMS {:.2} m, beyond 3σ {:.2} %; heading RMS {:.2}°, beyond 3σ {:.2} %; fixes used {} rejected {} restarts {}",
                d.distance_m(),
                (sq / n.max(1) as f64).sqrt(),
                100.0 * beyond as f64 / n.max(1) as f64,
                (hsq / hn.max(1) as f64).sqrt().to_degrees(),
                100.0 * hbeyond as f64 / hn.max(1) as f64,
                c.used,
                c.rejected,
                c.restarts
            );
        }
    }
}
