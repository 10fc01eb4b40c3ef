//! The configuration of a drive as real logs come: the vehicle, its sensors, how it moves,
//! how its readings are timed, and the ranges every error is drawn from.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_range};

use super::body_tilt::TiltConfig;
use super::gnss_config::GnssConfig;
use super::motion::{MotionConfig, Rests, RouteShape};
use super::sensor_set::SensorSet;
use super::skid_ground::SkidSteerConfig;
use super::span::Span;
use super::timing::TimingConfig;
use super::wheel_controller::WheelConfig;
use super::yaw_sensor::YawRateConfig;
use crate::VehicleKind;
use crate::range_drive::CompassRanges;

/// The ranges a compass installation's errors are drawn from, each uniformly per drive
/// (defaults in brackets: those of [`crate::RangeDrive`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CompassConfig {
    /// Horizontal field, µT (15–40; 1–100).
    pub field_ut: Span,
    /// Hard iron, times the horizontal field, in any direction (0.1–0.8; 0–5).
    pub hard_iron: Span,
    /// Soft iron, major over minor axis, the major axis at any angle (1–1.5; 1–5).
    pub soft_iron_ratio: Span,
    /// Noise per axis, times the horizontal field (0.005–0.03; 0–0.5).
    pub noise: Span,
    /// Magnetic disturbances on the way (true): short strong ones and long slow ones that
    /// turn the field, as [`crate::DriveSpec`] describes them.
    pub disturbances: bool,
    /// The declination, degrees east (−180–180): the compass sees the true heading less
    /// it. `None` (the default): the World Magnetic Model's at the GNSS origin when the
    /// drive has a GNSS receiver, 0 otherwise.
    pub declination_deg: Option<f64>,
}

impl Default for CompassConfig {
    fn default() -> Self {
        let r = CompassRanges::RANGE;
        Self {
            field_ut: Span::new(15.0, 40.0),
            hard_iron: Span::new(r.hard_iron.0, r.hard_iron.1),
            soft_iron_ratio: Span::new(r.soft_iron.0, r.soft_iron.1),
            noise: Span::new(r.noise.0, r.noise.1),
            disturbances: true,
            declination_deg: None,
        }
    }
}

impl CompassConfig {
    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.field_ut.check("compass field_ut", 1.0, 100.0)?;
        self.hard_iron.check("compass hard_iron", 0.0, 5.0)?;
        self.soft_iron_ratio
            .check("compass soft_iron_ratio", 1.0, 5.0)?;
        self.noise.check("compass noise", 0.0, 0.5)?;
        if let Some(d) = self.declination_deg {
            check_range("compass declination_deg", d, -180.0, 180.0)?;
        }
        Ok(())
    }

    pub(crate) fn ranges(&self) -> CompassRanges {
        CompassRanges {
            hard_iron: (self.hard_iron.lo, self.hard_iron.hi),
            soft_iron: (self.soft_iron_ratio.lo, self.soft_iron_ratio.hi),
            noise: (self.noise.lo, self.noise.hi),
        }
    }
}

/// A habit of real logs, which [`LogDriveConfig::without`] leaves out so that an ensemble
/// can be run with and without each one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Habit {
    /// Starting and ending in motion. Without: a standstill of 3–12 s first and a stop at
    /// the end.
    InMotion,
    /// Rare, short rests. Without: stops as a simulator makes them, 2–30 s about every
    /// minute, the first at once.
    RareRests,
    /// Each sensor at its own rate and instants. Without: all on the odometry's clock.
    OwnClocks,
    /// Latency and arrival jitter. Without: each reading stamped at the instant it
    /// measured (to the stamps' resolution).
    Latency,
    /// Lost readings. Without: none lost.
    Drops,
    /// The odometry's speed filter. Without: no lag.
    WheelLag,
    /// Quantised readings: speeds, counts, distances, yaw rates. Without: continuous (counts
    /// of 1 µm).
    Quanta,
    /// The yaw-rate sensor's scale errors. Without: none.
    YawScale,
    /// The yaw-rate sensor's mounting tilt. Without: upright.
    Tilt,
    /// A skid-steer's effective track changing with the ground and the turn. Without: one
    /// track factor for the whole drive.
    VaryingTrack,
    /// GNSS outages. Without: none.
    GnssOutages,
    /// Urban canyons: larger errors and multipath jumps. Without: none.
    GnssCanyons,
    /// Frozen fixes. Without: none.
    GnssFrozen,
    /// Fixes seconds late. Without: none (the receiver's usual latency stays).
    GnssLate,
    /// A time-correlated GNSS error. Without: white (a correlation time of 10 ms).
    GnssCorrelation,
    /// The antenna's lever arm. Without: the antenna over the rear-axle centre.
    LeverArm,
    /// The body's roll and pitch under a level-assumed compass. Without: a level compass.
    CompassTilt,
}

impl Habit {
    /// Every habit.
    pub const ALL: [Self; 17] = [
        Self::InMotion,
        Self::RareRests,
        Self::OwnClocks,
        Self::Latency,
        Self::Drops,
        Self::WheelLag,
        Self::Quanta,
        Self::YawScale,
        Self::Tilt,
        Self::VaryingTrack,
        Self::GnssOutages,
        Self::GnssCanyons,
        Self::GnssFrozen,
        Self::GnssLate,
        Self::GnssCorrelation,
        Self::LeverArm,
        Self::CompassTilt,
    ];
}

/// A robot's geometry and speed where a test wants them fixed rather than drawn from the
/// kind's range (cars ignore it).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RobotConfig {
    /// The physical track, m, drawn uniformly (none: the kind's range; 0.1–3).
    pub track_m: Option<Span>,
    /// The cruising speed, m/s, drawn uniformly per segment (none: the kind's range;
    /// 0.05–5).
    pub speed_mps: Option<Span>,
}

impl RobotConfig {
    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        if let Some(t) = self.track_m {
            t.check("robot track_m", 0.1, 3.0)?;
        }
        if let Some(v) = self.speed_mps {
            v.check("robot speed_mps", 0.05, 5.0)?;
        }
        Ok(())
    }
}

/// What to simulate: a vehicle, its sensors, and every habit of a real log. Build it with
/// [`LogDriveConfig::new`], which picks the defaults of the vehicle's kind, then change
/// what a test needs. Every error and habit is drawn from `seed`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LogDriveConfig {
    /// Seed of every draw.
    pub seed: u64,
    /// The kind of vehicle.
    pub kind: VehicleKind,
    /// The sensors the log carries.
    pub sensors: SensorSet,
    /// How the vehicle moves.
    pub motion: MotionConfig,
    /// When each sensor reads and how its readings reach the log.
    pub timing: TimingConfig,
    /// How the odometry reads.
    pub wheels: WheelConfig,
    /// The yaw-rate sensor's error ranges.
    pub yaw_rate: YawRateConfig,
    /// The compass's error ranges.
    pub compass: CompassConfig,
    /// How a skid-steer's sides see its turns (used for [`VehicleKind::SkidSteer`] only).
    pub skid_steer: SkidSteerConfig,
    /// A robot's geometry and speed, where fixed (robots only).
    pub robot: RobotConfig,
    /// A GNSS receiver (`None`, the default: none; [`GnssConfig::for_car`] and
    /// [`GnssConfig::for_robot`] give one).
    pub gnss: Option<GnssConfig>,
    /// How the body tilts under the compass ([`TiltConfig::for_car`] or
    /// [`TiltConfig::for_robot`]; `None`: a level compass).
    pub tilt: Option<TiltConfig>,
}

impl Default for LogDriveConfig {
    /// A rear-wheel car's CAN bus: vehicle speed and yaw rate, seed 0.
    fn default() -> Self {
        Self::new(0, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW)
    }
}

impl LogDriveConfig {
    /// A drive of a `kind` vehicle carrying `sensors`, with the defaults of its kind: a car
    /// on roads with its ESP yaw rate and ABS wheel data on CAN, a robot at work with a
    /// MEMS gyro and a motor controller; both in motion from the first row to the last.
    pub fn new(seed: u64, kind: VehicleKind, sensors: SensorSet) -> Self {
        let car = kind.is_car();
        Self {
            seed,
            kind,
            sensors,
            motion: if car {
                MotionConfig::for_car()
            } else {
                MotionConfig::for_robot()
            },
            timing: if car {
                TimingConfig::for_car()
            } else {
                TimingConfig::for_robot()
            },
            wheels: if car {
                WheelConfig::for_car()
            } else {
                WheelConfig::for_robot()
            },
            yaw_rate: if car {
                YawRateConfig::for_car()
            } else {
                YawRateConfig::for_robot()
            },
            compass: CompassConfig::default(),
            skid_steer: SkidSteerConfig::default(),
            robot: RobotConfig::default(),
            gnss: None,
            tilt: Some(if car {
                TiltConfig::for_car()
            } else {
                TiltConfig::for_robot()
            }),
        }
    }

    /// The same configuration with the GNSS receiver of its kind ([`GnssConfig::for_car`]
    /// or [`GnssConfig::for_robot`]).
    pub fn with_gnss(self) -> Self {
        Self {
            gnss: Some(if self.kind.is_car() {
                GnssConfig::for_car()
            } else {
                GnssConfig::for_robot()
            }),
            ..self
        }
    }

    /// A skid-steer robot like a real one whose log is the hardest the project has met:
    /// four unsteered wheels, physical track 0.57 m, about 0.9 m/s, side distances from its
    /// motor controller at 10 Hz and a MEMS yaw gyro at 30 Hz on rows of their own, at rest
    /// a few per cent of the time and never for long.
    pub fn real_skid_steer(seed: u64) -> Self {
        let mut c = Self::new(seed, VehicleKind::SkidSteer, SensorSet::WHEELS_GYRO);
        c.robot = RobotConfig {
            track_m: Some(Span::fixed(0.57)),
            speed_mps: Some(Span::new(0.8, 1.0)),
        };
        c.timing.odometry.rate_hz = Span::fixed(10.0);
        c.timing.gyro.rate_hz = Span::fixed(30.0);
        c
    }

    /// The same configuration without `habit` (everything else, the seed included, as it
    /// was).
    pub fn without(mut self, habit: Habit) -> Self {
        let t = &mut self.timing;
        match habit {
            Habit::InMotion => {
                self.motion.start_in_motion = false;
                self.motion.end_in_motion = false;
            }
            Habit::RareRests => {
                self.motion.rests = Some(Rests {
                    first_after_s: 0.0,
                    min_gap_s: 20.0,
                    mean_extra_gap_s: 40.0,
                    duration_s: Span::new(2.0, 30.0),
                })
            }
            Habit::OwnClocks => t.common_clock = true,
            Habit::Latency => {
                for s in [&mut t.gyro, &mut t.odometry, &mut t.compass] {
                    s.latency_s = Span::fixed(0.0);
                    s.jitter_s = 0.0;
                }
                if let Some(g) = &mut self.gnss {
                    g.timing.latency_s = Span::fixed(0.0);
                    g.timing.jitter_s = 0.0;
                }
            }
            Habit::Drops => {
                for s in [&mut t.gyro, &mut t.odometry, &mut t.compass] {
                    s.drop_probability = Span::fixed(0.0);
                }
                if let Some(g) = &mut self.gnss {
                    g.timing.drop_probability = Span::fixed(0.0);
                }
            }
            Habit::WheelLag => self.wheels.lag_s = Span::fixed(0.0),
            Habit::Quanta => {
                self.wheels.speed_quantum_mps = 0.0;
                self.wheels.tick_m = Span::fixed(1e-6);
                self.wheels.dist_quantum_m = 1e-6;
                self.yaw_rate.quantum_dps = 0.0;
            }
            Habit::YawScale => {
                self.yaw_rate.scale_error = 0.0;
                self.yaw_rate.scale_asymmetry = 0.0;
            }
            Habit::Tilt => self.yaw_rate.tilt_deg = Span::fixed(0.0),
            Habit::VaryingTrack => {
                let s = &mut self.skid_steer;
                s.patch_m = Span::fixed(1e5);
                s.tight_turn_gain = Span::fixed(0.0);
                s.per_g = Span::fixed(0.0);
                s.wander = 0.0;
            }
            Habit::GnssOutages | Habit::GnssCanyons | Habit::GnssFrozen | Habit::GnssLate => {
                if let Some(g) = &mut self.gnss {
                    match habit {
                        Habit::GnssOutages => g.outages = None,
                        Habit::GnssCanyons => g.canyons = None,
                        Habit::GnssFrozen => g.frozen = None,
                        _ => g.late = None,
                    }
                }
            }
            Habit::GnssCorrelation => {
                if let Some(g) = &mut self.gnss {
                    g.tau_s = Span::fixed(0.01);
                }
            }
            Habit::CompassTilt => self.tilt = None,
            Habit::LeverArm => {
                if let Some(g) = &mut self.gnss {
                    g.lever_forward_m = Span::fixed(0.0);
                    g.lever_right_m = Span::fixed(0.0);
                }
            }
        }
        self
    }

    /// A car's CAN bus like a real one's: the vehicle speed and the ESP's yaw rate at 5 Hz.
    pub fn real_can_car(seed: u64) -> Self {
        let mut c = Self::new(seed, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
        c.timing.odometry.rate_hz = Span::fixed(5.0);
        c.timing.gyro.rate_hz = Span::fixed(5.0);
        c
    }

    /// A car with a gyro and a compass and no wheels, circling three times from the first
    /// row (a real log of such a car circled three times in 63 s).
    pub fn real_circling_car(seed: u64) -> Self {
        let mut c = Self::new(seed, VehicleKind::RearWheelCar, SensorSet::GYRO_COMPASS);
        c.motion.shape = RouteShape::THREE_CIRCLES;
        c
    }
}

impl Validate for LogDriveConfig {
    /// Every part within its documented range, and a sensor set the vehicle can carry.
    fn validate(&self) -> Result<()> {
        self.sensors.check(self.kind)?;
        self.motion.check()?;
        self.timing.check()?;
        self.wheels.check()?;
        self.yaw_rate.check()?;
        self.compass.check()?;
        self.skid_steer.check()?;
        self.robot.check()?;
        if let Some(g) = &self.gnss {
            g.check()?;
        }
        if let Some(t) = &self.tilt {
            t.check()?;
        }
        Ok(())
    }
}
