//! Rear-axle kinematic vehicle: integrates a [`Route`] into ground truth at a fixed rate.

use serde::{Deserialize, Serialize};
use truenorth_core::{Error, Result, check_finite, check_range, wrap_pi};

use crate::route::Route;

/// Most samples one simulation may produce (10⁸: about 8 GB of truth); more is refused
/// rather than attempted.
pub const MAX_SAMPLES: f64 = 1e8;

/// The state of the vehicle (rear-axle centre) at one instant: the ground truth.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct VehicleTruth {
    /// Time, seconds.
    pub t_s: f64,
    /// Northward position from the start, metres.
    pub north_m: f64,
    /// Eastward position from the start, metres.
    pub east_m: f64,
    /// Heading, radians clockwise from north, (-π, π].
    pub heading_rad: f64,
    /// Heading without wrapping (total turned), radians.
    pub heading_unwrapped_rad: f64,
    /// Forward speed, m/s.
    pub speed_mps: f64,
    /// Longitudinal acceleration, m/s².
    pub accel_mps2: f64,
    /// Path curvature, 1/m, positive right.
    pub curvature_per_m: f64,
    /// Yaw rate, rad/s, positive right.
    pub yaw_rate_rps: f64,
    /// Distance travelled by the rear-axle centre since the start, metres.
    pub distance_m: f64,
}

/// Integrates `route` from heading `heading0_rad` at `rate_hz`, returning one truth sample per
/// step, the first at t = 0 and the last exactly at the route's end (so the last step may be
/// shorter than `1/rate_hz`).
///
/// Positions are integrated exactly along each step's arc (chord of length
/// `ds · sinc(dψ/2)` at the mid-step heading), so the only error is the sampling of speed.
pub fn simulate(route: &Route, heading0_rad: f64, rate_hz: f64) -> Result<Vec<VehicleTruth>> {
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(Error::OutOfRange {
            what: "rate_hz",
            value: rate_hz,
            min: f64::MIN_POSITIVE,
            max: f64::INFINITY,
        });
    }
    let dt = 1.0 / rate_hz;
    let total = route.duration_s();
    let steps = check_range(
        "route samples (duration × rate)",
        total * rate_hz,
        0.0,
        MAX_SAMPLES,
    )?;
    // Whole steps strictly before the end, then the end itself.
    let whole = (steps * (1.0 - 1e-12)).floor() as usize;
    let mut out = Vec::with_capacity(whole + 2);
    let mut vehicle = Integrator::new(route, heading0_rad);
    out.push(vehicle.s);
    let times = (1..=whole)
        .map(|k| k as f64 * dt)
        .chain(core::iter::once(total));
    for t1 in times {
        if t1 > vehicle.s.t_s {
            out.push(vehicle.advance_to(t1));
        }
    }
    Ok(out)
}

/// Integrates `route` from heading `heading0_rad` and returns the truth at each of `times_s`
/// (seconds from the route's start, finite, non-negative and strictly increasing): the truth
/// at instants a sensor's own clock chooses, as exact as [`simulate`]'s. Past the route's
/// end the vehicle keeps its last speed in a straight line.
pub fn simulate_at(route: &Route, heading0_rad: f64, times_s: &[f64]) -> Result<Vec<VehicleTruth>> {
    check_finite("heading0_rad", heading0_rad)?;
    check_range("number of instants", times_s.len() as f64, 0.0, MAX_SAMPLES)?;
    let mut vehicle = Integrator::new(route, heading0_rad);
    let mut out = Vec::with_capacity(times_s.len());
    for &t1 in times_s {
        check_range("instant (s from the route's start)", t1, 0.0, f64::MAX)?;
        if let Some(prev) = out.last().map(|p: &VehicleTruth| p.t_s)
            && t1 <= prev
        {
            return Err(Error::NonIncreasingTime {
                t_s: t1,
                prev_s: prev,
            });
        }
        out.push(if t1 > vehicle.s.t_s {
            vehicle.advance_to(t1)
        } else {
            vehicle.s
        });
    }
    Ok(out)
}

/// The vehicle on its way along a route: the state, and where in the route it is.
struct Integrator<'a> {
    route: &'a Route,
    s: VehicleTruth,
    planned_v: f64,
    cmd_idx: usize,
    cmd_end: f64,
    turning: Turning,
}

impl<'a> Integrator<'a> {
    /// At the route's start (t = 0), heading `heading0_rad`.
    fn new(route: &'a Route, heading0_rad: f64) -> Self {
        let mut s = VehicleTruth {
            heading_rad: wrap_pi(heading0_rad),
            heading_unwrapped_rad: heading0_rad,
            speed_mps: route.start_speed_mps,
            ..VehicleTruth::default()
        };
        let turning = set_command(&mut s, route, 0);
        Self {
            route,
            s,
            planned_v: route.start_speed_mps,
            cmd_idx: 0,
            cmd_end: route.commands.first().map_or(0.0, |c| c.duration_s),
            turning,
        }
    }

    /// Integrates to `t1` (later than the current time), piecewise across command
    /// boundaries, and returns the state there.
    fn advance_to(&mut self, t1: f64) -> VehicleTruth {
        let route = self.route;
        let s = &mut self.s;
        let mut t = s.t_s;
        while t < t1 - 1e-12 {
            while self.cmd_idx < route.commands.len() && t >= self.cmd_end - 1e-12 {
                // Snap to the planned speed at the boundary so rounding cannot leave a
                // "stopped" vehicle creeping at 1e-16 m/s.
                if let Some(c) = route.commands.get(self.cmd_idx) {
                    self.planned_v = (self.planned_v + c.accel_mps2 * c.duration_s).max(0.0);
                    s.speed_mps = self.planned_v;
                }
                self.cmd_idx += 1;
                self.cmd_end += route
                    .commands
                    .get(self.cmd_idx)
                    .map_or(0.0, |c| c.duration_s);
                self.turning = set_command(s, route, self.cmd_idx);
            }
            let h = if self.cmd_idx < route.commands.len() {
                (t1.min(self.cmd_end)) - t
            } else {
                t1 - t
            };
            advance(s, h, self.turning);
            t += h;
        }
        s.t_s = t1;
        s.yaw_rate_rps = s.speed_mps * s.curvature_per_m + self.turning.pivot_rps;
        *s
    }
}

/// How the curvature and the heading change within a command besides the path.
#[derive(Debug, Clone, Copy, Default)]
struct Turning {
    /// Rate of change of the curvature, 1/(m·s).
    curvature_rate: f64,
    /// Turn rate in place, rad/s.
    pivot_rps: f64,
}

/// Takes the command's acceleration and curvature (and returns how it turns).
fn set_command(s: &mut VehicleTruth, route: &Route, idx: usize) -> Turning {
    let turning = match route.commands.get(idx) {
        Some(c) => {
            s.accel_mps2 = c.accel_mps2;
            s.curvature_per_m = c.curvature_per_m;
            Turning {
                curvature_rate: c.curvature_rate_per_m_s,
                pivot_rps: c.pivot_rate_rps,
            }
        }
        None => {
            s.accel_mps2 = 0.0;
            s.curvature_per_m = 0.0;
            Turning::default()
        }
    };
    s.yaw_rate_rps = s.speed_mps * s.curvature_per_m + turning.pivot_rps;
    turning
}

/// Sub-steps of a step in which the curvature changes: the heading is exact, the position
/// exact to third order in the sub-step's turn.
const CLOTHOID_SUBSTEPS: usize = 8;

fn advance(s: &mut VehicleTruth, h: f64, turning: Turning) {
    if turning.pivot_rps != 0.0 {
        s.heading_unwrapped_rad += turning.pivot_rps * h;
        s.heading_rad = wrap_pi(s.heading_unwrapped_rad);
        return;
    }
    let curvature_rate = turning.curvature_rate;
    if curvature_rate == 0.0 {
        advance_arc(s, h);
        return;
    }
    let sub = h / CLOTHOID_SUBSTEPS as f64;
    for _ in 0..CLOTHOID_SUBSTEPS {
        // Heading change over the sub-step, exactly: ∫ (κ₀ + κ̇τ)(v₀ + aτ) dτ.
        let (k0, v0, a) = (s.curvature_per_m, s.speed_mps, s.accel_mps2);
        let dpsi = k0 * v0 * sub
            + (k0 * a + curvature_rate * v0) * sub * sub / 2.0
            + curvature_rate * a * sub * sub * sub / 3.0;
        let v1 = (v0 + a * sub).max(0.0);
        let ds = 0.5 * (v0 + v1) * sub;
        // The arc with the sub-step's mean curvature has the same heading change.
        s.curvature_per_m = if ds > 0.0 { dpsi / ds } else { k0 };
        advance_arc(s, sub);
        s.curvature_per_m = k0 + curvature_rate * sub;
    }
}

fn advance_arc(s: &mut VehicleTruth, h: f64) {
    let v0 = s.speed_mps;
    let v1 = (v0 + s.accel_mps2 * h).max(0.0);
    let ds = 0.5 * (v0 + v1) * h;
    let dpsi = s.curvature_per_m * ds;
    let mid = s.heading_unwrapped_rad + 0.5 * dpsi;
    let chord = ds * sinc(0.5 * dpsi);
    s.north_m += chord * mid.cos();
    s.east_m += chord * mid.sin();
    s.heading_unwrapped_rad += dpsi;
    s.heading_rad = wrap_pi(s.heading_unwrapped_rad);
    s.speed_mps = v1;
    s.distance_m += ds;
}

fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-6 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}
