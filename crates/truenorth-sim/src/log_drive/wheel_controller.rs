//! Wheel data as the controllers that send it make it: an ABS unit on a car's CAN bus, a
//! motor controller on a robot.
//!
//! The controller runs a loop (100 Hz by default). Each loop step it counts each wheel's
//! pulses (the distance quantised to whole pulses, [`OdometerModel`]) and passes each
//! wheel's speed through a first-order lag `τ·ẏ + y = v` (the speed filter every ABS unit
//! and motor controller runs, discretised exactly for a speed held over the step). When it
//! sends, it sends its newest loop step's values: speeds rounded to their quantum (a real
//! car's CAN sends 0.01 km/h), distances in whole pulses, and a cumulative distance counter
//! in its own quantum. Wheel geometry and scale errors are the odometer crate's forward
//! model; the wheels see a turn times the vehicle's slip (tyres) or a skid-steer's
//! expansion factor ([`super::skid_ground`]).

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, SensorModel, SplitMix64, ZeroNoise, check_range};
use truenorth_odometer::{OdometerModel, OdometerParams};

use super::skid_ground::SkidProcess;
use super::span::Span;
use crate::VehicleTruth;
use crate::range_drive::{peak_curvature, wheel_motion};
use crate::vehicle_kind::SlipProcess;

/// How the odometry reads (defaults per vehicle kind in [`WheelConfig::for_car`] and
/// [`WheelConfig::for_robot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WheelConfig {
    /// The controller's loop rate, Hz (100; 10–10 000).
    pub loop_hz: f64,
    /// Time constant of the speeds' first-order lag, s, drawn uniformly per drive (0–5).
    pub lag_s: Span,
    /// Quantum of a speed, m/s (0–1; 0: continuous).
    pub speed_quantum_mps: f64,
    /// Distance per pulse of a wheel's count, m, drawn log-uniformly per drive (1e-6–1).
    pub tick_m: Span,
    /// Quantum of the cumulative distance `dist_m`, m (1e-6–10).
    pub dist_quantum_m: f64,
    /// The wheels' mean scale error is drawn uniformly in ±this (0–0.2).
    pub scale_error: f64,
    /// Each wheel's scale error differs from the mean by a uniform ±this/2 (0–0.2).
    pub scale_difference: f64,
    /// The `a` of the wheels' `1 + aV²` difference error (US 4,788,645, eq. 2), s²/m², drawn
    /// uniformly per drive (0–0.01).
    pub speed_coeff_s2_per_m2: Span,
}

impl Default for WheelConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl WheelConfig {
    /// A car's ABS unit: speeds lagged 20–100 ms in quanta of 0.01 km/h, tone wheels of
    /// 1–4 cm a pulse, a distance counter in centimetres, wheel scales ±0.5 % with ±0.25 %
    /// between wheels, `a` up to 3·10⁻⁴ s²/m².
    pub const fn for_car() -> Self {
        Self {
            loop_hz: 100.0,
            lag_s: Span::new(0.02, 0.1),
            speed_quantum_mps: 0.01 / 3.6,
            tick_m: Span::new(0.01, 0.04),
            dist_quantum_m: 0.01,
            scale_error: 0.005,
            scale_difference: 0.005,
            speed_coeff_s2_per_m2: Span::new(0.0, 3e-4),
        }
    }

    /// A robot's motor controller: speeds lagged 50–300 ms in mm/s, encoders of
    /// 0.1–2 mm a count, a distance counter in millimetres, wheel scales ±2 % with ±0.5 %
    /// between wheels.
    pub const fn for_robot() -> Self {
        Self {
            loop_hz: 100.0,
            lag_s: Span::new(0.05, 0.3),
            speed_quantum_mps: 0.001,
            tick_m: Span::new(1e-4, 2e-3),
            dist_quantum_m: 0.001,
            scale_error: 0.02,
            scale_difference: 0.01,
            speed_coeff_s2_per_m2: Span::fixed(0.0),
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        check_range("wheel loop_hz", self.loop_hz, 10.0, 1e4)?;
        self.lag_s.check("wheel lag_s", 0.0, 5.0)?;
        check_range("wheel speed_quantum_mps", self.speed_quantum_mps, 0.0, 1.0)?;
        self.tick_m.check("wheel tick_m", 1e-6, 1.0)?;
        check_range("wheel dist_quantum_m", self.dist_quantum_m, 1e-6, 10.0)?;
        check_range("wheel scale_error", self.scale_error, 0.0, 0.2)?;
        check_range("wheel scale_difference", self.scale_difference, 0.0, 0.2)?;
        self.speed_coeff_s2_per_m2
            .check("wheel speed_coeff_s2_per_m2", 0.0, 0.01)?;
        Ok(())
    }
}

/// The wheels' running error on a turn.
#[derive(Debug, Clone)]
pub(crate) enum TurnSlip {
    /// Rolling tyres (cars, differential-drive robots).
    Tyres(SlipProcess),
    /// A skid-steer's sides.
    Skid(Box<SkidProcess>),
}

impl TurnSlip {
    fn step(&mut self, p: &VehicleTruth, s: &VehicleTruth, rng: &mut SplitMix64) -> f64 {
        match self {
            Self::Tyres(slip) => slip.step(s.t_s - p.t_s, s.speed_mps * s.yaw_rate_rps, rng),
            Self::Skid(skid) => skid.step(p, s, rng),
        }
    }
}

/// What the controller holds after one loop step (wheels in the order front left, front
/// right, rear left, rear right; a robot's "front" and "rear" wheels are those of each
/// side).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ControllerState {
    /// When, s after the truth starts.
    pub t_s: f64,
    /// Each wheel's count, in metres of whole pulses.
    pub counted_m: [f64; 4],
    /// Each wheel's lagged speed, m/s (not yet quantised).
    pub lagged_mps: [f64; 4],
    /// The mean of the odometer pair's distances before they are counted in pulses, m.
    pub pair_raw_m: f64,
    /// By how much the wheels saw the vehicle's turn over the step (the skid-steer's χ).
    pub turn_factor: f64,
}

/// An axle's odometer: its forward model and the curvature its wheels are driven to.
#[derive(Debug, Clone)]
struct Axle {
    model: OdometerModel,
    peak: f64,
}

impl Axle {
    fn new(params: OdometerParams) -> Result<Self> {
        let model = OdometerModel::new(params)?;
        let peak = peak_curvature(model.geometry());
        Ok(Self { model, peak })
    }

    /// Rolls the axle from `p` to `s`, returning its two wheels' speeds over the step.
    fn roll(&mut self, p: &VehicleTruth, s: &VehicleTruth, factor: f64) -> Result<[f64; 2]> {
        let dt = s.t_s - p.t_s;
        let motion = wheel_motion(p, s, factor, self.peak);
        let d = self.model.ideal(&motion)?;
        self.model.sample(&motion, dt, &mut ZeroNoise)?;
        Ok([d.left_m / dt, d.right_m / dt])
    }
}

/// The controller: both axles' odometers (the front one absent on a differential-drive
/// robot), the speed filter and the turn slip.
#[derive(Debug, Clone)]
pub(crate) struct Controller {
    rear: Axle,
    front: Option<Axle>,
    /// Whether the odometer pair (the wheels a two-wheel reading comes from) is the front.
    pair_front: bool,
    lag_s: f64,
    slip: TurnSlip,
    state: Option<ControllerState>,
}

impl Controller {
    pub fn new(
        rear: OdometerParams,
        front: Option<OdometerParams>,
        pair_front: bool,
        lag_s: f64,
        slip: TurnSlip,
    ) -> Result<Self> {
        Ok(Self {
            rear: Axle::new(rear)?,
            front: front.map(Axle::new).transpose()?,
            pair_front,
            lag_s,
            slip,
            state: None,
        })
    }

    /// The skid-steer's ground, when the wheels skid.
    pub fn skid(&self) -> Option<&SkidProcess> {
        match &self.slip {
            TurnSlip::Skid(s) => Some(s),
            TurnSlip::Tyres(_) => None,
        }
    }

    /// Runs one loop step from `p` to `s` and returns the state after it. The first step
    /// starts the lag at the wheels' speed: the controller has been running long before the
    /// log starts.
    pub fn step(
        &mut self,
        p: &VehicleTruth,
        s: &VehicleTruth,
        rng: &mut SplitMix64,
    ) -> Result<ControllerState> {
        let factor = self.slip.step(p, s, rng);
        let [rl, rr] = self.rear.roll(p, s, factor)?;
        let [fl, fr] = match &mut self.front {
            Some(axle) => axle.roll(p, s, factor)?,
            None => [rl, rr],
        };
        let speeds = [fl, fr, rl, rr];
        let dt = s.t_s - p.t_s;
        let gain = if self.lag_s > 0.0 {
            1.0 - (-dt / self.lag_s).exp()
        } else {
            1.0
        };
        let lagged = match &self.state {
            Some(prev) => core::array::from_fn(|k| {
                prev.lagged_mps[k] + gain * (speeds[k] - prev.lagged_mps[k])
            }),
            None => speeds,
        };
        let rear = self.rear.model.cumulative_m();
        let front = self.front.as_ref().map_or(rear, |a| a.model.cumulative_m());
        let pair = if self.pair_front {
            self.front.as_ref().unwrap_or(&self.rear)
        } else {
            &self.rear
        };
        let raw = pair.model.state();
        let state = ControllerState {
            t_s: s.t_s,
            counted_m: [front.left_m, front.right_m, rear.left_m, rear.right_m],
            lagged_mps: lagged,
            pair_raw_m: 0.5 * (raw.raw_l_m + raw.raw_r_m),
            turn_factor: factor,
        };
        self.state = Some(state);
        Ok(state)
    }
}
