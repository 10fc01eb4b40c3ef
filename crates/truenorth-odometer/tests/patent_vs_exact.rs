//! The patent's effective-track formula (US 4,788,645 eq. 14) and its look-up table against
//! the exact Ackermann geometry. The formula's error is the figure the crate docs and the
//! README report (`cargo run -p truenorth-odometer --example ackermann_error`, printed again
//! by `cargo test -p truenorth-odometer --test patent_vs_exact -- --nocapture`): the tests
//! check those figures to the precision they are printed with. The table's interpolation
//! error is bounded analytically.

#[path = "../examples/ackermann_error.rs"]
mod example;

use proptest::prelude::*;
use truenorth_odometer::{
    AckermannGeometry, AckermannParams, EffectiveTrack, EffectiveTrackTable, PatentAckermannTrack,
};

/// A printed figure and the half unit of its last printed digit.
type Printed = (f64, f64);

/// The figures of the crate docs' table for the main vehicle (B 2.7 m, T_F 1.55 m,
/// p 0.10 m): ratio c, relative error of T_E and heading error on a 90° turn (degrees), each
/// with the half unit of its last printed digit as the tolerance. `None` for c_max.
const DOC_ROWS: [(Option<f64>, Printed, Printed); 8] = [
    (Some(0.04), (-1.6e-6, 0.05e-6), (0.000, 0.0005)),
    (Some(0.10), (-6.8e-5, 0.05e-5), (0.006, 0.0005)),
    (Some(0.16), (-5.6e-4, 0.05e-4), (0.05, 0.005)),
    (Some(0.20), (-1.8e-3, 0.05e-3), (0.16, 0.005)),
    (Some(0.24), (-6.0e-3, 0.05e-3), (0.55, 0.005)),
    (Some(0.26), (-1.26e-2, 0.005e-2), (1.15, 0.005)),
    (Some(0.28), (-4.1e-2, 0.05e-2), (3.8, 0.05)),
    (None, (-8.9e-2, 0.05e-2), (8.8, 0.05)),
];

/// The README's figures: relative error −2.0 % and heading error 1.9° per 90° at c = 0.27.
const README_ROW: (f64, Printed, Printed) = (0.27, (-2.0e-2, 0.05e-2), (1.9, 0.05));

fn main_car() -> (AckermannGeometry, PatentAckermannTrack) {
    let geometry = AckermannGeometry::new(AckermannParams {
        wheelbase_m: example::WHEELBASE_M,
        track_m: example::TRACK_M,
        kingpin_offset_m: example::KINGPIN_OFFSET_M,
    })
    .unwrap();
    let formula = PatentAckermannTrack::from_params(geometry.params()).unwrap();
    (geometry, formula)
}

#[test]
fn print_and_check_the_main_table() {
    example::print();
    let (geometry, formula) = main_car();
    let c_max = formula.max_ratio();
    // The formula's limit lies before the geometry's, so every c up to c_max is drivable.
    assert!(c_max < geometry.peak_ratio());
    let rel = |c: f64| {
        let exact = geometry.effective_track_m(c).unwrap();
        (formula.effective_track_m(c).unwrap() - exact) / exact
    };
    // With a kingpin offset the formula under-estimates the track, i.e. over-states the turn,
    // and its error grows with the turn: so "below x up to c" follows from the value at c.
    let n = 4000;
    let mut prev = 0.0f64;
    for i in 0..=n {
        let c = c_max * i as f64 / n as f64;
        let r = rel(c);
        assert!(r <= 1e-15, "c {c}: {r}");
        assert!(r.abs() >= prev.abs() - 1e-15, "c {c}: |{r}| < |{prev}|");
        prev = r;
    }
    let rows = DOC_ROWS
        .iter()
        .map(|&(c, e, h)| (c.unwrap_or(c_max), e, h))
        .chain([README_ROW]);
    for (c, (want_rel, tol_rel), (want_deg, tol_deg)) in rows {
        let r = rel(c);
        assert!(
            (r - want_rel).abs() <= tol_rel,
            "c {c}: {r} vs printed {want_rel}"
        );
        // Δθ ∝ 1/T_E: the formula turns 90°·(T_exact/T_patent − 1) too far.
        let heading_deg = 90.0 * (1.0 / (1.0 + r) - 1.0);
        assert!(
            (heading_deg - want_deg).abs() <= tol_deg,
            "c {c}: {heading_deg}° vs printed {want_deg}°"
        );
    }
    // Just past c_max the formula refuses instead of returning NaN.
    assert!(formula.effective_track_m(c_max * 1.0001).is_err());
}

/// The range of cars the crate docs' general claim covers: wheelbase, front track and
/// kingpin offset, m.
const CAR_BOX: [(f64, f64); 3] = [(2.2, 3.3), (1.3, 1.8), (0.0, 0.12)];

/// |relative error| of the formula at `u = c/c_max` for one car.
fn car_error(b: f64, t: f64, p: f64, u: f64) -> Option<f64> {
    let params = AckermannParams {
        wheelbase_m: b,
        track_m: t,
        kingpin_offset_m: p,
    };
    let g = AckermannGeometry::new(params).ok()?;
    let f = PatentAckermannTrack::from_params(&params).ok()?;
    let c = u * f.max_ratio();
    let exact = g.effective_track_m(c).ok()?;
    Some(((f.effective_track_m(c).ok()? - exact) / exact).abs())
}

/// The largest |relative error| at `u` over the corners of [`CAR_BOX`]. If the error is
/// monotone in each dimension (and the property below checks every car it draws against
/// this), the corners bound the whole box.
fn corner_bound(u: f64) -> f64 {
    let [(b0, b1), (t0, t1), (p0, p1)] = CAR_BOX;
    let mut worst = 0.0f64;
    for b in [b0, b1] {
        for t in [t0, t1] {
            for p in [p0, p1] {
                // A corner whose geometry peaks before u·c_max has no exact track there.
                if let Some(e) = car_error(b, t, p, u) {
                    worst = worst.max(e);
                }
            }
        }
    }
    worst
}

/// The crate docs: "the error stays below 4.5e-4 for c ≤ c_max/2 and 1.4 % for c ≤ 0.9 c_max".
#[test]
fn the_general_claim_holds_at_the_worst_corner() {
    assert!(corner_bound(0.5) < 4.5e-4, "{}", corner_bound(0.5));
    assert!(corner_bound(0.9) < 1.4e-2, "{}", corner_bound(0.9));
}

/// Upper bound on |T_E″(c)| over `0 ≤ c ≤ x` for the patent formula (x < c_max), from its
/// derivatives (US 4,788,645 eq. 14):
///
/// `T_E = T_F·[P + (1 − P)·g]`, `g = √((1 + q)/2)`, `q = √w`, `w = 1 − A·c²/D`,
/// `D = 1 − c²/4`, `A = (2B/T_F)²`. Then
///
/// * `w′ = −2Ac/D²`, `w″ = −2A/D² − 2Ac²/D³`;
/// * `q′ = w′/(2q)`, `q″ = w″/(2q) − w′²/(4q³)`;
/// * `g′ = q′/(4g)`, `g″ = q″/(4g) − q′²/(16g³)`; `T_E″ = T_F(1 − P)·g″`.
///
/// On `[0, x]`, D falls with c, so `|w′| ≤ 2Ax/D(x)²` and `|w″| ≤ 2A/D(x)² + 2Ax²/D(x)³`;
/// w falls with c, so `q ≥ q(x)` and `g ≥ g(x)`. Putting the largest numerators over the
/// smallest denominators term by term bounds |T_E″| on the whole interval.
fn second_derivative_bound(f: &PatentAckermannTrack, x: f64) -> f64 {
    let a = (2.0 * f.wheelbase_m() / f.track_m()).powi(2);
    let d = 1.0 - 0.25 * x * x;
    let w1 = 2.0 * a * x / (d * d);
    let w2 = 2.0 * a / (d * d) + 2.0 * a * x * x / (d * d * d);
    let q = (1.0 - a * x * x / d).sqrt();
    let g = (0.5 * (1.0 + q)).sqrt();
    let q1 = w1 / (2.0 * q);
    let q2 = w2 / (2.0 * q) + w1 * w1 / (4.0 * q.powi(3));
    let g2 = q2 / (4.0 * g) + q1 * q1 / (16.0 * g.powi(3));
    f.track_m() * (1.0 - f.pitman_ratio()) * g2
}

/// Analytic bound on |table − formula| at |c| for a table of step h on `0..=c_max`.
///
/// In a cell `[a, b]` the linear interpolant's error is `f″(ξ)/2·(c − a)(b − c)`
/// (≤ h²/8·max|f″|), bounded by [`second_derivative_bound`] up to b. In the last cell
/// (b = c_max) f″ is unbounded, but T_E falls monotonically (w falls with c), so the formula
/// and its interpolant both lie between f(a) and f(b): the error is at most f(a) − f(b). The
/// smaller of the two applies wherever both do.
fn table_error_bound(f: &PatentAckermannTrack, h: f64, c: f64) -> f64 {
    let c = c.abs();
    let c_max = f.max_ratio();
    let i = ((c / h) as usize).min(((c_max / h).round() as usize).saturating_sub(1));
    let a = h * i as f64;
    let b = (a + h).min(c_max);
    let span = f.effective_track_m(a).unwrap() - f.effective_track_m(b).unwrap();
    let curvature = if b < c_max {
        0.5 * (c - a).max(0.0) * (b - c).max(0.0) * second_derivative_bound(f, b)
    } else {
        f64::INFINITY
    };
    curvature.min(span.abs())
}

proptest! {
    /// Every car in the box is within the worst corner's error at the same u = c/c_max.
    #[test]
    fn patent_is_within_the_corner_bound_for_any_car(
        b in CAR_BOX[0].0..CAR_BOX[0].1, t in CAR_BOX[1].0..CAR_BOX[1].1,
        p in CAR_BOX[2].0..CAR_BOX[2].1, u in 0.0f64..0.95,
    ) {
        let params = AckermannParams { wheelbase_m: b, track_m: t, kingpin_offset_m: p };
        let g = AckermannGeometry::new(params).unwrap();
        let f = PatentAckermannTrack::from_params(&params).unwrap();
        // Without an offset the geometry may peak a little before the formula's limit.
        prop_assume!(u * f.max_ratio() <= g.peak_ratio());
        let e = car_error(b, t, p, u).unwrap();
        // 1e-15: rounding of the two tracks' difference.
        prop_assert!(e <= corner_bound(u) + 1e-15, "u {u}: {e} > {}", corner_bound(u));
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

    /// Look-up tables agree with the formula within the analytic interpolation bound
    /// ([`table_error_bound`]) everywhere, the last cell included.
    #[test]
    fn lookup_table_is_within_the_interpolation_bound(u in 0.0f64..=1.0, neg in any::<bool>()) {
        let (_, f) = main_car();
        let t256 = EffectiveTrackTable::<256>::build(&f, f.max_ratio()).unwrap();
        let t64 = EffectiveTrackTable::<64>::build(&f, f.max_ratio()).unwrap();
        let c = if neg { -u } else { u } * f.max_ratio();
        let want = f.effective_track_m(c).unwrap();
        for (got, h) in [(t256.effective_track_m(c).unwrap(), t256.step()),
                         (t64.effective_track_m(c).unwrap(), t64.step())] {
            // 1e-13 m: rounding in the interpolation and in locating the cell (hundreds of
            // ulp of a 1.5 m track, far below any interpolation error that matters).
            let bound = table_error_bound(&f, h, c) + 1e-13;
            prop_assert!((got - want).abs() <= bound, "u {u}, h {h}: {} > {bound}", (got - want).abs());
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

/// The analytic bound is small where the table is meant to be used, and it is not loose by
/// orders of magnitude: the worst error found on a fine scan reaches a fair share of it.
#[test]
fn interpolation_bound_is_useful() {
    let (_, f) = main_car();
    let t = EffectiveTrackTable::<256>::build(&f, f.max_ratio()).unwrap();
    let h = t.step();
    let c_max = f.max_ratio();
    // h²/8 · max|f″| up to 0.9 c_max (plus a cell), relative to the track.
    let max_bound = h * h / 8.0 * second_derivative_bound(&f, 0.9 * c_max + h) / f.track_m();
    println!("256 entries, c ≤ 0.9 c_max: h²/8·max|f″|/T_F = {max_bound:.2e}");
    assert!(max_bound < 1e-4, "{max_bound}");
    let (mut worst_ratio, mut n) = (0.0f64, 0);
    for i in 0..=20_000 {
        let c = 0.9 * c_max * i as f64 / 20_000.0;
        let err = (t.effective_track_m(c).unwrap() - f.effective_track_m(c).unwrap()).abs();
        let bound = table_error_bound(&f, h, c);
        // 1e-13 m: the rounding allowance of the property above.
        assert!(err <= bound + 1e-13, "c {c}: {err} > {bound}");
        if bound > 1e-9 {
            worst_ratio = worst_ratio.max(err / bound);
            n += 1;
        }
    }
    println!("worst error / bound over {n} points: {worst_ratio:.6}");
    assert!(worst_ratio > 0.1, "{worst_ratio}");
}
