//! Wheel speeds sent in quanta and integrated into distances: while the speeds hold steady
//! each wheel's rounding error holds too, and the wheels' heading drifts at a constant rate
//! — an error that grows with time, not with its square root, and that the heading's σ must
//! carry.

use truenorth_core::{HeadingEstimator, VehicleSample, angle_diff};
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_odometer::OdometerWheels;

/// A differential robot (track 0.3 m) drives 100 s on a gentle curve, side speeds 1.0004 and
/// 0.9986 m/s, which its controller sends rounded to 1 mm/s — 1.000 and 0.999: the wheels'
/// heading turns 0.15°/s slower than the robot, 15° in the 100 s (34° turned). With the quantum
/// declared the error ends within 3σ (the rounding of two wheels turns the heading at up to
/// q/T); without it, far beyond. The wheels' scale difference is known (calibrated before),
/// so nothing but the rounding moves their heading.
#[test]
fn a_held_rounding_error_is_inside_the_heading_sigma() {
    let run = |quantum: f64| {
        let wheels = OdometerWheels::Differential { track_m: 0.3 };
        let mut priors = SensorPriors::for_wheels(&wheels);
        priors.wheel_speed_quantum_mps = quantum;
        // Wheels calibrated beforehand: what is left is the speeds' rounding.
        priors.wheel_diff_sigma = 1e-6;
        let mut nav = VehicleEstimator::new(VehicleConfig {
            wheels,
            priors: Some(priors),
            ..VehicleConfig::default()
        })
        .unwrap();
        let (v_l, v_r) = (1.0004, 0.9986);
        let read = |v: f64| (v * 1000.0).round() / 1000.0;
        let rate = (v_l - v_r) / 0.3;
        let (mut d_l, mut d_r) = (0.0, 0.0);
        let mut last = None;
        for k in 0..=1000 {
            let t = 0.1 * f64::from(k);
            if k > 0 {
                d_l += read(v_l) * 0.1;
                d_r += read(v_r) * 0.1;
            }
            last = Some(
                nav.update(&VehicleSample::at(t).with_wheels(d_l, d_r))
                    .unwrap(),
            );
        }
        let e = last.unwrap();
        let truth = rate * 100.0;
        angle_diff(e.heading.rad(), truth).abs() / e.heading_sigma_rad
    };
    let declared = run(0.001);
    let undeclared = run(0.0);
    println!("error over σ: quantum declared {declared:.2}, not declared {undeclared:.1}");
    assert!(declared < 3.0, "{declared:.2}σ");
    assert!(
        undeclared > 3.0,
        "the test would not fail without the model: {undeclared:.2}σ"
    );
}
