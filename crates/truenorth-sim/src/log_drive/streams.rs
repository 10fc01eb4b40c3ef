//! Each sensor's readings from the truth at its own instants, stamped as its clock
//! delivers them.

use nalgebra::{Matrix3, Vector2, Vector3};
use truenorth_compass::{
    AttitudeTruth, Disturbance, HeadingTruth, MagnetometerModel2d, MagnetometerModel3d,
};
use truenorth_core::{NoiseSource, Result, SensorModel, SplitMix64};
use truenorth_gyro::{GyroAxisModel, RateTruth};

use super::body_tilt::TiltProcess;
use super::gnss_truth::{GnssFix, GnssTruth};
use super::row::OdometryReading;
use super::sensor_set::Odometry;
use super::skid_ground::{SkidGround, SkidProcess};
use super::timing::{Clock, Timed, TimingConfig, rounded};
use super::wheel_controller::{Controller, ControllerState, TurnSlip};
use super::yaw_sensor::quantized;
use super::{LogDriveConfig, LogErrors};
use crate::route::Route;
use crate::vehicle::{VehicleTruth, simulate_at};
use crate::vehicle_kind::{RangeVehicle, SlipProcess, VehicleKind};

/// A reading of one sensor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Slot {
    /// The odometry's reading and the wheels' turn factor at its loop step.
    Odometry(OdometryReading, f64),
    /// A yaw rate and the gyro's true bias in it (its constant part and random walk), rad/s.
    Gyro(f64, f64),
    /// A compass reading, µT, and the body's roll and pitch under it, rad.
    Compass(Vector2<f64>, Option<[f64; 2]>),
    /// A GNSS fix and the truth behind it.
    Gnss(GnssFix, GnssTruth),
}

/// The route, where it starts, and how the log stamps: what every stream reads.
pub(crate) struct Track<'a> {
    pub route: &'a Route,
    pub heading0_rad: f64,
    pub duration_s: f64,
    pub timing: &'a TimingConfig,
}

impl Track<'_> {
    pub(crate) fn at(&self, times: &[f64]) -> Result<Vec<VehicleTruth>> {
        simulate_at(self.route, self.heading0_rad, times)
    }

    /// Stamps the readings (the instant each measured, the instant its sensor sent it,
    /// the reading) as `clock` delivers them: late by its latency and jitter, rounded to
    /// the log's resolution and strictly increasing, the lost ones dropped.
    pub(crate) fn stamped(
        &self,
        clock: &Clock,
        measured: Vec<(f64, f64, Slot)>,
        rng: &mut SplitMix64,
    ) -> Vec<Timed<Slot>> {
        let (start, res) = (self.timing.start_s, self.timing.stamp_resolution_s);
        let mut out = Vec::with_capacity(measured.len());
        let mut last = f64::NEG_INFINITY;
        for (t, sent, value) in measured {
            let (at, kept) = clock.arrival(sent, rng);
            let mut stamp = rounded(at, start, res);
            if stamp <= last {
                stamp = rounded(last + res, start, res);
            }
            last = stamp;
            if kept {
                out.push(Timed {
                    measured_s: t,
                    stamp_s: stamp,
                    value,
                });
            }
        }
        out
    }
}

/// The yaw-rate sensor's readings: the true rate times cos(tilt), through the gyro's
/// forward model, quantised.
pub(crate) fn gyro_stream(
    track: &Track,
    e: &LogErrors,
    rng: &mut SplitMix64,
) -> Result<Vec<Timed<Slot>>> {
    let clock = &e.gyro_clock;
    let truth = track.at(&clock.instants(track.duration_s))?;
    let mut model = GyroAxisModel::new(e.yaw_rate.gyro)?;
    let tilt = e.yaw_rate.tilt_rad.cos();
    let mut prev = -1.0 / clock.rate_hz;
    let mut out = Vec::with_capacity(truth.len());
    for s in &truth {
        let rate = RateTruth {
            rate_rps: s.yaw_rate_rps * tilt,
            temp_c: e.yaw_rate.gyro.ref_temp_c,
        };
        let g = model.sample(&rate, s.t_s - prev, rng)?;
        let bias = model.bias_rps(rate.temp_c) + model.state().bias_walk_rps;
        out.push((
            s.t_s,
            s.t_s,
            Slot::Gyro(quantized(g, e.yaw_rate.quantum_rps), bias),
        ));
        prev = s.t_s;
    }
    Ok(track.stamped(clock, out, rng))
}

/// The compass's readings through the magnetometer's forward model, with the disturbances:
/// a level compass, or a two-axis compass on the tilting body (the three-axis model's `x`
/// and `y`, in the field with its vertical part), each with the truth's roll and pitch.
pub(crate) fn compass_stream(
    track: &Track,
    e: &LogErrors,
    disturbances: &[Disturbance],
    rng: &mut SplitMix64,
) -> Result<Vec<Timed<Slot>>> {
    let clock = &e.compass_clock;
    let truth = track.at(&clock.instants(track.duration_s))?;
    let mut compass = Compass::new(e, disturbances, rng)?;
    let period = 1.0 / clock.rate_hz;
    let mut prev = truth.first().map_or(0.0, |s| s.t_s - period);
    compass.set_time_s(prev);
    let mut out = Vec::with_capacity(truth.len());
    for s in &truth {
        let (m, tilt) = compass.sample(s, s.t_s - prev, e, rng)?;
        out.push((s.t_s, s.t_s, Slot::Compass(m, tilt)));
        prev = s.t_s;
    }
    Ok(track.stamped(clock, out, rng))
}

/// A compass level in the vehicle, or on its tilting body.
enum Compass {
    Level(MagnetometerModel2d),
    Tilted(MagnetometerModel3d, TiltProcess, Vector3<f64>),
}

impl Compass {
    fn new(e: &LogErrors, disturbances: &[Disturbance], rng: &mut SplitMix64) -> Result<Self> {
        let (h, s) = (e.compass_hard_iron, e.compass_soft_iron);
        Ok(match e.tilt {
            None => {
                let mut m = MagnetometerModel2d::new(h, s, e.compass_noise_ut)?;
                for d in disturbances {
                    m = m.with_disturbance(*d)?;
                }
                Self::Level(m)
            }
            Some(body) => {
                let soft = Matrix3::new(s.m11, s.m12, 0.0, s.m21, s.m22, 0.0, 0.0, 0.0, 1.0);
                let mut m = MagnetometerModel3d::new(h.push(0.0), soft, e.compass_noise_ut)?;
                for d in disturbances {
                    m = m.with_disturbance(*d)?;
                }
                // The field in the frame of true north: magnetic north lies the declination
                // east of it.
                let (sin, cos) = e.declination_rad.sin_cos();
                let f = e.field_ut;
                let field = Vector3::new(f * cos, f * sin, f * e.dip_rad.tan());
                Self::Tilted(m, TiltProcess::new(body, rng), field)
            }
        })
    }

    fn set_time_s(&mut self, t_s: f64) {
        match self {
            Self::Level(m) => m.set_time_s(t_s),
            Self::Tilted(m, ..) => m.set_time_s(t_s),
        }
    }

    /// The reading at `s`, `dt_s` after the previous, and the body's roll and pitch.
    fn sample(
        &mut self,
        s: &VehicleTruth,
        dt_s: f64,
        e: &LogErrors,
        rng: &mut SplitMix64,
    ) -> Result<(Vector2<f64>, Option<[f64; 2]>)> {
        match self {
            Self::Level(m) => {
                let heading = HeadingTruth {
                    // The compass sees the magnetic heading: the true one less the
                    // declination.
                    heading_rad: s.heading_rad - e.declination_rad,
                    horizontal_field: e.field_ut,
                };
                Ok((m.sample(&heading, dt_s, rng)?, None))
            }
            Self::Tilted(m, tilt, field) => {
                let attitude = tilt.attitude(s, rng);
                let truth = AttitudeTruth {
                    attitude,
                    field_ned: *field,
                };
                let reading = m.sample(&truth, dt_s, rng)?;
                Ok((reading.xy(), Some([attitude.roll_rad, attitude.pitch_rad])))
            }
        }
    }
}

/// The odometry's readings: the controller run at its loop rate over the whole drive, and
/// what it sends at each of the odometry clock's instants (its newest loop step's values).
/// Also the skid-steer's ground, when it skids.
pub(crate) fn odometry_stream(
    track: &Track,
    config: &LogDriveConfig,
    v: &RangeVehicle,
    e: &LogErrors,
    rng: &mut SplitMix64,
) -> Result<(Vec<Timed<Slot>>, Option<SkidGround>)> {
    let slip = if v.kind == VehicleKind::SkidSteer {
        TurnSlip::Skid(Box::new(SkidProcess::new(
            config.skid_steer,
            v.wheels.track_m(),
            rng,
        )))
    } else {
        TurnSlip::Tyres(SlipProcess::new(v.slip, rng))
    };
    let pair_front = v.kind == VehicleKind::FrontWheelCar;
    let mut controller = Controller::new(e.rear, e.front, pair_front, e.wheel_lag_s, slip)?;
    let loop_period = 1.0 / config.wheels.loop_hz;
    let phase = loop_period * rng.uniform();
    let loops: Vec<f64> = (0..)
        .map(|k| phase + k as f64 * loop_period)
        .take_while(|&t| t <= track.duration_s)
        .collect();
    let truth = track.at(&loops)?;
    let mut states: Vec<ControllerState> = Vec::with_capacity(truth.len());
    for w in truth.windows(2) {
        states.push(controller.step(&w[0], &w[1], rng)?);
    }
    let ground = controller.skid().map(|s| s.ground.clone());
    let clock = &e.odometry_clock;
    let mut next = 0;
    let mut out = Vec::new();
    for t in clock.instants(track.duration_s) {
        while next < states.len() && states[next].t_s <= t {
            next += 1;
        }
        if let Some(s) = next.checked_sub(1).and_then(|k| states.get(k)) {
            out.push((
                s.t_s,
                t,
                Slot::Odometry(
                    reading(config.sensors.odometry, s, e, pair_front),
                    s.turn_factor,
                ),
            ));
        }
    }
    Ok((track.stamped(clock, out, rng), ground))
}

/// What the controller sends of `s` for `odometry`.
fn reading(
    odometry: Odometry,
    s: &ControllerState,
    e: &LogErrors,
    pair_front: bool,
) -> OdometryReading {
    let q = |v: f64| quantized(v, e.speed_quantum_mps);
    let pair = if pair_front { 0 } else { 2 };
    let [l, r] = [s.lagged_mps[pair], s.lagged_mps[pair + 1]];
    match odometry {
        Odometry::VehicleSpeed | Odometry::None => OdometryReading::VehicleSpeed(q(0.5 * (l + r))),
        Odometry::VehicleDistance => OdometryReading::VehicleDistance(
            (s.pair_raw_m / e.dist_quantum_m).floor() * e.dist_quantum_m,
        ),
        Odometry::WheelDistances => {
            OdometryReading::WheelDistances([s.counted_m[pair], s.counted_m[pair + 1]])
        }
        Odometry::WheelSpeeds => OdometryReading::WheelSpeeds([q(l), q(r)]),
        Odometry::FourWheelSpeeds => OdometryReading::FourWheelSpeeds(s.lagged_mps.map(q)),
    }
}
