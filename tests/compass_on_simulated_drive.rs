//! Cross-crate: the simulator's drive → every 2-D compass calibrator → heading on the whole
//! drive, against the ground truth. The figures the demo prints are held to here.

use truenorth::Error;
use truenorth::calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, MeritCircleCalibrator, TurnCompassCalibrator,
};
use truenorth::compass::CompassCalibration2d;
use truenorth::prelude::*;
use truenorth_sim::{VehicleSensorParams, VehicleTruth, scenario, simulate, vehicle_streams};

type Boxed = Box<
    dyn Calibrator<Sample = Mag2Sample, Params = CompassCalibration2d, Quality = CompassQuality>,
>;

struct Drive {
    truth: Vec<VehicleTruth>,
    mags: Vec<Mag2Sample>,
    circle_end_s: f64,
    params: VehicleSensorParams,
}

fn drive(seed: u64) -> Drive {
    let circle = scenario::calibration_circle(12.0, 5.0, 1.25).unwrap();
    let mut route = circle.clone();
    route
        .commands
        .extend(scenario::city_blocks(4, 120.0).unwrap().commands);
    let truth = simulate(&route, 0.4, 50.0).unwrap();
    let params = VehicleSensorParams::typical();
    let mags = vehicle_streams(&truth, &params, seed)
        .unwrap()
        .into_iter()
        .map(|s| Mag2Sample {
            t_s: s.t_s,
            mag: s.mag.unwrap(),
        })
        .collect();
    Drive {
        truth,
        mags,
        circle_end_s: circle.duration_s(),
        params,
    }
}

fn heading_rms_deg(d: &Drive, cal: &CompassCalibration2d) -> f64 {
    let sum: f64 = d
        .truth
        .iter()
        .zip(&d.mags)
        .map(|(t, m)| angle_diff(cal.heading_rad(&m.mag), t.heading_rad).powi(2))
        .sum();
    (sum / d.truth.len() as f64).sqrt().to_degrees()
}

fn fit(cal: &mut Boxed, samples: &[Mag2Sample]) -> Result<Solution<CompassCalibration2d>, Error> {
    cal.reset();
    for s in samples {
        cal.push(s)?;
    }
    cal.solve()
}

#[test]
fn every_calibrator_on_a_simulated_drive() {
    for seed in [1, 2, 3] {
        let d = drive(seed);
        let true_cal = CompassCalibration2d {
            hard_iron: d.params.compass_hard_iron,
            soft_iron: d.params.compass_soft_iron.try_inverse().unwrap(),
        };
        let floor = heading_rms_deg(&d, &true_cal);
        let circle: Vec<Mag2Sample> = d
            .mags
            .iter()
            .copied()
            .filter(|m| m.t_s <= d.circle_end_s)
            .collect();

        let mut ls: Boxed = Box::<EllipseCalibrator>::default();
        let ls_sol = fit(&mut ls, &circle).unwrap();
        let ls_rms = heading_rms_deg(&d, &ls_sol.params);
        // Least squares at the noise floor: a heading errs by the reading's own noise and by
        // the calibration's error, independent of it (the fit reads the radial residual),
        // whose mean square at any heading is at most G²/N times the floor's — G the
        // dilution of the circle, N its readings — times a χ² of the 4 parameters that move
        // the heading over 4, plus a cross term of standard deviation G²/N. The limit takes
        // the 1 − 1/(200·3) points of both over the three drives (a χ²₄ of 17.3; 3σ).
        let g = truenorth::calib::quality::assess_2d(
            &circle.iter().map(|m| m.mag).collect::<Vec<_>>(),
            &ls_sol.params,
            ls_sol.quality.field_magnitude,
        )
        .quality
        .uncertainty
        .dilution;
        let g2_n = g * g / circle.len() as f64;
        let limit = floor * (1.0 + g2_n * (17.3 / 4.0 + 3.0)).sqrt();
        assert!(
            ls_rms <= limit,
            "seed {seed}: LS {ls_rms:.3} vs floor {floor:.3} (limit {limit:.3})"
        );

        let mut binned: Boxed = Box::<BinnedEllipseCalibrator>::default();
        let b_sol = fit(&mut binned, &circle).unwrap();
        let b_rms = heading_rms_deg(&d, &b_sol.params);
        // Its own report holds: the calibration's error within its bound (3σ plus the
        // systematic part), the readings' noise on top in quadrature.
        let b_limit = floor.hypot(b_sol.quality.heading_error_bound_deg());
        assert!(
            b_rms <= b_limit,
            "seed {seed}: binned ellipse {b_rms:.3} deg over {b_limit:.3}"
        );
        // And the demo's claim for it: at most 1°.
        assert!(b_rms <= 1.0, "seed {seed}: binned ellipse {b_rms:.3} deg");

        // Circle-only methods cannot remove a rotated soft iron: worse than the ellipse
        // methods, but their own quality report must own up to it.
        for mut cal in [
            Box::new(MeritCircleCalibrator::default()) as Boxed,
            Box::new(TurnCompassCalibrator::default()),
        ] {
            let sol = fit(&mut cal, &circle).unwrap();
            let rms = heading_rms_deg(&d, &sol.params);
            assert!(
                rms > 2.0 * ls_rms,
                "seed {seed}: circle method {rms:.2} unexpectedly good"
            );
            assert!(
                sol.quality.heading_error_bound_deg() >= rms,
                "seed {seed}: bound {:.2} hides an error of {rms:.2}",
                sol.quality.heading_error_bound_deg()
            );
        }
    }
}

#[test]
fn half_a_turn_is_refused_by_every_calibrator() {
    let d = drive(7);
    // The circle starts after a 5 s standstill; keep the run-up plus < 180° of turn.
    let half: Vec<Mag2Sample> = d
        .mags
        .iter()
        .zip(&d.truth)
        .filter(|(_, t)| {
            t.t_s <= d.circle_end_s && t.heading_unwrapped_rad - 0.4 < 170f64.to_radians()
        })
        .map(|(m, _)| *m)
        .collect();
    let all: [Boxed; 4] = [
        Box::new(EllipseCalibrator::default()),
        Box::new(BinnedEllipseCalibrator::default()),
        Box::new(MeritCircleCalibrator::default()),
        Box::new(TurnCompassCalibrator::default()),
    ];
    for mut cal in all {
        let r = fit(&mut cal, &half);
        assert!(r.is_err(), "a half turn was accepted: {r:?}");
    }
}

mod round_trip {
    use super::*;
    use proptest::prelude::*;
    use truenorth_sim::rotated_soft_iron;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// Model → calibration round trip across the crates: whatever the hard and soft iron,
        /// the least-squares fit on a simulated circle gives headings within a hair of the
        /// truth (noise here is 0.2 % of the field, a 0.11° floor per reading).
        #[test]
        fn least_squares_undoes_any_installation(
            hx in -1.0f64..1.0, hy in -1.0f64..1.0,
            ratio in 1.0f64..1.6, angle in 0.0f64..3.2, heading0 in -3.1f64..3.1,
            seed in any::<u64>(),
        ) {
            let field = 20.0;
            let params = VehicleSensorParams {
                compass_hard_iron: nalgebra::Vector2::new(hx, hy) * field,
                compass_soft_iron: rotated_soft_iron(ratio, 1.0, angle),
                compass_noise: 0.002 * field,
                horizontal_field: field,
                ..VehicleSensorParams::typical()
            };
            let route = scenario::calibration_circle(10.0, 5.0, 1.1).unwrap();
            let truth = simulate(&route, heading0, 20.0).unwrap();
            let mags: Vec<Mag2Sample> = vehicle_streams(&truth, &params, seed)
                .unwrap()
                .into_iter()
                .map(|s| Mag2Sample { t_s: s.t_s, mag: s.mag.unwrap() })
                .collect();
            let mut cal: Boxed = Box::<EllipseCalibrator>::default();
            let sol = fit(&mut cal, &mags).unwrap();
            let d = Drive { truth, mags, circle_end_s: route.duration_s(), params };
            let rms = heading_rms_deg(&d, &sol.params);
            // The reading's noise and the calibration's error (within its 3σ bound) in
            // quadrature, widened by 3/√(2N) for the sampling of an RMS over N headings. The
            // report's noise is the RMS over the turn; the soft iron S stretches the sensor's
            // isotropic noise by its eigenvalues, so at one heading (the drive's standstill
            // holds a few seconds at one) a reading's heading noise is up to
            // λ_max/√((λ₁² + λ₂²)/2) of that.
            let n = d.truth.len() as f64;
            let l = sol.params.soft_iron.symmetric_eigenvalues();
            let stretch = l.max() / (0.5 * (l[0] * l[0] + l[1] * l[1])).sqrt();
            let limit = (sol.quality.heading_noise_rms_deg * stretch)
                .hypot(sol.quality.heading_error_bound_deg())
                * (1.0 + 3.0 / (2.0 * n).sqrt());
            prop_assert!(rms <= limit, "heading RMS {rms:.3} deg over {limit:.3}");
            // 1.1 turns fill every 10° heading bin.
            prop_assert_eq!(sol.quality.fit.coverage, 1.0);
        }
    }
}
