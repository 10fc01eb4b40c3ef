//! Drives across the whole physical range of vehicles, sensors and motions, with each sensor
//! at its own rate and rows missing, as real logs come.
//!
//! A [`RangeSpec`] names a seed, a [`VehicleKind`] and the sensors fitted; everything else
//! is drawn from the seed:
//!
//! | what | range drawn |
//! |---|---|
//! | vehicle | [`RangeVehicle::draw`]: car geometry, Pitman ratio 0.1–0.35, skid-steer track factor 1.5–2.5 |
//! | route | opening circle from full lock to 30 m, a turn in place, or none; cars to 36 m/s, robots 0.3–2 m/s |
//! | gyro bias | 0.05–5 °/s either sign, walking 0.002–0.01 °/s/√s |
//! | gyro scale | ±4 % common and ±1 % between turning directions |
//! | gyro noise | 0.005–0.05 °/s/√Hz |
//! | wheel scale | cars: mean ±0.5 %, left against right ±0.5 %, pulses of 1–4 cm; robots: mean ±2 %, ±1 %, 0.1–2 mm |
//! | speed coefficient `a` | cars 0–3·10⁻⁴ s²/m², robots 0 |
//! | compass | hard iron 0.1–0.8 × field, soft iron up to 1.5 : 1 at any angle, noise 0.5–3 % |
//! | rates | gyro 10–100 Hz, wheels 10–50 Hz, compass 2–20 Hz, each with its own phase |
//! | missing readings | 0–2 % dropped one by one, and 0–2 outages of 0.3–2 s per sensor |
//!
//! The truth is integrated at 100 Hz; a row is written wherever a sensor reads, carrying
//! just the readings taken then, and [`RangeDrive::truth`] holds the truth at each row.

use core::f64::consts::PI;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::{Disturbance, HeadingTruth, MagnetometerModel2d};
use truenorth_core::{
    NoiseSource, Result, SensorModel, SplitMix64, VehicleSample, angle_diff, check_range,
};
use truenorth_gyro::{GyroAxisModel, GyroAxisParams, RateTruth};
use truenorth_odometer::{OdometerModel, OdometerParams, WheelGeometry, WheelMotion};

use crate::draw::{between, either_sign, pick};
use crate::drive::{active_at, random_disturbances, soft_iron};
use crate::range_route::{Opening, range_route};
use crate::route::Route;
use crate::streams::VehicleSensorParams;
use crate::vehicle::{VehicleTruth, simulate};
use crate::vehicle_kind::{RangeVehicle, SlipProcess, VehicleKind};

/// Rate of the integrated truth, Hz; every sensor's period is a whole number of its steps.
const TRUTH_HZ: f64 = 100.0;

/// Which sensors are fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fitted {
    /// A yaw-rate gyro.
    pub gyro: bool,
    /// Wheel odometers.
    pub wheels: bool,
    /// A two-axis compass.
    pub compass: bool,
}

impl Fitted {
    /// Gyro, wheels and compass.
    pub const ALL: Self = Self {
        gyro: true,
        wheels: true,
        compass: true,
    };
}

/// What to draw.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeSpec {
    /// Seed of every draw.
    pub seed: u64,
    /// The kind of vehicle.
    pub kind: VehicleKind,
    /// The sensors fitted.
    pub fitted: Fitted,
    /// Length of the route's segments to aim for, m (the speed changes between them add
    /// some): 5 km for cars and 0.6 km for robots by [`RangeSpec::new`].
    pub length_m: f64,
    /// Add magnetic disturbances (as [`crate::DriveSpec`] describes them).
    pub disturbances: bool,
}

impl RangeSpec {
    /// A drive of `kind` with every sensor fitted and disturbances.
    pub fn new(seed: u64, kind: VehicleKind) -> Self {
        Self {
            seed,
            kind,
            fitted: Fitted::ALL,
            length_m: if kind.is_car() { 5000.0 } else { 600.0 },
            disturbances: true,
        }
    }
}

/// Each sensor's rate, Hz.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SensorRates {
    /// Gyro readings per second.
    pub gyro_hz: f64,
    /// Wheel readings per second.
    pub wheels_hz: f64,
    /// Compass readings per second.
    pub compass_hz: f64,
}

/// A drive drawn from the physical range: the truth at each row, the rows, and every true
/// error behind them.
#[derive(Debug, Clone)]
pub struct RangeDrive {
    /// What was asked for.
    pub spec: RangeSpec,
    /// The vehicle drawn.
    pub vehicle: RangeVehicle,
    /// How the drive opened: `None` set off straight away, otherwise the radius of its
    /// opening circle, m (0: a turn in place).
    pub opening_radius_m: Option<f64>,
    /// The route driven.
    pub route: Route,
    /// Ground truth at each row.
    pub truth: Vec<VehicleTruth>,
    /// The rows, each with the readings taken at its time.
    pub samples: Vec<VehicleSample>,
    /// The sensors' true errors (the compass terms are unused without a compass).
    pub params: VehicleSensorParams,
    /// Each sensor's rate.
    pub rates: SensorRates,
    /// The magnetic disturbances (times from the start).
    pub disturbances: Vec<Disturbance>,
}

impl RangeDrive {
    /// Draws the drive `spec` describes.
    pub fn new(spec: RangeSpec) -> Result<Self> {
        check_range("drive length_m", spec.length_m, 1.0, 1e6)?;
        let mut rng = SplitMix64::new(spec.seed);
        let vehicle = RangeVehicle::draw(spec.kind, &mut rng);
        let opening = Opening::draw(&vehicle, &mut rng);
        let route = range_route(&vehicle, opening, spec.length_m, &mut rng)?;
        let params = sensor_errors(&vehicle, &mut rng);
        let grid = simulate(&route, PI * (2.0 * rng.uniform() - 1.0), TRUTH_HZ)?;
        let duration_s = grid.last().map_or(0.0, |t| t.t_s);
        let disturbances = if spec.disturbances && spec.fitted.compass {
            random_disturbances(&mut rng, duration_s, params.horizontal_field)
        } else {
            Vec::new()
        };
        let periods = [
            pick(&mut rng, &[1, 2, 4, 5, 10]),
            pick(&mut rng, &[2, 4, 5, 10]),
            pick(&mut rng, &[5, 10, 20, 50]),
        ];
        let rates = SensorRates {
            gyro_hz: TRUTH_HZ / f64::from(periods[0]),
            wheels_hz: TRUTH_HZ / f64::from(periods[1]),
            compass_hz: TRUTH_HZ / f64::from(periods[2]),
        };
        let mut streams = Streams::new(
            &vehicle,
            &params,
            &disturbances,
            spec.fitted,
            periods,
            duration_s,
            &mut rng,
        )?;
        let (truth, samples) = streams.run(&grid, &mut rng)?;
        Ok(Self {
            spec,
            vehicle,
            opening_radius_m: match opening {
                Opening::None => None,
                Opening::Circle { radius_m, .. } => Some(radius_m),
            },
            route,
            truth,
            samples,
            params,
            rates,
            disturbances,
        })
    }

    /// Distance driven, m.
    pub fn distance_m(&self) -> f64 {
        self.truth.last().map_or(0.0, |t| t.distance_m)
    }

    /// Whether a disturbance is active at `t_s`.
    pub fn disturbed_at(&self, t_s: f64) -> bool {
        active_at(&self.disturbances, t_s)
    }

    /// The odometer's mean scale (`1 +` the mean of the two wheels' scale errors): what
    /// no sensor on board can see.
    pub fn mean_wheel_scale(&self) -> f64 {
        let o = self.params.odometer;
        1.0 + 0.5 * (o.scale_error_l + o.scale_error_r)
    }

    /// Distance per wheel pulse, m (the wheels' resolution).
    pub fn wheel_resolution_m(&self) -> f64 {
        self.params.odometer.dist_per_pulse_m.unwrap_or(1e-3)
    }
}

/// The sensor errors of one installation on `v`.
fn sensor_errors(v: &RangeVehicle, rng: &mut SplitMix64) -> VehicleSensorParams {
    let field = between(rng, 15.0, 40.0);
    let common = between(rng, -0.04, 0.04);
    let car = v.kind.is_car();
    let (mean, diff) = if car { (0.005, 0.005) } else { (0.02, 0.01) };
    let mean = between(rng, -mean, mean);
    let diff = between(rng, -diff, diff);
    let gyro = GyroAxisParams {
        bias_rps: either_sign(rng) * between(rng, 0.05, 5.0).to_radians(),
        bias_walk_rps_per_sqrt_s: between(rng, 0.002, 0.01).to_radians(),
        scale_error_pos: common + between(rng, -0.01, 0.01),
        scale_error_neg: common + between(rng, -0.01, 0.01),
        noise_density_rps_per_sqrt_hz: between(rng, 0.005, 0.05).to_radians(),
        ..GyroAxisParams::PERFECT
    };
    let odometer = OdometerParams {
        wheels: v.wheels,
        scale_error_l: mean + 0.5 * diff,
        scale_error_r: mean - 0.5 * diff,
        speed_coeff_s2_per_m2: if car { between(rng, 0.0, 3e-4) } else { 0.0 },
        dist_per_pulse_m: Some(if car {
            between(rng, 0.01, 0.04)
        } else {
            between(rng, 1e-4, 2e-3)
        }),
    };
    let compass = CompassRanges::RANGE.draw(field, rng);
    VehicleSensorParams {
        gyro,
        gyro_temp_c: 25.0,
        odometer,
        compass_hard_iron: compass.hard_iron,
        compass_soft_iron: compass.soft_iron,
        compass_noise: compass.noise,
        horizontal_field: field,
    }
}

/// The ranges a compass installation's errors are drawn from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CompassRanges {
    /// Hard iron, times the horizontal field, in any direction.
    pub hard_iron: (f64, f64),
    /// Soft iron ratio, major axis at any angle.
    pub soft_iron: (f64, f64),
    /// Noise per axis, times the horizontal field.
    pub noise: (f64, f64),
}

/// One compass installation's errors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CompassDraw {
    pub hard_iron: Vector2<f64>,
    pub soft_iron: nalgebra::Matrix2<f64>,
    pub noise: f64,
}

impl CompassRanges {
    /// The ranges of the module documentation.
    pub const RANGE: Self = Self {
        hard_iron: (0.1, 0.8),
        soft_iron: (1.0, 1.5),
        noise: (0.005, 0.03),
    };

    /// An installation on a horizontal field of `field` µT.
    pub fn draw(&self, field: f64, rng: &mut SplitMix64) -> CompassDraw {
        let hard_iron = {
            let (s, c) = (2.0 * PI * rng.uniform()).sin_cos();
            Vector2::new(c, s) * field * between(rng, self.hard_iron.0, self.hard_iron.1)
        };
        let soft_iron = soft_iron(rng, self.soft_iron.0, self.soft_iron.1);
        CompassDraw {
            hard_iron,
            soft_iron,
            noise: field * between(rng, self.noise.0, self.noise.1),
        }
    }
}

/// When each sensor reads and whether the log keeps the reading.
#[derive(Debug, Clone)]
struct Schedule {
    period: u32,
    phase: u32,
    drop_probability: f64,
    /// Outages, (start, end) in seconds.
    outages: Vec<(f64, f64)>,
    last_read_s: Option<f64>,
}

impl Schedule {
    fn new(period: u32, duration_s: f64, rng: &mut SplitMix64) -> Self {
        let outages = (0..(rng.uniform() * 3.0) as usize)
            .map(|_| {
                let start = between(rng, 0.1, 0.9) * duration_s;
                (start, start + between(rng, 0.3, 2.0))
            })
            .collect();
        Self {
            period,
            phase: (rng.uniform() * f64::from(period)) as u32 % period,
            drop_probability: between(rng, 0.0, 0.02),
            outages,
            last_read_s: None,
        }
    }

    /// Whether the sensor reads at grid step `k` (time `t_s`); `Some(dt)` is the time since
    /// its previous reading (whether or not that one was kept).
    fn reads(&mut self, k: usize, t_s: f64) -> Option<f64> {
        if (k as u64 % u64::from(self.period)) as u32 != self.phase {
            return None;
        }
        let dt = self
            .last_read_s
            .map_or(f64::from(self.period) / TRUTH_HZ, |t0| t_s - t0);
        self.last_read_s = Some(t_s);
        Some(dt)
    }

    /// Whether the log keeps a reading taken at `t_s`.
    fn kept(&self, t_s: f64, rng: &mut SplitMix64) -> bool {
        let out = self.outages.iter().any(|&(a, b)| t_s >= a && t_s < b);
        !out && rng.uniform() >= self.drop_probability
    }
}

/// The sensor models and their schedules while the truth is run through them.
struct Streams {
    fitted: Fitted,
    geometry: WheelGeometry,
    gyro: GyroAxisModel,
    odometer: OdometerModel,
    compass: MagnetometerModel2d,
    slip: SlipProcess,
    schedules: [Schedule; 3],
    temp_c: f64,
    field: f64,
}

impl Streams {
    fn new(
        v: &RangeVehicle,
        p: &VehicleSensorParams,
        disturbances: &[Disturbance],
        fitted: Fitted,
        periods: [u32; 3],
        duration_s: f64,
        rng: &mut SplitMix64,
    ) -> Result<Self> {
        let mut compass =
            MagnetometerModel2d::new(p.compass_hard_iron, p.compass_soft_iron, p.compass_noise)?;
        for d in disturbances {
            compass = compass.with_disturbance(*d)?;
        }
        Ok(Self {
            fitted,
            geometry: WheelGeometry::new(v.wheels)?,
            gyro: GyroAxisModel::new(p.gyro)?,
            odometer: OdometerModel::new(p.odometer)?,
            compass,
            slip: SlipProcess::new(v.slip, rng),
            schedules: periods.map(|period| Schedule::new(period, duration_s, rng)),
            temp_c: p.gyro_temp_c,
            field: p.horizontal_field,
        })
    }

    /// The truth at each row and the rows.
    fn run(
        &mut self,
        grid: &[VehicleTruth],
        rng: &mut SplitMix64,
    ) -> Result<(Vec<VehicleTruth>, Vec<VehicleSample>)> {
        let mut truth = Vec::new();
        let mut rows = Vec::new();
        let peak = peak_curvature(&self.geometry);
        for (k, s) in grid.iter().enumerate() {
            if let Some(p) = k.checked_sub(1).and_then(|j| grid.get(j)) {
                self.roll_wheels(p, s, peak, rng)?;
            }
            let mut row = VehicleSample::at(s.t_s);
            if let Some(dt) = self.schedules[0].reads(k, s.t_s) {
                let rate = RateTruth {
                    rate_rps: s.yaw_rate_rps,
                    temp_c: self.temp_c,
                };
                let g = self.gyro.sample(&rate, dt, rng)?;
                if self.fitted.gyro && self.schedules[0].kept(s.t_s, rng) {
                    row = row.with_gyro(g);
                }
            }
            if self.schedules[1].reads(k, s.t_s).is_some()
                && self.fitted.wheels
                && self.schedules[1].kept(s.t_s, rng)
            {
                let c = self.odometer.cumulative_m();
                row = row.with_wheels(c.left_m, c.right_m);
            }
            if let Some(dt) = self.schedules[2].reads(k, s.t_s) {
                if k == self.schedules[2].phase as usize {
                    // The first reading: the model's clock starts here.
                    self.compass.set_time_s(s.t_s - dt);
                }
                let heading = HeadingTruth {
                    heading_rad: s.heading_rad,
                    horizontal_field: self.field,
                };
                let m = self.compass.sample(&heading, dt, rng)?;
                if self.fitted.compass && self.schedules[2].kept(s.t_s, rng) {
                    row = row.with_mag(m);
                }
            }
            if row.wheels.is_some() || row.gyr_z_rps.is_some() || row.mag.is_some() {
                truth.push(*s);
                rows.push(row);
            }
        }
        Ok((truth, rows))
    }

    /// Rolls the odometer wheels from `p` to `s`: the wheels see the turn times the slip.
    fn roll_wheels(
        &mut self,
        p: &VehicleTruth,
        s: &VehicleTruth,
        peak_curvature: f64,
        rng: &mut SplitMix64,
    ) -> Result<()> {
        let dt = s.t_s - p.t_s;
        let a_lat = s.speed_mps * s.yaw_rate_rps;
        let factor = self.slip.step(dt, a_lat, rng);
        let motion = wheel_motion(p, s, factor, peak_curvature);
        self.odometer.sample(&motion, dt, rng)?;
        Ok(())
    }
}

/// The largest curvature the wheels of `geometry` are driven at: just short of the peak an
/// Ackermann front axle can report, unlimited for an unsteered axle.
pub(crate) fn peak_curvature(geometry: &WheelGeometry) -> f64 {
    match geometry {
        WheelGeometry::Front(g) => 0.98 * g.peak_curvature_per_m(),
        WheelGeometry::Rear { .. } => f64::INFINITY,
    }
}

/// What the wheels roll from `p` to `s` when they see `factor` times the vehicle's turn (a
/// turn in place when the vehicle does not move), the curvature limited to
/// `peak_curvature`.
pub(crate) fn wheel_motion(
    p: &VehicleTruth,
    s: &VehicleTruth,
    factor: f64,
    peak_curvature: f64,
) -> WheelMotion {
    let ds = s.distance_m - p.distance_m;
    let dpsi = angle_diff(s.heading_rad, p.heading_rad) * factor;
    if ds > 0.0 {
        WheelMotion {
            ds_m: ds,
            curvature_per_m: (dpsi / ds).clamp(-peak_curvature, peak_curvature),
            speed_mps: ds / (s.t_s - p.t_s),
            pivot_rad: 0.0,
        }
    } else {
        WheelMotion {
            pivot_rad: dpsi,
            ..WheelMotion::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_drive_is_repeatable_and_its_rows_carry_subsets() {
        for kind in VehicleKind::ALL {
            let spec = RangeSpec::new(3, kind);
            let a = RangeDrive::new(spec).unwrap();
            let b = RangeDrive::new(spec).unwrap();
            assert_eq!(a.samples, b.samples);
            assert_eq!(a.truth.len(), a.samples.len());
            assert!(
                a.distance_m() >= 0.8 * spec.length_m,
                "{kind:?} {}",
                a.distance_m()
            );
            // Sensors at their own rates: some rows lack the wheels, some the compass.
            assert!(a.samples.iter().any(|s| s.wheels.is_none()));
            assert!(a.samples.iter().any(|s| s.mag.is_none()));
            for (s, t) in a.samples.iter().zip(&a.truth) {
                assert_eq!(s.t_s, t.t_s);
            }
        }
    }

    #[test]
    fn a_skid_steer_robot_s_wheels_turn_further_than_it_does() {
        let d = RangeDrive::new(RangeSpec::new(5, VehicleKind::SkidSteer)).unwrap();
        let track = d.vehicle.wheels.track_m();
        let (first, last) = (
            d.samples.iter().find_map(|s| s.wheels).unwrap(),
            d.samples.iter().rev().find_map(|s| s.wheels).unwrap(),
        );
        let turned =
            d.truth.last().unwrap().heading_unwrapped_rad - d.truth[0].heading_unwrapped_rad;
        let wheels = ((last.dist_l_m - first.dist_l_m) - (last.dist_r_m - first.dist_r_m)) / track;
        // The net turn of the whole drive, seen by the wheels, is 1.5–2.5 times the truth
        // (the scale difference and slip move it a little).
        if turned.abs() > 4.0 * PI {
            let ratio = wheels / turned;
            assert!((1.3..2.8).contains(&ratio), "{ratio}");
        }
    }

    #[test]
    fn fitted_sensors_only() {
        let spec = RangeSpec {
            fitted: Fitted {
                gyro: true,
                wheels: false,
                compass: true,
            },
            ..RangeSpec::new(2, VehicleKind::RearWheelCar)
        };
        let d = RangeDrive::new(spec).unwrap();
        assert!(d.samples.iter().all(|s| s.wheels.is_none()));
        assert!(d.samples.iter().any(|s| s.gyr_z_rps.is_some()));
    }
}
