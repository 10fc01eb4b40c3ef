//! Magnetometer units and the check that a fitted field is an Earth field in the unit the
//! user declared: a wrong unit is a factor of 10, 100 or 1000, which no disturbance makes.

use truenorth_core::Fixed;

use crate::finding::{Finding, Fix};
use crate::units::MagUnit;

/// How far a fitted field may stray from the expected one: the calibrators' own ±15 %.
const TOLERANCE: f64 = truenorth_calib::quality::FIELD_RATIO_TOLERANCE;

/// The Earth's total field ranges over about 22,000–67,000 nT (the World Magnetic Model's
/// extremes at the surface, South Atlantic anomaly to the south magnetic pole), its
/// horizontal part up to about 42,000 nT; below 1,000 nT of horizontal field (within a few
/// hundred km of the dip poles) a compass is useless anyway.
const TOTAL_NT: (f64, f64) = (22_000.0, 67_000.0);
const HORIZONTAL_NT: (f64, f64) = (1_000.0, 42_000.0);

/// What is wrong with a fitted field `fitted` (input unit) declared in `unit`: compared
/// with `expected` (the World Magnetic Model's, input unit) when given, else with the range
/// of Earth fields (total for `dimensions` = 3, horizontal for 2). `None` when it fits or
/// no unit was declared. The fix names the unit the data are probably in, when one fits.
pub fn check_field(
    fitted: f64,
    unit: Option<MagUnit>,
    expected: Option<f64>,
    dimensions: usize,
) -> Option<Finding> {
    let unit = unit?;
    let fitted_nt = fitted * unit.nanotesla();
    let which = if dimensions == 3 {
        "total"
    } else {
        "horizontal"
    };
    // What fits, and the most typical field (to order several units that would fit).
    let (fits, typical, expectation): (Box<dyn Fn(f64) -> bool>, f64, String) = match expected {
        Some(e) => {
            let e_nt = e * unit.nanotesla();
            (
                Box::new(move |nt: f64| (nt / e_nt - 1.0).abs() <= TOLERANCE),
                e_nt,
                format!("the World Magnetic Model's {which} field there, {e_nt:.0} nT"),
            )
        }
        None => {
            let (lo, hi) = if dimensions == 3 {
                TOTAL_NT
            } else {
                HORIZONTAL_NT
            };
            (
                Box::new(move |nt: f64| {
                    nt >= lo * (1.0 - TOLERANCE) && nt <= hi * (1.0 + TOLERANCE)
                }),
                (lo * hi).sqrt(),
                format!("an Earth {which} field ({lo:.0}-{hi:.0} nT)"),
            )
        }
    };
    if fits(fitted_nt) {
        return None;
    }
    let mut guesses: Vec<MagUnit> = MagUnit::ALL
        .into_iter()
        .filter(|&u| u != unit && fits(fitted * u.nanotesla()))
        .collect();
    guesses.sort_by(|a, b| {
        let d = |u: &MagUnit| (fitted * u.nanotesla() / typical).ln().abs();
        d(a).total_cmp(&d(b))
    });
    let head = format!(
        "the fitted field {} {} = {} nT is not {expectation}",
        Fixed(fitted, 6),
        unit.name(),
        Fixed(fitted_nt, 0)
    );
    Some(match (expected, guesses.split_first()) {
        (_, Some((&likely, also))) => Finding::units(
            head,
            Fix::MagUnit {
                likely,
                also: also.to_vec(),
                declared: unit,
            },
        ),
        (Some(e), None) => Finding::units(
            format!("{head} ({} x)", Fixed(fitted / e, 2)),
            Fix::Advice(
                "a magnetically disturbed site, a tilted 2-axis sensor, or readings in raw counts"
                    .into(),
            ),
        ),
        (None, None) => Finding::units(
            head,
            Fix::Advice("a magnetically disturbed site, or readings in raw counts".into()),
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit the fix names, if it names one.
    fn likely(f: &Finding) -> Option<MagUnit> {
        match f.fix {
            Fix::MagUnit { likely, .. } => Some(likely),
            _ => None,
        }
    }

    #[test]
    fn a_wrong_unit_is_named() {
        // 19.6 µT read as mG: 10 x too small against London's WMM field.
        let e = check_field(19.6, Some(MagUnit::MilliGauss), Some(196.0), 2).unwrap();
        assert_eq!(likely(&e), Some(MagUnit::MicroTesla), "{e:?}");
        // Gauss readings declared as µT, no place: 0.53 µT is no Earth field.
        let e = check_field(0.53, Some(MagUnit::MicroTesla), None, 3).unwrap();
        assert_eq!(likely(&e), Some(MagUnit::Gauss), "{e:?}");
        // nT declared as µT.
        let e = check_field(48_000.0, Some(MagUnit::MicroTesla), None, 3).unwrap();
        assert_eq!(likely(&e), Some(MagUnit::NanoTesla), "{e:?}");
        // Right units pass; no unit, no judgement.
        assert!(check_field(0.53, Some(MagUnit::Gauss), None, 3).is_none());
        assert!(check_field(19.6, Some(MagUnit::MicroTesla), Some(19.56), 2).is_none());
        assert!(check_field(1e9, None, None, 3).is_none());
        // Raw counts fit no unit.
        let e = check_field(1234.0, Some(MagUnit::MicroTesla), Some(48.0), 3).unwrap();
        assert!(
            matches!(&e.fix, Fix::Advice(a) if a.contains("raw counts")) && likely(&e).is_none(),
            "{e:?}"
        );
    }
}
