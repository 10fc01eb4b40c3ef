//! The yardstick a fused vehicle estimator must never fall behind: dead reckoning with the
//! gyro alone for the heading and the wheels' mean distance for the track, given the true
//! start heading.
//!
//! The gyro's bias is taken from the first standstill of at least a second, as every gyro
//! dead reckoner does at power-up; a drive that never stops has it from the wheels instead:
//! the mean gyro reading over the first two minutes' straight stretches, where the wheels
//! say the vehicle does not turn.

use truenorth_core::VehicleSample;
use truenorth_gyro::YawIncrement;

use crate::VehicleTruth;

/// Standstill that gives the bias, s.
const REST_S: f64 = 1.0;

/// Straight stretches the bias is averaged over when the drive never stops: the first this
/// many seconds.
const STRAIGHT_WINDOW_S: f64 = 120.0;

/// The wheels' heading rate below which a stretch counts as straight, rad/s (0.2°/s).
const STRAIGHT_RATE_RPS: f64 = 0.2 * core::f64::consts::PI / 180.0;

/// Final position (north, east) of gyro-times-wheels dead reckoning over `samples`, for a
/// vehicle whose wheels' track is `track_m`, starting at the true heading `truth[0]`; `None`
/// without a gyro or wheels.
pub fn gyro_wheels_final_position(
    truth: &[VehicleTruth],
    samples: &[VehicleSample],
    track_m: f64,
) -> Option<(f64, f64)> {
    let bias = rest_bias(samples).or_else(|| straight_bias(samples, track_m))?;
    let mut psi = truth.first()?.heading_rad;
    let (mut north, mut east) = (0.0, 0.0);
    let mut last_gyro: Option<(f64, f64)> = None;
    let mut last_wheels: Option<(f64, f64)> = None;
    let mut psi_at_wheels = psi;
    for s in samples {
        if let Some(g) = s.gyr_z_rps {
            if let Some((t0, g0)) = last_gyro {
                psi += YawIncrement::new(g0, g, s.t_s - t0).corrected_rad(bias, 1.0);
            }
            last_gyro = Some((s.t_s, g));
        }
        if let Some(w) = s.wheels {
            let mean = 0.5 * (w.dist_l_m + w.dist_r_m);
            if let Some((_, m0)) = last_wheels {
                let mid = 0.5 * (psi + psi_at_wheels);
                north += (mean - m0) * mid.cos();
                east += (mean - m0) * mid.sin();
            }
            psi_at_wheels = psi;
            last_wheels = Some((s.t_s, mean));
        }
    }
    last_wheels.map(|_| (north, east))
}

/// Final position error of [`gyro_wheels_final_position`], % of the distance driven.
pub fn gyro_wheels_final_error_pct(
    truth: &[VehicleTruth],
    samples: &[VehicleSample],
    track_m: f64,
) -> Option<f64> {
    let (n, e) = gyro_wheels_final_position(truth, samples, track_m)?;
    let t = truth.last()?;
    Some(100.0 * (n - t.north_m).hypot(e - t.east_m) / t.distance_m.max(f64::MIN_POSITIVE))
}

/// The mean gyro reading over the first standstill of [`REST_S`], if any.
fn rest_bias(samples: &[VehicleSample]) -> Option<f64> {
    let mut still_since: Option<f64> = None;
    let mut last = None;
    let (mut sum, mut n) = (0.0, 0u32);
    for s in samples {
        if let Some(w) = s.wheels {
            let moved = last.is_some_and(|l: (f64, f64)| l != (w.dist_l_m, w.dist_r_m));
            last = Some((w.dist_l_m, w.dist_r_m));
            if moved {
                if still_since.is_some_and(|t0| s.t_s - t0 >= REST_S) && n > 0 {
                    return Some(sum / f64::from(n));
                }
                still_since = None;
                (sum, n) = (0.0, 0);
            } else {
                still_since.get_or_insert(s.t_s);
            }
        }
        if let (Some(g), Some(_)) = (s.gyr_z_rps, still_since) {
            sum += g;
            n += 1;
        }
    }
    None
}

/// The mean gyro reading over the straight stretches of the first
/// [`STRAIGHT_WINDOW_S`], if any.
fn straight_bias(samples: &[VehicleSample], track_m: f64) -> Option<f64> {
    let t0 = samples.first()?.t_s;
    let mut last: Option<(f64, f64, f64)> = None;
    let mut straight = false;
    let (mut sum, mut n) = (0.0, 0u32);
    for s in samples
        .iter()
        .take_while(|s| s.t_s - t0 <= STRAIGHT_WINDOW_S)
    {
        if let Some(w) = s.wheels {
            if let Some((tl, l, r)) = last {
                let rate = ((w.dist_l_m - l) - (w.dist_r_m - r)) / track_m / (s.t_s - tl);
                straight = rate.abs() < STRAIGHT_RATE_RPS && w.dist_l_m != l;
            }
            last = Some((s.t_s, w.dist_l_m, w.dist_r_m));
        }
        if let (Some(g), true) = (s.gyr_z_rps, straight) {
            sum += g;
            n += 1;
        }
    }
    (n > 0).then(|| sum / f64::from(n))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RangeDrive, RangeSpec, VehicleKind};

    /// Readings made from the truth: a gyro off by `bias` only, and exact wheels.
    fn ideal(d: &RangeDrive, bias: f64, track_m: f64) -> Vec<VehicleSample> {
        let psi0 = d.truth[0].heading_unwrapped_rad;
        d.truth
            .iter()
            .map(|t| {
                let turned = 0.5 * track_m * (t.heading_unwrapped_rad - psi0);
                VehicleSample::at(t.t_s)
                    .with_gyro(t.yaw_rate_rps + bias)
                    .with_wheels(t.distance_m + turned, t.distance_m - turned)
            })
            .collect()
    }

    #[test]
    fn the_baseline_learns_the_bias_and_follows_the_truth() {
        let d = RangeDrive::new(RangeSpec::new(1, VehicleKind::RearWheelCar)).unwrap();
        let track_m = d.vehicle.wheels.track_m();
        let samples = ideal(&d, 0.02, track_m);
        // Range drives start with a stop: the bias comes from it, exactly.
        assert!((rest_bias(&samples).unwrap() - 0.02).abs() < 1e-12);
        let e = gyro_wheels_final_error_pct(&d.truth, &samples, track_m).unwrap();
        // What is left is the trapezoid rule's and the mid-step heading's, of second order
        // in the 10 ms step.
        assert!(e < 0.05, "{e}");
        // Without the stop, the straight stretches give the bias to within the turns'
        // easing at their ends.
        let moving: Vec<VehicleSample> = samples.iter().copied().filter(|s| s.t_s > 15.0).collect();
        assert!((straight_bias(&moving, track_m).unwrap() - 0.02).abs() < 1e-3);
    }
}
