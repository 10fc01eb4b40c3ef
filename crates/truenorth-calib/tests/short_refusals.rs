//! A refusal names the number that was wrong in a form that reads at a glance: a reading or
//! a timestamp of 1e308 shows as `1e308`, not as 309 digits.

use nalgebra::Vector2;
use truenorth_calib::{
    BinnedEllipseCalibrator, EllipseCalibrator, MeritCircleCalibrator, OnlineEllipseCalibrator,
    TurnCompassCalibrator,
};
use truenorth_core::{Calibrator, Mag2Sample};

/// Every refusal of `c` on samples carrying 1e308 (as a time, forward and back, and as a
/// reading).
fn refusals<C: Calibrator<Sample = Mag2Sample>>(mut c: C) -> Vec<String> {
    let s = |t_s: f64, x: f64| Mag2Sample {
        t_s,
        mag: Vector2::new(x, 1.0),
    };
    let mut out = Vec::new();
    for sample in [s(0.0, 20.0), s(1e308, 20.0), s(1.0, 20.0), s(2.0, 1e308)] {
        if let Err(e) = c.push(&sample) {
            out.push(e.to_string());
        }
    }
    out
}

#[test]
fn a_refusal_of_1e308_is_short() {
    let all = [
        refusals(EllipseCalibrator::default()),
        refusals(OnlineEllipseCalibrator::new(Default::default()).unwrap()),
        refusals(BinnedEllipseCalibrator::default()),
        refusals(MeritCircleCalibrator::default()),
        refusals(TurnCompassCalibrator::default()),
    ];
    let mut named = 0;
    for m in all.iter().flatten() {
        println!("{m}");
        assert!(m.len() < 300, "{m}");
        assert!(!m.contains("0000000000"), "{m}");
        named += usize::from(m.contains("1e308"));
    }
    assert!(named > 0, "no refusal named the value: {all:?}");
}
