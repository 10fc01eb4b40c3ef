//! The GNSS receiver: at each epoch of its clock, the antenna's true position (the rear-axle
//! centre plus the lever arm turned with the heading) plus a time-correlated error, white
//! noise and any multipath jump, as WGS84 latitude and longitude; nothing in an outage; the
//! last fix again while frozen. The velocity is the antenna's (the vehicle's plus the turn
//! times the lever arm) with white noise.

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, SplitMix64};

use super::gnss_config::{Episodes, GnssConfig};
use super::streams::{Slot, Track};
use super::timing::{Clock, Timed};
use crate::LocalTangentPlane;

use super::gnss_truth::{FixCondition, GnssFix, GnssTruth};

/// A multipath jump: an offset held for a while.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Jump {
    /// Start, s after the truth starts.
    pub start_s: f64,
    /// Length, s.
    pub duration_s: f64,
    /// The offset, m north and east.
    pub offset_ne_m: [f64; 2],
}

/// Every error of one drive's receiver (times in s after the truth starts).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GnssErrors {
    /// The receiver's clock (rate, latency, jitter, lost fixes).
    pub clock: Clock,
    /// Share of the fixes sent late.
    pub late_share: f64,
    /// The antenna from the rear-axle centre, m forward and right.
    pub lever_arm_m: [f64; 2],
    /// σ of the time-correlated error per axis in the open, m.
    pub sigma_m: f64,
    /// Its correlation time, s.
    pub tau_s: f64,
    /// σ of the white error per axis, m.
    pub white_m: f64,
    /// The reported σ over the process's.
    pub sigma_honesty: f64,
    /// σ of the velocity's error per axis, m/s.
    pub velocity_noise_mps: f64,
    /// The error's σ in a canyon over its σ in the open.
    pub canyon_sigma_factor: f64,
    /// Outages, (start, end).
    pub outages: Vec<(f64, f64)>,
    /// Urban canyons, (start, end).
    pub canyons: Vec<(f64, f64)>,
    /// Multipath jumps.
    pub jumps: Vec<Jump>,
    /// Frozen spells, (start, end).
    pub frozen: Vec<(f64, f64)>,
}

/// An exponentially distributed time of mean `mean`.
fn exponential(mean: f64, rng: &mut SplitMix64) -> f64 {
    -mean * (1.0 - rng.uniform()).ln()
}

/// The windows of `e` within `[0, duration_s]`.
fn windows(e: &Option<Episodes>, duration_s: f64, rng: &mut SplitMix64) -> Vec<(f64, f64)> {
    let Some(e) = e else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut t = e.first_after_s + exponential(e.mean_gap_s, rng);
    while t < duration_s {
        let end = t + e.duration_s.draw(rng);
        out.push((t, end));
        t = end + exponential(e.mean_gap_s, rng);
    }
    out
}

/// Whether `t` lies in one of `windows` (in time order, not overlapping).
fn inside(windows: &[(f64, f64)], t: f64) -> bool {
    let k = windows.partition_point(|w| w.0 <= t);
    k > 0 && windows[k - 1].1 > t
}

impl GnssErrors {
    /// A receiver drawn from `config` for a drive of `duration_s`.
    pub fn draw(config: &GnssConfig, duration_s: f64, rng: &mut SplitMix64) -> Self {
        let clock = Clock::draw(&config.timing, rng);
        let late_share = config.late.map_or(0.0, |l| l.share.draw(rng));
        let lever_arm_m = [
            config.lever_forward_m.draw(rng),
            config.lever_right_m.draw(rng),
        ];
        let sigma_m = config.sigma_m.draw(rng);
        let tau_s = config.tau_s.draw(rng);
        let white_m = config.white_m.draw(rng);
        let sigma_honesty = config.sigma_honesty.draw(rng);
        let velocity_noise_mps = config.velocity_noise_mps.draw(rng);
        let outages = windows(&config.outages, duration_s, rng);
        let canyons = windows(&config.canyons.map(|c| c.episodes), duration_s, rng);
        let frozen = windows(&config.frozen, duration_s, rng);
        let (mut canyon_sigma_factor, mut jumps) = (1.0, Vec::new());
        if let Some(c) = config.canyons {
            canyon_sigma_factor = c.sigma_factor.draw(rng);
            let per_s = c.jumps_per_min.draw(rng) / 60.0;
            for &(a, b) in &canyons {
                if per_s <= 0.0 {
                    break;
                }
                let mut t = a + exponential(1.0 / per_s, rng);
                while t < b {
                    let size = c.jump_m.draw(rng);
                    let (s, co) = (2.0 * core::f64::consts::PI * rng.uniform()).sin_cos();
                    jumps.push(Jump {
                        start_s: t,
                        duration_s: c.jump_s.draw(rng),
                        offset_ne_m: [size * co, size * s],
                    });
                    t += exponential(1.0 / per_s, rng);
                }
            }
        }
        Self {
            clock,
            late_share,
            lever_arm_m,
            sigma_m,
            tau_s,
            white_m,
            sigma_honesty,
            velocity_noise_mps,
            canyon_sigma_factor,
            outages,
            canyons,
            jumps,
            frozen,
        }
    }

    /// The multipath offset at `t_s`, m north and east, if a jump is on (`longest_s`: the
    /// longest jump's length).
    fn jump_at(&self, t_s: f64, longest_s: f64) -> Option<[f64; 2]> {
        let started = self.jumps.partition_point(|j| j.start_s <= t_s);
        self.jumps[..started]
            .iter()
            .rev()
            .take_while(|j| t_s - j.start_s < longest_s)
            .filter(|j| t_s < j.start_s + j.duration_s)
            .map(|j| j.offset_ne_m)
            .reduce(|a, b| [a[0] + b[0], a[1] + b[1]])
    }
}

/// `x` to whole steps of 10⁻⁷, as receivers report degrees.
fn seventh(x: f64) -> f64 {
    (x * 1e7).round() / 1e7
}

/// The receiver's fixes over the drive, with the truth behind each.
pub(crate) fn gnss_stream(
    track: &Track,
    config: &GnssConfig,
    e: &GnssErrors,
    plane: &LocalTangentPlane,
    rng: &mut SplitMix64,
) -> Result<Vec<Timed<Slot>>> {
    let epochs = e.clock.instants(track.duration_s);
    let truth = track.at(&epochs)?;
    let late = config.late.map(|l| l.extra_s);
    let mut error = [rng.normal(e.sigma_m), rng.normal(e.sigma_m)];
    let mut prev_t = truth.first().map_or(0.0, |s| s.t_s);
    let mut last: Option<(GnssFix, [f64; 2])> = None;
    let longest = e.jumps.iter().map(|j| j.duration_s).fold(0.0, f64::max);
    let mut out = Vec::with_capacity(truth.len());
    for s in &truth {
        let canyon = inside(&e.canyons, s.t_s);
        let sigma = e.sigma_m * if canyon { e.canyon_sigma_factor } else { 1.0 };
        let decay = (-(s.t_s - prev_t) / e.tau_s).exp();
        let drive = sigma * (1.0 - decay * decay).sqrt();
        error = [
            error[0] * decay + rng.normal(drive),
            error[1] * decay + rng.normal(drive),
        ];
        prev_t = s.t_s;
        let white = [rng.normal(e.white_m), rng.normal(e.white_m)];
        let noise_v = [
            rng.normal(e.velocity_noise_mps),
            rng.normal(e.velocity_noise_mps),
        ];
        let sent = match late {
            Some(extra) if rng.uniform() < e.late_share => s.t_s + extra.draw(rng),
            _ => s.t_s,
        };
        if inside(&e.outages, s.t_s) {
            continue;
        }
        let (sin, cos) = s.heading_rad.sin_cos();
        let [fwd, right] = e.lever_arm_m;
        let antenna = [
            s.north_m + fwd * cos - right * sin,
            s.east_m + fwd * sin + right * cos,
        ];
        let (fix, at, condition) = match last {
            Some((fix, at)) if inside(&e.frozen, s.t_s) => (fix, at, FixCondition::Frozen),
            _ => {
                let jump = e.jump_at(s.t_s, longest);
                let j = jump.unwrap_or([0.0; 2]);
                let n = antenna[0] + error[0] + white[0] + j[0];
                let east = antenna[1] + error[1] + white[1] + j[1];
                let g = plane.to_geodetic(n, east, 0.0)?;
                // The antenna's velocity: the vehicle's along its heading plus the turn
                // times the lever arm (body x forward, y right, z down).
                let (vx, vy) = (s.speed_mps - s.yaw_rate_rps * right, s.yaw_rate_rps * fwd);
                let vn = vx * cos - vy * sin + noise_v[0];
                let ve = vx * sin + vy * cos + noise_v[1];
                let fix = GnssFix {
                    lat_deg: seventh(g.lat_rad().to_degrees()),
                    lon_deg: seventh(g.lon_rad().to_degrees()),
                    sigma_m: config.report_sigma.then(|| {
                        let s = e.sigma_honesty * sigma.hypot(e.white_m);
                        (s * 1e3).round() / 1e3
                    }),
                    speed_mps: config.report_velocity.then(|| vn.hypot(ve)),
                    course_deg: config
                        .report_velocity
                        .then(|| ve.atan2(vn).to_degrees().rem_euclid(360.0)),
                };
                // Where the reported (rounded) latitude and longitude are, at the plane's
                // height there.
                let reported = truenorth_geomag::Geodetic::from_degrees(
                    fix.lat_deg,
                    fix.lon_deg,
                    g.height_m(),
                )?;
                let [rn, re, _] = plane.from_geodetic(&reported);
                let condition = match (jump, canyon) {
                    (Some(_), _) => FixCondition::Multipath,
                    (None, true) => FixCondition::Canyon,
                    (None, false) => FixCondition::Open,
                };
                (fix, [rn, re], condition)
            }
        };
        last = Some((fix, at));
        let truth = GnssTruth {
            epoch_s: s.t_s,
            antenna_ne_m: antenna,
            error_ne_m: [at[0] - antenna[0], at[1] - antenna[1]],
            condition,
        };
        out.push((s.t_s, sent, Slot::Gnss(fix, truth)));
    }
    Ok(track.stamped(&e.clock, out, rng))
}
