//! What a GNSS receiver on a vehicle does, and the ranges its errors are drawn from.
//!
//! | habit | default, drawn per drive | why |
//! |---|---|---|
//! | rate, latency | 1–10 Hz; fixes stamped 50–500 ms after their epoch, 20 ms jitter | consumer receivers send 1–10 fixes a second, each after it is computed (a real robot log: one every 0.4 s) |
//! | late fixes | 0–2 % of the fixes a further 0.5–2 s late | a receiver or a logger that stalls |
//! | error | a first-order Gauss–Markov process per axis, σ 0.7–3 m, correlation time 20–200 s, plus 0.05–0.3 m of white noise | single-frequency fixes are strongly correlated in time, an Ornstein–Uhlenbeck process fitting them far better than white noise (Sensors 20(21), 6050, 2020, "Comparison of enhanced noise model performance based on analysis of civilian GPS data") |
//! | reported σ (`gnss_sigma_m`) | the process's σ times 0.7–1.4 | roughly honest in the open; it knows nothing of a multipath jump |
//! | speed and course | Doppler velocity with 0.03–0.2 m/s of white noise per axis | the course is the velocity's direction, so it is noise at walking speed and at rest |
//! | outages | tunnels and car parks of 10–90 s, one every 5 minutes on average, none in the first minute | |
//! | urban canyons | 20–120 s every 4 minutes on average: σ 2–4 times larger, and jumps of 10–60 m lasting 1–8 s, 1–6 a minute | multipath and non-line-of-sight reception (Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems*, 2nd ed., 2013, on multipath and NLOS) |
//! | frozen fix | the last fix repeated for 1–5 s, 2–10 times an hour | a receiver that keeps sending its last solution when it loses lock |
//! | lever arm | the antenna 0.5–2.5 m ahead of the rear axle on a car (−0.3–0.3 m on a robot), ±0.3 m to the side | roof antennas sit over the cabin; the truth is the rear-axle centre |
//!
//! Fixes are WGS84 latitude and longitude in the tangent plane at [`GnssConfig::origin`]
//! ([`crate::LocalTangentPlane`]), in steps of 10⁻⁷° as receivers report them.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, check_range};

use super::span::Span;
use super::timing::SensorTiming;

/// Where the truth's start is on the Earth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Origin {
    /// Latitude, degrees north (within ±85).
    pub lat_deg: f64,
    /// Longitude, degrees east.
    pub lon_deg: f64,
    /// Height above the WGS84 ellipsoid, m (−500–9000).
    pub height_m: f64,
}

impl Origin {
    /// Potsdamer Platz, Berlin.
    pub const BERLIN: Self = Self {
        lat_deg: 52.5096,
        lon_deg: 13.3760,
        height_m: 74.0,
    };
}

/// Windows in which something happens now and then: the first no sooner than
/// `first_after_s`, then one every `mean_gap_s` on average (exponential gaps), each lasting
/// a time drawn from `duration_s`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Episodes {
    /// No episode before this time, s (0–1e5).
    pub first_after_s: f64,
    /// Mean time from the end of one episode to the start of the next, s (1–1e6).
    pub mean_gap_s: f64,
    /// Length of an episode, s, drawn uniformly (0.1–1e4).
    pub duration_s: Span,
}

impl Episodes {
    fn check(&self, what: &'static str) -> Result<()> {
        check_range(what, self.first_after_s, 0.0, 1e5)?;
        check_range(what, self.mean_gap_s, 1.0, 1e6)?;
        self.duration_s.check(what, 0.1, 1e4)
    }
}

/// Urban canyons: episodes with a larger error and multipath jumps.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Canyons {
    /// When the vehicle is in a canyon.
    pub episodes: Episodes,
    /// The error's σ in a canyon over its σ in the open, drawn uniformly per drive (1–20).
    pub sigma_factor: Span,
    /// Multipath jumps per minute in a canyon, drawn uniformly per drive (0–60).
    pub jumps_per_min: Span,
    /// Size of a jump, m, drawn uniformly per jump, in any direction (0–1000).
    pub jump_m: Span,
    /// Length of a jump, s, drawn uniformly per jump (0.05–600).
    pub jump_s: Span,
}

/// Fixes that arrive seconds late.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LateFixes {
    /// Share of the fixes that are late, drawn uniformly per drive (0–0.5).
    pub share: Span,
    /// How much later than the others, s, drawn uniformly per late fix (0–30).
    pub extra_s: Span,
}

/// A GNSS receiver (defaults per vehicle kind in [`GnssConfig::for_car`] and
/// [`GnssConfig::for_robot`]; the module documentation gives them and their reasons).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GnssConfig {
    /// Where the truth starts: the tangent plane's origin.
    pub origin: Origin,
    /// Decimal year of the drive, for the declination the compass sees (2025–2030).
    pub year: f64,
    /// When the receiver computes fixes and when they reach the log.
    pub timing: SensorTiming,
    /// Fixes that arrive seconds late (`None`: none).
    pub late: Option<LateFixes>,
    /// σ of the time-correlated error per axis in the open, m, drawn uniformly (0–100).
    pub sigma_m: Span,
    /// Its correlation time, s, drawn uniformly (0.01–1e5).
    pub tau_s: Span,
    /// σ of the white error per axis, m, drawn uniformly (0–100).
    pub white_m: Span,
    /// The reported σ over the process's σ, drawn uniformly per drive (0.1–10).
    pub sigma_honesty: Span,
    /// Whether the fixes carry `gnss_sigma_m`.
    pub report_sigma: bool,
    /// Whether the fixes carry `gnss_speed_mps,gnss_course_deg`.
    pub report_velocity: bool,
    /// σ of the velocity's white error per axis, m/s, drawn uniformly (0–10).
    pub velocity_noise_mps: Span,
    /// Antenna ahead of the rear-axle centre, m, drawn uniformly (−10–10).
    pub lever_forward_m: Span,
    /// Antenna to the right of the rear-axle centre, m, drawn uniformly (−10–10).
    pub lever_right_m: Span,
    /// Tunnels and car parks (`None`: none).
    pub outages: Option<Episodes>,
    /// Urban canyons (`None`: none).
    pub canyons: Option<Canyons>,
    /// The last fix sent again while the receiver has lost lock (`None`: never).
    pub frozen: Option<Episodes>,
}

impl Default for GnssConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl GnssConfig {
    /// A car's receiver in a city (module documentation).
    pub const fn for_car() -> Self {
        Self {
            origin: Origin::BERLIN,
            year: 2026.0,
            timing: SensorTiming {
                rate_hz: Span::new(1.0, 10.0),
                latency_s: Span::new(0.05, 0.5),
                jitter_s: 0.02,
                drop_probability: Span::new(0.0, 0.02),
            },
            late: Some(LateFixes {
                share: Span::new(0.0, 0.02),
                extra_s: Span::new(0.5, 2.0),
            }),
            sigma_m: Span::new(0.7, 3.0),
            tau_s: Span::new(20.0, 200.0),
            white_m: Span::new(0.05, 0.3),
            sigma_honesty: Span::new(0.7, 1.4),
            report_sigma: true,
            report_velocity: true,
            velocity_noise_mps: Span::new(0.03, 0.2),
            lever_forward_m: Span::new(0.5, 2.5),
            lever_right_m: Span::new(-0.3, 0.3),
            outages: Some(Episodes {
                first_after_s: 60.0,
                mean_gap_s: 300.0,
                duration_s: Span::new(10.0, 90.0),
            }),
            canyons: Some(Canyons {
                episodes: Episodes {
                    first_after_s: 30.0,
                    mean_gap_s: 240.0,
                    duration_s: Span::new(20.0, 120.0),
                },
                sigma_factor: Span::new(2.0, 4.0),
                jumps_per_min: Span::new(1.0, 6.0),
                jump_m: Span::new(10.0, 60.0),
                jump_s: Span::new(1.0, 8.0),
            }),
            frozen: Some(Episodes {
                first_after_s: 0.0,
                mean_gap_s: 600.0,
                duration_s: Span::new(1.0, 5.0),
            }),
        }
    }

    /// A robot's receiver: the antenna within 0.3 m of the axle, the rest as a car's.
    pub const fn for_robot() -> Self {
        let mut c = Self::for_car();
        c.lever_forward_m = Span::new(-0.3, 0.3);
        c
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        let o = &self.origin;
        check_range("gnss origin lat_deg", o.lat_deg, -85.0, 85.0)?;
        check_range("gnss origin lon_deg", o.lon_deg, -180.0, 180.0)?;
        check_range("gnss origin height_m", o.height_m, -500.0, 9000.0)?;
        check_range("gnss year", self.year, 2025.0, 2030.0)?;
        self.timing.check()?;
        if let Some(l) = self.late {
            l.share.check("gnss late share", 0.0, 0.5)?;
            l.extra_s.check("gnss late extra_s", 0.0, 30.0)?;
        }
        self.sigma_m.check("gnss sigma_m", 0.0, 100.0)?;
        self.tau_s.check("gnss tau_s", 0.01, 1e5)?;
        self.white_m.check("gnss white_m", 0.0, 100.0)?;
        self.sigma_honesty.check("gnss sigma_honesty", 0.1, 10.0)?;
        self.velocity_noise_mps
            .check("gnss velocity_noise_mps", 0.0, 10.0)?;
        self.lever_forward_m
            .check("gnss lever_forward_m", -10.0, 10.0)?;
        self.lever_right_m
            .check("gnss lever_right_m", -10.0, 10.0)?;
        if let Some(e) = self.outages {
            e.check("gnss outages")?;
        }
        if let Some(c) = self.canyons {
            c.episodes.check("gnss canyons")?;
            c.sigma_factor
                .check("gnss canyon sigma_factor", 1.0, 20.0)?;
            c.jumps_per_min
                .check("gnss canyon jumps_per_min", 0.0, 60.0)?;
            c.jump_m.check("gnss canyon jump_m", 0.0, 1000.0)?;
            c.jump_s.check("gnss canyon jump_s", 0.05, 600.0)?;
        }
        if let Some(e) = self.frozen {
            e.check("gnss frozen")?;
        }
        Ok(())
    }
}
