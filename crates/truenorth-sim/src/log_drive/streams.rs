//! Each sensor's readings from the truth at its own instants, stamped as its clock
//! delivers them.

use nalgebra::Vector2;
use truenorth_compass::{Disturbance, HeadingTruth, MagnetometerModel2d};
use truenorth_core::{NoiseSource, Result, SensorModel, SplitMix64};
use truenorth_gyro::{GyroAxisModel, RateTruth};

use super::gnss_receiver::{GnssFix, GnssTruth};
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
    /// A yaw rate, rad/s.
    Gyro(f64),
    /// A compass reading, µT.
    Compass(Vector2<f64>),
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
        out.push((
            s.t_s,
            s.t_s,
            Slot::Gyro(quantized(g, e.yaw_rate.quantum_rps)),
        ));
        prev = s.t_s;
    }
    Ok(track.stamped(clock, out, rng))
}

/// The compass's readings through the magnetometer's forward model, with the disturbances.
pub(crate) fn compass_stream(
    track: &Track,
    e: &LogErrors,
    disturbances: &[Disturbance],
    rng: &mut SplitMix64,
) -> Result<Vec<Timed<Slot>>> {
    let clock = &e.compass_clock;
    let truth = track.at(&clock.instants(track.duration_s))?;
    let mut model =
        MagnetometerModel2d::new(e.compass_hard_iron, e.compass_soft_iron, e.compass_noise_ut)?;
    for d in disturbances {
        model = model.with_disturbance(*d)?;
    }
    let period = 1.0 / clock.rate_hz;
    if let Some(first) = truth.first() {
        model.set_time_s(first.t_s - period);
    }
    let mut prev = truth.first().map_or(0.0, |s| s.t_s - period);
    let mut out = Vec::with_capacity(truth.len());
    for s in &truth {
        let heading = HeadingTruth {
            // The compass sees the magnetic heading: the true one less the declination.
            heading_rad: s.heading_rad - e.declination_rad,
            horizontal_field: e.field_ut,
        };
        let m = model.sample(&heading, s.t_s - prev, rng)?;
        out.push((s.t_s, s.t_s, Slot::Compass(m)));
        prev = s.t_s;
    }
    Ok(track.stamped(clock, out, rng))
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
