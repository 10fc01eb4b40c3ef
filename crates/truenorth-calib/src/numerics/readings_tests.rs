//! The fits through readings cut into runs give the fits of one slice, bit for bit; a
//! replay that fails fails the fit with its own error.

use core::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Matrix2, Matrix3, SVector, Vector2, Vector3};
use proptest::prelude::*;
use truenorth_core::{Calibrator, Error, Mag2Sample, Mag3Sample, Result};

use crate::fits::ellipse::{EllipseCalibrator, EllipseConfig, fit_ellipse, fit_ellipse_readings};
use crate::fits::ellipsoid::{
    EllipsoidCalibrator, EllipsoidConfig, fit_ellipsoid, fit_ellipsoid_readings,
};
use crate::numerics::readings::{READINGS_RUN_MULTIPLE, ReadingStore, Readings};

/// Readings replayed in runs of the given numbers of [`READINGS_RUN_MULTIPLE`] (cycled),
/// failing on replay number `fail_at` (counting from 0) after its first run, if given.
#[derive(Debug, Default)]
pub(crate) struct Cut<const D: usize> {
    pub points: Vec<SVector<f64, D>>,
    pub runs: Vec<usize>,
    pub fail_at: Option<usize>,
    pub replays: AtomicUsize,
}

impl<const D: usize> Clone for Cut<D> {
    fn clone(&self) -> Self {
        Self {
            points: self.points.clone(),
            runs: self.runs.clone(),
            fail_at: self.fail_at,
            replays: AtomicUsize::new(self.replays.load(Ordering::Relaxed)),
        }
    }
}

/// The error a failing [`Cut`] gives.
pub(crate) const FAILED: Error = Error::ReadingsUnavailable {
    reason: "test replay failure",
};

impl<const D: usize> Readings<D> for Cut<D> {
    fn len(&self) -> usize {
        self.points.len()
    }

    fn replay(&self, run: &mut dyn FnMut(&[SVector<f64, D>])) -> Result<()> {
        let k = self.replays.fetch_add(1, Ordering::Relaxed);
        let mut rest = self.points.as_slice();
        for &blocks in self.runs.iter().cycle() {
            if rest.is_empty() {
                break;
            }
            let (head, tail) = rest.split_at((blocks * READINGS_RUN_MULTIPLE).min(rest.len()));
            run(head);
            if self.fail_at == Some(k) {
                return Err(FAILED);
            }
            rest = tail;
        }
        Ok(())
    }
}

impl<const D: usize> ReadingStore<D> for Cut<D> {
    fn push(&mut self, reading: SVector<f64, D>) -> Result<()> {
        self.points.push(reading);
        Ok(())
    }

    fn clear(&mut self) {
        self.points.clear();
    }
}

/// A noisy ellipse arc of `n` readings over `arc_deg` (deterministic pseudo-noise).
fn arc_2d(n: usize, arc_deg: f64, noise: f64, tilt: f64) -> Vec<Vector2<f64>> {
    let soft = Matrix2::new(1.2, tilt, tilt, 0.85);
    (0..n)
        .map(|k| {
            let psi = (arc_deg * k as f64 / n as f64).to_radians();
            let wobble = noise * ((k as f64 * 12.9898).sin() * 43_758.545).fract();
            Vector2::new(7.0, -3.0) + soft * Vector2::new(psi.cos(), psi.sin()) * (25.0 + wobble)
        })
        .collect()
}

/// `n` readings over a cap of the sphere of half-angle `cap_deg` (deterministic pseudo-noise).
fn cap_3d(n: usize, cap_deg: f64, noise: f64) -> Vec<Vector3<f64>> {
    let soft = Matrix3::new(1.1, 0.05, -0.02, 0.05, 0.95, 0.04, -0.02, 0.04, 1.02);
    let golden = core::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let zmin = cap_deg.to_radians().cos();
    (0..n)
        .map(|k| {
            let z = 1.0 - (1.0 - zmin) * (k as f64 + 0.5) / n as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            let wobble = noise * ((k as f64 * 78.233).sin() * 43_758.545).fract();
            Vector3::new(0.3, -0.7, 0.2) + soft * Vector3::new(r * c, r * s, z) * (50.0 + wobble)
        })
        .collect()
}

fn runs() -> impl Strategy<Value = Vec<usize>> {
    proptest::collection::vec(1usize..6, 1..5)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The ellipse fit (refusals included) through runs is the fit of the slice, bit for
    /// bit (compared through `Debug`, which writes every `f64` so that it reads back
    /// exactly).
    #[test]
    fn ellipse_through_runs_is_the_slice_fit(
        n in 3usize..1500, arc in 20.0f64..400.0, noise in 0.0f64..3.0, tilt in -0.2f64..0.2,
        runs in runs(),
    ) {
        let points = arc_2d(n, arc, noise, tilt);
        let config = EllipseConfig::default();
        let cut = Cut { points: points.clone(), runs, ..Cut::default() };
        let want = format!("{:?}", fit_ellipse(&points, &config));
        prop_assert_eq!(format!("{:?}", fit_ellipse_readings(&cut, &config)), want.clone());
        // And the calibrator with its own store, `progress` included.
        let mut cal = EllipseCalibrator::with_store(config, cut.clone()).unwrap();
        let mut plain = EllipseCalibrator::new(config).unwrap();
        for (k, mag) in points.iter().enumerate() {
            let s = Mag2Sample { t_s: k as f64, mag: *mag };
            cal.push(&s).unwrap();
            plain.push(&s).unwrap();
        }
        prop_assert_eq!(format!("{:?}", cal.solve()), want);
        prop_assert_eq!(format!("{:?}", cal.progress()), format!("{:?}", plain.progress()));
    }

    /// The ellipsoid fit (refusals included) through runs is the fit of the slice, bit for
    /// bit.
    #[test]
    fn ellipsoid_through_runs_is_the_slice_fit(
        n in 5usize..1500, cap in 30.0f64..180.0, noise in 0.0f64..4.0, runs in runs(),
    ) {
        let points = cap_3d(n, cap, noise);
        let config = EllipsoidConfig::default();
        let cut = Cut { points: points.clone(), runs, ..Cut::default() };
        let want = format!("{:?}", fit_ellipsoid(&points, &config));
        prop_assert_eq!(format!("{:?}", fit_ellipsoid_readings(&cut, &config)), want.clone());
        let mut cal = EllipsoidCalibrator::with_store(config, cut.clone()).unwrap();
        let mut plain = EllipsoidCalibrator::new(config).unwrap();
        for (k, mag) in points.iter().enumerate() {
            let s = Mag3Sample { t_s: k as f64, mag: *mag };
            cal.push(&s).unwrap();
            plain.push(&s).unwrap();
        }
        prop_assert_eq!(format!("{:?}", cal.solve()), want);
        prop_assert_eq!(format!("{:?}", cal.progress()), format!("{:?}", plain.progress()));
    }

    /// A replay that fails, whichever pass it is, fails the fit with its error.
    #[test]
    fn a_failed_replay_is_the_error(
        n in 200usize..800, arc in 60.0f64..400.0, noise in 0.0f64..3.0, fail_at in 0usize..40,
        runs in runs(),
    ) {
        let points = arc_2d(n, arc, noise, 0.1);
        let cut = Cut { points: points.clone(), runs: runs.clone(), ..Cut::default() };
        let config = EllipseConfig::default();
        let _ = fit_ellipse_readings(&cut, &config);
        let passes = cut.replays.load(Ordering::Relaxed);
        let failing = Cut { points, runs, fail_at: Some(fail_at), ..Cut::default() };
        let got = fit_ellipse_readings(&failing, &config);
        if fail_at < passes {
            prop_assert_eq!(got, Err(FAILED));
        }

        let points = cap_3d(n, arc.min(180.0), noise);
        let cut = Cut { points: points.clone(), runs: vec![1, 2], ..Cut::default() };
        let config = EllipsoidConfig::default();
        let _ = fit_ellipsoid_readings(&cut, &config);
        let passes = cut.replays.load(Ordering::Relaxed);
        let failing = Cut { points, runs: vec![1, 2], fail_at: Some(fail_at), ..Cut::default() };
        let got = fit_ellipsoid_readings(&failing, &config);
        if fail_at < passes {
            prop_assert_eq!(got, Err(FAILED));
        }
    }
}

/// The readings come back in order, every run but the last a multiple of the run length.
#[test]
fn slices_and_vecs_replay_in_one_run() {
    let v: Vec<Vector2<f64>> = (0..100).map(|k| Vector2::new(k as f64, 0.0)).collect();
    let mut runs = Vec::new();
    v.replay(&mut |r| runs.push(r.to_vec())).unwrap();
    assert_eq!(runs, vec![v.clone()]);
    let mut none = 0;
    Vec::<Vector2<f64>>::new()
        .replay(&mut |_| none += 1)
        .unwrap();
    assert_eq!(none, 0);
}

/// Readings in one slice, three segments long, are folded on every core (see the
/// `numerics::segments` module); the same readings replayed in runs are folded on one
/// thread. (Three: with two, the merge is one addition, which rounds the same in either
/// order.) The fits agree to the bit. (On a machine with one core both take one thread;
/// the segments' own tests hold the thread count at 2, 3 and 7.)
#[test]
fn fits_on_several_threads_are_the_fits_on_one() {
    let n = 2 * crate::numerics::segments::SEGMENT + 3_000;
    let points = arc_2d(n, 400.0, 2.0, 0.1);
    let config = EllipseConfig::default();
    let cut = Cut {
        points: points.clone(),
        runs: vec![3, 1],
        ..Cut::default()
    };
    let on_threads = format!("{:?}", fit_ellipse(&points, &config));
    assert!(on_threads.starts_with("Ok"), "{on_threads}");
    assert_eq!(
        format!("{:?}", fit_ellipse_readings(&cut, &config)),
        on_threads
    );

    let points = cap_3d(n, 180.0, 2.0);
    let config = EllipsoidConfig::default();
    let cut = Cut {
        points: points.clone(),
        runs: vec![5, 2],
        ..Cut::default()
    };
    let on_threads = format!("{:?}", fit_ellipsoid(&points, &config));
    assert!(on_threads.starts_with("Ok"), "{on_threads}");
    assert_eq!(
        format!("{:?}", fit_ellipsoid_readings(&cut, &config)),
        on_threads
    );
}
