//! How a vehicle's body tilts, which a level-assumed two-axis compass reads as heading: it
//! rolls out of every turn, pitches on grades and as it speeds up and brakes, and sits on the
//! road's camber. A tilt of φ lets the vertical field `Z = H·tan(dip)` into the compass's
//! axes, so at mid-latitudes (dip 60–70°) one degree of roll turns a heading near north or
//! south by 2–3°: the largest error a vehicle's compass has, periodic in heading for a steady
//! roll.
//!
//! | tilt | cars | robots | why |
//! |---|---|---|---|
//! | roll | 2–5° per g of lateral acceleration, out of the turn | 0–1°/g | a car's roll gradient; a robot's stiff chassis |
//! | pitch | 0.5–2°/g, nose up accelerating | 0–0.5°/g | squat and dive |
//! | grade | a Gauss–Markov grade along the road, σ 2–5 %, over 100–400 m | σ 1–4 % over 10–50 m | |
//! | camber | −2…2 % (roll) | none | a road's cross-fall |
//! | dip | 50–75°, no steeper than keeps the total field within the Earth's 67 µT; the World Magnetic Model's at the GNSS origin when there is a receiver | | mid-latitudes |

use serde::{Deserialize, Serialize};
use truenorth_core::{EulerZyx, NoiseSource, Result, STANDARD_GRAVITY_MPS2, SplitMix64};

use super::span::Span;
use crate::VehicleTruth;

/// Strongest total field on the Earth's surface, µT (the World Magnetic Model's range is
/// about 22–67 µT).
const MAX_TOTAL_FIELD_UT: f64 = 67.0;

/// The ranges a vehicle body's tilt is drawn from, each per drive (defaults per vehicle kind
/// in [`TiltConfig::for_car`] and [`TiltConfig::for_robot`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TiltConfig {
    /// Roll out of a turn per g of lateral acceleration, degrees, drawn uniformly (0–20).
    pub roll_deg_per_g: Span,
    /// Pitch, nose up, per g of forward acceleration, degrees, drawn uniformly (0–20).
    pub pitch_deg_per_g: Span,
    /// The road's camber: roll, right side down, %, drawn uniformly (−10–10).
    pub camber_pct: Span,
    /// Standard deviation of the grade, %, drawn uniformly (0–30).
    pub grade_pct: Span,
    /// Distance over which the grade changes (its correlation length), m, drawn uniformly
    /// (1–1e5).
    pub grade_length_m: Span,
    /// The field's dip, degrees, drawn uniformly (0–89), where no GNSS origin gives it.
    pub dip_deg: Span,
}

impl Default for TiltConfig {
    fn default() -> Self {
        Self::for_car()
    }
}

impl TiltConfig {
    /// A car (module documentation).
    pub const fn for_car() -> Self {
        Self {
            roll_deg_per_g: Span::new(2.0, 5.0),
            pitch_deg_per_g: Span::new(0.5, 2.0),
            camber_pct: Span::new(-2.0, 2.0),
            grade_pct: Span::new(2.0, 5.0),
            grade_length_m: Span::new(100.0, 400.0),
            dip_deg: Span::new(50.0, 75.0),
        }
    }

    /// A robot (module documentation).
    pub const fn for_robot() -> Self {
        Self {
            roll_deg_per_g: Span::new(0.0, 1.0),
            pitch_deg_per_g: Span::new(0.0, 0.5),
            camber_pct: Span::fixed(0.0),
            grade_pct: Span::new(1.0, 4.0),
            grade_length_m: Span::new(10.0, 50.0),
            dip_deg: Span::new(50.0, 75.0),
        }
    }

    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.roll_deg_per_g
            .check("tilt roll_deg_per_g", 0.0, 20.0)?;
        self.pitch_deg_per_g
            .check("tilt pitch_deg_per_g", 0.0, 20.0)?;
        self.camber_pct.check("tilt camber_pct", -10.0, 10.0)?;
        self.grade_pct.check("tilt grade_pct", 0.0, 30.0)?;
        self.grade_length_m.check("tilt grade_length_m", 1.0, 1e5)?;
        self.dip_deg.check("tilt dip_deg", 0.0, 89.0)
    }
}

/// One drive's body tilt.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TiltErrors {
    /// Roll out of a turn per g of lateral acceleration, rad.
    pub roll_rad_per_g: f64,
    /// Pitch, nose up, per g of forward acceleration, rad.
    pub pitch_rad_per_g: f64,
    /// Roll from the road's camber, rad, right side down.
    pub camber_rad: f64,
    /// Standard deviation of the grade (rise over run).
    pub grade_sigma: f64,
    /// The grade's correlation length, m.
    pub grade_length_m: f64,
}

impl TiltErrors {
    /// A body drawn from `config`.
    pub fn draw(config: &TiltConfig, rng: &mut SplitMix64) -> Self {
        Self {
            roll_rad_per_g: config.roll_deg_per_g.draw(rng).to_radians(),
            pitch_rad_per_g: config.pitch_deg_per_g.draw(rng).to_radians(),
            camber_rad: (config.camber_pct.draw(rng) / 100.0).atan(),
            grade_sigma: config.grade_pct.draw(rng) / 100.0,
            grade_length_m: config.grade_length_m.draw(rng),
        }
    }
}

/// The dip drawn from `config` for a horizontal field of `field_ut`, no steeper than keeps
/// the total field within the Earth's, rad.
pub(crate) fn drawn_dip_rad(config: &TiltConfig, field_ut: f64, rng: &mut SplitMix64) -> f64 {
    let steepest = (field_ut / MAX_TOTAL_FIELD_UT).min(1.0).acos();
    config.dip_deg.draw(rng).to_radians().min(steepest)
}

/// The grade along the road, a first-order Gauss–Markov process in distance.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TiltProcess {
    body: TiltErrors,
    grade: f64,
    distance_m: Option<f64>,
}

impl TiltProcess {
    pub fn new(body: TiltErrors, rng: &mut SplitMix64) -> Self {
        Self {
            grade: rng.normal(body.grade_sigma),
            body,
            distance_m: None,
        }
    }

    /// The body's attitude at `s`, with the grade advanced along the road to it.
    pub fn attitude(&mut self, s: &VehicleTruth, rng: &mut SplitMix64) -> EulerZyx {
        let b = self.body;
        if let Some(d0) = self.distance_m {
            let decay = (-(s.distance_m - d0).abs() / b.grade_length_m).exp();
            let drive = b.grade_sigma * (1.0 - decay * decay).sqrt();
            self.grade = self.grade * decay + rng.normal(drive);
        }
        self.distance_m = Some(s.distance_m);
        let lateral = s.speed_mps * s.yaw_rate_rps / STANDARD_GRAVITY_MPS2;
        let forward = s.accel_mps2 / STANDARD_GRAVITY_MPS2;
        EulerZyx {
            yaw_rad: s.heading_rad,
            // Out of the turn: a right turn (lateral acceleration to the right) lowers the
            // left side.
            roll_rad: b.camber_rad - b.roll_rad_per_g * lateral,
            pitch_rad: self.grade.atan() + b.pitch_rad_per_g * forward,
        }
    }
}
