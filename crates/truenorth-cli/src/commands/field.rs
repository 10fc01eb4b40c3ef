//! `truenorth field`: the World Magnetic Model 2025 field at a place and date, as one CSV
//! row `x_nt,y_nt,z_nt,h_nt,f_nt,incl_deg,decl_deg` on stdout (ARCHITECTURE.md, section
//! "CLI contract").
//!
//! Every argument is read as text and parsed here, so that any bad input — a missing flag
//! included — ends with exactly one line on stderr and a non-zero exit.

use std::time::{SystemTime, UNIX_EPOCH};

use truenorth::core::Error;
use truenorth::geomag::{
    EXTRAPOLATION_LIMIT_YEARS, Extrapolation, MagneticField, WorldMagneticModel,
    decimal_year_from_date, decimal_year_from_unix_seconds,
};
use truenorth::{Place, TrueNorth};

use crate::io::{CliError, CliResult};
use crate::io::{errln, outln};

/// The CSV header of the contract.
pub const HEADER: &str = "x_nt,y_nt,z_nt,h_nt,f_nt,incl_deg,decl_deg";

/// Arguments of `truenorth field`.
#[derive(Debug, Clone, Default, clap::Args)]
#[command(
    override_usage = "truenorth field --lat DEG --lon DEG [--alt-km KM] [--date DECIMAL_YEAR] [--allow-extrapolation]",
    long_about = "The geomagnetic field of the World Magnetic Model 2025 (valid 2025.0-2030.0) at a \
place and date. Prints one CSV header `x_nt,y_nt,z_nt,h_nt,f_nt,incl_deg,decl_deg` and one row: \
X north, Y east, Z down (nT, in the local WGS84 north-east-down frame), horizontal and total \
intensity H and F (nT), inclination (dip, positive down) and declination (positive east: \
true heading = magnetic heading + declination), in degrees.\n\n\
Without --date the date is today's decimal year in UTC, from the system clock. A date outside \
2025.0-2030.0 is refused unless --allow-extrapolation is given; then the row is printed and a \
one-line warning goes to stderr."
)]
pub struct Args {
    /// The place and date.
    #[command(flatten)]
    pub place: PlaceArgs,
}

/// Where and when to evaluate the World Magnetic Model, as given on the command line (the
/// library's [`Place`] once read); shared by every command that can turn magnetic into true
/// heading.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PlaceArgs {
    /// Geodetic latitude (WGS84), degrees north, -90 to 90.
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub lat: Option<String>,
    /// Longitude, degrees east (west negative).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub lon: Option<String>,
    /// Height above the WGS84 ellipsoid, km [default: 0].
    #[arg(long = "alt-km", value_name = "KM", allow_negative_numbers = true)]
    pub alt_km: Option<String>,
    /// Decimal year (e.g. 2026.5) or a calendar date YYYY-MM-DD (00:00 UTC)
    /// [default: now, UTC, from the system clock].
    #[arg(long, value_name = "DECIMAL_YEAR")]
    pub date: Option<String>,
    /// Evaluate dates outside 2025.0-2030.0 by extending the linear secular variation
    /// (prints a warning on stderr).
    #[arg(long)]
    pub allow_extrapolation: bool,
}

/// Runs the subcommand: the CSV on stdout, an extrapolation warning (if any) on stderr.
pub fn run(args: &Args) -> CliResult {
    let field = args.place.field()?;
    outln!("{HEADER}")?;
    outln!("{}", csv_row(&field))?;
    Ok(())
}

/// Inclination the World Magnetic Model must give before the sign of a dip is judged,
/// degrees: near the magnetic equator the field is nearly level and either sign is the
/// place's.
const DIP_SIGN_MIN_DEG: f64 = 10.0;

impl PlaceArgs {
    /// The dip `dip_deg` and the World Magnetic Model's inclination here, when a place is
    /// given and they have opposite signs beyond the equator's band (±10°): no field dips
    /// the other way than the place's.
    pub fn dip_of_the_other_sign(&self, dip_deg: Option<f64>) -> CliResult<Option<(f64, f64)>> {
        let Some(dip) = dip_deg.filter(|d| d.is_finite() && self.is_given()) else {
            return Ok(None);
        };
        let model = self.field()?.inclination_deg();
        Ok((model.abs() >= DIP_SIGN_MIN_DEG && dip * model < 0.0).then_some((dip, model)))
    }

    /// Whether a place was given at all (`--lat` or `--lon`).
    pub fn is_given(&self) -> bool {
        self.lat.is_some() || self.lon.is_some()
    }

    /// The date given, as a decimal year (today if none was given).
    pub fn decimal_year(&self) -> CliResult<f64> {
        match &self.date {
            Some(text) => parse_date(text),
            None => today_decimal_year(),
        }
    }

    /// The field at this place and date (today if no date was given); an extrapolation
    /// warning goes to stderr.
    pub fn field(&self) -> CliResult<MagneticField> {
        let year = self.decimal_year()?;
        let field = evaluate(self, year)?;
        if let Some(w) = field.extrapolated {
            errln!("truenorth: warning: {w}");
        }
        if let Some(w) = weak_horizontal_field(&field) {
            errln!("truenorth: warning: {w}");
        }
        Ok(field)
    }

    /// True north at the place given, `None` without one (its warnings go to stderr).
    pub fn true_north(&self) -> CliResult<Option<TrueNorth>> {
        if !self.is_given() {
            return Ok(None);
        }
        Ok(Some(TrueNorth::from(self.field()?.declination())))
    }
}

/// Below this horizontal intensity, nT, a magnetic compass is unreliable: the World
/// Magnetic Model's own "blackout zone" around the magnetic poles (Chulliat et al., *The
/// US/UK World Magnetic Model for 2020-2025*, NOAA technical report, 2020: blackout zones
/// where H < 2000 nT, caution zones where H < 6000 nT).
pub const WEAK_HORIZONTAL_NT: f64 = 2000.0;

/// A warning when the horizontal field is too weak for a compass.
fn weak_horizontal_field(f: &MagneticField) -> Option<String> {
    (f.h_nt < WEAK_HORIZONTAL_NT).then(|| {
        format!(
            "the horizontal field here is {:.0} nT, below {WEAK_HORIZONTAL_NT:.0} nT (the World Magnetic Model's blackout zone near a magnetic pole): a magnetic compass is unreliable, and the declination changes fast with position",
            f.h_nt
        )
    })
}

/// The heights at which the World Magnetic Model is valid, km above the WGS84 ellipsoid:
/// from 1 km below to 850 km above (Chulliat et al., *The US/UK World Magnetic Model for
/// 2025-2030*, NOAA technical report, 2024, section 1).
pub const ALTITUDE_RANGE_KM: (f64, f64) = (-1.0, 850.0);

/// The field for the parsed arguments at decimal year `year`.
fn evaluate(args: &PlaceArgs, year: f64) -> CliResult<MagneticField> {
    let lat = parse_number("--lat", required("--lat", &args.lat)?)?;
    let lon = parse_number("--lon", required("--lon", &args.lon)?)?;
    if !((-180.0..360.0).contains(&lon)) {
        return Err(CliError::msg(format!(
            "--lon: {lon} is outside [-180, 360) degrees east (west is negative, or 180-360)"
        )));
    }
    let alt_km = match &args.alt_km {
        Some(text) => parse_number("--alt-km", text)?,
        None => 0.0,
    };
    let (lowest, highest) = ALTITUDE_RANGE_KM;
    if !(lowest..=highest).contains(&alt_km) {
        return Err(CliError::msg(format!(
            "--alt-km: {alt_km} is outside {lowest} to {highest} km above the WGS84 ellipsoid, the heights at which the World Magnetic Model holds (it is in kilometres: 0.1 for 100 m)"
        )));
    }
    let policy = if args.allow_extrapolation {
        Extrapolation::Allow
    } else {
        Extrapolation::Refuse
    };
    let place = Place {
        lat_deg: lat,
        lon_deg: lon,
        height_m: alt_km * 1000.0,
        year,
    };
    place
        .field_in(&WorldMagneticModel::WMM2025.with_extrapolation(policy))
        .map_err(|e| match e {
            Error::DateOutOfRange { .. } if !args.allow_extrapolation => {
                CliError::msg(format!("{e} (with --allow-extrapolation)"))
            }
            Error::DateOutOfRange {
                year,
                valid_from,
                valid_to,
            } => CliError::msg(format!(
                "--date: {year} is more than {EXTRAPOLATION_LIMIT_YEARS} years outside the model's validity {valid_from}–{valid_to}, beyond what --allow-extrapolation extends to ({}–{}): no linear secular variation holds that far",
                valid_from - EXTRAPOLATION_LIMIT_YEARS,
                valid_to + EXTRAPOLATION_LIMIT_YEARS
            )),
            e => CliError::msg(e.to_string()),
        })
}

/// One CSV row in the header's order; nT to 0.001, degrees to 0.00001.
fn csv_row(f: &MagneticField) -> String {
    format!(
        "{:.3},{:.3},{:.3},{:.3},{:.3},{:.5},{:.5}",
        f.x_nt,
        f.y_nt,
        f.z_nt,
        f.h_nt,
        f.f_nt,
        f.inclination_deg(),
        f.declination_deg()
    )
}

fn required<'a>(flag: &str, value: &'a Option<String>) -> CliResult<&'a str> {
    value
        .as_deref()
        .ok_or_else(|| CliError::msg(format!("{flag} is required")))
}

/// A number; NaN and infinities parse here and are refused by the model with a reason.
fn parse_number(flag: &str, text: &str) -> CliResult<f64> {
    text.trim()
        .parse::<f64>()
        .map_err(|_| CliError::msg(format!("{flag}: `{text}` is not a number")))
}

/// A decimal year (`2026.5`) or a calendar date (`2026-07-02`, 00:00 UTC).
fn parse_date(text: &str) -> CliResult<f64> {
    let t = text.trim();
    if let Ok(year) = t.parse::<f64>() {
        return Ok(year);
    }
    let bad = || {
        CliError::msg(format!(
            "--date: `{text}` is neither a decimal year (e.g. 2026.5) nor a date YYYY-MM-DD"
        ))
    };
    let mut parts = t.splitn(3, '-');
    let (Some(y), Some(m), Some(d)) = (parts.next(), parts.next(), parts.next()) else {
        return Err(bad());
    };
    let (Ok(y), Ok(m), Ok(d)) = (y.parse::<i32>(), m.parse::<u32>(), d.parse::<u32>()) else {
        return Err(bad());
    };
    decimal_year_from_date(y, m, d).map_err(|e| CliError::msg(format!("--date: {e}")))
}

/// Today's decimal year in UTC from the system clock.
fn today_decimal_year() -> CliResult<f64> {
    let unix_s = match SystemTime::now().duration_since(UNIX_EPOCH) {
        Ok(d) => d.as_secs_f64(),
        // A clock set before 1970: the error carries how far before.
        Err(e) => -e.duration().as_secs_f64(),
    };
    decimal_year_from_unix_seconds(unix_s).map_err(|e| {
        CliError::msg(format!(
            "cannot read today's date from the system clock: {e}"
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(lat: &str, lon: &str) -> PlaceArgs {
        PlaceArgs {
            lat: Some(lat.into()),
            lon: Some(lon.into()),
            ..PlaceArgs::default()
        }
    }

    /// A row of the official WMM2025 test values: 2025.0, 100 km, 80° S 240° E.
    #[test]
    fn reproduces_a_test_value_row() {
        let a = PlaceArgs {
            alt_km: Some("100".into()),
            ..args("-80", "240")
        };
        let f = evaluate(&a, 2025.0).unwrap();
        let row: Vec<f64> = csv_row(&f).split(',').map(|v| v.parse().unwrap()).collect();
        let want = [5907.6, 14780.3, -49540.7, 15917.1, 52035.0, -72.19, 68.21];
        assert_eq!(row.len(), HEADER.split(',').count());
        for (i, (got, want)) in row.iter().zip(want).enumerate() {
            let tol = if i < 5 { 0.1 } else { 0.01 };
            assert!((got - want).abs() <= tol, "column {i}: {got} vs {want}");
        }
    }

    #[test]
    fn bad_input_is_one_line_errors() {
        let one_line = |e: CliError| {
            let s = e.to_string();
            assert!(!s.contains('\n'), "{s}");
            s
        };
        assert!(
            one_line(evaluate(&PlaceArgs::default(), 2026.0).unwrap_err())
                .contains("--lat is required")
        );
        assert!(
            one_line(evaluate(&args("abc", "0"), 2026.0).unwrap_err()).contains("not a number")
        );
        assert!(one_line(evaluate(&args("91", "0"), 2026.0).unwrap_err()).contains("latitude"));
        for lon in ["360", "-180.5", "720", "nan", "inf"] {
            let e = evaluate(&args("10", lon), 2026.0).unwrap_err().to_string();
            assert!(
                e.contains("--lon") && e.contains("[-180, 360)"),
                "{lon}: {e}"
            );
        }
        assert!(evaluate(&args("10", "-180"), 2026.0).is_ok());
        assert!(evaluate(&args("10", "359.9"), 2026.0).is_ok());
        assert!(one_line(evaluate(&args("nan", "0"), 2026.0).unwrap_err()).contains("not finite"));
        let late = one_line(evaluate(&args("10", "0"), 2031.0).unwrap_err());
        assert!(late.contains("--allow-extrapolation"), "{late}");
        assert!(one_line(parse_date("20x6").unwrap_err()).contains("--date"));
        assert!(one_line(parse_date("2026-02-30").unwrap_err()).contains("day of month"));
    }

    /// Near the north magnetic pole (86° N, 140° E in 2026) the horizontal field is too
    /// weak for a compass, and a warning says so; at mid-latitudes there is none.
    #[test]
    fn weak_horizontal_field_near_the_poles_warns() {
        let polar = evaluate(&args("86", "140"), 2026.0).unwrap();
        let w = weak_horizontal_field(&polar).expect("a warning near the pole");
        assert!(w.contains("blackout"), "{w}");
        let london = evaluate(&args("51.5", "-0.13"), 2026.0).unwrap();
        assert!(weak_horizontal_field(&london).is_none());
    }

    /// A height outside the model's range is refused naming the range; a date beyond the
    /// extrapolation limit says so, not "opt in" again.
    #[test]
    fn heights_and_far_dates_are_named() {
        let deep = PlaceArgs {
            alt_km: Some("-1000".into()),
            ..args("10", "0")
        };
        let e = evaluate(&deep, 2026.0).unwrap_err().to_string();
        assert!(e.contains("--alt-km") && e.contains("-1 to 850 km"), "{e}");
        let far = PlaceArgs {
            allow_extrapolation: true,
            ..args("10", "0")
        };
        let e = evaluate(&far, 1900.0).unwrap_err().to_string();
        assert!(
            e.contains("beyond what --allow-extrapolation extends to (1925–2130)")
                && !e.contains("opt in"),
            "{e}"
        );
    }

    #[test]
    fn extrapolation_is_an_explicit_opt_in() {
        let a = PlaceArgs {
            allow_extrapolation: true,
            ..args("10", "0")
        };
        let f = evaluate(&a, 2031.0).unwrap();
        assert!(f.extrapolated.is_some());
        assert!(evaluate(&a, 2026.0).unwrap().extrapolated.is_none());
    }

    #[test]
    fn dates_parse_as_decimal_years_or_calendar_dates() {
        assert_eq!(parse_date("2026.5").unwrap(), 2026.5);
        assert_eq!(parse_date(" 2027 ").unwrap(), 2027.0);
        assert_eq!(parse_date("2025-01-01").unwrap(), 2025.0);
        assert!((parse_date("2027-07-02").unwrap() - (2027.0 + 182.0 / 365.0)).abs() < 1e-12);
        let today = today_decimal_year().unwrap();
        assert!(today > 2020.0 && today < 2100.0, "{today}");
    }
}
