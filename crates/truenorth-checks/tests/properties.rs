//! Properties of the checks: no panic on any input, finite or not; a recording read in its
//! own units and axes draws no finding, the same motion read in another unit or along other
//! axes draws the one that undoes it.

use nalgebra::{UnitQuaternion, Vector3};
use proptest::prelude::*;
use truenorth_checks::{
    AccUnit, Fix, GyroUnit, MagUnit, SignedPermutation, check_field, check_inertial,
};
use truenorth_core::{Axes, ImuSample};

/// A body turning about a fixed axis at a rate that swings between ½ and 1½ times `w`
/// (rad/s, body axes): its gyro, the specific force (gravity's reaction) and the Earth's field
/// in its axes, 100 Hz. (At a constant rate a gyro read 57 times too fast can turn by whole
/// revolutions more and land where the right one does.)
fn turning(w: Vector3<f64>, seconds: f64) -> Vec<ImuSample> {
    let field = Vector3::new(18.0, 1.5, 45.0);
    let up = Vector3::new(0.0, 0.0, -9.80665);
    let n = (seconds * 100.0) as usize;
    // The turn so far: ∫ w (1 + ½ sin 1.3t) dt.
    let turned = |t: f64| w * (t + 0.5 / 1.3 * (1.0 - (1.3 * t).cos()));
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.01;
            let q = UnitQuaternion::from_scaled_axis(turned(t));
            ImuSample {
                t_s: t,
                gyr_rps: Axes::xyz(w * (1.0 + 0.5 * (1.3 * t).sin())),
                acc_mps2: Axes::xyz(q.inverse() * up),
                mag: Axes::xyz(q.inverse() * field),
            }
        })
        .collect()
}

/// A cell: mostly ordinary numbers, sometimes huge, zero, NaN or infinite.
fn cell() -> impl Strategy<Value = f64> {
    prop_oneof![
        6 => -20.0f64..20.0,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(0.0),
        1 => -1e300f64..1e300,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Any readings at all, in or out of time order: findings or none, never a panic.
    #[test]
    fn no_input_makes_a_check_panic(
        cells in proptest::collection::vec(cell(), 0..900),
        gyro in prop_oneof![Just(GyroUnit::RadPerS), Just(GyroUnit::DegPerS)],
        acc in prop_oneof![Just(AccUnit::MetrePerS2), Just(AccUnit::G), Just(AccUnit::MilliG)],
    ) {
        let samples: Vec<ImuSample> = cells
            .chunks_exact(9)
            .enumerate()
            .map(|(k, c)| ImuSample {
                t_s: if c[0].is_finite() { k as f64 * 0.01 } else { c[0] },
                gyr_rps: Axes::xyz(Vector3::new(c[0], c[1], c[2])),
                acc_mps2: Axes::xyz(Vector3::new(c[3], c[4], c[5])),
                mag: Axes::xyz(Vector3::new(c[6], c[7], c[8])),
            })
            .collect();
        let _ = check_inertial(&samples, gyro, acc);
    }

    /// A turn seen in its own units and axes draws nothing; its gyro in deg/s read as rad/s
    /// is named deg/s; its gyro with x and y swapped is named with the mapping that swaps
    /// them back. (Turns of at least 1.5 rad/s: the axis check judges a mapping wrong only
    /// beyond 5° of mismatch over half a second, and a swap tilts the axis by as little as
    /// 11° here.)
    #[test]
    fn each_misreading_is_named_for_what_undoes_it(
        axis in proptest::array::uniform3(-1.0f64..1.0),
        rate in 1.5f64..3.0,
    ) {
        prop_assume!(Vector3::from(axis).norm() > 0.3);
        let w = Vector3::from(axis).normalize() * rate;
        let right = turning(w, 20.0);
        prop_assert!(check_inertial(&right, GyroUnit::RadPerS, AccUnit::MetrePerS2).is_empty());
        let degrees: Vec<ImuSample> = right
            .iter()
            .map(|s| ImuSample { gyr_rps: Axes::xyz(s.gyr_rps.as_xyz().unwrap().map(f64::to_degrees)), ..*s })
            .collect();
        let f = check_inertial(&degrees, GyroUnit::RadPerS, AccUnit::MetrePerS2);
        // Gravity's direction turns (by more than 5° in half a second) unless the turn is
        // about the vertical, where it shows no unit.
        if w.xy().norm() * 0.5 > 0.15 {
            prop_assert_eq!(f.first().map(|f| &f.fix), Some(&Fix::GyroUnit(GyroUnit::DegPerS)));
        }
        let swapped: Vec<ImuSample> = right
            .iter()
            .map(|s| {
                let g = s.gyr_rps.as_xyz().unwrap();
                ImuSample { gyr_rps: Axes::xyz(Vector3::new(g.y, g.x, g.z)), ..*s }
            })
            .collect();
        let swap = SignedPermutation { source: [1, 0, 2], sign: [1, 1, 1] };
        let f = check_inertial(&swapped, GyroUnit::RadPerS, AccUnit::MetrePerS2);
        // Only the turn's axis is seen: a mapping is told from the swap when the axis's
        // components differ in size (a turn about z alone, or with |x| = |y|, cannot).
        let [a, b, c] = [w.x.abs(), w.y.abs(), w.z.abs()];
        let distinct = (a - b).abs().min((a - c).abs()).min((b - c).abs()) > 0.2 * rate;
        if distinct && a.max(b) > 0.3 * rate {
            prop_assert_eq!(f.first().map(|f| &f.fix), Some(&Fix::GyroAxes(swap)));
        }
    }

    /// A field within the Earth's range in its declared unit draws nothing; the same
    /// field in a unit 10 to 1000 times off is named for the unit it is in.
    #[test]
    fn a_field_is_judged_in_its_unit(nt in 25_000.0f64..60_000.0) {
        prop_assert!(check_field(nt / 1e3, Some(MagUnit::MicroTesla), None, 3).is_none());
        let f = check_field(nt, Some(MagUnit::MicroTesla), None, 3).unwrap();
        let named = matches!(f.fix, Fix::MagUnit { likely: MagUnit::NanoTesla, .. });
        prop_assert!(named, "{:?}", f);
    }
}
