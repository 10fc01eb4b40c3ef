//! Dates: the model's validity window, the opt-in to extrapolate beyond it, and decimal
//! years from calendar dates or Unix time (pure arithmetic: this crate never reads a clock).

use core::fmt;

use serde::{Deserialize, Serialize};
#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;
use truenorth_core::{Error, Result, check_finite};

use crate::coefficients::Coefficients;

/// What to do with a date outside the model's validity (2025.0–2030.0 for WMM2025).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Extrapolation {
    /// Refuse with [`Error::DateOutOfRange`] (the default: a silent answer for a date the
    /// model does not cover would be a wrong declination nobody notices).
    #[default]
    Refuse,
    /// Evaluate anyway, extending the linear secular variation, and mark the result with an
    /// [`Extrapolated`] warning. Still refused beyond [`EXTRAPOLATION_LIMIT_YEARS`].
    Allow,
}

/// Even with [`Extrapolation::Allow`], dates more than this many years outside the validity
/// window are refused: the linear secular variation is meaningless long before, and the
/// bound keeps every result finite.
pub const EXTRAPOLATION_LIMIT_YEARS: f64 = 100.0;

/// The warning carried by a result computed for a date outside the model's validity.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Extrapolated {
    /// The requested decimal year.
    pub year: f64,
    /// First valid decimal year of the model.
    pub valid_from: f64,
    /// Last valid decimal year of the model.
    pub valid_to: f64,
}

impl fmt::Display for Extrapolated {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "date {} is outside the model's validity {}–{}: the field was extrapolated with the linear secular variation and may be far less accurate than the model's stated uncertainty",
            self.year, self.valid_from, self.valid_to
        )
    }
}

/// Checks `year` against the validity of `coefficients` under `policy`: `Ok(None)` inside
/// the window, `Ok(Some(warning))` outside it when extrapolation is allowed.
pub(crate) fn check_year(
    coefficients: &Coefficients,
    year: f64,
    policy: Extrapolation,
) -> Result<Option<Extrapolated>> {
    check_finite("decimal year", year)?;
    let valid_from = coefficients.valid_from_year();
    let valid_to = coefficients.valid_to_year();
    if (valid_from..=valid_to).contains(&year) {
        return Ok(None);
    }
    let within_limit = (valid_from - EXTRAPOLATION_LIMIT_YEARS
        ..=valid_to + EXTRAPOLATION_LIMIT_YEARS)
        .contains(&year);
    match policy {
        Extrapolation::Allow if within_limit => Ok(Some(Extrapolated {
            year,
            valid_from,
            valid_to,
        })),
        _ => Err(Error::DateOutOfRange {
            year,
            valid_from,
            valid_to,
        }),
    }
}

const SECONDS_PER_DAY: f64 = 86_400.0;

/// Days from 1970-01-01 to the given proleptic Gregorian date (month 1–12, day 1–31).
///
/// The era-based counting of H. Hinnant, "chrono-Compatible Low-Level Date Algorithms"
/// (public description of `days_from_civil`): shift the year to start in March so that the
/// leap day is last, then count 400-year eras of 146 097 days.
fn days_from_civil(year: i64, month: i64, day: i64) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = y.div_euclid(400);
    let year_of_era = y.rem_euclid(400);
    let month_from_march = (month + 9) % 12;
    let day_of_year = (153 * month_from_march + 2) / 5 + day - 1;
    let day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
    era * 146_097 + day_of_era - 719_468
}

fn is_leap(year: i64) -> bool {
    (year % 4 == 0 && year % 100 != 0) || year % 400 == 0
}

fn days_in_month(year: i64, month: i64) -> i64 {
    match month {
        2 if is_leap(year) => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// First and last calendar year the decimal-year helpers accept.
const YEAR_RANGE: (i64, i64) = (1, 9999);

/// The decimal year at 00:00 UTC of a calendar date: `year + (day_of_year − 1) / days_in_year`
/// (the convention of the WMM test values, e.g. 2027-07-02 → 2027.5).
///
/// Errors: [`Error::OutOfRange`] for a year outside 1–9999, a month outside 1–12 or a day
/// that the month does not have.
pub fn decimal_year_from_date(year: i32, month: u32, day: u32) -> Result<f64> {
    let (y, m, d) = (i64::from(year), i64::from(month), i64::from(day));
    let range = |what, value: i64, min: i64, max: i64| Error::OutOfRange {
        what,
        value: value as f64,
        min: min as f64,
        max: max as f64,
    };
    if !(YEAR_RANGE.0..=YEAR_RANGE.1).contains(&y) {
        return Err(range("year", y, YEAR_RANGE.0, YEAR_RANGE.1));
    }
    if !(1..=12).contains(&m) {
        return Err(range("month", m, 1, 12));
    }
    let last = days_in_month(y, m);
    if !(1..=last).contains(&d) {
        return Err(range("day of month", d, 1, last));
    }
    let start = days_from_civil(y, 1, 1);
    let length = days_from_civil(y + 1, 1, 1) - start;
    Ok(y as f64 + (days_from_civil(y, m, d) - start) as f64 / length as f64)
}

/// The decimal year of a Unix time (seconds since 1970-01-01 00:00 UTC, leap seconds not
/// counted, as `SystemTime` reports it): the calendar year plus the elapsed share of it.
///
/// Errors: [`Error::NonFinite`]; [`Error::OutOfRange`] outside the years 1–9999.
pub fn decimal_year_from_unix_seconds(unix_s: f64) -> Result<f64> {
    check_finite("unix time (s)", unix_s)?;
    let min_s = days_from_civil(YEAR_RANGE.0, 1, 1) as f64 * SECONDS_PER_DAY;
    let max_s = days_from_civil(YEAR_RANGE.1 + 1, 1, 1) as f64 * SECONDS_PER_DAY;
    if !(min_s..max_s).contains(&unix_s) {
        return Err(Error::OutOfRange {
            what: "unix time (s)",
            value: unix_s,
            min: min_s,
            max: max_s,
        });
    }
    // Within the checked range the day count fits comfortably in an i64.
    let day = (unix_s / SECONDS_PER_DAY).floor() as i64;
    // A first guess from the mean Gregorian year, corrected by at most a step or two.
    let mut year = 1970 + (day as f64 / 365.2425).floor() as i64;
    year = year.clamp(YEAR_RANGE.0, YEAR_RANGE.1);
    while year > YEAR_RANGE.0 && days_from_civil(year, 1, 1) > day {
        year -= 1;
    }
    while year < YEAR_RANGE.1 && days_from_civil(year + 1, 1, 1) <= day {
        year += 1;
    }
    let start_s = days_from_civil(year, 1, 1) as f64 * SECONDS_PER_DAY;
    let end_s = days_from_civil(year + 1, 1, 1) as f64 * SECONDS_PER_DAY;
    Ok(year as f64 + (unix_s - start_s) / (end_s - start_s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coefficients::WMM2025;
    use proptest::prelude::*;

    #[test]
    fn validity_window_and_policy() {
        assert_eq!(
            check_year(&WMM2025, 2025.0, Extrapolation::Refuse),
            Ok(None)
        );
        assert_eq!(
            check_year(&WMM2025, 2030.0, Extrapolation::Refuse),
            Ok(None)
        );
        assert!(matches!(
            check_year(&WMM2025, 2024.999, Extrapolation::Refuse),
            Err(Error::DateOutOfRange { .. })
        ));
        assert!(matches!(
            check_year(&WMM2025, 2030.001, Extrapolation::Refuse),
            Err(Error::DateOutOfRange { .. })
        ));
        let w = check_year(&WMM2025, 2031.0, Extrapolation::Allow)
            .unwrap()
            .unwrap();
        assert_eq!((w.year, w.valid_from, w.valid_to), (2031.0, 2025.0, 2030.0));
        assert!(w.to_string().contains("extrapolated"));
        assert!(matches!(
            check_year(&WMM2025, 2200.0, Extrapolation::Allow),
            Err(Error::DateOutOfRange { .. })
        ));
        assert!(matches!(
            check_year(&WMM2025, f64::NAN, Extrapolation::Allow),
            Err(Error::NonFinite { .. })
        ));
    }

    #[test]
    fn civil_days_known_values() {
        assert_eq!(days_from_civil(1970, 1, 1), 0);
        assert_eq!(days_from_civil(2000, 3, 1), 11_017);
        assert_eq!(days_from_civil(1969, 12, 31), -1);
        assert_eq!(days_from_civil(2025, 1, 1), 20_089);
    }

    #[test]
    fn decimal_years_of_dates() {
        assert_eq!(decimal_year_from_date(2025, 1, 1), Ok(2025.0));
        // 2027 has 365 days; 2 July is day 183, so (183 − 1)/365.
        assert_eq!(
            decimal_year_from_date(2027, 7, 2),
            Ok(2027.0 + 182.0 / 365.0)
        );
        assert_eq!(
            decimal_year_from_date(2028, 12, 31),
            Ok(2028.0 + 365.0 / 366.0)
        );
        assert!(decimal_year_from_date(2027, 2, 29).is_err());
        assert!(decimal_year_from_date(2028, 2, 29).is_ok());
        assert!(decimal_year_from_date(2027, 13, 1).is_err());
        assert!(decimal_year_from_date(0, 1, 1).is_err());
    }

    #[test]
    fn decimal_years_of_unix_times() {
        // 2025-01-01T00:00:00Z = 1 735 689 600 s.
        assert_eq!(decimal_year_from_unix_seconds(1_735_689_600.0), Ok(2025.0));
        let mid = decimal_year_from_unix_seconds(1_735_689_600.0 + 365.0 * 43_200.0).unwrap();
        assert!((mid - 2025.5).abs() < 1e-12);
        assert_eq!(decimal_year_from_unix_seconds(0.0), Ok(1970.0));
        assert!(decimal_year_from_unix_seconds(-1.0).unwrap() < 1970.0);
        assert!(decimal_year_from_unix_seconds(f64::NAN).is_err());
        assert!(decimal_year_from_unix_seconds(1e20).is_err());
    }

    proptest! {
        /// Midnight of any date gives the same decimal year by both routes.
        #[test]
        fn unix_and_calendar_agree(y in 1i32..9999, m in 1u32..=12, d in 1u32..=28) {
            let days = days_from_civil(i64::from(y), i64::from(m), i64::from(d));
            let via_unix = decimal_year_from_unix_seconds(days as f64 * SECONDS_PER_DAY).unwrap();
            let via_date = decimal_year_from_date(y, m, d).unwrap();
            prop_assert!((via_unix - via_date).abs() < 1e-9);
        }

        /// Decimal years increase with time and stay within [year, year + 1).
        #[test]
        fn monotonic(t in -6.0e10f64..2.5e11, dt in 1.0f64..1e7) {
            let a = decimal_year_from_unix_seconds(t).unwrap();
            let b = decimal_year_from_unix_seconds(t + dt).unwrap();
            prop_assert!(b > a);
        }

        /// Any number: a Unix time is accepted exactly when finite and within the years
        /// 1–9999 (giving a decimal year there), a decimal year exactly when finite and
        /// inside the model's validity (refusing extrapolation) or within the extrapolation
        /// limit of it (allowing it, with a warning outside the validity).
        #[test]
        fn any_f64_never_panics(
            t in prop_oneof![any::<f64>(), -6.2e10f64..2.6e11],
            y in prop_oneof![any::<f64>(), 1900.0f64..2150.0],
        ) {
            match decimal_year_from_unix_seconds(t) {
                Ok(year) => prop_assert!((1.0..10_000.0).contains(&year), "{t} → {year}"),
                Err(Error::NonFinite { .. }) => prop_assert!(!t.is_finite()),
                Err(Error::OutOfRange { min, max, .. }) => {
                    prop_assert!(t.is_finite() && !(min..max).contains(&t));
                }
                Err(e) => prop_assert!(false, "{e}"),
            }
            let inside = (2025.0..=2030.0).contains(&y);
            let near = (2025.0 - EXTRAPOLATION_LIMIT_YEARS..=2030.0 + EXTRAPOLATION_LIMIT_YEARS).contains(&y);
            prop_assert_eq!(check_year(&WMM2025, y, Extrapolation::Refuse).is_ok(), inside);
            match check_year(&WMM2025, y, Extrapolation::Allow) {
                Ok(warning) => prop_assert!(near && warning.is_some() != inside),
                Err(_) => prop_assert!(!near),
            }
        }

        /// Any date: accepted exactly when it exists (year 1–9999, month 1–12, day within
        /// the month by the Gregorian leap rule, recomputed here), giving a decimal year in
        /// [year, year + 1).
        #[test]
        fn any_date_never_panics(
            y in prop_oneof![any::<i32>(), 1i32..10_000],
            m in prop_oneof![any::<u32>(), 0u32..14],
            d in prop_oneof![any::<u32>(), 0u32..33],
        ) {
            let leap = y % 4 == 0 && (y % 100 != 0 || y % 400 == 0);
            let days = match m {
                1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
                4 | 6 | 9 | 11 => 30,
                2 if leap => 29,
                2 => 28,
                _ => 0,
            };
            let exists = (1..=9999).contains(&y) && (1..=days).contains(&d);
            match decimal_year_from_date(y, m, d) {
                Ok(year) => {
                    prop_assert!(exists, "{y}-{m}-{d}");
                    prop_assert!((f64::from(y)..f64::from(y) + 1.0).contains(&year));
                }
                Err(e) => prop_assert!(!exists, "{y}-{m}-{d}: {e}"),
            }
        }
    }
}
