//! Mixed drives for testing vehicle dead reckoning: a random but repeatable route of city
//! blocks, suburban curves, roundabouts, ramps and highway, the sensor errors of a randomly
//! drawn low-cost installation, and the magnetic disturbances a car meets on the road.
//!
//! Every draw comes from one seed, so a drive can be rebuilt exactly; the ranges are those of
//! production cars and MEMS sensors, not tuned to any estimator:
//!
//! | error | range drawn |
//! |---|---|
//! | gyro bias | 0.2–0.6 °/s, either sign, plus a random walk of 0.004 °/s/√s |
//! | gyro scale | −3 … +3 % for right and for left turns separately |
//! | gyro noise | 0.015 °/s/√Hz |
//! | wheel scale | −0.4 … +0.4 % per wheel, 2 cm pulses |
//! | speed coefficient `a` | 2·10⁻⁵ – 8·10⁻⁵ s²/m² (1–3 % at 20 m/s) |
//! | compass | hard iron 0.2–0.6 × field, soft iron 1.1–1.4 : 1 at any angle, noise 1 % |
//!
//! Disturbances (world-fixed fields, as [`Disturbance`]s): short strong ones (a lorry, a
//! bridge, a tram line: 2–8 s, 0.3–1.5 × the horizontal field in any direction) about every
//! two minutes, and long slow ones that turn the horizontal field by 10–25° for 30–90 s at
//! nearly constant magnitude (`|H + w(R(θ)H − H)|` dips by at most `1 − cos(θ/2)`, 2.4 % at
//! 25°), which a field-magnitude test cannot see.

use core::f64::consts::PI;

use nalgebra::{Matrix2, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use truenorth_compass::{Disturbance, DisturbanceShape, MAX_DISTURBANCES};
use truenorth_core::{NoiseSource, Result, SplitMix64, VehicleSample, check_range};
use truenorth_gyro::GyroAxisParams;
use truenorth_odometer::{AckermannParams, OdometerParams, OdometerWheels};

use crate::draw::{between, either_sign};
use crate::route::{Route, RouteBuilder};
use crate::streams::{VehicleSensorParams, rotated_soft_iron, vehicle_streams_disturbed};
use crate::vehicle::{VehicleTruth, simulate};

/// Comfortable longitudinal acceleration, m/s².
const ACCEL_MPS2: f64 = 1.5;

/// Time the steering wheel takes to wind in or out, s: the curvature of every turn rises
/// and falls over it (a clothoid), as on a real road, rather than jumping.
const EASE_S: f64 = 1.5;

/// Which wheels carry the simulated odometer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum DriveWheels {
    /// Rear wheels, track 1.55 m.
    Rear,
    /// Ackermann-steered front wheels: wheelbase 2.7 m, track 1.55 m, kingpin offset 0.10 m
    /// (Pitman ratio 0.129).
    Front,
}

impl DriveWheels {
    /// The odometer wheel geometry of the simulated car.
    pub fn odometer_wheels(self) -> OdometerWheels {
        match self {
            Self::Rear => OdometerWheels::Rear { track_m: 1.55 },
            Self::Front => OdometerWheels::Front(AckermannParams {
                wheelbase_m: 2.7,
                track_m: 1.55,
                kingpin_offset_m: 0.10,
            }),
        }
    }
}

/// What to simulate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveSpec {
    /// Seed of every random draw (route, sensor errors, disturbances, noise).
    pub seed: u64,
    /// Length of the segments' straights and arcs to aim for, m (the route ends at the
    /// first segment past it); the speed changes between them add 15-65 %, so the default
    /// 8000 m gives drives of 9-13 km.
    pub length_m: f64,
    /// Which wheels carry the odometer.
    pub wheels: DriveWheels,
    /// Start with a 1.25-turn circle (radius 12 m, 5 m/s) after the first stop, as a
    /// calibration run; otherwise the drive sets off straight away.
    pub opening_turn: bool,
    /// Add the magnetic disturbances described in the module documentation.
    pub disturbances: bool,
    /// Sample rate of every sensor, Hz.
    pub rate_hz: f64,
}

impl DriveSpec {
    /// A drive of 9-13 km on rear wheels with an opening turn and disturbances, sampled at
    /// 10 Hz.
    pub fn new(seed: u64) -> Self {
        Self {
            seed,
            length_m: 8000.0,
            wheels: DriveWheels::Rear,
            opening_turn: true,
            disturbances: true,
            rate_hz: 10.0,
        }
    }
}

/// A simulated drive: the truth, the sensor stream and every true error behind it.
#[derive(Debug, Clone)]
pub struct SimulatedDrive {
    /// What was asked for.
    pub spec: DriveSpec,
    /// The route driven.
    pub route: Route,
    /// Ground truth, one per sample.
    pub truth: Vec<VehicleTruth>,
    /// The sensors' readings, one per truth sample.
    pub samples: Vec<VehicleSample>,
    /// The sensors' true errors.
    pub params: VehicleSensorParams,
    /// The magnetic disturbances (times in seconds from the start).
    pub disturbances: Vec<Disturbance>,
}

impl SimulatedDrive {
    /// Builds the drive `spec` describes.
    pub fn new(spec: DriveSpec) -> Result<Self> {
        check_range("drive length_m", spec.length_m, 1.0, 1e6)?;
        check_range("drive rate_hz", spec.rate_hz, 0.1, 1e4)?;
        let mut rng = SplitMix64::new(spec.seed);
        let route = mixed_route(&mut rng, spec.length_m, spec.opening_turn)?;
        let params = random_sensor_params(&mut rng, spec.wheels);
        let truth = simulate(&route, PI * (2.0 * rng.uniform() - 1.0), spec.rate_hz)?;
        let duration_s = truth.last().map_or(0.0, |t| t.t_s);
        let disturbances = if spec.disturbances {
            random_disturbances(&mut rng, duration_s, params.horizontal_field)
        } else {
            Vec::new()
        };
        let samples = vehicle_streams_disturbed(&truth, &params, &disturbances, rng.next_u64())?;
        Ok(Self {
            spec,
            route,
            truth,
            samples,
            params,
            disturbances,
        })
    }

    /// Distance driven, m.
    pub fn distance_m(&self) -> f64 {
        self.truth.last().map_or(0.0, |t| t.distance_m)
    }

    /// Whether a disturbance is active at `t_s` (inside any window).
    pub fn disturbed_at(&self, t_s: f64) -> bool {
        active_at(&self.disturbances, t_s)
    }
}

/// Whether any of `disturbances` is active at `t_s`.
pub(crate) fn active_at(disturbances: &[Disturbance], t_s: f64) -> bool {
    disturbances
        .iter()
        .any(|d| t_s >= d.start_s && t_s <= d.start_s + d.duration_s)
}

/// A random mix of driving, `length_m` long or a segment more.
fn mixed_route(rng: &mut SplitMix64, length_m: f64, opening_turn: bool) -> Result<Route> {
    let mut b = RouteBuilder::new().stop(between(rng, 8.0, 15.0))?;
    let mut driven = 0.0;
    if opening_turn {
        let dir = either_sign(rng);
        b = b
            .change_speed(5.0, ACCEL_MPS2)?
            .eased_turn(dir * 2.5 * PI, 12.0, EASE_S)?
            .change_speed(0.0, ACCEL_MPS2)?
            .stop(between(rng, 3.0, 8.0))?;
        driven += 2.5 * PI * 12.0;
    }
    while driven < length_m {
        let (next, d) = match (rng.uniform() * 6.0) as u32 {
            0 | 1 => city_block(rng, b)?,
            2 => suburban_curve(rng, b)?,
            3 => roundabout(rng, b)?,
            4 => ramp(rng, b)?,
            _ => highway(rng, b)?,
        };
        b = next;
        driven += d;
    }
    Ok(b.change_speed(0.0, ACCEL_MPS2)?.stop(5.0)?.build())
}

/// A block at 10–14 m/s, a 90° corner (radius 8–12 m at 4–6 m/s), and a stop at the
/// lights half the time.
fn city_block(rng: &mut SplitMix64, b: RouteBuilder) -> Result<(RouteBuilder, f64)> {
    let block = between(rng, 80.0, 250.0);
    let radius = between(rng, 8.0, 12.0);
    let mut b = b
        .change_speed(between(rng, 10.0, 14.0), ACCEL_MPS2)?
        .straight(block)?
        .change_speed(between(rng, 4.0, 6.0), ACCEL_MPS2)?
        .eased_turn(either_sign(rng) * PI / 2.0, radius, EASE_S)?;
    if rng.uniform() < 0.5 {
        b = b
            .change_speed(0.0, ACCEL_MPS2)?
            .stop(between(rng, 2.0, 30.0))?;
    }
    Ok((b, block + radius * PI / 2.0))
}

/// A sweeping bend of 30–120° (radius 30–80 m at 8–15 m/s) between two straights.
fn suburban_curve(rng: &mut SplitMix64, b: RouteBuilder) -> Result<(RouteBuilder, f64)> {
    let angle = between(rng, 30.0, 120.0).to_radians();
    let radius = between(rng, 30.0, 80.0);
    let (s1, s2) = (between(rng, 50.0, 300.0), between(rng, 50.0, 300.0));
    let b = b
        .change_speed(between(rng, 8.0, 15.0), ACCEL_MPS2)?
        .straight(s1)?
        .eased_turn(either_sign(rng) * angle, radius, EASE_S)?
        .straight(s2)?;
    Ok((b, s1 + s2 + angle * radius))
}

/// A roundabout: a short swerve one way, 180–450° the other way round (radius 12–20 m at
/// 5–7 m/s), and out.
fn roundabout(rng: &mut SplitMix64, b: RouteBuilder) -> Result<(RouteBuilder, f64)> {
    let dir = either_sign(rng);
    let radius = between(rng, 12.0, 20.0);
    let around = between(rng, 180.0, 450.0).to_radians();
    let swerve = 30f64.to_radians();
    let b = b
        .change_speed(between(rng, 5.0, 7.0), ACCEL_MPS2)?
        .straight(30.0)?
        .eased_turn(-dir * swerve, 15.0, EASE_S)?
        .eased_turn(dir * (around + 2.0 * swerve), radius, EASE_S)?
        .eased_turn(-dir * swerve, 15.0, EASE_S)?
        .straight(30.0)?;
    Ok((
        b,
        60.0 + 2.0 * swerve * 15.0 + (around + 2.0 * swerve) * radius,
    ))
}

/// A motorway ramp: 90–270° on a 40–80 m radius at 9–16 m/s (20–36 mph), the turns that
/// refine the speed coefficient of US 4,788,645.
fn ramp(rng: &mut SplitMix64, b: RouteBuilder) -> Result<(RouteBuilder, f64)> {
    let angle = between(rng, 90.0, 270.0).to_radians();
    let radius = between(rng, 40.0, 80.0);
    let b = b
        .change_speed(between(rng, 9.0, 16.0), ACCEL_MPS2)?
        .straight(100.0)?
        .eased_turn(either_sign(rng) * angle, radius, EASE_S)?
        .straight(100.0)?;
    Ok((b, 200.0 + angle * radius))
}

/// 0.8–2.5 km at 25–33 m/s with a gentle bend (radius 800–2000 m) in the middle.
fn highway(rng: &mut SplitMix64, b: RouteBuilder) -> Result<(RouteBuilder, f64)> {
    let length = between(rng, 800.0, 2500.0);
    let radius = between(rng, 800.0, 2000.0);
    let bend = between(rng, 5.0, 25.0).to_radians();
    let straight = 0.5 * (length - bend * radius).max(100.0);
    let b = b
        .change_speed(between(rng, 25.0, 33.0), ACCEL_MPS2)?
        .straight(straight)?
        .eased_turn(either_sign(rng) * bend, radius, EASE_S)?
        .straight(straight)?;
    Ok((b, 2.0 * straight + bend * radius))
}

/// Sensor errors of one randomly drawn installation (ranges in the module documentation).
fn random_sensor_params(rng: &mut SplitMix64, wheels: DriveWheels) -> VehicleSensorParams {
    let field = 20.0;
    VehicleSensorParams {
        gyro: GyroAxisParams {
            bias_rps: either_sign(rng) * between(rng, 0.2, 0.6).to_radians(),
            bias_walk_rps_per_sqrt_s: 0.004f64.to_radians(),
            scale_error_pos: between(rng, -0.03, 0.03),
            scale_error_neg: between(rng, -0.03, 0.03),
            noise_density_rps_per_sqrt_hz: 0.015f64.to_radians(),
            ..GyroAxisParams::PERFECT
        },
        gyro_temp_c: 25.0,
        odometer: OdometerParams {
            wheels: wheels.odometer_wheels(),
            scale_error_l: between(rng, -0.004, 0.004),
            scale_error_r: between(rng, -0.004, 0.004),
            speed_coeff_s2_per_m2: between(rng, 2e-5, 8e-5),
            dist_per_pulse_m: Some(0.02),
        },
        compass_hard_iron: {
            let (s, c) = (2.0 * PI * rng.uniform()).sin_cos();
            Vector2::new(c, s) * field * between(rng, 0.2, 0.6)
        },
        compass_soft_iron: soft_iron(rng, 1.1, 1.4),
        compass_noise: 0.01 * field,
        horizontal_field: field,
    }
}

/// A soft iron of ratio `lo`–`hi` : 1 with its major axis at any angle.
pub(crate) fn soft_iron(rng: &mut SplitMix64, lo: f64, hi: f64) -> Matrix2<f64> {
    let ratio = between(rng, lo, hi);
    rotated_soft_iron(ratio, 1.0, PI * rng.uniform())
}

/// Short strong disturbances about every two minutes and a slow field-turning one about
/// every five, none in the first 60 s (which a calibration run may use) and none
/// overlapping.
pub(crate) fn random_disturbances(
    rng: &mut SplitMix64,
    duration_s: f64,
    field: f64,
) -> Vec<Disturbance> {
    let mut out = Vec::new();
    let mut t = 60.0 + between(rng, 0.0, 60.0);
    let mut since_slow = 0.0;
    while t < duration_s - 100.0 && out.len() < MAX_DISTURBANCES {
        let d = if since_slow > 240.0 && rng.uniform() < 0.5 {
            since_slow = 0.0;
            let angle = either_sign(rng) * between(rng, 10.0, 25.0).to_radians();
            let (s, c) = angle.sin_cos();
            Disturbance {
                start_s: t,
                duration_s: between(rng, 30.0, 90.0),
                field_ned: Vector3::new(field * (c - 1.0), field * s, 0.0),
                shape: DisturbanceShape::RaisedCosine,
            }
        } else {
            let (s, c) = (2.0 * PI * rng.uniform()).sin_cos();
            Disturbance {
                start_s: t,
                duration_s: between(rng, 2.0, 8.0),
                field_ned: Vector3::new(c, s, 0.0) * field * between(rng, 0.3, 1.5),
                shape: if rng.uniform() < 0.5 {
                    DisturbanceShape::Step
                } else {
                    DisturbanceShape::RaisedCosine
                },
            }
        };
        let gap = between(rng, 60.0, 180.0);
        since_slow += d.duration_s + gap;
        t += d.duration_s + gap;
        out.push(d);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_is_repeatable_and_about_as_long_as_asked() {
        let spec = DriveSpec {
            length_m: 3000.0,
            ..DriveSpec::new(3)
        };
        let a = SimulatedDrive::new(spec).unwrap();
        let b = SimulatedDrive::new(spec).unwrap();
        assert_eq!(a.samples, b.samples);
        assert!(a.distance_m() >= 3000.0 && a.distance_m() < 6000.0);
        assert_eq!(a.samples.len(), a.truth.len());
        assert!(!a.disturbances.is_empty());
    }

    #[test]
    fn slow_disturbances_turn_the_field_at_nearly_constant_magnitude() {
        for seed in 0..20 {
            let drive = SimulatedDrive::new(DriveSpec::new(seed)).unwrap();
            for d in drive.disturbances.iter().filter(|d| d.duration_s >= 30.0) {
                let h = Vector2::new(20.0, 0.0);
                let full = h + d.field_ned.xy();
                let angle = full.y.atan2(full.x).abs().to_degrees();
                assert!((10.0..=25.0 + 1e-9).contains(&angle), "{angle}");
                assert!((full.norm() - 20.0).abs() < 1e-9);
                let half = h + 0.5 * d.field_ned.xy();
                assert!(half.norm() > 20.0 * (1.0 - 0.025));
            }
        }
    }

    #[test]
    fn bad_specs_are_refused() {
        let spec = DriveSpec::new(1);
        for bad in [
            DriveSpec {
                length_m: f64::NAN,
                ..spec
            },
            DriveSpec {
                rate_hz: 0.0,
                ..spec
            },
        ] {
            assert!(SimulatedDrive::new(bad).is_err());
        }
    }
}
