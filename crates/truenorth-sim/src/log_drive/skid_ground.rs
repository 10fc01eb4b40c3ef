//! How a skid-steered robot's sides see its turns: the effective track.
//!
//! A skid-steered vehicle turns by sliding its wheels sideways, so its sides' speeds differ
//! by more than the physical track predicts: `v_l − v_r = ω·χ·B`, with `B` the physical track
//! and `χ ≥ 1` the expansion factor, the distance between the instantaneous centres of
//! rotation of the two sides over `B` (Mandow et al., "Experimental kinematics for wheeled
//! skid-steer mobile robots", IROS 2007, eq. 7, who measured it per surface for one robot;
//! Martínez et al., "Approximating kinematics for tracked mobile robots", IJRR 24(10), 2005).
//! `χ` is a property of the ground first (the friction and the tyres' sinkage), and changes
//! with the radius of the turn and the speed (Wang et al., "Analysis and experimental
//! kinematics of a skid-steering wheeled robot based on a laser scanner sensor", Sensors
//! 15(5), 2015, measured a Pioneer 3-AT's ICR coefficient against both). The model here:
//!
//! `χ = χ_ground · (1 + g_tight · B/(B + |R|)) · (1 + g_lat · a_lat/g) · (1 + w)`
//!
//! with `χ_ground` drawn per patch of ground, `R` the turn's radius (0 in place), `a_lat`
//! the lateral acceleration and `w` a Gauss–Markov wander. The direction of the radius and
//! speed dependence differs between robots and grounds in the published experiments, so
//! their gains are drawn with either sign. The sides' mean speed is the robot's (symmetric
//! centres of rotation), so a skid-steer's sides are exact about "not turning".

use serde::{Deserialize, Serialize};
use truenorth_core::{NoiseSource, Result, STANDARD_GRAVITY_MPS2, SplitMix64, check_range};

use super::span::Span;
use crate::VehicleTruth;

/// How a skid-steered robot's sides see its turns (defaults in brackets).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SkidSteerConfig {
    /// The expansion factor χ of each patch of ground, drawn uniformly per patch (1.4–2.4;
    /// 1–5).
    pub ground_factor: Span,
    /// Length of a patch of ground, m, drawn uniformly per patch (10–100; 0.1–1e5).
    pub patch_m: Span,
    /// Relative change of χ in a turn in place against a wide arc, drawn uniformly per
    /// drive (−0.1–0.3; −0.5–1).
    pub tight_turn_gain: Span,
    /// Relative change of χ per g of lateral acceleration, drawn uniformly per drive
    /// (−0.5–0.5; −2–2).
    pub per_g: Span,
    /// Standard deviation of χ's relative wander (0.03; 0–0.5).
    pub wander: f64,
    /// Correlation time of the wander, s (5; 0.01–1e4).
    pub wander_tau_s: f64,
}

impl Default for SkidSteerConfig {
    fn default() -> Self {
        Self {
            ground_factor: Span::new(1.4, 2.4),
            patch_m: Span::new(10.0, 100.0),
            tight_turn_gain: Span::new(-0.1, 0.3),
            per_g: Span::new(-0.5, 0.5),
            wander: 0.03,
            wander_tau_s: 5.0,
        }
    }
}

impl SkidSteerConfig {
    /// Checks every field against its range.
    pub fn check(&self) -> Result<()> {
        self.ground_factor.check("skid ground_factor", 1.0, 5.0)?;
        self.patch_m.check("skid patch_m", 0.1, 1e5)?;
        self.tight_turn_gain
            .check("skid tight_turn_gain", -0.5, 1.0)?;
        self.per_g.check("skid per_g", -2.0, 2.0)?;
        check_range("skid wander", self.wander, 0.0, 0.5)?;
        check_range("skid wander_tau_s", self.wander_tau_s, 0.01, 1e4)?;
        Ok(())
    }
}

/// The ground a skid-steer drive crossed and how its sides saw the turns there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkidGround {
    /// The patches of ground: where each starts (m of the robot's travel) and its χ.
    pub patches: Vec<(f64, f64)>,
    /// The relative change of χ in a turn in place.
    pub tight_turn_gain: f64,
    /// The relative change of χ per g of lateral acceleration.
    pub per_g: f64,
    /// The physical track, m.
    pub track_m: f64,
}

impl SkidGround {
    /// χ without its wander at `distance_m` of travel, in a turn of radius `radius_m` (0 in
    /// place, infinite when straight) at lateral acceleration `a_lat_mps2`.
    pub fn factor(&self, distance_m: f64, radius_m: f64, a_lat_mps2: f64) -> f64 {
        let ground = self
            .patches
            .iter()
            .take_while(|(start, _)| *start <= distance_m)
            .last()
            .map_or(1.0, |p| p.1);
        let b = self.track_m;
        let tight = if radius_m.is_finite() {
            b / (b + radius_m.abs())
        } else {
            0.0
        };
        ground
            * (1.0 + self.tight_turn_gain * tight)
            * (1.0 + self.per_g * a_lat_mps2.abs() / STANDARD_GRAVITY_MPS2)
    }
}

/// The running χ: the ground drawn patch by patch as the robot reaches it, and the wander.
#[derive(Debug, Clone)]
pub(crate) struct SkidProcess {
    config: SkidSteerConfig,
    pub ground: SkidGround,
    /// Where the last drawn patch ends, m.
    drawn_to_m: f64,
    wander: f64,
}

impl SkidProcess {
    /// Draws the drive's gains and the first patch.
    pub fn new(config: SkidSteerConfig, track_m: f64, rng: &mut SplitMix64) -> Self {
        let ground = SkidGround {
            patches: vec![(0.0, config.ground_factor.draw(rng))],
            tight_turn_gain: config.tight_turn_gain.draw(rng),
            per_g: config.per_g.draw(rng),
            track_m,
        };
        Self {
            drawn_to_m: config.patch_m.draw(rng),
            wander: rng.normal(config.wander),
            config,
            ground,
        }
    }

    /// Advances from `p` to `s` and returns the factor by which the sides' turn exceeds the
    /// robot's over the step.
    pub fn step(&mut self, p: &VehicleTruth, s: &VehicleTruth, rng: &mut SplitMix64) -> f64 {
        while self.drawn_to_m <= s.distance_m {
            let chi = self.config.ground_factor.draw(rng);
            self.ground.patches.push((self.drawn_to_m, chi));
            self.drawn_to_m += self.config.patch_m.draw(rng);
        }
        let dt = s.t_s - p.t_s;
        let decay = (-dt / self.config.wander_tau_s).exp();
        self.wander =
            self.wander * decay + rng.normal(self.config.wander * (1.0 - decay * decay).sqrt());
        let rate = 0.5 * (p.yaw_rate_rps + s.yaw_rate_rps);
        let speed = 0.5 * (p.speed_mps + s.speed_mps);
        let radius = if rate == 0.0 {
            f64::INFINITY
        } else {
            speed / rate
        };
        self.ground.factor(s.distance_m, radius, speed * rate) * (1.0 + self.wander)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ground(tight: f64, per_g: f64) -> SkidGround {
        SkidGround {
            patches: vec![(0.0, 1.5), (50.0, 2.0)],
            tight_turn_gain: tight,
            per_g,
            track_m: 0.57,
        }
    }

    #[test]
    fn the_factor_follows_the_ground_the_radius_and_the_lateral_acceleration() {
        let g = ground(0.2, 0.0);
        assert_eq!(g.factor(10.0, f64::INFINITY, 0.0), 1.5);
        assert_eq!(g.factor(60.0, f64::INFINITY, 0.0), 2.0);
        // In place the tight-turn gain applies in full, on a wide arc hardly at all.
        assert!((g.factor(10.0, 0.0, 0.0) - 1.5 * 1.2).abs() < 1e-12);
        assert!(g.factor(10.0, 100.0, 0.0) < 1.5 * 1.002);
        let g = ground(0.0, 0.5);
        let a = STANDARD_GRAVITY_MPS2 * 0.1;
        assert!((g.factor(10.0, 2.0, a) - 1.5 * 1.05).abs() < 1e-12);
    }

    #[test]
    fn the_ground_is_drawn_as_the_robot_reaches_it() {
        let mut rng = SplitMix64::new(2);
        let mut p = SkidProcess::new(SkidSteerConfig::default(), 0.57, &mut rng);
        let mut prev = VehicleTruth::default();
        for k in 1..=5000 {
            let s = VehicleTruth {
                t_s: k as f64 * 0.1,
                distance_m: k as f64 * 0.1,
                speed_mps: 1.0,
                ..VehicleTruth::default()
            };
            let f = p.step(&prev, &s, &mut rng);
            assert!((1.0..3.0).contains(&f), "{f}");
            prev = s;
        }
        let patches = &p.ground.patches;
        // 500 m in patches of 10–100 m.
        assert!((5..=51).contains(&patches.len()), "{}", patches.len());
        assert!(patches.windows(2).all(|w| w[1].0 - w[0].0 >= 10.0 - 1e-9));
        assert!(patches.iter().all(|p| (1.4..=2.4).contains(&p.1)));
    }
}
