//! A refusal names the number that was wrong in a form that reads at a glance: a track or a
//! timestamp of 1e308 shows as `1e308`, not as 309 digits.

use truenorth_core::WheelSample;
use truenorth_odometer::{
    DifferentialOdometer, DifferentialOdometerConfig, FixedTrack, OdometerWheels, WheelGeometry,
};

fn short(m: &str) -> bool {
    println!("{m}");
    assert!(m.len() < 300 && !m.contains("0000000000"), "{m}");
    m.contains("1e308")
}

#[test]
fn a_refusal_of_1e308_is_short() {
    let e = WheelGeometry::new(OdometerWheels::Rear { track_m: 1e308 }).unwrap_err();
    assert!(short(&e.to_string()));
    let mut odo = DifferentialOdometer::new(
        FixedTrack::new(1.5).unwrap(),
        DifferentialOdometerConfig::default(),
    )
    .unwrap();
    let s = |t_s: f64| WheelSample {
        t_s,
        dist_l_m: 0.0,
        dist_r_m: 0.0,
    };
    odo.push(&s(1e308)).unwrap();
    let e = odo.push(&s(0.0)).unwrap_err();
    assert!(short(&e.to_string()));
}
