//! What a drive log's own data say about how it was written, before the estimator is
//! trusted with it: a wheel whose distance runs backwards while the car moves forwards (a
//! column negated), wheels and gyro turning opposite ways (the gyro negated, or the left
//! and right wheels swapped: the compass's turns tell which), a compass that turns against
//! both (mirrored: an axis negated or the two swapped), and the size of the wheels'
//! turns against the gyro's (a unit off by 57, 3.6 or 1000, or a wrong track). Each
//! finding names the file, the row where the evidence became clear and the fix; it runs
//! on every row, so that it is ready when the estimator fails and can speak in its place.

use std::f64::consts::PI;
use std::path::PathBuf;

use truenorth::checks::{FindingKind, GyroUnit, Turns, YawRateCheck};
use truenorth::core::VehicleSample;

use crate::io::checking::{Refusal, refusals, refuse_or_warn};
use crate::io::{CliError, CliResult, InputOptions, errln};

/// Driving with one wheel's distance falling while the other's rises, m, before a car's
/// wheel is called negated: a car's wheels never turn opposite ways (only a pivoting
/// vehicle's do), and 20 m is more than any wheel slip or counter jitter.
const OPPOSED_M: f64 = 20.0;
/// A compass step larger than this within one row is a disturbance or a gap, not a turn,
/// rad.
const MAX_COMPASS_STEP_RAD: f64 = 0.5;
/// Length of a compass comparison window, s (as the gyro's against the wheels').
const WINDOW_S: f64 = 1.0;
/// A window counts when the gyro turned by at least this, rad (3°).
const MIN_WINDOW_TURN_RAD: f64 = 0.05;
/// Turning windows before the compass is heard, and the correlation it must reach with
/// the gyro or with the wheels.
const MIN_COMPASS_WINDOWS: usize = 10;
const MIN_COMPASS_CORRELATION: f64 = 0.5;
/// The squared correlation the wheels' turns must reach with the gyro's, over the windows
/// the gyro chose, before distances in kilometres are named: 0.99 on the simulated drive
/// of the test `each_mistake_is_named_for_what_it_is`, 0.59 on the real straight drive
/// with a raw gyro (`comma2k19`), where nothing is wrong.
const MIN_KM_R2: f64 = 0.8;

/// One wheel's distance unchanged, to the last bit, while the other's advances this far
/// (m) and the gyro turns less than half of what pivoting about the still wheel would turn
/// the vehicle: that wheel's odometer stalled. 5 m is over three radians of pivot for a
/// 1.5 m track, far beyond what a gyro's bias or a wheel's slip hides.
const STALL_M: f64 = 5.0;

/// A wheel that has not moved while the other has.
#[derive(Debug, Clone, Copy, Default)]
struct StillWheel {
    /// The row where it stopped changing.
    from_row: usize,
    /// Its distance then.
    at_m: f64,
    /// How far the other wheel has gone since, m.
    other_m: f64,
    /// The gyro's integrated turn when it stopped, rad.
    turn_at_rad: f64,
}

/// A stalled odometer: which wheel, where, and the evidence.
#[derive(Debug, Clone, Copy)]
struct Stall {
    side: usize,
    still: StillWheel,
    /// What pivoting about it would have turned, and what the gyro turned (if any), rad.
    pivot_rad: f64,
    gyro_rad: Option<f64>,
}

/// The running diagnosis of a drive log.
#[derive(Debug, Clone)]
pub struct Diagnosis {
    /// The gyro against the wheels.
    pub yaw: YawRateCheck,
    /// Whether the vehicle can turn its wheels opposite ways (skid-steer, differential).
    can_pivot: bool,
    /// The wheel columns are speeds.
    speeds: bool,
    /// The wheel readings of the last row that had them.
    last_wheels: Option<[f64; 2]>,
    /// Distance driven with the left (0) or right (1) wheel falling while the other rises, m.
    opposed_m: [f64; 2],
    /// The row where a wheel was found negated, and which.
    negated: Option<(usize, usize)>,
    /// The compass's and the wheels' turns over the windows in which the gyro turned.
    compass: CompassTurns,
    /// The gyro's turn integrated over the log, rad, and its last reading (time, rate).
    gyro_turn_rad: f64,
    last_gyro: Option<(f64, f64)>,
    /// Each wheel while it stays still and the other moves.
    still: [Option<StillWheel>; 2],
    stall: Option<Stall>,
}

/// The compass's turn per window against the gyro's and the wheels': the sums behind two
/// correlations, so that a log of any length is judged in constant memory.
#[derive(Debug, Clone, Default)]
struct CompassTurns {
    last_heading: Option<f64>,
    last_gyro: Option<(f64, f64)>,
    last_wheels: Option<[f64; 2]>,
    start_s: Option<f64>,
    /// Compass, gyro and wheels' turns in the open window, rad.
    window: [f64; 3],
    /// Σ c·g, Σ c·w, Σ c², Σ g², Σ w², Σ g·w.
    sums: [f64; 6],
    windows: usize,
    /// The row at which the windows became enough to judge.
    judged_at_row: Option<usize>,
}

impl CompassTurns {
    fn push(&mut self, s: &VehicleSample, track_m: f64, row: usize) {
        let start = *self.start_s.get_or_insert(s.t_s);
        // Integrated from the previous row on (not from the reading), so that a row without
        // a gyro reading does not add the last rate's turn since its reading again.
        if let Some((t0, g0)) = self.last_gyro {
            self.window[1] += g0 * (s.t_s - t0);
            self.last_gyro = Some((s.t_s, g0));
        }
        if let Some(g) = s.gyr_z_rps {
            self.last_gyro = Some((s.t_s, g));
        }
        if let Some(w) = s.wheels {
            if let Some([l, r]) = self.last_wheels {
                self.window[2] += ((w.dist_l_m - l) - (w.dist_r_m - r)) / track_m;
            }
            self.last_wheels = Some([w.dist_l_m, w.dist_r_m]);
        }
        if let Some(m) = s.mag {
            // A level compass reads mag_x = H cos ψ, mag_y = −H sin ψ (clockwise ψ).
            let heading = (-m.y).atan2(m.x);
            if let Some(h0) = self.last_heading {
                let step = (heading - h0 + PI).rem_euclid(2.0 * PI) - PI;
                if step.abs() < MAX_COMPASS_STEP_RAD {
                    self.window[0] += step;
                }
            }
            self.last_heading = Some(heading);
        }
        if s.t_s - start >= WINDOW_S {
            let [c, g, w] = self.window;
            if g.abs() >= MIN_WINDOW_TURN_RAD && [c, g, w].iter().all(|v| v.is_finite()) {
                for (sum, v) in self
                    .sums
                    .iter_mut()
                    .zip([c * g, c * w, c * c, g * g, w * w, g * w])
                {
                    *sum += v;
                }
                self.windows += 1;
                if self.windows == MIN_COMPASS_WINDOWS {
                    self.judged_at_row = Some(row);
                }
            }
            self.window = [0.0; 3];
            self.start_s = Some(s.t_s);
        }
    }

    /// The wheels' turns against the gyro's over the windows in which the gyro turned
    /// (the wheels' own choice of windows sees nothing when their distances are 1000 times
    /// too small).
    fn wheels_per_gyro(&self, track_m: f64) -> Option<Turns> {
        let [_, _, _, gg, ww, gw] = self.sums;
        (self.windows >= MIN_COMPASS_WINDOWS && gg > 0.0 && ww > 0.0).then(|| Turns {
            ratio: gw / gg,
            r2: gw * gw / (gg * ww),
            windows: self.windows,
            row: self.judged_at_row,
            track_m,
        })
    }

    /// The compass's correlation with the gyro's turns when it turns against the gyro and
    /// against the wheels too (or there are none): a mirrored compass — one axis negated,
    /// or the two swapped — since a level compass's heading turns with the vehicle.
    fn mirrored(&self) -> Option<f64> {
        if self.windows < MIN_COMPASS_WINDOWS {
            return None;
        }
        let [cg, cw, cc, gg, ww, _] = self.sums;
        let with_gyro = cg / (cc * gg).sqrt();
        let with_wheels = if ww > 0.0 {
            cw / (cc * ww).sqrt()
        } else {
            -1.0
        };
        (with_gyro < -MIN_COMPASS_CORRELATION && with_wheels < -MIN_COMPASS_CORRELATION)
            .then_some(with_gyro)
    }

    /// Whether the compass turns with the gyro (`Some(true)`) or with the wheels
    /// (`Some(false)`), when it clearly does one and not the other.
    fn sides_with_gyro(&self) -> Option<bool> {
        if self.windows < MIN_COMPASS_WINDOWS {
            return None;
        }
        let [cg, cw, cc, gg, ww, _] = self.sums;
        let with_gyro = cg / (cc * gg).sqrt();
        let with_wheels = cw / (cc * ww).sqrt();
        if with_gyro > MIN_COMPASS_CORRELATION && with_wheels < -MIN_COMPASS_CORRELATION {
            Some(true)
        } else if with_wheels > MIN_COMPASS_CORRELATION && with_gyro < -MIN_COMPASS_CORRELATION {
            Some(false)
        } else {
            None
        }
    }
}

impl Diagnosis {
    /// A diagnosis for odometer wheels `track_m` apart; `can_pivot` for vehicles whose
    /// wheels may turn opposite ways, `speeds` when the wheel columns are speeds.
    pub fn new(track_m: f64, can_pivot: bool, speeds: bool) -> Self {
        Self {
            yaw: YawRateCheck::new(track_m),
            can_pivot,
            speeds,
            last_wheels: None,
            opposed_m: [0.0; 2],
            negated: None,
            compass: CompassTurns::default(),
            gyro_turn_rad: 0.0,
            last_gyro: None,
            still: [None; 2],
            stall: None,
        }
    }

    /// Takes the reading on `row` of the input.
    pub fn push(&mut self, sample: &VehicleSample, row: usize) {
        self.yaw.push_at(sample, row);
        self.compass.push(sample, self.yaw.track_m(), row);
        if let Some((t0, g0)) = self.last_gyro {
            self.gyro_turn_rad += g0 * (sample.t_s - t0);
            self.last_gyro = Some((sample.t_s, g0));
        }
        if let Some(g) = sample.gyr_z_rps.filter(|g| g.is_finite()) {
            self.last_gyro = Some((sample.t_s, g));
        }
        let Some(w) = sample.wheels else { return };
        let now = [w.dist_l_m, w.dist_r_m];
        if let Some(last) = self.last_wheels {
            self.follow_still_wheels(last, now, row);
        }
        if let Some(last) = self.last_wheels.replace(now)
            && !self.can_pivot
            && self.negated.is_none()
        {
            let d = [now[0] - last[0], now[1] - last[1]];
            if d[0] * d[1] < 0.0 {
                let falling = usize::from(d[1] < 0.0);
                self.opposed_m[falling] += d[0].abs().min(d[1].abs());
                if self.opposed_m[falling] >= OPPOSED_M {
                    self.negated = Some((row, falling));
                }
            }
        }
    }

    /// Follows each wheel that stays still while the other moves, and finds a stall.
    fn follow_still_wheels(&mut self, last: [f64; 2], now: [f64; 2], row: usize) {
        let track_m = self.yaw.track_m();
        for side in 0..2 {
            let moved = [now[0] - last[0], now[1] - last[1]];
            if moved[side] != 0.0 || !moved[side].is_finite() {
                self.still[side] = None;
                continue;
            }
            if moved[1 - side] == 0.0 || !moved[1 - side].is_finite() {
                continue;
            }
            let turn = self.gyro_turn_rad;
            let still = self.still[side].get_or_insert(StillWheel {
                from_row: row,
                at_m: now[side],
                other_m: 0.0,
                turn_at_rad: turn,
            });
            still.other_m += moved[1 - side].abs();
            let pivot_rad = still.other_m / track_m;
            let gyro_rad = self.last_gyro.map(|_| (turn - still.turn_at_rad).abs());
            // Without a gyro only a whole circle about the still wheel is beyond doubt.
            let stalled = match gyro_rad {
                Some(g) => still.other_m >= STALL_M && g < 0.5 * pivot_rad,
                None => pivot_rad >= 2.0 * PI,
            };
            if stalled && self.stall.is_none() {
                self.stall = Some(Stall {
                    side,
                    still: *still,
                    pivot_rad,
                    gyro_rad,
                });
            }
        }
    }

    /// A stalled odometer, said as the evidence and what to do, and its row.
    fn stall_message(&self, context: &Context) -> Option<(String, usize)> {
        let s = self.stall?;
        let names = context.wheel_names();
        let (name, other) = (&names[s.side], &names[1 - s.side]);
        let turned = match s.gyro_rad {
            Some(g) => format!("the gyro turned {:.0}°", g.to_degrees()),
            None => "a whole circle about one wheel, which no drive makes".to_string(),
        };
        Some((
            format!(
                "{name} stayed at {} while {other} went {:.1} m: pivoting about that wheel would have turned the vehicle {:.0}°, and {turned}, so the {} odometer stalled (a stuck encoder or a dropped signal), not a unit: leave its cells empty where it stalled, or cut those rows",
                s.still.at_m,
                s.still.other_m,
                s.pivot_rad.to_degrees(),
                if s.side == 0 { "left" } else { "right" }
            ),
            s.still.from_row,
        ))
    }

    /// Everything found, the most telling first: a negated wheel spoils every other
    /// comparison, so it comes alone.
    pub fn findings(&self, context: &Context) -> Vec<Refusal> {
        let [left, right] = context.wheel_names();
        if let Some((row, falling)) = self.negated {
            let (name, other) = if falling == 0 {
                (&left, &right)
            } else {
                (&right, &left)
            };
            return vec![Refusal {
                kind: FindingKind::Axes,
                message: format!(
                    "{name} falls while {other} rises over {OPPOSED_M:.0} m of driving: a car's wheels never turn opposite ways, so {name} has its sign flipped: pass --column {}",
                    context.column_fix(name, name, true)
                ),
                row: Some(row),
            }];
        }
        let mut findings = refusals(&self.yaw.findings(context.gyro_unit), context.options);
        let opposite = self.yaw.agreeing_ratio().is_some_and(|(r, _)| r < 0.0);
        if opposite && let Some(sign) = findings.iter_mut().find(|f| f.kind == FindingKind::Axes) {
            let swap = format!(
                "{},{}",
                context.column_fix(&left, &right, false),
                context.column_fix(&right, &left, false)
            );
            match self.compass.sides_with_gyro() {
                Some(true) => {
                    sign.message = format!(
                        "the wheels turn against gyr_z and the compass over {} turning seconds: the left and right wheels are swapped ({left} holds the right wheel): pass --column {swap}",
                        self.yaw.windows
                    );
                }
                Some(false) => {
                    sign.message += "; the compass turns with the wheels, so it is the gyro";
                }
                None => {
                    sign.message += &format!(
                        ", or, if the gyro is right, the left and right wheels are swapped: pass --column {swap}"
                    );
                }
            }
        }
        if !opposite && let Some(r) = self.compass.mirrored() {
            findings.push(Refusal {
                kind: FindingKind::Axes,
                message: format!(
                    "the compass turns against gyr_z{} over {} turning seconds (correlation {r:.2}): a level compass turns with the vehicle, so it is mirrored — one axis negated or the two swapped: pass --column {} if mag_y is negated, {} if mag_x is, or {},{} if they are swapped (each turns it the right way; they differ by a constant offset only the mounting can tell)",
                    if self.compass.sums[4] > 0.0 { " and the wheels" } else { "" },
                    self.compass.windows,
                    context.column_fix("mag_y", "mag_y", true),
                    context.column_fix("mag_x", "mag_x", true),
                    context.column_fix("mag_x", "mag_y", false),
                    context.column_fix("mag_y", "mag_x", false),
                ),
                row: self.compass.judged_at_row,
            });
        }
        let wheels = format!("{left}, {right}");
        let vehicle = context.vehicle.display().to_string();
        let scale = if self.yaw.agreeing_ratio().is_some() {
            self.yaw.wheel_scale_finding(&wheels, self.speeds, &vehicle)
        } else {
            // Windows chosen by the gyro carry its bias (a raw gyro's few °/s turn every
            // straight second), so only a ratio near a thousand's, which no bias makes,
            // is judged from them.
            self.compass
                .wheels_per_gyro(self.yaw.track_m())
                .filter(|t| t.r2 >= MIN_KM_R2 && (t.ratio.abs() / 1e-3).ln().abs() < 3f64.ln())
                .and_then(|t| t.wheel_scale_finding(&wheels, self.speeds, &vehicle))
        };
        if findings.iter().all(|f| f.kind != FindingKind::Units) {
            findings.extend(scale.map(|f| Refusal::of(&f, context.options)));
        }
        findings
    }

    /// Refuses the drive on the first finding not accepted (`--accept-units`,
    /// `--accept-axes`), naming the input and the row; says each accepted one on stderr.
    /// `e` with what explains it when an odometer stalled (accepted, so the estimator met the
    /// spoiled wheels and refused by their turns).
    pub fn explain(&self, mut e: CliError) -> CliError {
        if let Some(s) = self.stall {
            e.message += &format!(
                " — the {} odometer that stalled at row {} explains this",
                if s.side == 0 { "left" } else { "right" },
                s.still.from_row
            );
        }
        e
    }

    /// A stalled odometer comes first, alone: it spoils the wheels' comparisons with the
    /// gyro (`--accept-sensor-faults` says it and skips them).
    pub fn check(&self, context: &Context) -> CliResult {
        if let Some((message, row)) = self.stall_message(context) {
            if !context.accept_sensor_faults {
                return Err(CliError::row(
                    &context.input,
                    row,
                    format!("{message} (or --accept-sensor-faults to go on)"),
                ));
            }
            errln!("warning: {}: row {row}: {message}", context.input.display());
            return Ok(());
        }
        refuse_or_warn(
            &self.findings(context),
            &context.input,
            context.accept_units,
            context.accept_axes,
        )
    }
}

/// What a finding needs to know about the command line: the files, the options the log
/// was read with and what may be accepted.
#[derive(Debug, Clone)]
pub struct Context<'a> {
    /// The drive log.
    pub input: PathBuf,
    /// The vehicle file.
    pub vehicle: PathBuf,
    /// The gyro's declared unit.
    pub gyro_unit: GyroUnit,
    /// How the log was read.
    pub options: &'a InputOptions,
    /// The wheel columns are speeds.
    pub speeds: bool,
    /// `--accept-units`.
    pub accept_units: bool,
    /// `--accept-axes`.
    pub accept_axes: bool,
    /// `--accept-sensor-faults`.
    pub accept_sensor_faults: bool,
}

impl Context<'_> {
    /// The wheel columns' names.
    fn wheel_names(&self) -> [String; 2] {
        if self.speeds {
            ["speed_l_mps".into(), "speed_r_mps".into()]
        } else {
            ["dist_l_m".into(), "dist_r_m".into()]
        }
    }

    /// `name=[-]HEADER` reading column `name` from where `from` is read now, negated
    /// (against how it is read now) when `negate`.
    fn column_fix(&self, name: &str, from: &str, negate: bool) -> String {
        let mapping = self
            .options
            .columns
            .iter()
            .rev()
            .find(|m| m.name.eq_ignore_ascii_case(from));
        let (header, minus) =
            mapping.map_or((from.to_string(), false), |m| (m.header.clone(), m.negate));
        let sign = if minus != negate { "-" } else { "" };
        format!("{name}={sign}{header}")
    }
}
