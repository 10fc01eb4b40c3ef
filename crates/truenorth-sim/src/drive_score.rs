//! How well a vehicle estimator did on a [`SimulatedDrive`]: heading against the truth
//! where the estimator says it is referred to north, and where it ended up.

use truenorth_core::{Error, NavEstimate, Result, angle_diff};

use crate::drive::active_at;
use crate::{LogDrive, RangeDrive, SimulatedDrive, VehicleTruth};

/// The figures by which a drive's estimates are judged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveScore {
    /// Heading RMS error over the estimates referred to north, degrees (infinite if none is).
    pub heading_rms_deg: f64,
    /// The same over the estimates inside a simulated disturbance, degrees (0 if none).
    pub disturbed_rms_deg: f64,
    /// Distance between the final estimated and true positions, % of the distance driven.
    pub final_error_pct: f64,
    /// The same after dividing the estimate by the mean of the two wheels' true scale:
    /// what is left once the one error that no sensor on board can see (the mean wheel
    /// scale, which only a position reference reveals) is taken out, %.
    pub scale_removed_pct: f64,
    /// Time of the first estimate referred to north, s after the first sample (infinite
    /// if none is).
    pub absolute_from_s: f64,
}

impl SimulatedDrive {
    /// Scores `estimates`, one per sample of the drive, in order.
    pub fn score(&self, estimates: &[NavEstimate]) -> Result<DriveScore> {
        let o = self.params.odometer;
        DriveScore::of(
            &self.truth,
            estimates,
            |t| self.disturbed_at(t),
            1.0 + 0.5 * (o.scale_error_l + o.scale_error_r),
        )
    }
}

impl RangeDrive {
    /// Scores `estimates`, one per row of the drive, in order.
    pub fn score(&self, estimates: &[NavEstimate]) -> Result<DriveScore> {
        rows_score(
            self.mean_wheel_scale(),
            &self.truth,
            estimates,
            &self.disturbances,
        )
    }
}

impl LogDrive {
    /// Scores `estimates`, one per row of the drive, in order.
    pub fn score(&self, estimates: &[NavEstimate]) -> Result<DriveScore> {
        rows_score(
            self.mean_wheel_scale(),
            &self.truth,
            estimates,
            &self.disturbances,
        )
    }
}

/// [`DriveScore::of`] for a drive with `disturbances` and the odometer's mean scale
/// `wheel_scale`.
fn rows_score(
    wheel_scale: f64,
    truth: &[VehicleTruth],
    estimates: &[NavEstimate],
    disturbances: &[truenorth_compass::Disturbance],
) -> Result<DriveScore> {
    DriveScore::of(
        truth,
        estimates,
        |t| active_at(disturbances, t),
        wheel_scale,
    )
}

impl DriveScore {
    /// Scores `estimates` against `truth`, one for one: `disturbed` says when a magnetic
    /// disturbance is active, `wheel_scale` is the odometer's true mean scale.
    pub fn of(
        truth: &[VehicleTruth],
        estimates: &[NavEstimate],
        disturbed: impl Fn(f64) -> bool,
        wheel_scale: f64,
    ) -> Result<DriveScore> {
        let n_truth = truth.len() as f64;
        if estimates.len() != truth.len() || estimates.is_empty() {
            return Err(Error::OutOfRange {
                what: "number of estimates (one per sample of the drive)",
                value: estimates.len() as f64,
                min: n_truth,
                max: n_truth,
            });
        }
        let t0 = truth[0].t_s;
        let (mut sum, mut n, mut dsum, mut dn) = (0.0, 0usize, 0.0, 0usize);
        let mut absolute_from_s = f64::INFINITY;
        for (e, t) in estimates.iter().zip(truth) {
            if !e.status.heading_absolute {
                continue;
            }
            absolute_from_s = absolute_from_s.min(t.t_s - t0);
            let d = angle_diff(e.heading.rad(), t.heading_rad).to_degrees();
            sum += d * d;
            n += 1;
            if disturbed(t.t_s) {
                dsum += d * d;
                dn += 1;
            }
        }
        let (e, t) = (&estimates[estimates.len() - 1], &truth[truth.len() - 1]);
        let distance_m = t.distance_m.max(f64::MIN_POSITIVE);
        // A track never referred to north is drawn as if the start heading were north.
        let (north, east) = truth_in_frame(t, truth[0].heading_rad, e.status.heading_absolute);
        let pct = |k: f64| 100.0 * (e.north_m / k - north).hypot(e.east_m / k - east) / distance_m;
        let rms = |s: f64, n: usize| if n == 0 { 0.0 } else { (s / n as f64).sqrt() };
        Ok(DriveScore {
            heading_rms_deg: if n == 0 { f64::INFINITY } else { rms(sum, n) },
            disturbed_rms_deg: rms(dsum, dn),
            final_error_pct: pct(1.0),
            scale_removed_pct: pct(wheel_scale),
            absolute_from_s,
        })
    }
}

/// The true position `t` in the frame of an estimate: north-referred when `absolute`,
/// otherwise turned so that the start heading `heading0_rad` points north.
pub(crate) fn truth_in_frame(t: &VehicleTruth, heading0_rad: f64, absolute: bool) -> (f64, f64) {
    if absolute {
        return (t.north_m, t.east_m);
    }
    let (s, c) = heading0_rad.sin_cos();
    (c * t.north_m + s * t.east_m, -s * t.north_m + c * t.east_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::DriveSpec;
    use truenorth_core::MagneticHeading;

    fn as_estimates(d: &SimulatedDrive, heading_offset_rad: f64, scale: f64) -> Vec<NavEstimate> {
        d.truth
            .iter()
            .map(|t| {
                let mut e = NavEstimate::at_start(
                    t.t_s,
                    MagneticHeading::new(t.heading_rad + heading_offset_rad),
                    0.0,
                );
                e.north_m = scale * t.north_m;
                e.east_m = scale * t.east_m;
                e.status.heading_absolute = true;
                e
            })
            .collect()
    }

    #[test]
    fn the_truth_scores_zero_and_an_offset_scores_itself() {
        let d = SimulatedDrive::new(DriveSpec {
            length_m: 500.0,
            ..DriveSpec::new(3)
        })
        .unwrap();
        let s = d.score(&as_estimates(&d, 0.0, 1.0)).unwrap();
        assert!(s.heading_rms_deg < 1e-9 && s.final_error_pct < 1e-9);
        assert_eq!(s.absolute_from_s, 0.0);
        let s = d.score(&as_estimates(&d, 1f64.to_radians(), 1.0)).unwrap();
        assert!((s.heading_rms_deg - 1.0).abs() < 1e-9);
        // A track scaled like the wheels: the error is the scale, and it is what the
        // scale-removed figure takes out.
        let o = d.params.odometer;
        let k = 1.0 + 0.5 * (o.scale_error_l + o.scale_error_r);
        let s = d.score(&as_estimates(&d, 0.0, k)).unwrap();
        let end = d.truth.last().unwrap();
        let expect = 100.0 * (k - 1.0).abs() * end.north_m.hypot(end.east_m) / d.distance_m();
        assert!((s.final_error_pct - expect).abs() < 1e-9);
        assert!(s.scale_removed_pct < 1e-9);
        assert!(d.score(&[]).is_err());
    }
}
