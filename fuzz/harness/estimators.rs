//! Every estimator's per-sample entry point: the orientation methods (through the registry
//! the commands use, and the single-precision quaternion filter directly) and the vehicle
//! methods, on readings that the bytes move, break and reorder.

use truenorth::core::{Axes, ImuSample, VehicleSample};
use truenorth::fusion::{
    QuaternionFilter, QuaternionFilterConfig, VehicleConfig, VehicleEstimator,
};
use truenorth::nalgebra::{UnitQuaternion, Vector2, Vector3};
use truenorth::odometer::{AckermannParams, OdometerWheels};
use truenorth_cli::registry::{OrientationMethod, Timing, VehicleMethod};

use super::input::Bytes;

/// The most samples one input feeds.
const MAX_SAMPLES: usize = 4000;

/// An attitude that an accepted sample leaves: finite and of unit norm.
fn check_attitude<T: truenorth::core::Real>(q: &UnitQuaternion<T>, what: &str, s: &ImuSample) {
    let n: f64 = T::to_f64(q.as_ref().norm());
    assert!(
        n.is_finite() && (n - 1.0).abs() < 1e-5,
        "{what}: attitude norm {n} after the accepted sample {s:?}"
    );
}

/// An axis reading that is there or not, as the bytes say.
fn axes(b: &mut Bytes, present: u8, base: Vector3<f64>, scale: f64) -> Axes {
    let mut a = Axes::NONE;
    let v = if present & 0x8 != 0 {
        Vector3::new(b.f64(scale), b.f64(scale), b.f64(scale))
    } else {
        base
    };
    if present & 1 != 0 {
        a.x = Some(v.x);
    }
    if present & 2 != 0 {
        a.y = Some(v.y);
    }
    if present & 4 != 0 {
        a.z = Some(v.z);
    }
    a
}

/// One orientation method per input (the quaternion filter in `f64` and `f32`, the Euler
/// detector; with and without the magnetometer; either gyro timing), then its samples.
pub fn orientation(data: &[u8]) {
    let mut b = Bytes::new(data);
    let pick = b.byte();
    let use_mag = pick & 1 != 0;
    let timing = if pick & 2 != 0 {
        Timing::Instantaneous
    } else {
        Timing::IntervalMean
    };
    let mut t_s = 0.0;
    let mut yaw = 0.0_f64;
    let mut next = |b: &mut Bytes| {
        t_s = b.time(t_s, 0.01);
        let present = b.byte();
        let rate = f64::from(present >> 4) * 0.05;
        yaw += rate * 0.01;
        let gyr = axes(b, 0x7 | (present & 0x8), Vector3::new(0.0, 0.0, rate), 5.0);
        let acc_p = if present & 0x40 != 0 { b.byte() } else { 0x7 };
        let acc = axes(b, acc_p, Vector3::new(0.0, 0.0, -9.81), 20.0);
        let mag_p = if present & 0x80 != 0 { b.byte() } else { 0x7 };
        let mag = axes(
            b,
            mag_p,
            Vector3::new(20.0 * yaw.cos(), -20.0 * yaw.sin(), 40.0),
            60.0,
        );
        ImuSample {
            t_s,
            gyr_rps: gyr,
            acc_mps2: acc,
            mag,
        }
    };
    let method = match (pick >> 2) % 3 {
        0 => Some(OrientationMethod::Quaternion),
        1 => Some(OrientationMethod::EulerDetector),
        _ => None,
    };
    match method {
        Some(method) => {
            let Ok(mut p) = method.estimator(use_mag, timing) else {
                return;
            };
            for _ in 0..MAX_SAMPLES {
                if b.is_empty() {
                    break;
                }
                let s = next(&mut b);
                if let Ok(r) = p.update(&s) {
                    check_attitude(&r.attitude, "orientation method", &s);
                }
            }
        }
        None => {
            let config = QuaternionFilterConfig {
                use_mag,
                ..QuaternionFilterConfig::default()
            };
            let Ok(mut f) = QuaternionFilter::<f32>::with_precision(config) else {
                return;
            };
            for _ in 0..MAX_SAMPLES {
                if b.is_empty() {
                    break;
                }
                let s = next(&mut b);
                let (Some(g), a, m) = (s.gyr_rps.as_xyz(), s.acc_mps2.as_xyz(), s.mag.as_xyz())
                else {
                    continue;
                };
                let f32v = |v: Vector3<f64>| v.map(|x| x as f32);
                if f.update_readings(s.t_s, f32v(g), a.map(f32v), m.map(f32v))
                    .is_ok()
                {
                    check_attitude(&f.attitude(), "f32 quaternion filter", &s);
                }
            }
        }
    }
}

/// One vehicle method per input on one kind of odometer wheels, then its samples: wheels,
/// gyro and compass each there or not, moved, broken or reordered by the bytes.
pub fn vehicle(data: &[u8]) {
    let mut b = Bytes::new(data);
    let pick = b.byte();
    let wheels = match (pick >> 2) % 4 {
        0 => OdometerWheels::Rear { track_m: 1.5 },
        1 => OdometerWheels::Front(AckermannParams::from_pitman_ratio(2.7, 1.55, 0.1)),
        2 => OdometerWheels::SkidSteer { track_m: 0.6 },
        _ => OdometerWheels::Differential {
            track_m: b.f64(2.0),
        },
    };
    let method = [
        VehicleMethod::Fused,
        VehicleMethod::SeedOdometerCompass,
        VehicleMethod::SeedGyroCompass,
    ][usize::from(pick % 3)];
    let config = VehicleConfig {
        wheels,
        ..VehicleConfig::default()
    };
    let Ok(fused) = VehicleEstimator::new(config) else {
        return;
    };
    let Ok(mut run) = method.runner(wheels, fused, pick & 0x40 != 0) else {
        return;
    };
    let mut emit = |e: &truenorth::core::NavEstimate, _: Option<&_>| {
        assert!(
            !e.north_m.is_nan() && !e.east_m.is_nan() && !e.heading.rad().is_nan(),
            "an estimate with NaN: {e:?}"
        );
    };
    let (mut t_s, mut dist, mut yaw) = (0.0, 0.0, 0.0_f64);
    for _ in 0..MAX_SAMPLES {
        if b.is_empty() {
            break;
        }
        t_s = b.time(t_s, 0.1);
        let present = b.byte();
        let rate = f64::from(present >> 4) * 0.02 - 0.15;
        yaw += rate * 0.1;
        dist += 1.0;
        let mut s = VehicleSample::at(t_s);
        if present & 1 != 0 {
            let turn = rate * 0.1 * 0.75;
            s = if present & 8 != 0 {
                s.with_wheels(b.f64(100.0), b.f64(100.0))
            } else {
                s.with_wheels(dist - turn, dist + turn)
            };
        }
        if present & 2 != 0 {
            s = s.with_gyro(if present & 8 != 0 {
                b.f64(1.0)
            } else {
                rate + 0.01
            });
        }
        if present & 4 != 0 {
            s = s.with_mag(if present & 8 != 0 {
                Vector2::new(b.f64(100.0), b.f64(100.0))
            } else {
                Vector2::new(5.0 + 20.0 * yaw.cos(), -3.0 - 18.0 * yaw.sin())
            });
        }
        let _ = run.push(&s, &mut emit);
    }
    let _ = run.finish(&mut emit);
    let _ = run.calibration();
}
