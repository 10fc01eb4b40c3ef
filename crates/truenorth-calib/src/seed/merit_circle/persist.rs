//! Saving and restoring a [`MeritCircleCalibrator`] exactly ([`Persistent`]).

extern crate alloc;

use alloc::vec::Vec;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_compass::CompassCalibration2d;
use truenorth_core::{Error, Persistent, Result, Solution, Validate};

use crate::seed::direction_slots::{DirectionSlots, SLOTS};
use crate::seed::seed_quality::SeedJob;

use crate::seed::merit_circle::calibrator::MeritCircleCalibrator;
use crate::seed::merit_circle::calibrator::MeritCircleState;
use crate::seed::merit_circle::config::MeritCircleConfig;
use crate::seed::merit_circle::config::RING;
/// The saved state of a [`MeritCircleCalibrator`] ([`Persistent::State`]): its
/// configuration and everything it has learned. Unset values are `None` (never an infinity),
/// so the state is plain JSON-friendly data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeritCircleCalibratorState {
    /// The configuration.
    pub config: MeritCircleConfig,
    /// Samples pushed.
    pub samples: usize,
    /// The previous reading.
    pub prev: Option<Vector2<f64>>,
    /// Sum of the sample-to-sample steps.
    pub step_sum: f64,
    /// Smallest and largest coordinates seen (`None` before any sample).
    pub range: Option<(Vector2<f64>, Vector2<f64>)>,
    /// The kept data points in ring order (at most [`RING`]).
    pub ring: Vec<Vector2<f64>>,
    /// Ring slot the next data point goes to.
    pub ring_next: usize,
    /// The last data point.
    pub last_point: Option<Vector2<f64>>,
    /// The estimate and its statistics.
    pub stats: MeritCircleState,
    /// Sum of squared deviations of the circumcentres from their mean (Welford).
    pub centre_m2: f64,
    /// The kept readings by direction slot (72 entries, `None` where empty).
    pub slots: Vec<Option<Vector2<f64>>>,
    /// The current estimate.
    pub estimate: Option<Solution<CompassCalibration2d>>,
    /// Whether the estimate is refreshed at the next push (a data point was just taken).
    #[serde(default)]
    pub refresh_due: bool,
    /// The quality report of a refresh in progress (opaque).
    #[serde(default)]
    refresh: Option<MeritRefreshState>,
}

/// A refresh of the merit-circle estimate in progress, as saved: what its quality report
/// assesses and how many of its steps are done (restoring replays them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeritRefreshState {
    points: Vec<Vector2<f64>>,
    calibration: CompassCalibration2d,
    field: f64,
    samples_used: usize,
    steps: usize,
}

fn finite2(v: &Vector2<f64>) -> bool {
    v.x.is_finite() && v.y.is_finite()
}

impl Persistent for MeritCircleCalibrator {
    type State = MeritCircleCalibratorState;
    const SNAPSHOT_VERSION: u32 = 2;

    fn state(&self) -> MeritCircleCalibratorState {
        MeritCircleCalibratorState {
            config: self.config,
            samples: self.samples,
            prev: self.prev,
            step_sum: self.step_sum,
            range: (self.samples > 0).then_some((self.lo, self.hi)),
            ring: self.ring[..self.ring_len].to_vec(),
            ring_next: self.ring_next,
            last_point: self.last_point,
            stats: self.state,
            centre_m2: self.centre_m2,
            slots: self.slots.to_vec(),
            estimate: self.estimate,
            refresh_due: self.refresh_due,
            refresh: self.seed.as_ref().map(|j| MeritRefreshState {
                points: j.points().to_vec(),
                calibration: *j.calibration(),
                field: j.field(),
                samples_used: j.samples_used(),
                steps: j.steps(),
            }),
        }
    }

    fn from_state(state: MeritCircleCalibratorState) -> Result<Self> {
        let s = state;
        s.config.validate()?;
        check_values(&s)?;
        check_counts(&s)?;
        let slots = DirectionSlots::from_slice(&s.slots).ok_or(Error::InvalidSnapshot {
            reason: "the merit-circle direction slots must be 72 finite readings or empty",
        })?;
        let mut c = Self::build(s.config);
        c.samples = s.samples;
        c.prev = s.prev;
        c.step_sum = s.step_sum;
        if let Some((lo, hi)) = s.range {
            c.lo = lo;
            c.hi = hi;
        }
        c.ring[..s.ring.len()].copy_from_slice(&s.ring);
        c.ring_len = s.ring.len();
        c.ring_next = s.ring_next;
        c.last_point = s.last_point;
        c.state = s.stats;
        c.centre_m2 = s.centre_m2;
        c.slots = slots;
        c.estimate = s.estimate;
        c.refresh_due = s.refresh_due;
        if let Some(r) = &s.refresh {
            c.seed = Some(resume_refresh(r, s.samples)?);
        }
        Ok(c)
    }
}

/// Refuses a saved merit circle with a reading, range, centre or estimate that is not
/// finite, or a sum or statistic that is negative or not finite.
fn check_values(s: &MeritCircleCalibratorState) -> Result<()> {
    let invalid = |reason| Err(Error::InvalidSnapshot { reason });
    let st = &s.stats;
    let vectors_finite = s
        .prev
        .iter()
        .chain(&s.last_point)
        .chain(&s.ring)
        .all(finite2)
        && s.range.iter().all(|(a, b)| finite2(a) && finite2(b))
        && st.centre.iter().all(finite2)
        && finite2(&st.centre_mean);
    let scalars_ok = [
        s.step_sum,
        s.centre_m2,
        st.centre_mse,
        st.weight,
        st.last_merit,
    ]
    .iter()
    .all(|x| x.is_finite() && *x >= 0.0);
    if !(vectors_finite && scalars_ok) {
        return invalid("a merit-circle value is negative or not finite");
    }
    Ok(())
}

/// Refuses a saved merit circle whose ring of data points or counts do not fit together,
/// or whose estimate is not finite.
fn check_counts(s: &MeritCircleCalibratorState) -> Result<()> {
    let invalid = |reason| Err(Error::InvalidSnapshot { reason });
    let st = &s.stats;
    if s.ring.len() > RING
        || s.ring_next >= RING
        || (s.ring.len() < RING && s.ring_next != s.ring.len())
    {
        return invalid("the merit-circle ring of data points is inconsistent");
    }
    if st.centres + st.degenerate_triples > st.data_points
        || st.data_points > s.samples
        || (st.centres > 0) != st.centre.is_some()
        || (s.samples > 0) != s.range.is_some()
        || (s.samples > 0) != s.prev.is_some()
    {
        return invalid("the merit-circle counts do not fit together");
    }
    if let Some(e) = &s.estimate
        && !(e.params.hard_iron.iter().chain(e.params.soft_iron.iter())).all(|x| x.is_finite())
    {
        return invalid("the merit-circle estimate is not finite");
    }
    Ok(())
}

/// The refresh in progress, restarted and replayed to the step it was saved at, after
/// checking it against the `samples` pushed.
fn resume_refresh(r: &MeritRefreshState, samples: usize) -> Result<SeedJob> {
    let cal = &r.calibration;
    if !(r.points.iter().all(finite2)
        && cal
            .hard_iron
            .iter()
            .chain(cal.soft_iron.iter())
            .all(|x| x.is_finite())
        && r.field > 0.0
        && r.field.is_finite())
        || r.points.len() > SLOTS
        || r.steps >= SeedJob::STEPS
        || r.samples_used > samples
    {
        return Err(Error::InvalidSnapshot {
            reason: "the saved merit-circle refresh in progress is inconsistent",
        });
    }
    let mut job = SeedJob::start(&r.points, cal, r.field, r.samples_used);
    for _ in 0..r.steps {
        job.step();
    }
    Ok(job)
}
