//! The patent's effective-track formula (US 4,788,645 eq. 14) and its look-up table against
//! the exact Ackermann geometry, with the tolerances measured by
//! `cargo run -p truenorth-odometer --example ackermann_error` (and printed again by
//! `cargo test -p truenorth-odometer --test patent_vs_exact -- --nocapture`).

#[path = "../examples/ackermann_error.rs"]
mod example;

use proptest::prelude::*;
use truenorth_odometer::{
    AckermannGeometry, AckermannParams, EffectiveTrack, EffectiveTrackTable, PatentAckermannTrack,
};

/// The measured error of the formula for the main vehicle (B 2.7 m, T_F 1.55 m, p 0.10 m),
/// as (largest ratio c, bound on |relative error| up to it). Measured maxima: 6.8e-5, 1.8e-3,
/// 1.26e-2, 4.06e-2, 8.9e-2; bounds sit just above them.
const MAIN_CAR_BANDS: [(f64, f64); 5] = [
    (0.10, 7.0e-5),
    (0.20, 1.9e-3),
    (0.26, 1.3e-2),
    (0.28, 4.2e-2),
    (0.2842, 9.0e-2),
];

#[test]
fn print_and_check_the_main_table() {
    example::print();
    let geometry = AckermannGeometry::new(AckermannParams {
        wheelbase_m: example::WHEELBASE_M,
        track_m: example::TRACK_M,
        kingpin_offset_m: example::KINGPIN_OFFSET_M,
    })
    .unwrap();
    let formula = PatentAckermannTrack::from_params(geometry.params()).unwrap();
    let c_max = formula.max_ratio();
    // The formula's limit lies before the geometry's, so every c up to c_max is drivable.
    assert!(c_max < geometry.peak_ratio());
    let n = 4000;
    for i in 0..=n {
        let c = c_max * i as f64 / n as f64;
        let exact = geometry.effective_track_m(c).unwrap();
        let patent = formula.effective_track_m(c).unwrap();
        let rel = (patent - exact) / exact;
        // With a kingpin offset the formula under-estimates the track, i.e. over-states the
        // turn.
        assert!(rel <= 1e-15, "c {c}: {rel}");
        let (_, bound) = MAIN_CAR_BANDS
            .iter()
            .copied()
            .find(|&(c_hi, _)| c <= c_hi)
            .unwrap();
        assert!(rel.abs() <= bound, "c {c}: |{rel}| > {bound}");
    }
    // Just past c_max the formula refuses instead of returning NaN.
    assert!(formula.effective_track_m(c_max * 1.0001).is_err());
}

/// Bands of c/c_max and the largest |relative error| measured over B 2.2-3.3 m,
/// T_F 1.3-1.8 m, p 0-0.12 m (maxima 4.6e-5, 4.3e-4, 2.3e-3, 5.3e-3, 1.36e-2, 2.5e-2, all at
/// the short-wide-long-arm corner B 2.2, T_F 1.3, p 0.12).
const GENERAL_BANDS: [(f64, f64); 6] = [
    (0.3, 5.0e-5),
    (0.5, 4.5e-4),
    (0.7, 2.5e-3),
    (0.8, 5.6e-3),
    (0.9, 1.43e-2),
    (0.95, 2.6e-2),
];

proptest! {
    #[test]
    fn patent_is_within_the_measured_tolerance_for_any_car(
        b in 2.2f64..3.3, t in 1.3f64..1.8, p in 0.0f64..0.12, u in 0.0f64..0.95,
    ) {
        let params = AckermannParams { wheelbase_m: b, track_m: t, kingpin_offset_m: p };
        let g = AckermannGeometry::new(params).unwrap();
        let f = PatentAckermannTrack::from_params(&params).unwrap();
        let c = u * f.max_ratio();
        // Without an offset the geometry may peak a little before the formula's limit.
        prop_assume!(c <= g.peak_ratio());
        let exact = g.effective_track_m(c).unwrap();
        let rel = (f.effective_track_m(c).unwrap() - exact) / exact;
        let (_, bound) = GENERAL_BANDS.iter().copied().find(|&(hi, _)| u <= hi).unwrap();
        prop_assert!(rel.abs() <= bound, "u {u}: |{rel}| > {bound}");
    }

    /// Both the formula and the exact track are below the nominal track and fall with |c|.
    #[test]
    fn effective_track_falls_with_curvature(
        b in 2.2f64..3.3, t in 1.3f64..1.8, p in 0.0f64..0.12, u1 in 0.0f64..1.0, u2 in 0.0f64..1.0,
    ) {
        let params = AckermannParams { wheelbase_m: b, track_m: t, kingpin_offset_m: p };
        let g = AckermannGeometry::new(params).unwrap();
        let f = PatentAckermannTrack::from_params(&params).unwrap();
        let (lo, hi) = if u1 < u2 { (u1, u2) } else { (u2, u1) };
        prop_assume!(hi - lo > 1e-6);
        for src in [&g as &dyn EffectiveTrack, &f] {
            let m = src.max_ratio().min(g.peak_ratio()).min(f.max_ratio());
            let a = src.effective_track_m(lo * m).unwrap();
            let z = src.effective_track_m(-hi * m).unwrap();
            prop_assert!(z < a, "{z} !< {a}");
            prop_assert!(a <= t && z < t);
        }
    }

    /// Look-up tables agree with the formula: 256 entries within 7.5e-7 for c ≤ 0.5 c_max
    /// and 8e-6 for c ≤ 0.9 c_max, and within 9.1e-3 up to c_max, where the root's
    /// unbounded slope makes the last cell the worst (measured 7.25e-7, 7.81e-6, 9.08e-3);
    /// 64 entries within 1.2e-5, 1.25e-4 and 1.8e-2 (measured 1.19e-5, 1.22e-4, 1.80e-2).
    #[test]
    fn lookup_table_agrees_with_the_formula(u in 0.0f64..=1.0, neg in any::<bool>()) {
        let f = PatentAckermannTrack::new(example::WHEELBASE_M, example::TRACK_M,
                                          2.0 * example::KINGPIN_OFFSET_M / example::TRACK_M).unwrap();
        let t256 = EffectiveTrackTable::<256>::build(&f, f.max_ratio()).unwrap();
        let t64 = EffectiveTrackTable::<64>::build(&f, f.max_ratio()).unwrap();
        let c = if neg { -u } else { u } * f.max_ratio();
        let want = f.effective_track_m(c).unwrap();
        let bands256 = [(0.5, 7.5e-7), (0.9, 8.0e-6), (1.0, 9.1e-3)];
        let bands64 = [(0.5, 1.2e-5), (0.9, 1.25e-4), (1.0, 1.8e-2)];
        for (got, bands) in [(t256.effective_track_m(c).unwrap(), bands256), (t64.effective_track_m(c).unwrap(), bands64)] {
            let rel = ((got - want) / want).abs();
            let (_, bound) = bands.iter().copied().find(|&(hi, _)| u <= hi).unwrap();
            prop_assert!(rel <= bound, "u {u}: {rel} > {bound}");
        }
    }

    /// The table reproduces its source exactly at the grid points.
    #[test]
    fn table_is_exact_at_its_entries(i in 0usize..64) {
        let g = AckermannGeometry::new(AckermannParams {
            wheelbase_m: 2.7, track_m: 1.55, kingpin_offset_m: 0.1,
        }).unwrap();
        let t = EffectiveTrackTable::<64>::build(&g, 0.28).unwrap();
        let c = t.step() * i as f64;
        let want = g.effective_track_m(c.min(0.28)).unwrap();
        prop_assert!((t.effective_track_m(c.min(0.28)).unwrap() - want).abs() < 1e-12);
    }

    #[test]
    fn no_panic_on_any_ratio(c in proptest::num::f64::ANY) {
        let f = PatentAckermannTrack::new(2.7, 1.55, 0.129).unwrap();
        let t = EffectiveTrackTable::<32>::build(&f, f.max_ratio()).unwrap();
        let ok = c.is_finite() && c.abs() <= f.max_ratio();
        prop_assert_eq!(f.effective_track_m(c).is_ok(), ok);
        prop_assert_eq!(t.effective_track_m(c).is_ok(), ok);
        if let Ok(x) = f.effective_track_m(c) { prop_assert!(x.is_finite() && x > 0.0); }
    }
}

#[test]
fn table_and_formula_refuse_bad_construction() {
    let f = PatentAckermannTrack::new(2.7, 1.55, 0.129).unwrap();
    assert!(EffectiveTrackTable::<1>::build(&f, 0.2).is_err());
    let t = EffectiveTrackTable::<16>::build(&f, 0.2).unwrap();
    assert!(t.effective_track_m(0.2).is_ok());
    assert!(t.effective_track_m(-0.200_001).is_err());
    assert!(EffectiveTrackTable::<16>::build(&f, 0.0).is_err());
    assert!(EffectiveTrackTable::<16>::build(&f, 0.3).is_err());
    assert!(EffectiveTrackTable::<16>::build(&f, f64::NAN).is_err());
    assert!(PatentAckermannTrack::new(2.7, 1.55, 1.0).is_err());
    assert!(PatentAckermannTrack::new(0.0, 1.55, 0.1).is_err());
    assert!(PatentAckermannTrack::new(2.7, f64::INFINITY, 0.1).is_err());
}
