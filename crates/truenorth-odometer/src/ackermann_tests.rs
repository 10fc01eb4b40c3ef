//! Tests of the exact Ackermann geometry (a child module of `ackermann`, so that they can
//! reach its private coefficients).
use super::*;
use proptest::prelude::*;

pub(crate) fn car(p: f64) -> AckermannGeometry {
    AckermannGeometry::new(AckermannParams {
        wheelbase_m: 2.7,
        track_m: 1.55,
        kingpin_offset_m: p,
    })
    .unwrap()
}

fn geometry() -> impl Strategy<Value = AckermannGeometry> {
    (2.0f64..3.5, 1.2f64..1.9, 0.0f64..0.2).prop_map(|(b, t, p)| {
        AckermannGeometry::new(AckermannParams {
            wheelbase_m: b,
            track_m: t,
            kingpin_offset_m: p,
        })
        .unwrap()
    })
}

/// Position of a front contact point in body axes, from the steer angle alone: kingpin
/// plus p along the wheel's outboard axle direction.
fn contact_point(g: &AckermannGeometry, left: bool, steer: f64) -> (f64, f64) {
    let b = g.params.wheelbase_m;
    let p = g.params.kingpin_offset_m;
    let tk = g.coeffs.kingpin_track_m;
    if left {
        (b + p * steer.sin(), -0.5 * tk - p * steer.cos())
    } else {
        (b - p * steer.sin(), 0.5 * tk + p * steer.cos())
    }
}

proptest! {
    #[test]
    fn straight_ahead_both_wheels_travel_the_same(g in geometry(), ds in -10.0f64..10.0) {
        let w = g.wheel_paths_m(ds, 0.0).unwrap();
        prop_assert_eq!(w.left_m, ds);
        prop_assert_eq!(w.right_m, ds);
        prop_assert!((g.effective_track_at_curvature_m(0.0).unwrap() - g.params.track_m).abs() < 1e-12);
    }

    #[test]
    fn outer_wheel_is_longer_and_sides_mirror(g in geometry(), u in 1e-6f64..0.999) {
        let k = u * g.coeffs.curvature_limit_per_m;
        let right_turn = g.wheel_paths_m(1.0, k).unwrap();
        let left_turn = g.wheel_paths_m(1.0, -k).unwrap();
        prop_assert!(right_turn.left_m > right_turn.right_m);
        prop_assert!(left_turn.right_m > left_turn.left_m);
        prop_assert!((right_turn.left_m - left_turn.right_m).abs() < 1e-12);
        prop_assert!((right_turn.right_m - left_turn.left_m).abs() < 1e-12);
    }

    /// Relations derived from the geometry (law of cosines about the turn centre):
    /// with kingpin factors ρ_L = f_L − pκ, ρ_R = f_R + pκ,
    /// ρ_L² − ρ_R² = 2κT_K and ρ_L² + ρ_R² = 2(1 + (Bκ)²) + (κT_K)²/2; and the mean of
    /// the two wheels is at least the front-axle midpoint's √(1 + (Bκ)²).
    #[test]
    fn sum_and_difference_relations(g in geometry(), u in -0.999f64..0.999) {
        let k = u * g.coeffs.curvature_limit_per_m;
        let w = g.wheel_paths_m(1.0, k).unwrap();
        let (b, p, tk) = (g.params.wheelbase_m, g.params.kingpin_offset_m, g.coeffs.kingpin_track_m);
        let rl = w.left_m - p * k;
        let rr = w.right_m + p * k;
        prop_assert!((rl * rl - rr * rr - 2.0 * k * tk).abs() < 1e-12 * (1.0 + rl * rl));
        let sum_sq = 2.0 * (1.0 + (b * k).powi(2)) + (k * tk).powi(2) / 2.0;
        prop_assert!((rl * rl + rr * rr - sum_sq).abs() < 1e-12 * sum_sq);
        prop_assert!(0.5 * (w.left_m + w.right_m) >= (1.0 + (b * k).powi(2)).sqrt() - 1e-12);
        // Difference over heading change is the effective track.
        if k != 0.0 {
            let te = g.effective_track_at_curvature_m(k).unwrap();
            prop_assert!(((w.left_m - w.right_m) / k - te).abs() < 1e-9);
        }
    }

    /// Independent check by rigid-body kinematics: move the body along the arc in small
    /// steps, place each contact point from its steer angle alone, and add up the chord
    /// lengths; also check that each contact point moves along its wheel's heading (no
    /// side slip), which holds only if the steer angles are the Ackermann ones.
    #[test]
    fn paths_match_a_rigid_body_simulation(g in geometry(), u in -0.95f64..0.95, s in 0.5f64..20.0) {
        let k = u * g.coeffs.peak_curvature_per_m;
        let (dl, dr) = g.steer_angles_rad(k).unwrap();
        let n = 4000;
        let pose = |sa: f64| {
            let psi = k * sa;
            // Rear-axle centre on a circle of curvature k (north, east), heading psi.
            let (n0, e0) = if k == 0.0 { (sa, 0.0) } else { (psi.sin() / k, (1.0 - psi.cos()) / k) };
            (n0, e0, psi)
        };
        let world = |sa: f64, left: bool| {
            let (n0, e0, psi) = pose(sa);
            let (x, y) = contact_point(&g, left, if left { dl } else { dr });
            (n0 + x * psi.cos() - y * psi.sin(), e0 + x * psi.sin() + y * psi.cos())
        };
        for (left, steer, want) in [(true, dl, g.wheel_paths_m(s, k).unwrap().left_m),
                                    (false, dr, g.wheel_paths_m(s, k).unwrap().right_m)] {
            let mut len = 0.0;
            let mut prev = world(0.0, left);
            for i in 1..=n {
                let sa = s * i as f64 / n as f64;
                let cur = world(sa, left);
                let (dn, de) = (cur.0 - prev.0, cur.1 - prev.1);
                len += dn.hypot(de);
                // Wheel heading in the world: body heading plus steer angle.
                let wheel = k * (sa - 0.5 * s / n as f64) + steer;
                let side = (dn * wheel.sin() - de * wheel.cos()).abs();
                prop_assert!(side < 1e-6 * dn.hypot(de) + 1e-15, "side slip {side}");
                prev = cur;
            }
            prop_assert!((len - want).abs() < 1e-6 * want, "{len} vs {want}");
        }
    }

    #[test]
    fn effective_track_is_below_nominal_and_falls_with_curvature(
        g in geometry(), u1 in 0.0f64..0.999, u2 in 0.0f64..0.999,
    ) {
        let (a, b) = if u1 < u2 { (u1, u2) } else { (u2, u1) };
        prop_assume!(b - a > 1e-6);
        let lim = g.coeffs.curvature_limit_per_m;
        let t_a = g.effective_track_at_curvature_m(a * lim).unwrap();
        let t_b = g.effective_track_at_curvature_m(b * lim).unwrap();
        prop_assert!(t_b < t_a);
        prop_assert!(t_a <= g.params.track_m);
        prop_assert!(t_b < g.params.track_m);
        prop_assert_eq!(t_b, g.effective_track_at_curvature_m(-b * lim).unwrap());
    }

    /// ratio → curvature → ratio, and curvature → ratio → curvature on the rising branch.
    #[test]
    fn ratio_inverse_round_trips(g in geometry(), u in -1.0f64..1.0) {
        let k = u * g.coeffs.peak_curvature_per_m;
        let c = g.ratio_at_curvature(k).unwrap();
        let back = g.curvature_from_ratio(c).unwrap();
        prop_assert!((back - k).abs() < 1e-9 * g.coeffs.peak_curvature_per_m, "{back} vs {k}");
        prop_assert!((g.ratio_at_curvature(back).unwrap() - c).abs() < 1e-14);
    }

    #[test]
    fn motion_from_paths_inverts_wheel_paths(g in geometry(), u in -0.999f64..0.999, ds in -20.0f64..20.0) {
        let k = u * g.coeffs.peak_curvature_per_m;
        let w = g.wheel_paths_m(ds, k).unwrap();
        let m = g.motion_from_paths(w.left_m, w.right_m).unwrap();
        prop_assert!((m.ds_m - ds).abs() < 1e-9 * (1.0 + ds.abs()));
        prop_assert!((m.heading_change_rad - k * ds).abs() < 1e-9 * (1.0 + ds.abs()));
    }

    #[test]
    fn no_panic_on_any_input(x in proptest::num::f64::ANY, y in proptest::num::f64::ANY) {
        let g = car(0.1);
        let _ = g.wheel_paths_m(x, y);
        let _ = g.steer_angles_rad(x);
        let _ = g.effective_track_at_curvature_m(x);
        let _ = g.ratio_at_curvature(x);
        prop_assert_eq!(g.curvature_from_ratio(x).is_ok(), x.is_finite() && x.abs() <= g.peak_ratio());
        if let Ok(m) = g.motion_from_paths(x, y) {
            prop_assert!(m.ds_m.is_finite() && m.heading_change_rad.is_finite());
        }
        let _ = AckermannGeometry::new(AckermannParams { wheelbase_m: x, track_m: y, kingpin_offset_m: 0.1 });
    }
}

/// The peak search relies on c(κ) rising up to the peak and falling after it.
#[test]
fn ratio_is_single_peaked() {
    for p in [0.0, 0.05, 0.1, 0.2, 0.3, 0.5] {
        let g = car(p);
        let kp = g.coeffs.peak_curvature_per_m;
        let lim = g.coeffs.curvature_limit_per_m;
        let mut prev = -1.0;
        for i in 0..=2000 {
            let c = g.ratio_at_curvature(kp * i as f64 / 2000.0).unwrap();
            assert!(c > prev, "p {p}: not rising at step {i}");
            prev = c;
        }
        for i in 1..=2000 {
            let k = kp + (lim - kp) * 0.999_999 * i as f64 / 2000.0;
            let c = g.ratio_at_curvature(k).unwrap();
            assert!(
                c <= prev + 1e-15,
                "p {p}: not falling after the peak at {k}"
            );
            prev = c;
        }
    }
}

#[test]
fn typical_car_peak_is_beyond_a_real_lock() {
    // A 2.7 m wheelbase car turns on about a 5 m radius at the outer front wheel, about
    // 4.3 m at the rear-axle centre; the peak must lie beyond that for the inverse to
    // cover every drivable curvature.
    let g = car(0.1);
    assert!(
        g.peak_curvature_per_m() > 1.0 / 4.0,
        "{}",
        g.peak_curvature_per_m()
    );
}

#[test]
fn invalid_dimensions_are_rejected() {
    let ok = AckermannParams {
        wheelbase_m: 2.7,
        track_m: 1.55,
        kingpin_offset_m: 0.1,
    };
    for bad in [
        AckermannParams {
            wheelbase_m: 0.0,
            ..ok
        },
        AckermannParams {
            track_m: -1.0,
            ..ok
        },
        AckermannParams {
            kingpin_offset_m: 0.775,
            ..ok
        },
        AckermannParams {
            kingpin_offset_m: -0.01,
            ..ok
        },
        AckermannParams {
            track_m: f64::NAN,
            ..ok
        },
    ] {
        assert!(AckermannGeometry::new(bad).is_err(), "{bad:?}");
    }
    assert!((ok.pitman_ratio() - 0.2 / 1.55).abs() < 1e-15);
    let again = AckermannParams::from_pitman_ratio(2.7, 1.55, ok.pitman_ratio());
    assert!((again.kingpin_offset_m - 0.1).abs() < 1e-15);
}
