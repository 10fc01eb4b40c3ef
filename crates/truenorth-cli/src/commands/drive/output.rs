//! The output of `truenorth drive`: its columns (the contract's and the `--extra` groups)
//! and how each estimate becomes a row.

use std::path::Path;

use truenorth::TrueNorth;
use truenorth::core::{MagneticHeading, NavEstimate, rad_to_deg, wrap_two_pi};
use truenorth::fusion::VehicleEstimator;
use truenorth::fusion::vehicle::{GnssCounts, NavFilter};
use truenorth::geomag::LocalTangentPlane;

use crate::io::{CliError, CliResult, CsvOutput, Precision};

/// Optional output column groups.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Extra {
    /// heading_sigma_deg, north_sigma_m, east_sigma_m.
    Sigma,
    /// heading_absolute, compass_used, compass_disturbed, at_rest.
    Status,
    /// The learned sensor errors (fused method only).
    Calibration,
    /// gap and the unobserved_* flags: where the estimate leans on the prior rather than
    /// on the data.
    Trust,
    /// lat_deg, lon_deg of the position (WGS84), on rows whose track is on the satellite
    /// fixes' tangent plane.
    Geodetic,
}

/// The output columns and how each row is written.
pub(super) struct Writer {
    pub(super) out: CsvOutput,
    pub(super) extra: Vec<Extra>,
    pub(super) true_north: Option<TrueNorth>,
    /// What was written, for the summary.
    pub(super) tally: Tally,
    pub(super) error: Option<CliError>,
    /// How the numbers are written.
    pub(super) precision: Precision,
}

/// What the rows written say, for the summary.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Tally {
    pub(super) rows: usize,
    /// Rows where a sensor resumed after a gap.
    pub(super) gaps: usize,
    /// Rows at which the fused estimate fell back to plain integration.
    pub(super) fallbacks: usize,
    /// What the satellite fixes did, and the tangent plane's origin, once there is one.
    pub(super) gnss: Option<(GnssCounts, (f64, f64))>,
    /// The last estimate written.
    pub(super) last: Option<NavEstimate>,
}

impl Writer {
    /// Creates the output `output` with the contract's columns and the `extra` groups;
    /// headings and the track turned onto true north when `true_north` is given.
    pub(super) fn create(
        output: &Path,
        extra: &[Extra],
        true_north: Option<TrueNorth>,
        precision: Precision,
    ) -> CliResult<Self> {
        Ok(Self {
            out: CsvOutput::create(output, &Self::header(extra))?,
            extra: extra.to_vec(),
            true_north,
            tally: Tally::default(),
            error: None,
            precision,
        })
    }

    fn header(extra: &[Extra]) -> Vec<&'static str> {
        let mut h = vec!["t_s", "north_m", "east_m", "heading_deg"];
        for e in extra {
            h.extend_from_slice(match e {
                Extra::Sigma => &["heading_sigma_deg", "north_sigma_m", "east_sigma_m"],
                Extra::Status => &[
                    "heading_absolute",
                    "compass_used",
                    "compass_disturbed",
                    "at_rest",
                ],
                Extra::Calibration => &[
                    "gyro_bias_dps",
                    "gyro_gain_right",
                    "gyro_gain_left",
                    "wheel_diff",
                    "track_scale",
                    "speed_coeff_s2_per_m2",
                    "wheel_scale",
                    "wheel_lag_s",
                ],
                Extra::Trust => &[
                    "gap",
                    "unobserved_gyro_bias",
                    "unobserved_gyro_gain_right",
                    "unobserved_gyro_gain_left",
                    "unobserved_wheel_diff",
                    "unobserved_track_scale",
                    "unobserved_speed_coeff",
                    "unobserved_wheel_scale",
                    "unobserved_wheel_lag",
                ],
                Extra::Geodetic => &["lat_deg", "lon_deg"],
            });
        }
        h
    }

    /// Writes one estimate of the fused estimator `fused`, if it is that method's
    /// (nothing after a write has failed: the error is kept for the caller).
    pub(super) fn write(&mut self, e: &NavEstimate, fused: Option<&VehicleEstimator>) {
        if self.error.is_some() {
            return;
        }
        let origin = fused.and_then(VehicleEstimator::gnss_origin);
        if let (Some(f), Some(o)) = (fused, origin) {
            self.tally.gnss = Some((f.gnss_counts(), o));
        }
        let declination = fused
            .and_then(VehicleEstimator::gnss_declination_rad)
            .filter(|_| e.status.gnss_frame);
        let mut row = self.position_and_heading(e, declination);
        let context = Context {
            filter: fused.map(VehicleEstimator::filter),
            plane: origin
                .filter(|_| e.status.gnss_frame)
                .and_then(|(lat, lon)| LocalTangentPlane::new(lat, lon, 0.0).ok()),
        };
        for x in &self.extra {
            extra_cells(*x, e, &context, &mut row);
        }
        if let Err(err) = self.out.row(&row, self.precision) {
            self.error = Some(err);
        }
        let t = &mut self.tally;
        t.rows += 1;
        t.gaps += usize::from(e.status.gap);
        t.fallbacks += usize::from(e.status.fell_back);
        t.last = Some(*e);
    }

    /// The contract's columns: `t_s,north_m,east_m,heading_deg`. A row the satellite fixes
    /// referred to true north (`declination` given) is in their tangent plane already: its
    /// heading is turned by the declination at the first fix, its track left as it is.
    fn position_and_heading(&self, e: &NavEstimate, declination: Option<f64>) -> Vec<f64> {
        let (mut n, mut east, mut heading) = (e.north_m, e.east_m, e.heading.rad());
        if let Some(d) = declination {
            heading += d;
        } else if let Some(north) = self.true_north {
            // True north: the heading and the whole track turn by the declination.
            heading = north.heading(MagneticHeading::new(heading)).rad();
            (n, east) = north.north_east(n, east);
        }
        if !e.status.position_known {
            // No wheels: no position, written as empty cells.
            (n, east) = (f64::NAN, f64::NAN);
        }
        vec![e.t_s, n, east, rad_to_deg(wrap_two_pi(heading))]
    }
}

/// What the cells of a row need beside its estimate.
struct Context<'a> {
    /// The fused filter's state, for the fused method.
    filter: Option<&'a NavFilter>,
    /// The satellite fixes' tangent plane, on rows whose track is on it.
    plane: Option<LocalTangentPlane>,
}

/// The cells of one `--extra` group, appended to `row`.
fn extra_cells(x: Extra, e: &NavEstimate, context: &Context<'_>, row: &mut Vec<f64>) {
    let flags = |b: &[bool]| {
        b.iter()
            .map(|&b| f64::from(u8::from(b)))
            .collect::<Vec<_>>()
    };
    match x {
        Extra::Sigma => {
            let p = e.position_cov_m2;
            let known = e.status.position_known;
            let sigma = |v: f64| if known { v.max(0.0).sqrt() } else { f64::NAN };
            row.extend([
                rad_to_deg(e.heading_sigma_rad),
                sigma(p[(0, 0)]),
                sigma(p[(1, 1)]),
            ]);
        }
        Extra::Status => {
            let s = e.status;
            row.extend(flags(&[
                s.heading_absolute,
                s.compass_used,
                s.compass_disturbed,
                s.at_rest,
            ]));
        }
        Extra::Calibration => match context.filter {
            Some(f) => {
                let x = &f.x;
                use truenorth::fusion::vehicle::nav_filter::*;
                row.extend([
                    rad_to_deg(x[BIAS]),
                    1.0 + x[GAIN_POS],
                    1.0 + x[GAIN_NEG],
                    x[WHEEL_DIFF],
                    x[TRACK_SCALE],
                    x[SPEED_COEFF],
                    1.0 + x[WHEEL_SCALE],
                    x[WHEEL_LAG],
                ]);
            }
            None => row.extend([f64::NAN; 8]),
        },
        Extra::Trust => {
            let u = e.status.unobserved;
            row.extend(flags(&[
                e.status.gap,
                u.gyro_bias,
                u.gyro_gain_right,
                u.gyro_gain_left,
                u.wheel_diff,
                u.track_scale,
                u.speed_coeff,
                u.wheel_scale,
                u.wheel_lag,
            ]));
        }
        Extra::Geodetic => {
            let point = context
                .plane
                .filter(|_| e.status.position_known)
                .and_then(|p| p.to_geodetic(e.north_m, e.east_m, 0.0).ok());
            row.extend(point.map_or([f64::NAN; 2], |g| {
                [g.lat_rad().to_degrees(), g.lon_rad().to_degrees()]
            }));
        }
    }
}
