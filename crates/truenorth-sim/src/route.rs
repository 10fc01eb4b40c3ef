//! A route as a list of driving commands (duration, longitudinal acceleration, path
//! curvature), built from distances, turn angles and speeds so scenarios read like directions.

use serde::{Deserialize, Serialize};
use truenorth_core::check_positive;
use truenorth_core::{Error, Result};

/// One driving command, held for `duration_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Command {
    /// How long the command lasts, seconds.
    pub duration_s: f64,
    /// Longitudinal acceleration, m/s².
    pub accel_mps2: f64,
    /// Path curvature of the rear-axle centre at the start of the command, 1/m, positive
    /// for a right turn.
    pub curvature_per_m: f64,
    /// Rate of change of the curvature, 1/(m·s): non-zero while the steering wheel turns
    /// (a clothoid at constant speed). The curvature must not change sign within a command.
    #[serde(default)]
    pub curvature_rate_per_m_s: f64,
    /// Turn rate in place, rad/s, positive right: a robot that drives its sides against
    /// each other turns without moving (the speed must stay zero).
    #[serde(default)]
    pub pivot_rate_rps: f64,
}

impl Command {
    /// Curvature at the end of the command, 1/m.
    pub fn end_curvature_per_m(&self) -> f64 {
        self.curvature_per_m + self.curvature_rate_per_m_s * self.duration_s
    }
}

/// A route: the commands and the speed it starts at.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Route {
    /// Speed at the start, m/s.
    pub start_speed_mps: f64,
    /// The commands in order.
    pub commands: Vec<Command>,
}

impl Route {
    /// Total heading change, turning either way counted positive, radians: `Σ |κ| · distance`
    /// over the commands (exact, unlike differences of sampled headings).
    pub fn turned_rad(&self) -> f64 {
        let mut v = self.start_speed_mps;
        let mut turned = 0.0;
        for c in &self.commands {
            let t = c.duration_s;
            // ∫ (κ₀ + κ̇τ)(v + aτ) dτ over the command; κ keeps its sign within one.
            let k0 = c.curvature_per_m;
            let kr = c.curvature_rate_per_m_s;
            let a = c.accel_mps2;
            let turn = k0 * v * t
                + (k0 * a + kr * v) * t * t / 2.0
                + kr * a * t * t * t / 3.0
                + c.pivot_rate_rps * t;
            turned += turn.abs();
            v = (v + a * t).max(0.0);
        }
        turned
    }

    /// Total duration, seconds.
    pub fn duration_s(&self) -> f64 {
        self.commands.iter().map(|c| c.duration_s).sum()
    }
}

/// Builds a [`Route`] from directions; tracks the current speed so each step's duration follows
/// from its distance or angle.
#[derive(Debug, Clone)]
pub struct RouteBuilder {
    speed_mps: f64,
    /// The duration of the commands so far, s (kept as they are added, so that asking
    /// for it costs nothing however long the route).
    duration_s: f64,
    route: Route,
}

impl Default for RouteBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl RouteBuilder {
    /// Starts at rest.
    pub fn new() -> Self {
        Self {
            speed_mps: 0.0,
            duration_s: 0.0,
            route: Route {
                start_speed_mps: 0.0,
                commands: Vec::new(),
            },
        }
    }

    /// Starts already moving at `speed_mps` (no run-up).
    pub fn at_speed(speed_mps: f64) -> Result<Self> {
        check_positive("speed_mps", speed_mps)?;
        Ok(Self {
            speed_mps,
            duration_s: 0.0,
            route: Route {
                start_speed_mps: speed_mps,
                commands: Vec::new(),
            },
        })
    }

    /// The speed at the end of the route so far, m/s.
    pub fn speed_mps(&self) -> f64 {
        self.speed_mps
    }

    /// The duration of the route so far, s.
    pub fn duration_s(&self) -> f64 {
        self.duration_s
    }

    fn push(&mut self, command: Command) {
        self.duration_s += command.duration_s;
        self.route.commands.push(command);
    }

    fn moving(&self) -> Result<f64> {
        if self.speed_mps > 0.0 {
            Ok(self.speed_mps)
        } else {
            Err(Error::NotReady {
                what: "a moving vehicle",
                hint: "call change_speed before straight or turn",
            })
        }
    }

    /// Drives straight for `distance_m` at the current speed.
    pub fn straight(mut self, distance_m: f64) -> Result<Self> {
        check_positive("distance_m", distance_m)?;
        let v = self.moving()?;
        self.push(Command {
            duration_s: distance_m / v,
            accel_mps2: 0.0,
            curvature_per_m: 0.0,
            curvature_rate_per_m_s: 0.0,
            pivot_rate_rps: 0.0,
        });
        Ok(self)
    }

    /// Turns through `angle_rad` (positive right) on a circle of `radius_m` at the current
    /// speed.
    pub fn turn(mut self, angle_rad: f64, radius_m: f64) -> Result<Self> {
        check_positive("radius_m", radius_m)?;
        check_positive("|angle_rad|", angle_rad.abs())?;
        let v = self.moving()?;
        self.push(Command {
            duration_s: angle_rad.abs() * radius_m / v,
            accel_mps2: 0.0,
            curvature_per_m: angle_rad.signum() / radius_m,
            curvature_rate_per_m_s: 0.0,
            pivot_rate_rps: 0.0,
        });
        Ok(self)
    }

    /// Turns through `angle_rad` (positive right) at the current speed as a road is built:
    /// the curvature rises linearly to `1/radius_m` over `ease_s` seconds (a clothoid, the
    /// steering wheel turning), holds, and falls back over `ease_s`. The easing is shortened
    /// when the turn is too small to hold the full curvature at all.
    pub fn eased_turn(mut self, angle_rad: f64, radius_m: f64, ease_s: f64) -> Result<Self> {
        check_positive("radius_m", radius_m)?;
        check_positive("|angle_rad|", angle_rad.abs())?;
        check_positive("ease_s", ease_s)?;
        let v = self.moving()?;
        let k = angle_rad.signum() / radius_m;
        // Each easing turns through k·v·T/2; together they may take at most the whole angle.
        let ease = ease_s.min(angle_rad.abs() * radius_m / v);
        let held = (angle_rad.abs() - ease * v / radius_m) * radius_m / v;
        self.push(Command {
            duration_s: ease,
            accel_mps2: 0.0,
            curvature_per_m: 0.0,
            curvature_rate_per_m_s: k / ease,
            pivot_rate_rps: 0.0,
        });
        if held > 0.0 {
            self.push(Command {
                duration_s: held,
                accel_mps2: 0.0,
                curvature_per_m: k,
                curvature_rate_per_m_s: 0.0,
                pivot_rate_rps: 0.0,
            });
        }
        self.push(Command {
            duration_s: ease,
            accel_mps2: 0.0,
            curvature_per_m: k,
            curvature_rate_per_m_s: -k / ease,
            pivot_rate_rps: 0.0,
        });
        Ok(self)
    }

    /// Changes speed to `to_mps` at `|accel_mps2|`, driving straight meanwhile.
    pub fn change_speed(mut self, to_mps: f64, accel_mps2: f64) -> Result<Self> {
        if !(to_mps.is_finite() && to_mps >= 0.0) {
            return Err(Error::OutOfRange {
                what: "to_mps",
                value: to_mps,
                min: 0.0,
                max: f64::INFINITY,
            });
        }
        check_positive("accel_mps2", accel_mps2.abs())?;
        let dv = to_mps - self.speed_mps;
        if dv != 0.0 {
            self.push(Command {
                duration_s: dv.abs() / accel_mps2.abs(),
                accel_mps2: dv.signum() * accel_mps2.abs(),
                curvature_per_m: 0.0,
                curvature_rate_per_m_s: 0.0,
                pivot_rate_rps: 0.0,
            });
            self.speed_mps = to_mps;
        }
        Ok(self)
    }

    /// Turns in place through `angle_rad` (positive right) at `rate_rps` (the vehicle must
    /// be at rest and able to pivot: a skid-steered or differential-drive robot).
    pub fn pivot(mut self, angle_rad: f64, rate_rps: f64) -> Result<Self> {
        check_positive("|angle_rad|", angle_rad.abs())?;
        check_positive("rate_rps", rate_rps)?;
        if self.speed_mps != 0.0 {
            return Err(Error::NotReady {
                what: "a vehicle at rest",
                hint: "call change_speed(0.0, ..) before pivot",
            });
        }
        self.push(Command {
            duration_s: angle_rad.abs() / rate_rps,
            accel_mps2: 0.0,
            curvature_per_m: 0.0,
            curvature_rate_per_m_s: 0.0,
            pivot_rate_rps: angle_rad.signum() * rate_rps,
        });
        Ok(self)
    }

    /// Stands still for `duration_s` (the vehicle must be at rest).
    pub fn stop(mut self, duration_s: f64) -> Result<Self> {
        check_positive("duration_s", duration_s)?;
        if self.speed_mps != 0.0 {
            return Err(Error::NotReady {
                what: "a vehicle at rest",
                hint: "call change_speed(0.0, ..) before stop",
            });
        }
        self.push(Command {
            duration_s,
            accel_mps2: 0.0,
            curvature_per_m: 0.0,
            curvature_rate_per_m_s: 0.0,
            pivot_rate_rps: 0.0,
        });
        Ok(self)
    }

    /// The route.
    pub fn build(self) -> Route {
        self.route
    }
}
