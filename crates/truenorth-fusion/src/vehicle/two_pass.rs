//! The two-pass start: a drive's first minutes are estimated again once the sensors are
//! known.
//!
//! A drive that starts uncalibrated does not know north until the compass has seen enough
//! of a turn, nor its gyro's gains until it has turned both ways; a causal estimator's
//! track of those first minutes is drawn with what it knew then, and a track is only as
//! good as its worst heading. When the whole log is at hand (post-processing, as the
//! `truenorth drive` command has it) the head of the drive can be held back, in bounded
//! memory, until the estimator has learned its sensors, and then run again from the start
//! by an estimator that knows them ([`VehicleEstimator::with_calibration`]); everything
//! after the head is estimated once, as it comes. The second pass knows the compass from
//! its first reading, but refers the heading to north only after a few readings that
//! agree; the estimates before that are turned by the offset it then finds, as they would
//! have been had it known it from the start.

extern crate alloc;

use alloc::vec::Vec;

use truenorth_core::{
    Error, HeadingEstimator, MagneticHeading, NavEstimate, Result, Validate, VehicleSample,
};

use super::estimator::VehicleEstimator;
use super::gnss_track::PlaneShift;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// When the head of the drive is run again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoPassConfig {
    /// Most samples held back (the memory bound); when it is reached the head is run again
    /// with whatever has been learned.
    pub capacity: usize,
    /// Time the estimator must have had its heading referred to north, with a calibration
    /// learned from gated readings, before the head is run again, s.
    pub settle_s: f64,
}

impl Validate for TwoPassConfig {
    /// A settling time that is a number and not negative (infinite: the head is run again
    /// only when [`TwoPassConfig::capacity`] is reached; a capacity of 0 runs it at once).
    fn validate(&self) -> Result<()> {
        if self.settle_s.is_nan() || self.settle_s < 0.0 {
            return Err(Error::OutOfRange {
                what: "two-pass settle_s, s",
                value: self.settle_s,
                min: 0.0,
                max: f64::INFINITY,
            });
        }
        Ok(())
    }
}

impl Default for TwoPassConfig {
    /// 2¹⁷ samples (about 8 MB; 3.6 h at 10 Hz, 22 min at 100 Hz), 120 s.
    fn default() -> Self {
        Self {
            capacity: 1 << 17,
            settle_s: 120.0,
        }
    }
}

/// A vehicle estimator with a two-pass start. See the module documentation.
#[derive(Debug, Clone)]
pub struct TwoPassStart {
    config: TwoPassConfig,
    estimator: VehicleEstimator,
    head: Vec<VehicleSample>,
    /// The second pass's estimates of the head made before it referred the heading to
    /// north.
    held: Vec<NavEstimate>,
    replayed: bool,
    settled_since_s: Option<f64>,
}

impl TwoPassStart {
    /// Wraps `estimator` (usually fresh from [`VehicleEstimator::new`]) under a validated
    /// `config`.
    pub fn new(estimator: VehicleEstimator, config: TwoPassConfig) -> Result<Self> {
        config.validate()?;
        Ok(Self {
            config,
            estimator,
            head: Vec::new(),
            held: Vec::new(),
            replayed: false,
            settled_since_s: None,
        })
    }

    /// The estimator (the second pass's once the head has been run again).
    pub fn estimator(&self) -> &VehicleEstimator {
        &self.estimator
    }

    /// Whether the head has been run again (estimates now come as samples arrive).
    pub fn replayed(&self) -> bool {
        self.replayed
    }

    /// Takes one sample; `emit` receives each sample with its final estimate and the
    /// estimator that made it (for its calibration states), in order — none while the head
    /// is held back, the whole head at once when it is run again. A sample the estimator
    /// refuses is an error and is not held back.
    pub fn push(
        &mut self,
        sample: &VehicleSample,
        mut emit: impl FnMut(&VehicleSample, &NavEstimate, &VehicleEstimator),
    ) -> Result<()> {
        let estimate = self.estimator.update(sample)?;
        if self.replayed {
            emit(sample, &estimate, &self.estimator);
            return Ok(());
        }
        self.head.push(*sample);
        let s = estimate.status;
        if s.heading_absolute && self.estimator.compass_learner().clean_in_use() {
            let since = *self.settled_since_s.get_or_insert(sample.t_s);
            if sample.t_s - since >= self.config.settle_s {
                return self.replay(&mut emit);
            }
        }
        if self.head.len() >= self.config.capacity {
            return self.replay(&mut emit);
        }
        Ok(())
    }

    /// Ends the drive: a head still held back is run again with what was learned.
    pub fn finish(
        &mut self,
        mut emit: impl FnMut(&VehicleSample, &NavEstimate, &VehicleEstimator),
    ) -> Result<()> {
        if self.replayed {
            Ok(())
        } else {
            self.replay(&mut emit)
        }
    }

    fn replay(
        &mut self,
        emit: &mut impl FnMut(&VehicleSample, &NavEstimate, &VehicleEstimator),
    ) -> Result<()> {
        let mut second = self.estimator.replay_start()?;
        // Where the first pass put its track on the fixes' plane, the second waits for it
        // too, so that the whole head comes out in the plane.
        let expect_plane = self.estimator.gnss_plane_shift().is_some();
        let mut waiting = 0;
        let mut last_sigma_rad = f64::NAN;
        for (k, s) in self.head.iter().enumerate() {
            // Every sample here was accepted by the first pass, which checks the same.
            let estimate = second.update(s)?;
            last_sigma_rad = estimate.heading_sigma_rad;
            let ready = match (second.alignment_offset_rad(), second.gnss_plane_shift()) {
                (Some(offset), plane) if plane.is_some() || !expect_plane => Some((offset, plane)),
                _ => None,
            };
            let Some((offset, plane)) = ready else {
                waiting += 1;
                self.held.push(estimate);
                continue;
            };
            let declination = second.gnss_declination_rad().unwrap_or(0.0);
            let drift_end = self.held.last().map_or(0.0, |e| e.heading_sigma_rad);
            for (w, earlier) in self.head[k - waiting..k].iter().enumerate() {
                let e = joined(
                    &self.held[w],
                    offset,
                    Sigmas {
                        offset_rad: estimate.heading_sigma_rad,
                        drift_end_rad: drift_end,
                    },
                    plane.map(|p| (p, declination)),
                );
                emit(earlier, &e, &second);
            }
            waiting = 0;
            self.held.clear();
            emit(s, &estimate, &second);
        }
        // Never referred to north, or (the second pass not reaching the plane within the
        // head) only by the compass: what is relative to the start is turned by what is known.
        let offset = second.alignment_offset_rad();
        let start = self.head.len() - waiting;
        let drift_end = self.held.last().map_or(0.0, |e| e.heading_sigma_rad);
        for (earlier, e) in self.head[start..].iter().zip(&self.held) {
            let e = match offset {
                Some(offset) => joined(
                    e,
                    offset,
                    Sigmas {
                        offset_rad: last_sigma_rad,
                        drift_end_rad: drift_end,
                    },
                    None,
                ),
                None => *e,
            };
            emit(earlier, &e, &second);
        }
        self.held = Vec::new();
        self.estimator = second;
        self.head = Vec::new();
        self.replayed = true;
        Ok(())
    }
}

/// The uncertainties a relative estimate of the head is joined with.
#[derive(Debug, Clone, Copy)]
struct Sigmas {
    /// The heading uncertainty of the estimate that found the offset, rad.
    offset_rad: f64,
    /// The relative heading's uncertainty at the last estimate before the offset was
    /// found, rad.
    drift_end_rad: f64,
}

/// An estimate of the head as the estimates after it are: one made relative to the start
/// heading turned by `offset` onto north (heading and track), with the heading uncertainty
/// of the estimate that found the offset and of the drift between it and the estimate
/// joined; and, when the fixes put the track on their plane
/// (`plane`, with the declination), turned and shifted as the track was (see
/// [`PlaneShift`]), the heading published magnetic as every estimate's. An estimate already
/// referred to north is left as it is but for the plane. A position not known yet (before
/// the wheels' first reading) stays unknown in every direction: its infinite covariance is
/// not turned, which would mix infinities into NaN.
fn joined(
    e: &NavEstimate,
    offset: f64,
    sigmas: Sigmas,
    plane: Option<(PlaneShift, f64)>,
) -> NavEstimate {
    let relative = !e.status.heading_absolute;
    let heading_sigma_rad = sigmas.offset_rad;
    let mut t = *e;
    let mut turn = 0.0;
    if relative {
        turn = offset;
        t.heading = MagneticHeading::new(e.heading.rad() + offset);
        // The offset refers the heading to north where it was found; an earlier heading is
        // off besides by the relative heading's drift between the two, whose variance is
        // what the relative variance grew by in between: exact for independent increments,
        // and more than a bias's share, whose drift from w to k has variance ∝ (k − w)²
        // where the difference of variances has k² − w².
        let drift_var = (sigmas.drift_end_rad.powi(2) - e.heading_sigma_rad.powi(2)).max(0.0);
        t.heading_sigma_rad = (heading_sigma_rad.powi(2) + drift_var).sqrt();
        t.status.heading_absolute = true;
    }
    if let Some((p, declination)) = plane {
        if p.after_compass {
            turn += p.turn_rad;
        } else if relative {
            // The offset referred the heading to true north; published, it is magnetic.
            t.heading = MagneticHeading::new(t.heading.rad() - declination);
        }
        t.status.gnss_frame = true;
    }
    let (s, c) = turn.sin_cos();
    let (north, east) = (c * e.north_m - s * e.east_m, s * e.north_m + c * e.east_m);
    let shift = plane.map_or([0.0; 2], |(p, _)| [p.north_m, p.east_m]);
    t.north_m = north + shift[0];
    t.east_m = east + shift[1];
    if !e.status.position_known {
        return t;
    }
    let r = nalgebra::Matrix2::new(c, -s, s, c);
    t.position_cov_m2 = r * e.position_cov_m2 * r.transpose();
    if relative {
        // The offset's own error turns the track about the start: across it, in
        // proportion to the distance from the start.
        let across = nalgebra::Vector2::new(-east, north);
        t.position_cov_m2 += heading_sigma_rad * heading_sigma_rad * across * across.transpose();
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A relative heading joined to north carries the offset's uncertainty and the drift
    /// between it and where the offset was found: the relative variance's growth since.
    #[test]
    fn a_joined_heading_carries_the_drift_to_where_north_was_found() {
        let deg = |d: f64| d.to_radians();
        let sigmas = Sigmas {
            offset_rad: deg(2.0),
            drift_end_rad: deg(5.0),
        };
        let early = NavEstimate::at_start(1.0, MagneticHeading::new(deg(10.0)), deg(1.0));
        let e = joined(&early, deg(30.0), sigmas, None);
        assert!(e.status.heading_absolute);
        assert!((e.heading.rad() - deg(40.0)).abs() < 1e-12);
        let expected = (2.0f64.powi(2) + 5.0f64.powi(2) - 1.0).sqrt();
        assert!((e.heading_sigma_rad.to_degrees() - expected).abs() < 1e-9);
        // The last relative estimate before the offset: the offset's uncertainty alone.
        let last = NavEstimate::at_start(2.0, MagneticHeading::new(0.0), deg(5.0));
        let e = joined(&last, 0.0, sigmas, None);
        assert!((e.heading_sigma_rad - deg(2.0)).abs() < 1e-12);
        // An estimate already referred to north is left as it was.
        let mut absolute = early;
        absolute.status.heading_absolute = true;
        let e = joined(&absolute, deg(30.0), sigmas, None);
        assert_eq!(
            (e.heading, e.heading_sigma_rad),
            (absolute.heading, deg(1.0))
        );
    }
}
