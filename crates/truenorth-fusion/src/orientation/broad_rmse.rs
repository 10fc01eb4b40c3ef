//! The BROAD benchmark's score of an attitude series (Laidig, Caruso, Cereatti & Seel,
//! *Data* 6(7):72, 2021, and its `example_code/broad_utils.py`): per sample the total,
//! heading and inclination error angles of [`AttitudeError`]; per trial the RMSE of each over
//! the samples of the movement phase whose reference is valid; per group of trials the mean
//! of the trial RMSEs. There is no alignment step: the references are already expressed in
//! the estimate's frame (ENU, magnetic north), heading included.

use nalgebra::UnitQuaternion;
use serde::Serialize;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

use super::AttitudeError;

/// RMSE of the error angles of one trial, or the mean of several trials' RMSEs, degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BroadRmse {
    /// Total error angle.
    pub total_deg: f64,
    /// Heading error (rotation about the vertical).
    pub heading_deg: f64,
    /// Inclination error.
    pub inclination_deg: f64,
}

impl BroadRmse {
    /// The mean of trial RMSEs, each figure separately (BROAD's group value); `None` for no
    /// trial.
    pub fn mean<'a>(trials: impl IntoIterator<Item = &'a BroadRmse> + Clone) -> Option<Self> {
        let n = trials.clone().into_iter().count();
        (n > 0).then(|| {
            let mean = |f: fn(&BroadRmse) -> f64| {
                trials.clone().into_iter().map(f).sum::<f64>() / n as f64
            };
            Self {
                total_deg: mean(|r| r.total_deg),
                heading_deg: mean(|r| r.heading_deg),
                inclination_deg: mean(|r| r.inclination_deg),
            }
        })
    }
}

/// BROAD's per-trial score of `estimate` against `reference` (both body → ENU with magnetic
/// north, one per sample; `None` where the reference is invalid) over the samples whose
/// `movement` flag is set; `None` when no sample is scored.
pub fn broad_rmse(
    estimate: &[UnitQuaternion<f64>],
    reference: &[Option<UnitQuaternion<f64>>],
    movement: &[bool],
) -> Option<BroadRmse> {
    let mut sum = [0.0; 3];
    let mut n = 0usize;
    for ((q, r), &m) in estimate.iter().zip(reference).zip(movement) {
        let (Some(r), true) = (r, m) else {
            continue;
        };
        let e = AttitudeError::between(q, r);
        for (s, x) in sum
            .iter_mut()
            .zip([e.total_rad, e.heading_rad, e.inclination_rad])
        {
            *s += x * x;
        }
        n += 1;
    }
    (n > 0).then(|| {
        let rms = |s: f64| (s / n as f64).sqrt().to_degrees();
        BroadRmse {
            total_deg: rms(sum[0]),
            heading_deg: rms(sum[1]),
            inclination_deg: rms(sum[2]),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn only_scored_samples_count() {
        let q = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.1);
        let id = UnitQuaternion::identity();
        let r = broad_rmse(
            &[q, id, q],
            &[Some(id), Some(id), None],
            &[false, true, true],
        )
        .unwrap();
        assert_eq!(r.total_deg, 0.0);
        assert!(broad_rmse(&[q], &[Some(id)], &[false]).is_none());
    }

    #[test]
    fn a_constant_heading_error_is_all_heading_and_the_mean_is_per_figure() {
        let id = UnitQuaternion::identity();
        let yaw = UnitQuaternion::from_scaled_axis(Vector3::z() * 0.2);
        let tilt = UnitQuaternion::from_scaled_axis(Vector3::x() * 0.1);
        let h = broad_rmse(&[yaw, yaw], &[Some(id); 2], &[true; 2]).unwrap();
        assert!((h.heading_deg - 0.2f64.to_degrees()).abs() < 1e-9);
        assert!((h.total_deg - h.heading_deg).abs() < 1e-9 && h.inclination_deg < 1e-9);
        let i = broad_rmse(&[tilt], &[Some(id)], &[true]).unwrap();
        let m = BroadRmse::mean(&[h, i]).unwrap();
        assert!((m.heading_deg - (h.heading_deg + i.heading_deg) / 2.0).abs() < 1e-12);
        assert!((m.inclination_deg - (h.inclination_deg + i.inclination_deg) / 2.0).abs() < 1e-12);
        assert!(BroadRmse::mean(&[]).is_none());
    }
}
