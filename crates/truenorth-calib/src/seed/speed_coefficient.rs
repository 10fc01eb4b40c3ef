//! The adaptive speed coefficient of US 4,788,645 (eqs. 9-13, claims
//! 10-11): in a turn the wheels' difference grows with speed as `1 + aV²`, and `a` is refined
//! turn by turn against the compass.
//!
//! Over a turn, `ERROR = Δθ_w − Δθ_c` when the wheels turned right (`Δθ_w ≥ 0`) and
//! `Δθ_c − Δθ_w` when they turned left (eq. 11), with `Δθ_w` the wheels' heading change
//! under the current `a` and `Δθ_c` the compass's; it is clamped to `±M` (eq. 12) and
//! `a ← a + ERROR/T_C` (eq. 13). A turn counts only when it is over 45°, driven at 15-45 mph,
//! and the compass is consistent (the patent's three criteria).
//!
//! What the patent leaves open is how the compass's change is read. Here it is read against
//! the wheels, on straights: before the turn the offset `ψ_c − θ_w` (compass minus wheel
//! heading) is averaged over [`SpeedCoefficientConfig::window_s`]; after it, once the
//! wheels have run straight for [`SpeedCoefficientConfig::settle_s`], again; the difference
//! of the two offsets is `Δθ_c − Δθ_w`, with the compass noise averaged down and the
//! vehicle's own turning in the windows taken out. The compass is consistent when the
//! readings of each window agree with their mean within
//! [`SpeedCoefficientConfig::max_spread_deg`].
//!
//! Units: `a` in s²/m², `ERROR` and `M` in radians, so `T_C` is in rad·m²/s² (the patent's
//! "filter distance constant" `T_C` relates the two without saying how).

use serde::{Deserialize, Serialize};
use truenorth_core::extended_float::check_plain_numbers_finite;
use truenorth_core::{
    Calibrator, Error, FitQuality, OnlineCalibrator, Persistent, Progress, Pushed, Result,
    ScalarQuality, Solution, TimeStep, Validate, check_finite, check_positive, check_range,
    mph_to_mps, wrap_pi,
};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Settings of the [`SpeedCoefficientCalibrator`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SpeedCoefficientConfig {
    /// The precomputed `a` to start from, s²/m² (0).
    pub initial_s2_per_m2: f64,
    /// The clamp `M` of eq. 12, rad (0.05, about 3°: a larger error is a disturbed
    /// compass, not a wrong `a`).
    pub error_clamp_rad: f64,
    /// The filter constant `T_C` of eq. 13, rad·m²/s² (4000: a 90° turn at 12 m/s moves
    /// `a` by 6 % of its error, a 270° ramp at 15 m/s by 40 %). One turn's error is measured
    /// to about half a degree (two compass windows and the wheels' pulses), a small share of
    /// the signal when `a` is small, so a long memory pays: after fifty-odd qualifying turns
    /// `tests/speed_coefficient.rs` found 1500 leaving one of eight vehicles 13 % off,
    /// 4000 none beyond 10 %.
    pub filter_constant: f64,
    /// Smallest turn that refines `a`, degrees (45).
    pub min_turn_deg: f64,
    /// Slowest mean speed through the turn, m/s (15 mph).
    pub min_speed_mps: f64,
    /// Fastest mean speed through the turn, m/s (45 mph).
    pub max_speed_mps: f64,
    /// Wheel heading rate that starts a turn, °/s (3), after a low-pass of
    /// [`SpeedCoefficientConfig::rate_smoothing_s`].
    pub turn_rate_dps: f64,
    /// Time constant of the low-pass on the wheel heading rate, s (0.5): one odometer
    /// pulse more on one wheel than the other in a step is a rate of several degrees per
    /// second at 10 Hz, and must not start a turn.
    pub rate_smoothing_s: f64,
    /// Straight running after a turn before the after-window opens, s (1).
    pub settle_s: f64,
    /// Length of the compass windows before and after the turn, s (2).
    pub window_s: f64,
    /// Largest spread of a window's offsets about their mean for the compass to count as
    /// consistent, degrees (2).
    pub max_spread_deg: f64,
}

impl Default for SpeedCoefficientConfig {
    fn default() -> Self {
        Self {
            initial_s2_per_m2: 0.0,
            error_clamp_rad: 0.05,
            filter_constant: 4000.0,
            min_turn_deg: 45.0,
            min_speed_mps: mph_to_mps(15.0),
            max_speed_mps: mph_to_mps(45.0),
            turn_rate_dps: 3.0,
            rate_smoothing_s: 0.5,
            settle_s: 1.0,
            window_s: 2.0,
            max_spread_deg: 2.0,
        }
    }
}

impl Validate for SpeedCoefficientConfig {
    fn validate(&self) -> Result<()> {
        check_range("initial_s2_per_m2", self.initial_s2_per_m2, -1e-2, 1e-2)?;
        check_positive("error_clamp_rad", self.error_clamp_rad)?;
        check_positive("filter_constant", self.filter_constant)?;
        check_range("min_turn_deg", self.min_turn_deg, 0.0, 3600.0)?;
        check_range("min_speed_mps", self.min_speed_mps, 0.0, 100.0)?;
        check_range(
            "max_speed_mps",
            self.max_speed_mps,
            self.min_speed_mps,
            100.0,
        )?;
        check_positive("turn_rate_dps", self.turn_rate_dps)?;
        check_range("rate_smoothing_s", self.rate_smoothing_s, 0.0, 60.0)?;
        check_range("settle_s", self.settle_s, 0.0, 60.0)?;
        check_positive("window_s", self.window_s)?;
        check_positive("max_spread_deg", self.max_spread_deg)?;
        Ok(())
    }
}

/// One step of the vehicle as the refiner sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpeedStep {
    /// Timestamp, seconds.
    pub t_s: f64,
    /// The wheels' heading change over the step under the current `a` (eq. 10), rad,
    /// positive right.
    pub wheel_heading_change_rad: f64,
    /// Speed over the step, m/s.
    pub speed_mps: f64,
    /// The calibrated compass heading at this step, if there is a reading the caller
    /// trusts, rad.
    pub compass_heading_rad: Option<f64>,
}

/// Offsets `ψ_c − θ_w` of one window, relative to its first (so they stay unwrapped).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
struct Window {
    first: Option<f64>,
    start_s: f64,
    n: u32,
    sum: f64,
    sum_sq: f64,
}

impl Window {
    fn push(&mut self, t_s: f64, offset: f64) {
        let first = *self.first.get_or_insert_with(|| {
            self.start_s = t_s;
            offset
        });
        let d = wrap_pi(offset - first);
        self.n += 1;
        self.sum += d;
        self.sum_sq += d * d;
    }

    /// Mean offset and spread of this window and an earlier one together (the spread is
    /// the larger of the two).
    fn merged(&self, earlier: &Window) -> Option<(f64, f64)> {
        match (earlier.mean_spread(), self.mean_spread()) {
            (Some((m1, s1)), Some((m2, s2))) => {
                let (n1, n2) = (f64::from(earlier.n), f64::from(self.n));
                let m = wrap_pi(m1 + n2 / (n1 + n2) * wrap_pi(m2 - m1));
                Some((m, s1.max(s2)))
            }
            (a, b) => b.or(a),
        }
    }

    /// Mean offset and spread, when the window has at least three readings.
    fn mean_spread(&self) -> Option<(f64, f64)> {
        let first = self.first?;
        if self.n < 3 {
            return None;
        }
        let n = f64::from(self.n);
        let m = self.sum / n;
        let var = ((self.sum_sq - n * m * m) / (n - 1.0)).max(0.0);
        Some((wrap_pi(first + m), var.sqrt()))
    }
}

/// Where the refiner is in the cycle straight → turn → straight. The offset before the turn
/// is NaN when the before-window was not consistent (the turn is then waited out unused).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
enum Phase {
    /// Running straight: the before-window slides along.
    Straight,
    /// Turning, with the offset before the turn.
    Turning {
        #[serde(with = "truenorth_core::extended_float::scalar")]
        before: f64,
    },
    /// Straight again, waiting out the settle time, then filling the after-window.
    After {
        #[serde(with = "truenorth_core::extended_float::scalar")]
        before: f64,
        straight_s: f64,
    },
}

/// The patent's adaptive refiner of `a`. Push allocates nothing.
///
/// ```
/// use truenorth_calib::{SpeedCoefficientCalibrator, SpeedCoefficientConfig, SpeedStep};
/// use truenorth_core::{Calibrator, OnlineCalibrator};
///
/// // Wheels that over-state every turn by a·V² with a = 5·10⁻⁵ s²/m², 90° turns at
/// // 12 m/s between straights, a perfect compass, 10 Hz.
/// let a_true = 5e-5;
/// let mut cal = SpeedCoefficientCalibrator::new(SpeedCoefficientConfig::default())?;
/// let (mut t, mut psi) = (0.0, 0.0f64);
/// for _ in 0..60 {
///     for k in 0..100 {
///         // 6 s straight, then a 90° turn over 4 s.
///         let rate = if k >= 60 { 90f64.to_radians() / 4.0 } else { 0.0 };
///         let dpsi = rate * 0.1;
///         psi += dpsi;
///         let a = cal.estimate().map_or(0.0, |s| s.params);
///         let wheel = dpsi * (1.0 + a_true * 144.0) / (1.0 + a * 144.0);
///         t += 0.1;
///         cal.push(&SpeedStep { t_s: t, wheel_heading_change_rad: wheel, speed_mps: 12.0, compass_heading_rad: Some(psi) })?;
///     }
/// }
/// let a = cal.solve()?.params;
/// assert!((a / a_true - 1.0).abs() < 0.05, "{a}");
/// # Ok::<(), truenorth_core::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedCoefficientCalibrator {
    config: SpeedCoefficientConfig,
    a: f64,
    clock: TimeStep,
    wheel_heading: f64,
    rate_rps: f64,
    phase: Phase,
    window: Window,
    /// The window before `window` on the same straight (the before-window slides along in
    /// two halves, so that a turn never finds it just emptied).
    earlier: Window,
    turn_rad: f64,
    turn_speed_sum: f64,
    turn_steps: u32,
    updates: usize,
    steps: usize,
    error_sq_sum: f64,
}

impl SpeedCoefficientCalibrator {
    /// A refiner starting from the configured `a`.
    pub fn new(config: SpeedCoefficientConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self::fresh(config))
    }

    /// A calibrator that has seen nothing, from a validated `config` (so that `reset` cannot
    /// fail).
    fn fresh(config: SpeedCoefficientConfig) -> Self {
        Self {
            config,
            a: config.initial_s2_per_m2,
            clock: TimeStep::new(),
            wheel_heading: 0.0,
            rate_rps: 0.0,
            phase: Phase::Straight,
            window: Window::default(),
            earlier: Window::default(),
            turn_rad: 0.0,
            turn_speed_sum: 0.0,
            turn_steps: 0,
            updates: 0,
            steps: 0,
            error_sq_sum: 0.0,
        }
    }

    /// The current `a`, s²/m².
    pub fn coefficient(&self) -> f64 {
        self.a
    }

    /// Turns that have refined `a` so far.
    pub fn updates(&self) -> usize {
        self.updates
    }

    /// The patent's update from a completed turn (eqs. 11-13), if the turn qualifies.
    fn finish_turn(&mut self, before: f64, after: f64) {
        let c = &self.config;
        let steps = f64::from(self.turn_steps.max(1));
        let speed = self.turn_speed_sum / steps;
        if self.turn_rad.abs() < c.min_turn_deg.to_radians()
            || speed < c.min_speed_mps
            || speed > c.max_speed_mps
        {
            return;
        }
        // Δθ_w − Δθ_c = offset before − offset after (the offsets are ψ_c − θ_w).
        let w_minus_c = wrap_pi(before - after);
        let error = if self.turn_rad >= 0.0 {
            w_minus_c
        } else {
            -w_minus_c
        };
        let clamped = error.clamp(-c.error_clamp_rad, c.error_clamp_rad);
        self.a += clamped / c.filter_constant;
        self.updates += 1;
        self.error_sq_sum += clamped * clamped;
    }
    /// Low-passes the wheels' heading rate over a step of `dt` s; true while it says the
    /// vehicle turns.
    fn turning(&mut self, step: &SpeedStep, dt: f64) -> bool {
        let c = &self.config;
        let alpha = if c.rate_smoothing_s > 0.0 {
            (dt / c.rate_smoothing_s).min(1.0)
        } else {
            1.0
        };
        self.rate_rps += alpha * (step.wheel_heading_change_rad / dt - self.rate_rps);
        self.rate_rps.abs() >= c.turn_rate_dps.to_radians()
    }

    /// Running straight: a turn starts, or the before-window slides along.
    fn straight(&mut self, step: &SpeedStep, offset: Option<f64>, turning: bool) {
        let c = self.config;
        if turning {
            // The before-window must be full and consistent, else the turn is not
            // used (but still waited out).
            let before = self
                .window
                .merged(&self.earlier)
                .filter(|&(_, s)| s <= c.max_spread_deg.to_radians())
                .map_or(f64::NAN, |(m, _)| m);
            self.phase = Phase::Turning { before };
            self.turn_rad = step.wheel_heading_change_rad;
            self.turn_speed_sum = step.speed_mps;
            self.turn_steps = 1;
        } else {
            if step.t_s - self.window.start_s > 0.5 * c.window_s {
                self.earlier = self.window;
                self.window = Window::default();
            }
            if let Some(o) = offset {
                self.window.push(step.t_s, o);
            }
        }
    }

    /// Turning: the turn grows, until the wheels run straight again.
    fn turn(&mut self, step: &SpeedStep, dt: f64, before: f64, turning: bool) {
        self.turn_rad += step.wheel_heading_change_rad;
        self.turn_speed_sum += step.speed_mps;
        self.turn_steps += 1;
        if !turning {
            self.phase = Phase::After {
                before,
                straight_s: dt,
            };
            self.window = Window::default();
            self.earlier = Window::default();
        }
    }

    /// Straight again after a turn, for `straight_s`: turning again makes one longer turn;
    /// otherwise the after-window fills once settled, and when full the turn is finished.
    fn after(
        &mut self,
        step: &SpeedStep,
        offset: Option<f64>,
        before: f64,
        straight_s: f64,
        turning: bool,
    ) {
        let c = self.config;
        if turning {
            // Turning again before the after-window filled: one longer turn.
            self.phase = Phase::Turning { before };
            self.turn_rad += step.wheel_heading_change_rad;
            self.turn_speed_sum += step.speed_mps;
            self.turn_steps += 1;
            return;
        }
        self.phase = Phase::After { before, straight_s };
        if let (true, Some(o)) = (straight_s > c.settle_s, offset) {
            self.window.push(step.t_s, o);
        }
        if straight_s > c.settle_s + c.window_s {
            let after = self
                .window
                .mean_spread()
                .filter(|&(_, s)| s <= c.max_spread_deg.to_radians());
            if let (Some((after, _)), true) = (after, before.is_finite()) {
                self.finish_turn(before, after);
            }
            // The after-window is the next turn's before-window.
            self.phase = Phase::Straight;
        }
    }
}

impl Calibrator for SpeedCoefficientCalibrator {
    type Sample = SpeedStep;
    type Params = f64;
    type Quality = ScalarQuality;

    /// Takes one step; a non-finite value or a timestamp that does not increase is refused
    /// and changes nothing. Returns [`Pushed::NewEstimate`] when a turn refined `a`.
    fn push(&mut self, step: &SpeedStep) -> Result<Pushed> {
        check_finite("wheel_heading_change_rad", step.wheel_heading_change_rad)?;
        check_finite("speed_mps", step.speed_mps)?;
        if let Some(h) = step.compass_heading_rad {
            check_finite("compass_heading_rad", h)?;
        }
        let mut clock = self.clock;
        let dt = clock.dt_s(step.t_s)?;
        self.clock = clock;
        self.steps += 1;
        self.wheel_heading += step.wheel_heading_change_rad;
        let offset = step
            .compass_heading_rad
            .map(|h| wrap_pi(h - self.wheel_heading));
        let Some(dt) = dt else {
            if let Some(o) = offset {
                self.window.push(step.t_s, o);
            }
            return Ok(Pushed::Accepted);
        };
        let turning = self.turning(step, dt);
        let before_updates = self.updates;
        match self.phase {
            Phase::Straight => self.straight(step, offset, turning),
            Phase::Turning { before } => self.turn(step, dt, before, turning),
            Phase::After { before, straight_s } => {
                self.after(step, offset, before, straight_s + dt, turning)
            }
        }
        Ok(if self.updates > before_updates {
            Pushed::NewEstimate
        } else {
            Pushed::Accepted
        })
    }

    /// `ready` once a turn has refined `a`; `coverage` is that count over ten.
    fn progress(&self) -> Progress {
        Progress {
            samples: self.steps,
            coverage: (self.updates as f64 / 10.0).min(1.0),
            ready: self.updates > 0,
        }
    }

    /// The current `a`, with the RMS of the clamped errors over `T_C` as its sigma (how
    /// much a single turn moves it), or [`truenorth_core::Error::NotReady`] before any
    /// turn has refined it.
    fn solve(&self) -> Result<Solution<f64, ScalarQuality>> {
        if self.updates == 0 {
            return Err(truenorth_core::Error::NotReady {
                what: "the speed coefficient",
                hint: "drive turns of over 45° at 15-45 mph with a calibrated compass",
            });
        }
        let n = self.updates as f64;
        Ok(Solution {
            params: self.a,
            quality: ScalarQuality {
                fit: FitQuality {
                    points: self.updates,
                    coverage: (n / 10.0).min(1.0),
                    residual_rms_rel: 0.0,
                    condition: 1.0,
                },
                sigma: (self.error_sq_sum / n).sqrt() / self.config.filter_constant,
            },
        })
    }

    fn reset(&mut self) {
        *self = Self::fresh(self.config);
    }
}

impl OnlineCalibrator for SpeedCoefficientCalibrator {
    fn estimate(&self) -> Option<Solution<f64, ScalarQuality>> {
        self.solve().ok()
    }
}

/// The saved state of a [`SpeedCoefficientCalibrator`] ([`Persistent::State`]): its
/// configuration, the coefficient learned and where the refiner is in its cycle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpeedCoefficientState {
    /// The configuration.
    pub config: SpeedCoefficientConfig,
    /// The current `a`, s²/m².
    pub coefficient_s2_per_m2: f64,
    /// The last accepted timestamp.
    pub clock: TimeStep,
    /// The wheels' heading summed since the start, rad.
    pub wheel_heading_rad: f64,
    /// The low-passed wheel heading rate, rad/s.
    pub rate_rps: f64,
    /// The wheels' heading change over the turn in progress, rad.
    pub turn_rad: f64,
    /// Sum of the speeds over the turn in progress, m/s.
    pub turn_speed_sum_mps: f64,
    /// Steps of the turn in progress.
    pub turn_steps: u32,
    /// Turns that have refined `a`.
    pub updates: usize,
    /// Steps taken.
    pub steps: usize,
    /// Sum of the squared clamped errors of those turns, rad².
    pub error_sq_sum_rad2: f64,
    /// Straight, turning or after a turn (opaque).
    phase: Phase,
    /// The compass window filling now (opaque).
    window: Window,
    /// The window before it on the same straight (opaque).
    earlier: Window,
}

/// Refuses a window whose count and first offset disagree, or whose sums could not come
/// from its readings.
fn check_window(w: &Window) -> Result<()> {
    if (w.n > 0) != w.first.is_some() || w.sum_sq < 0.0 {
        return Err(Error::InvalidSnapshot {
            reason: "a speed-coefficient compass window is inconsistent",
        });
    }
    Ok(())
}

impl Persistent for SpeedCoefficientCalibrator {
    type State = SpeedCoefficientState;
    const SNAPSHOT_VERSION: u32 = 1;

    fn state(&self) -> SpeedCoefficientState {
        SpeedCoefficientState {
            config: self.config,
            coefficient_s2_per_m2: self.a,
            clock: self.clock,
            wheel_heading_rad: self.wheel_heading,
            rate_rps: self.rate_rps,
            turn_rad: self.turn_rad,
            turn_speed_sum_mps: self.turn_speed_sum,
            turn_steps: self.turn_steps,
            updates: self.updates,
            steps: self.steps,
            error_sq_sum_rad2: self.error_sq_sum,
            phase: self.phase,
            window: self.window,
            earlier: self.earlier,
        }
    }

    fn from_state(s: SpeedCoefficientState) -> Result<Self> {
        s.config.validate()?;
        check_plain_numbers_finite(&s)?;
        let invalid = |reason| Err(Error::InvalidSnapshot { reason });
        if let Phase::Turning { before } | Phase::After { before, .. } = s.phase
            && before.is_infinite()
        {
            return invalid("the offset saved before a turn is infinite");
        }
        if s.updates > s.steps || (s.steps > 0) != s.clock.last_s().is_some() {
            return invalid("the speed-coefficient counts do not fit together");
        }
        if s.error_sq_sum_rad2 < 0.0 {
            return invalid("the speed-coefficient sum of squared errors is negative");
        }
        check_window(&s.window)?;
        check_window(&s.earlier)?;
        Ok(Self {
            config: s.config,
            a: s.coefficient_s2_per_m2,
            clock: s.clock,
            wheel_heading: s.wheel_heading_rad,
            rate_rps: s.rate_rps,
            phase: s.phase,
            window: s.window,
            earlier: s.earlier,
            turn_rad: s.turn_rad,
            turn_speed_sum: s.turn_speed_sum_mps,
            turn_steps: s.turn_steps,
            updates: s.updates,
            steps: s.steps,
            error_sq_sum: s.error_sq_sum_rad2,
        })
    }
}
