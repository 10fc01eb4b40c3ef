//! The kinds of sample the commands read ([`SampleKind`]): a two- or three-axis
//! magnetometer, with the accelerometer or the yaw gyro beside it, a compass reading to turn
//! into a heading, an IMU, a vehicle's sensors. Each names its columns, finds them and makes
//! its sample of a row, in the library's units.

use std::path::Path;

use nalgebra::{Vector2, Vector3};
use truenorth::calib::{MagAccelSample, TurnSample};
use truenorth::checks::{AccUnit, GyroUnit};
use truenorth::core::{Axes, GnssFix, ImuSample, Mag2Sample, Mag3Sample, VehicleSample};

use super::columns::DRIVE;
use super::reader::{RowReader, RowRef};
use super::samples::SampleKind;
use super::wheels::{DistanceColumn, FourWheels, WheelColumns};
use crate::io::{CliError, CliResult};

const MAG2: [&str; 2] = ["mag_x", "mag_y"];
const MAG3: [&str; 3] = ["mag_x", "mag_y", "mag_z"];
const ACC3: [&str; 3] = ["acc_x", "acc_y", "acc_z"];
const GYR3: [&str; 3] = ["gyr_x", "gyr_y", "gyr_z"];

/// The position of a column the reader was asked for and requires (so present).
fn at(rows: &RowReader, name: &str) -> usize {
    rows.index(name).unwrap_or(0)
}

/// The positions of three required columns.
fn at3(rows: &RowReader, names: [&str; 3]) -> [usize; 3] {
    names.map(|n| at(rows, n))
}

/// Three columns of a row as a vector.
fn vector(r: &RowRef<'_>, [x, y, z]: [usize; 3]) -> Vector3<f64> {
    Vector3::new(r[x], r[y], r[z])
}

/// A calibration's time: `t_s` where the file has it, else the sample's index (rows one
/// second apart).
#[derive(Debug, Clone, Copy, Default)]
struct Time {
    column: Option<usize>,
    index: usize,
}

impl Time {
    fn next(&mut self, r: &RowRef<'_>) -> f64 {
        let t = self.column.map_or(self.index as f64, |i| r[i]);
        self.index += 1;
        t
    }
}

/// Two-axis magnetometer readings (`mag_x,mag_y`, `t_s` where present).
#[derive(Debug, Clone, Default)]
pub struct Mag2 {
    time: Time,
    mag: [usize; 2],
}

impl SampleKind for Mag2 {
    type Sample = Mag2Sample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (&MAG2, &["t_s"])
    }

    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.time.column = rows.index("t_s");
        self.mag = MAG2.map(|n| at(rows, n));
        Ok(())
    }

    fn sample(&mut self, r: &RowRef<'_>, _: &Path) -> CliResult<Mag2Sample> {
        let [x, y] = self.mag;
        Ok(Mag2Sample {
            t_s: self.time.next(r),
            mag: Vector2::new(r[x], r[y]),
        })
    }
}

/// Three-axis magnetometer readings (`mag_x,mag_y,mag_z`, `t_s` where present).
#[derive(Debug, Clone, Default)]
pub struct Mag3 {
    time: Time,
    mag: [usize; 3],
}

impl SampleKind for Mag3 {
    type Sample = Mag3Sample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (&MAG3, &["t_s"])
    }

    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.time.column = rows.index("t_s");
        self.mag = at3(rows, MAG3);
        Ok(())
    }

    fn sample(&mut self, r: &RowRef<'_>, _: &Path) -> CliResult<Mag3Sample> {
        Ok(Mag3Sample {
            t_s: self.time.next(r),
            mag: vector(r, self.mag),
        })
    }
}

/// Magnetometer and accelerometer readings together (`t_s` where present).
#[derive(Debug, Clone, Default)]
pub struct MagAccel {
    time: Time,
    mag: [usize; 3],
    acc: [usize; 3],
}

impl SampleKind for MagAccel {
    type Sample = MagAccelSample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (
            &["mag_x", "mag_y", "mag_z", "acc_x", "acc_y", "acc_z"],
            &["t_s"],
        )
    }

    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.time.column = rows.index("t_s");
        self.mag = at3(rows, MAG3);
        self.acc = at3(rows, ACC3);
        Ok(())
    }

    fn sample(&mut self, r: &RowRef<'_>, _: &Path) -> CliResult<MagAccelSample> {
        Ok(MagAccelSample {
            t_s: self.time.next(r),
            mag: vector(r, self.mag),
            acc: vector(r, self.acc),
        })
    }
}

/// One turn of a two-axis compass, with the yaw gyro where the file has `gyr_z` (then
/// `t_s` is needed: the rate is integrated over time).
#[derive(Debug, Clone, Default)]
pub struct Turn {
    mag: Mag2,
    gyr: Option<usize>,
}

impl Turn {
    /// Whether the file has the yaw gyro.
    pub fn has_gyro(&self) -> bool {
        self.gyr.is_some()
    }
}

impl SampleKind for Turn {
    type Sample = TurnSample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (&MAG2, &["t_s", "gyr_z"])
    }

    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.mag.locate(rows)?;
        self.gyr = rows.index("gyr_z");
        if self.gyr.is_some() && rows.index("t_s").is_none() {
            return Err(CliError::file(
                rows.path(),
                "`gyr_z` needs a `t_s` column: the gyro's rate is integrated over time (or drop `gyr_z` to calibrate the compass alone)",
            ));
        }
        Ok(())
    }

    /// The turn's sample: the yaw rate NaN without a gyro.
    fn sample(&mut self, r: &RowRef<'_>, path: &Path) -> CliResult<TurnSample> {
        let m = self.mag.sample(r, path)?;
        Ok(TurnSample {
            t_s: m.t_s,
            gyr_z_rps: self.gyr.map_or(f64::NAN, |g| r[g]),
            mag: m.mag,
        })
    }
}

/// One raw compass reading to turn into a heading: time, the magnetometer (`mag_z` NaN for
/// a two-axis one) and the accelerometer where the file has all three axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompassReading {
    /// Time, s.
    pub t_s: f64,
    /// Magnetometer, input unit.
    pub mag: Vector3<f64>,
    /// Specific force, any unit.
    pub acc: Option<Vector3<f64>>,
}

/// The readings a compass calibration of `dimensions` axes is applied to: `t_s,mag_x,mag_y`
/// (and `mag_z`, with the accelerometer where present, for three).
#[derive(Debug, Clone)]
pub struct Compass {
    dimensions: usize,
    t: usize,
    mag: [usize; 2],
    z: Option<usize>,
    acc: Option<[usize; 3]>,
}

impl Compass {
    /// Readings for a calibration of `dimensions` (2 or 3) axes.
    pub fn new(dimensions: usize) -> Self {
        Self {
            dimensions,
            t: 0,
            mag: [0; 2],
            z: None,
            acc: None,
        }
    }

    /// Whether the file has the accelerometer.
    pub fn has_acc(&self) -> bool {
        self.acc.is_some()
    }
}

impl SampleKind for Compass {
    type Sample = CompassReading;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        if self.dimensions == 2 {
            (&["t_s", "mag_x", "mag_y"], &[])
        } else {
            (&["t_s", "mag_x", "mag_y", "mag_z"], &ACC3)
        }
    }

    /// Finds the columns; refuses an input with some of the accelerometer's but not all.
    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.acc = match ACC3.map(|n| rows.index(n)) {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            [None, None, None] => None,
            _ => {
                return Err(CliError::row(
                    rows.path(),
                    1,
                    "the input has some of acc_x, acc_y, acc_z but not all three; give all three for tilt compensation, or none to assume a level sensor",
                ));
            }
        };
        self.t = at(rows, "t_s");
        self.mag = MAG2.map(|n| at(rows, n));
        self.z = rows.index("mag_z");
        Ok(())
    }

    fn sample(&mut self, r: &RowRef<'_>, _: &Path) -> CliResult<CompassReading> {
        let [x, y] = self.mag;
        Ok(CompassReading {
            t_s: r[self.t],
            mag: Vector3::new(r[x], r[y], self.z.map_or(f64::NAN, |z| r[z])),
            acc: self.acc.map(|a| vector(r, a)),
        })
    }
}

/// IMU rows: gyro and accelerometer in their declared units, turned into rad/s and m/s²,
/// and the magnetometer where the row has it; a row whose three magnetometer cells are empty
/// has no magnetometer reading, and without `use_mag` none has.
#[derive(Debug, Clone)]
pub struct Imu {
    to_rps: f64,
    to_mps2: f64,
    use_mag: bool,
    t: usize,
    gyr: [usize; 3],
    acc: [usize; 3],
    mag: Option<[usize; 3]>,
    mag_columns: usize,
}

impl Imu {
    /// How many of `mag_x,mag_y,mag_z` the file has (the magnetometer is read with all
    /// three).
    pub fn mag_columns(&self) -> usize {
        self.mag_columns
    }

    /// IMU rows in `gyro` and `acc` units; the magnetometer read when `use_mag`.
    pub fn new(gyro: GyroUnit, acc: AccUnit, use_mag: bool) -> Self {
        Self {
            to_rps: gyro.to_rad_per_s(),
            to_mps2: acc.to_mps2(),
            use_mag,
            t: 0,
            gyr: [0; 3],
            acc: [0; 3],
            mag: None,
            mag_columns: 0,
        }
    }
}

impl SampleKind for Imu {
    type Sample = ImuSample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (
            &["t_s", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z"],
            &MAG3,
        )
    }

    fn locate(&mut self, rows: &RowReader) -> CliResult {
        self.t = at(rows, "t_s");
        self.gyr = at3(rows, GYR3);
        self.acc = at3(rows, ACC3);
        self.mag_columns = MAG3.iter().filter(|n| rows.index(n).is_some()).count();
        self.mag = match MAG3.map(|n| rows.index(n)) {
            [Some(x), Some(y), Some(z)] if self.use_mag => Some([x, y, z]),
            _ => None,
        };
        Ok(())
    }

    fn sample(&mut self, r: &RowRef<'_>, _: &Path) -> CliResult<ImuSample> {
        Ok(ImuSample {
            t_s: r[self.t],
            gyr_rps: Axes::xyz(vector(r, self.gyr) * self.to_rps),
            acc_mps2: Axes::xyz(vector(r, self.acc) * self.to_mps2),
            mag: match self.mag {
                Some([x, y, z]) if r[x].is_nan() && r[y].is_nan() && r[z].is_nan() => Axes::NONE,
                Some(m) => Axes::xyz(vector(r, m)),
                None => Axes::NONE,
            },
        })
    }
}

/// A satellite fix's columns: latitude and longitude, and what the receiver reports with
/// them.
#[derive(Debug, Clone, Copy)]
struct GnssColumns {
    lat: usize,
    lon: usize,
    sigma: Option<usize>,
    /// Speed and course over ground, both or neither.
    velocity: Option<[usize; 2]>,
}

/// A vehicle's sensors, each on the rows that carry it: the wheels (cumulative distances,
/// or speeds integrated into them) or the vehicle's one distance or speed, the yaw gyro in
/// its declared unit, a raw two-axis compass. Something that measures the heading or its
/// changes must be there: wheels, a gyro or a compass.
#[derive(Debug, Clone)]
pub struct Vehicle {
    to_rps: f64,
    t: usize,
    wheels: Option<WheelColumns>,
    /// The vehicle's one distance (`dist_m`) or speed (`speed_mps`), where there are no
    /// wheels.
    distance: Option<DistanceColumn>,
    /// Which of four wheel speeds are the odometer's, where a log gives four.
    four_wheels: FourWheels,
    /// The columns the log gives that are not used, each with why, said on stderr.
    unused: Vec<(&'static str, &'static str)>,
    gyr: Option<usize>,
    /// `mag_x` and `mag_y`, where present.
    mag: [Option<usize>; 2],
    /// A satellite fix's columns, where present.
    gnss: Option<GnssColumns>,
}

impl Vehicle {
    /// A vehicle's rows with the yaw gyro in `gyro` units, and `four_wheels` the odometer's
    /// wheels where the log gives a car's four wheel speeds.
    pub fn new(gyro: GyroUnit, four_wheels: FourWheels) -> Self {
        Self {
            to_rps: gyro.to_rad_per_s(),
            t: 0,
            wheels: None,
            distance: None,
            four_wheels,
            unused: Vec::new(),
            gyr: None,
            mag: [None; 2],
            gnss: None,
        }
    }

    /// Whether the log carries odometry: wheels, or the vehicle's one distance or speed.
    pub fn has_odometry(&self) -> bool {
        self.wheels.is_some() || self.distance.is_some()
    }

    /// Whether the log carries satellite fixes (`lat_deg,lon_deg`).
    pub fn has_gnss(&self) -> bool {
        self.gnss.is_some()
    }

    /// Whether the fixes carry their speed and course over ground.
    pub fn gnss_course_given(&self) -> bool {
        self.gnss.is_some_and(|g| g.velocity.is_some())
    }

    /// Whether the fixes carry their accuracy (`gnss_sigma_m`).
    pub fn gnss_sigma_given(&self) -> bool {
        self.gnss.is_some_and(|g| g.sigma.is_some())
    }

    /// Whether the wheel columns are speeds (or the vehicle's one speed).
    pub fn speeds(&self) -> bool {
        matches!(
            self.wheels,
            Some(WheelColumns::Speeds { .. } | WheelColumns::FourSpeeds { .. })
        ) || matches!(self.distance, Some(DistanceColumn::Speed { .. }))
    }

    /// The columns the log gives that are not used (a distance beside wheels, the wheels of
    /// the axle that is not the odometer's), each with why.
    pub fn unused_columns(&self) -> &[(&'static str, &'static str)] {
        &self.unused
    }

    /// Refuses a compass with one axis and not the other (`path` names the file). Asked
    /// apart from [`SampleKind::locate`], once the vehicle and the method are set up, so
    /// that their own errors come first.
    pub fn check_compass(&self, path: &Path) -> CliResult {
        match self.mag {
            [Some(_), None] | [None, Some(_)] => Err(CliError::row(
                path,
                1,
                "has one of mag_x, mag_y but not both; give both (any unit, uncalibrated) or neither",
            )),
            _ => Ok(()),
        }
    }
}

impl Vehicle {
    /// The satellite fix's columns: latitude and longitude together or neither; speed and
    /// course over ground together or neither (one without the other is said unused).
    fn locate_gnss(&mut self, rows: &RowReader) -> CliResult {
        let ix = |n: &str| rows.index(n);
        let (lat, lon) = match (ix("lat_deg"), ix("lon_deg")) {
            (Some(lat), Some(lon)) => (lat, lon),
            (None, None) => {
                for name in ["gnss_sigma_m", "gnss_speed_mps", "gnss_course_deg"] {
                    if ix(name).is_some() {
                        self.unused
                            .push((name, "there is no fix (`lat_deg,lon_deg`) to go with it"));
                    }
                }
                return Ok(());
            }
            _ => {
                return Err(CliError::row(
                    rows.path(),
                    1,
                    "has one of lat_deg, lon_deg but not both: a fix needs both (WGS84 degrees), or neither",
                ));
            }
        };
        let velocity = match (ix("gnss_speed_mps"), ix("gnss_course_deg")) {
            (Some(s), Some(c)) => Some([s, c]),
            (Some(_), None) => {
                self.unused.push((
                    "gnss_speed_mps",
                    "a speed over ground is used with its course (`gnss_course_deg`)",
                ));
                None
            }
            (None, Some(_)) => {
                self.unused.push(("gnss_course_deg", "a course is used with its speed over ground (`gnss_speed_mps`): below a few m/s it is noise"));
                None
            }
            (None, None) => None,
        };
        self.gnss = Some(GnssColumns {
            lat,
            lon,
            sigma: ix("gnss_sigma_m"),
            velocity,
        });
        Ok(())
    }
}

impl SampleKind for Vehicle {
    type Sample = VehicleSample;

    fn columns(&self) -> (&'static [&'static str], &'static [&'static str]) {
        (&["t_s"], &DRIVE)
    }

    /// The wheel columns (distances before speeds), the gyro and the compass; an error if
    /// the log has neither wheels nor a gyro (for the compass's axes see
    /// [`Vehicle::check_compass`]).
    fn locate(&mut self, rows: &RowReader) -> CliResult {
        let ix = |n: &str| rows.index(n);
        self.wheels = match (
            ix("dist_l_m"),
            ix("dist_r_m"),
            ix("speed_l_mps"),
            ix("speed_r_mps"),
        ) {
            (Some(l), Some(r), _, _) => Some(WheelColumns::Distances([l, r])),
            (_, _, Some(l), Some(r)) => Some(WheelColumns::Speeds {
                columns: [l, r],
                last: None,
                dist: [0.0; 2],
            }),
            _ => None,
        };
        let four = [
            "speed_fl_mps",
            "speed_fr_mps",
            "speed_rl_mps",
            "speed_rr_mps",
        ]
        .map(ix);
        if let [Some(fl), Some(fr), Some(rl), Some(rr)] = four {
            if self.wheels.is_some() {
                self.unused.push((
                    "speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps",
                    "the odometer wheels' own columns give the distance and the turn",
                ));
            } else {
                self.wheels = Some(WheelColumns::FourSpeeds {
                    columns: [fl, fr, rl, rr],
                    pick: self.four_wheels,
                    last: None,
                    dist: [0.0; 2],
                });
                if let Some(name) = self.four_wheels.unused() {
                    self.unused
                        .push((name, "the vehicle's odometer_wheels names the other axle"));
                }
            }
        } else if four.iter().any(Option::is_some) {
            return Err(CliError::row(
                rows.path(),
                1,
                "has some of the four wheel speeds and not all: give `speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps` together, or the odometer wheels as `speed_l_mps,speed_r_mps`",
            ));
        }
        let single = match (ix("dist_m"), ix("speed_mps")) {
            (Some(c), _) => Some((DistanceColumn::Distance(c), "dist_m")),
            (None, Some(column)) => Some((
                DistanceColumn::Speed {
                    column,
                    last: None,
                    dist: 0.0,
                },
                "speed_mps",
            )),
            (None, None) => None,
        };
        match single {
            Some((_, name)) if self.wheels.is_some() => self.unused.push((
                name,
                "the wheels' own columns give the distance, and the turn besides",
            )),
            Some((c, _)) => self.distance = Some(c),
            None => {}
        }
        self.locate_gnss(rows)?;
        let compass = ix("mag_x").is_some() && ix("mag_y").is_some();
        let speed_and_compass = compass && self.distance.is_some();
        if self.wheels.is_none() && ix("gyr_z").is_none() && !speed_and_compass {
            return Err(CliError::row(
                rows.path(),
                1,
                if self.distance.is_some() {
                    "has a distance or speed but nothing that measures the heading: add a yaw gyro (`gyr_z`, rad/s), the wheels' own distances or speeds (`dist_l_m,dist_r_m` or `speed_l_mps,speed_r_mps`), or a compass (`mag_x,mag_y`)"
                } else if compass {
                    "needs a heading sensor besides the compass: the wheels (`dist_l_m,dist_r_m` or `speed_l_mps,speed_r_mps`), a gyro (`gyr_z`, rad/s), or a vehicle speed (`speed_mps` or `dist_m`) to travel along it (a compass alone: `truenorth heading`)"
                } else {
                    "needs a heading sensor: the wheels (`dist_l_m,dist_r_m` cumulative distances or `speed_l_mps,speed_r_mps` wheel speeds) or a gyro (`gyr_z`, rad/s)"
                },
            ));
        }
        self.mag = [ix("mag_x"), ix("mag_y")];
        self.t = at(rows, "t_s");
        self.gyr = ix("gyr_z");
        Ok(())
    }

    /// The sample a row carries: each sensor whose cells are filled (wheel speeds
    /// integrated into distances on the way).
    fn sample(&mut self, row: &RowRef<'_>, path: &Path) -> CliResult<VehicleSample> {
        let v = row.values;
        let mut sample = VehicleSample::at(v[self.t]);
        if let Some(w) = self.wheels.as_mut()
            && let Some([l, r]) = w
                .cumulative(v[self.t], v)
                .map_err(|m| CliError::row(path, row.number, m))?
        {
            sample = sample.with_wheels(l, r);
        }
        if let Some(d) = self
            .distance
            .as_mut()
            .and_then(|d| d.cumulative(v[self.t], v))
        {
            sample = sample.with_distance(d);
        }
        if let Some(g) = self.gyr.map(|g| v[g]).filter(|g| g.is_finite()) {
            sample = sample.with_gyro(g * self.to_rps);
        }
        if let [Some(x), Some(y)] = self.mag
            && v[x].is_finite()
            && v[y].is_finite()
        {
            sample = sample.with_mag(Vector2::new(v[x], v[y]));
        }
        if let Some(g) = self.gnss
            && v[g.lat].is_finite()
            && v[g.lon].is_finite()
        {
            let mut fix = GnssFix::at(v[g.lat], v[g.lon]);
            fix.sigma_m = g.sigma.map(|c| v[c]).filter(|s| s.is_finite());
            if let Some([s, c]) = g.velocity
                && v[s].is_finite()
                && v[c].is_finite()
            {
                fix = fix.with_velocity(v[s], v[c]);
            }
            sample = sample.with_gnss(fix);
        }
        Ok(sample)
    }
}
