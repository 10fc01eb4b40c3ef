//! Magnetometer units and the check that a fitted field is an Earth field in the unit the
//! user declared: a wrong unit is a factor of 10, 100 or 1000, which no disturbance makes.

use truenorth::core::Fixed;

/// Units a magnetometer may report in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MagUnit {
    /// Nanotesla.
    #[value(name = "nT")]
    NanoTesla,
    /// Microtesla.
    #[value(name = "uT")]
    MicroTesla,
    /// Milligauss (= 100 nT).
    #[value(name = "mG")]
    MilliGauss,
    /// Gauss (= 100 000 nT).
    #[value(name = "G")]
    Gauss,
}

impl MagUnit {
    /// Every unit, smallest first.
    const ALL: [MagUnit; 4] = [
        MagUnit::NanoTesla,
        MagUnit::MilliGauss,
        MagUnit::MicroTesla,
        MagUnit::Gauss,
    ];

    /// nT per unit.
    pub fn nanotesla(self) -> f64 {
        match self {
            Self::NanoTesla => 1.0,
            Self::MicroTesla => 1e3,
            Self::MilliGauss => 1e2,
            Self::Gauss => 1e5,
        }
    }

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::NanoTesla => "nT",
            Self::MicroTesla => "uT",
            Self::MilliGauss => "mG",
            Self::Gauss => "G",
        }
    }
}

/// How far a fitted field may stray from the expected one: the library's ±15 %
/// (`truenorth::calib::quality::FIELD_RATIO_TOLERANCE`).
const TOLERANCE: f64 = truenorth::calib::quality::FIELD_RATIO_TOLERANCE;

/// The Earth's total field ranges over about 22,000–67,000 nT (the World Magnetic Model's
/// extremes at the surface, South Atlantic anomaly to the south magnetic pole), its
/// horizontal part up to about 42,000 nT; below 1,000 nT of horizontal field (within a few
/// hundred km of the dip poles) a compass is useless anyway.
const TOTAL_NT: (f64, f64) = (22_000.0, 67_000.0);
const HORIZONTAL_NT: (f64, f64) = (1_000.0, 42_000.0);

/// What is wrong with a fitted field `fitted` (input unit) declared in `unit`: compared
/// with `expected` (the World Magnetic Model's, input unit) when given, else with the range
/// of Earth fields (total for `dimensions` = 3, horizontal for 2). `None` when it fits or
/// no unit was declared. The message names the unit the data are probably in, when one
/// fits.
pub fn check_field(
    fitted: f64,
    unit: Option<MagUnit>,
    expected: Option<f64>,
    dimensions: usize,
) -> Option<String> {
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
    let guess = guesses.first().copied();
    let others: String = guesses
        .iter()
        .skip(1)
        .map(|u| format!(" (or {})", u.name()))
        .collect();
    let head = format!(
        "the fitted field {} {} = {} nT is not {expectation}",
        Fixed(fitted, 6),
        unit.name(),
        Fixed(fitted_nt, 0)
    );
    Some(match (expected, guess) {
        (_, Some(g)) => format!(
            "{head}: the data are probably in {}{others} (--mag-unit {}), not {}",
            g.name(),
            g.name(),
            unit.name()
        ),
        (Some(e), None) => format!(
            "{head} ({} x): a magnetically disturbed site, a tilted 2-axis sensor, or readings in raw counts",
            Fixed(fitted / e, 2)
        ),
        (None, None) => format!("{head}: a magnetically disturbed site, or readings in raw counts"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wrong_unit_is_named() {
        // 19.6 µT read as mG: 10 x too small against London's WMM field.
        let e = check_field(19.6, Some(MagUnit::MilliGauss), Some(196.0), 2).unwrap();
        assert!(e.contains("probably in uT"), "{e}");
        // Gauss readings declared as µT, no place: 0.53 µT is no Earth field.
        let e = check_field(0.53, Some(MagUnit::MicroTesla), None, 3).unwrap();
        assert!(e.contains("probably in G"), "{e}");
        // nT declared as µT.
        let e = check_field(48_000.0, Some(MagUnit::MicroTesla), None, 3).unwrap();
        assert!(e.contains("probably in nT"), "{e}");
        // Right units pass; no unit, no judgement.
        assert!(check_field(0.53, Some(MagUnit::Gauss), None, 3).is_none());
        assert!(check_field(19.6, Some(MagUnit::MicroTesla), Some(19.56), 2).is_none());
        assert!(check_field(1e9, None, None, 3).is_none());
        // Raw counts fit no unit.
        let e = check_field(1234.0, Some(MagUnit::MicroTesla), Some(48.0), 3).unwrap();
        assert!(e.contains("raw counts") && !e.contains("probably"), "{e}");
    }
}
