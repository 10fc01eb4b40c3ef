//! What the seed configurations share: a heading carried by one relative source and pulled
//! towards a calibrated compass by a fixed-gain complementary filter — the way the
//! navigation computers of the seed patents' time combined them — and the track drawn
//! from it.
//!
//! Per calibrated compass reading: its field magnitude must be within
//! [`SeedBlendConfig::field_tolerance`] of the fitted one, and its heading within
//! [`SeedBlendConfig::outlier_deg`] of the carried one; then the heading moves by `dt/τ` of
//! the difference (a first-order low-pass of the compass with the relative source's changes
//! passed through). The first readings refer the heading to north.

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_core::{
    MagneticHeading, NavEstimate, Result, Validate, check_positive, check_range, wrap_pi,
};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// Settings shared by the seed configurations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SeedBlendConfig {
    /// Time constant of the pull towards the compass, s (20).
    pub tau_s: f64,
    /// Largest relative departure of the calibrated field magnitude (0.15).
    pub field_tolerance: f64,
    /// Largest difference from the carried heading a reading may have, degrees (20).
    pub outlier_deg: f64,
    /// Readings averaged to refer the heading to north (10).
    pub alignment_readings: u32,
    /// The wheels must stand still this long before the vehicle counts as at rest, s (0.5).
    pub standstill_s: f64,
    /// Readings refused as outliers for this long, with nothing used between, mean the
    /// carried heading is lost rather than the compass disturbed: the heading is referred
    /// to north again from the next readings, s (30). Without it a heading that drifted
    /// past the gate is never recovered (the wheels of US 4,788,645 drift a tenth of a
    /// degree per metre with a few tenths of a percent of scale difference).
    pub reacquire_s: f64,
}

impl Default for SeedBlendConfig {
    fn default() -> Self {
        Self {
            tau_s: 20.0,
            field_tolerance: 0.15,
            outlier_deg: 20.0,
            alignment_readings: 10,
            standstill_s: 0.5,
            reacquire_s: 30.0,
        }
    }
}

impl Validate for SeedBlendConfig {
    fn validate(&self) -> Result<()> {
        check_positive("tau_s", self.tau_s)?;
        check_range("field_tolerance", self.field_tolerance, 1e-3, 1.0)?;
        check_range("outlier_deg", self.outlier_deg, 0.1, 180.0)?;
        check_range(
            "alignment_readings",
            f64::from(self.alignment_readings),
            1.0,
            1e4,
        )?;
        check_range("standstill_s", self.standstill_s, 0.0, 60.0)?;
        check_positive("reacquire_s", self.reacquire_s)?;
        Ok(())
    }
}

/// The blended heading and the track (plain data: a seed configuration's saved state carries
/// it whole).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SeedBlend {
    config: SeedBlendConfig,
    /// Heading, rad (from the start heading until aligned).
    pub psi: f64,
    /// Position, m (north, east).
    pub position: Vector2<f64>,
    /// Distance travelled, m.
    pub distance_m: f64,
    /// The heading at the last travel, rad (the track follows the heading half-way
    /// between two).
    psi_at_travel: f64,
    aligned: bool,
    sin_sum: f64,
    cos_sum: f64,
    n: u32,
    still_s: f64,
    last_compass_t: Option<f64>,
    /// Time of the first of the outliers refused since the last reading used.
    outliers_since: Option<f64>,
    /// Whether the heading was referred to north before (the track is then not turned).
    lost: bool,
}

impl SeedBlend {
    /// At the start point, heading unknown.
    pub fn new(config: SeedBlendConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            psi: 0.0,
            position: Vector2::zeros(),
            distance_m: 0.0,
            psi_at_travel: 0.0,
            aligned: false,
            sin_sum: 0.0,
            cos_sum: 0.0,
            n: 0,
            still_s: 0.0,
            last_compass_t: None,
            outliers_since: None,
            lost: false,
        })
    }

    /// The configuration in use.
    pub fn config(&self) -> &SeedBlendConfig {
        &self.config
    }

    /// Whether the heading is referred to north.
    pub fn aligned(&self) -> bool {
        self.aligned
    }

    /// Turns the heading by `dpsi` (a relative heading sensor's step).
    pub fn turn(&mut self, dpsi: f64) {
        self.psi = wrap_pi(self.psi + dpsi);
    }

    /// Advances the rear axle by `ds_m` over `dt`, along the heading half-way between this
    /// travel and the last; returns whether the vehicle is at rest (`moved` false for the
    /// standstill time).
    pub fn travel(&mut self, ds_m: f64, dt: f64, moved: bool) -> bool {
        let mid = self.psi_at_travel + 0.5 * wrap_pi(self.psi - self.psi_at_travel);
        self.psi_at_travel = self.psi;
        let (s, c) = mid.sin_cos();
        self.position += Vector2::new(c, s) * ds_m;
        self.distance_m += ds_m.abs();
        self.still_s = if moved { 0.0 } else { self.still_s + dt };
        self.still_s >= self.config.standstill_s && self.still_s > 0.0
    }

    /// Corrects the heading by `d` (not a turn of the vehicle: the track's last heading is
    /// corrected with it).
    fn correct(&mut self, d: f64) {
        self.psi = wrap_pi(self.psi + d);
        self.psi_at_travel = wrap_pi(self.psi_at_travel + d);
    }

    /// Takes a calibrated horizontal reading `u` (body axes: x forward, y right) from a
    /// field of fitted magnitude `field` at `t_s`: its heading is `atan2(−u_y, u_x)`, since a
    /// level compass reads `(H cos ψ, −H sin ψ)`. Returns the heading if it was used.
    pub fn compass_vector(&mut self, t_s: f64, u: Vector2<f64>, field: f64) -> Option<f64> {
        self.compass(t_s, (-u.y).atan2(u.x), u.norm() / field)
    }

    /// Writes the carried heading, track and distance into `e` at `t_s`. A fixed-gain blend
    /// keeps no variance: σ is NaN once referred to north, infinite before.
    pub fn write_estimate(&self, e: &mut NavEstimate, t_s: f64) {
        e.t_s = t_s;
        e.north_m = self.position.x;
        e.east_m = self.position.y;
        e.heading = MagneticHeading::new(self.psi);
        e.heading_sigma_rad = if self.aligned {
            f64::NAN
        } else {
            f64::INFINITY
        };
        e.distance_m = self.distance_m;
        e.status.heading_absolute = self.aligned;
    }

    /// Takes a calibrated reading with heading `heading` and field ratio `ratio` (its
    /// magnitude over the fitted one) at `t_s`. Returns the heading if the reading was used.
    pub fn compass(&mut self, t_s: f64, heading: f64, ratio: f64) -> Option<f64> {
        let dt = self.last_compass_t.map_or(0.0, |t0| (t_s - t0).max(0.0));
        self.last_compass_t = Some(t_s);
        if (ratio - 1.0).abs() > self.config.field_tolerance {
            return None;
        }
        let d = wrap_pi(heading - self.psi);
        if !self.aligned {
            self.sin_sum += d.sin();
            self.cos_sum += d.cos();
            self.n += 1;
            if self.n >= self.config.alignment_readings {
                let offset = self.sin_sum.atan2(self.cos_sum);
                if !self.lost {
                    let (s, c) = offset.sin_cos();
                    self.position = Vector2::new(
                        c * self.position.x - s * self.position.y,
                        s * self.position.x + c * self.position.y,
                    );
                }
                self.correct(offset);
                self.aligned = true;
            }
            return None;
        }
        if d.abs() > self.config.outlier_deg.to_radians() {
            let since = *self.outliers_since.get_or_insert(t_s);
            if t_s - since >= self.config.reacquire_s {
                self.aligned = false;
                self.lost = true;
                (self.sin_sum, self.cos_sum, self.n) = (0.0, 0.0, 0);
                self.outliers_since = None;
            }
            return None;
        }
        self.outliers_since = None;
        self.correct((dt / self.config.tau_s).min(1.0) * d);
        Some(heading)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aligns_then_follows_the_compass_slowly() {
        let mut b = SeedBlend::new(SeedBlendConfig::default()).unwrap();
        b.travel(10.0, 1.0, true);
        for k in 0..10 {
            b.compass(k as f64 * 0.1, 1.0, 1.0);
        }
        assert!(b.aligned() && (b.psi - 1.0).abs() < 1e-12);
        // The start-to-here track turned with the heading: 10 m along heading 1 rad.
        assert!((b.position - Vector2::new(1f64.cos(), 1f64.sin()) * 10.0).norm() < 1e-9);
        // A reading 10° off pulls by dt/τ of it; one 30° off is ignored.
        b.compass(1.0, 1.0 + 10f64.to_radians(), 1.0);
        assert!((b.psi - (1.0 + 10f64.to_radians() * 0.1 / 20.0)).abs() < 1e-9);
        let before = b.psi;
        assert!(b.compass(1.2, 1.0 + 30f64.to_radians(), 1.0).is_none());
        assert!(b.compass(1.3, 1.0, 1.3).is_none());
        assert_eq!(b.psi, before);
        // Outliers for the re-acquisition time: the heading is lost and taken from the
        // compass again, without turning the track already driven.
        let position = b.position;
        for k in 0..=300 {
            assert!(b.compass(1.4 + k as f64 * 0.1, 2.0, 1.0).is_none());
        }
        assert!(!b.aligned());
        for k in 0..10 {
            b.compass(31.5 + k as f64 * 0.1, 2.0, 1.0);
        }
        assert!(b.aligned() && (b.psi - 2.0).abs() < 1e-12);
        assert_eq!(b.position, position);
    }
}
