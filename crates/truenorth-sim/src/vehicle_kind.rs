//! The kinds of land vehicle the simulator drives, each drawn from its physical range: the
//! geometry an estimator is told, and what its wheels really do in a turn.
//!
//! | kind | geometry drawn | what the wheels see of a turn |
//! |---|---|---|
//! | rear-wheel car | track 1.4–1.7 m, wheelbase 2.3–3.2 m | the turn, plus tyre slip growing with lateral acceleration |
//! | front-wheel car | the same, kingpin offset from a Pitman ratio of 0.1–0.35, full lock 33–42° | exact Ackermann paths, plus tyre slip |
//! | skid-steer robot | track 0.4–1.2 m | 1.5–2.5 times the turn (the sides slide), varying ±8 % with the ground |
//! | differential-drive robot | track 0.25–0.8 m | the turn, ±1 % (contact patch width) |
//!
//! Tyre slip: the wheels' share of a turn is off by a Gauss–Markov error of standard
//! deviation `base + per_g · |a_lat|/g` with a correlation time of 5 s. Cars: 0.2 % plus
//! 0.5–2 % per g (what lateral load transfer does to the rolling radii beyond the `aV²` law
//! of US 4,788,645, which the odometer model carries separately); skid-steer: the effective
//! track changes with the ground (Mandow et al., IROS 2007, measured 1.5–2.0 on one robot
//! over different surfaces).

use crate::draw::between;
use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, STANDARD_GRAVITY_MPS2, SplitMix64};
use truenorth_odometer::{AckermannParams, OdometerWheels};

/// A kind of land vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum VehicleKind {
    /// A car with the odometer on its rear (unsteered) wheels.
    RearWheelCar,
    /// A car with the odometer on its Ackermann-steered front wheels.
    FrontWheelCar,
    /// A skid-steered robot (no steering; the sides slide in every turn).
    SkidSteer,
    /// A differential-drive robot (two driven wheels, casters).
    Differential,
}

impl VehicleKind {
    /// Every kind, in a fixed order.
    pub const ALL: [Self; 4] = [
        Self::RearWheelCar,
        Self::FrontWheelCar,
        Self::SkidSteer,
        Self::Differential,
    ];

    /// Whether this kind is a road car (rather than a robot).
    pub fn is_car(self) -> bool {
        matches!(self, Self::RearWheelCar | Self::FrontWheelCar)
    }
}

/// The error the wheels make on a turn beyond their nominal geometry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Slip {
    /// The factor by which the wheels' turn exceeds the vehicle's on average (1 for
    /// rolling wheels; the skid-steer effective track over the physical one).
    pub track_factor: f64,
    /// Standard deviation of the relative error of the wheels' turn at no lateral
    /// acceleration.
    pub base: f64,
    /// Its growth per g of lateral acceleration.
    pub per_g: f64,
    /// Correlation time of the error, s.
    pub tau_s: f64,
}

/// One vehicle drawn from its kind's range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeVehicle {
    /// Its kind.
    pub kind: VehicleKind,
    /// The odometer geometry as a user would describe it in `VEHICLE.json`.
    pub wheels: OdometerWheels,
    /// What the wheels do in a turn beyond the geometry.
    pub slip: Slip,
    /// Tightest turn the vehicle drives, radius of the rear-axle centre, m (full lock for a
    /// car; robots can turn in place as well).
    pub min_radius_m: f64,
    /// Cruising speed range on its usual ground, m/s.
    pub speed_range_mps: (f64, f64),
}

impl RangeVehicle {
    /// A vehicle of `kind` with dimensions drawn from its range.
    pub fn draw(kind: VehicleKind, rng: &mut SplitMix64) -> Self {
        let car_slip = Slip {
            track_factor: 1.0,
            base: 0.002,
            per_g: between(rng, 0.005, 0.02),
            tau_s: 5.0,
        };
        match kind {
            VehicleKind::RearWheelCar | VehicleKind::FrontWheelCar => {
                let track_m = between(rng, 1.4, 1.7);
                let wheelbase_m = between(rng, 2.3, 3.2);
                let pitman = between(rng, 0.10, 0.35);
                let axle = AckermannParams::from_pitman_ratio(wheelbase_m, track_m, pitman);
                // Full lock: the inner wheel at 33–42° (tan δ = Bκ/(1 − κT_K/2)).
                let lock = between(rng, 33.0, 42.0).to_radians().tan();
                let kingpin_track = track_m - 2.0 * axle.kingpin_offset_m;
                let kappa = lock / (wheelbase_m + 0.5 * lock * kingpin_track);
                let wheels = if kind == VehicleKind::RearWheelCar {
                    OdometerWheels::Rear { track_m }
                } else {
                    OdometerWheels::Front(axle)
                };
                Self {
                    kind,
                    wheels,
                    slip: car_slip,
                    min_radius_m: 1.0 / kappa,
                    speed_range_mps: (5.0, 36.0),
                }
            }
            VehicleKind::SkidSteer => Self {
                kind,
                wheels: OdometerWheels::SkidSteer {
                    track_m: between(rng, 0.4, 1.2),
                },
                slip: Slip {
                    track_factor: between(rng, 1.5, 2.5),
                    base: 0.08,
                    per_g: 0.0,
                    tau_s: 5.0,
                },
                min_radius_m: 0.0,
                speed_range_mps: (0.3, 2.0),
            },
            VehicleKind::Differential => Self {
                kind,
                wheels: OdometerWheels::Differential {
                    track_m: between(rng, 0.25, 0.8),
                },
                slip: Slip {
                    track_factor: between(rng, 1.0, 1.03),
                    base: 0.01,
                    per_g: 0.0,
                    tau_s: 5.0,
                },
                min_radius_m: 0.0,
                speed_range_mps: (0.3, 1.5),
            },
        }
    }
}

/// The wheels' running error on a turn: a first-order Gauss–Markov process whose
/// stationary spread follows the lateral acceleration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlipProcess {
    slip: Slip,
    /// The current relative error of the wheels' turn.
    pub error: f64,
}

impl SlipProcess {
    /// Starts the process at a draw from its stationary spread at rest.
    pub fn new(slip: Slip, rng: &mut SplitMix64) -> Self {
        Self {
            slip,
            error: rng.normal(slip.base),
        }
    }

    /// Advances by `dt_s` at lateral acceleration `a_lat_mps2` and returns the factor by
    /// which the wheels' turn exceeds the vehicle's over the step.
    pub fn step(&mut self, dt_s: f64, a_lat_mps2: f64, rng: &mut SplitMix64) -> f64 {
        let s = &self.slip;
        let sigma = s.base + s.per_g * a_lat_mps2.abs() / STANDARD_GRAVITY_MPS2;
        let decay = (-dt_s / s.tau_s).exp();
        self.error = self.error * decay + rng.normal(sigma * (1.0 - decay * decay).sqrt());
        s.track_factor * (1.0 + self.error)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_draws_within_its_range() {
        let mut rng = SplitMix64::new(4);
        for _ in 0..200 {
            for kind in VehicleKind::ALL {
                let v = RangeVehicle::draw(kind, &mut rng);
                assert_eq!(v.kind, kind);
                let t = v.wheels.track_m();
                match kind {
                    VehicleKind::RearWheelCar | VehicleKind::FrontWheelCar => {
                        assert!((1.4..=1.7).contains(&t));
                        // Full lock of a car: a radius of 3–7 m.
                        assert!((3.0..7.0).contains(&v.min_radius_m), "{}", v.min_radius_m);
                    }
                    VehicleKind::SkidSteer => {
                        assert!((1.5..=2.5).contains(&v.slip.track_factor));
                        assert!(v.wheels.can_pivot());
                    }
                    VehicleKind::Differential => assert!(v.wheels.can_pivot()),
                }
            }
        }
    }

    #[test]
    fn slip_spreads_as_drawn() {
        let mut rng = SplitMix64::new(9);
        let slip = Slip {
            track_factor: 2.0,
            base: 0.05,
            per_g: 0.0,
            tau_s: 1.0,
        };
        let mut p = SlipProcess::new(slip, &mut rng);
        let n = 200_000;
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let f = p.step(0.1, 0.0, &mut rng);
            s += f;
            s2 += f * f;
        }
        let mean = s / n as f64;
        let sd = (s2 / n as f64 - mean * mean).sqrt();
        // 200 000 steps of 0.1 s with τ = 1 s: about 10 000 independent values, so the
        // mean is within 4σ/√10⁴ of 2 and the spread within a few percent of 0.1.
        assert!((mean - 2.0).abs() < 4.0 * 0.1 / 100.0, "{mean}");
        assert!((sd / 0.1 - 1.0).abs() < 0.05, "{sd}");
    }
}
