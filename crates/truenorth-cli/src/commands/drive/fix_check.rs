//! What a drive's use of its satellite fixes says of them. A count of rejected fixes in the
//! summary is easy to read past; fixes that lie outside the sensors' rows, that the gate
//! rejects in numbers neither their errors nor the sensors' explain, none of which is used,
//! or whose course follows the gyro's turns later than the estimator takes them to be, are
//! said in a warning with what can cause it.

use truenorth::checks::CourseLagCheck;
use truenorth::checks::course_lag::{MAX_LAG_S, MIN_LAG_S};
use truenorth::core::VehicleSample;
use truenorth::fusion::GnssConfig;
use truenorth::fusion::vehicle::GnssCounts;

/// Share of the fixes judged beyond which rejections are said: the gate's 4σ rejects a
/// fix in ten thousand that is as good as it claims; the simulated receivers of
/// `truenorth-fusion`'s `vehicle_gnss` test, 2.7 % under open sky, 5.9 % in canyons between
/// jumps and 82.9 % within jumps, which is a quarter over a drive in its multipath-heavy
/// city — a drive worth a warning that names multipath first.
const REJECTED_SHARE: f64 = 0.25;

/// Fewest rejections said: a handful is a jump or two.
const REJECTED_MIN: u32 = 10;

/// The rise of the course's misfit (a χ² of one degree of freedom) beyond which the
/// estimator's delay is refuted: 5σ.
const REFUTED_EXCESS: f64 = 25.0;

/// The course's misfit per pair beyond which no delay explains it: four times the
/// variance modelled (the receiver's speed error over the speed, and a degree).
const NO_FIT_MISFIT: f64 = 4.0;

/// When the fixes came against the other sensors' rows.
#[derive(Debug, Default)]
pub(super) struct FixTimes {
    /// The fixes' delay the estimator assumes, s.
    latency_s: f64,
    fixes: usize,
    /// Fixes on rows before any other sensor's, and since the last.
    before: usize,
    after: usize,
    fix_span: Option<(f64, f64)>,
    sensor_span: Option<(f64, f64)>,
    /// The fixes' course against the gyro's turns.
    lag: Box<CourseLagCheck>,
}

fn widen(span: &mut Option<(f64, f64)>, t_s: f64) {
    let (a, b) = span.get_or_insert((t_s, t_s));
    (*a, *b) = (a.min(t_s), b.max(t_s));
}

impl FixTimes {
    /// A check of fixes the estimator takes to be `latency_s` late.
    pub(super) fn new(latency_s: f64) -> Self {
        Self {
            latency_s,
            ..Self::default()
        }
    }

    /// Notes a row.
    pub(super) fn push(&mut self, sample: &VehicleSample) {
        self.lag.push(sample);
        let sensor = sample.gyr_z_rps.is_some()
            || sample.wheels.is_some()
            || sample.dist_m.is_some()
            || sample.mag.is_some();
        if sensor {
            widen(&mut self.sensor_span, sample.t_s);
            self.after = 0;
        }
        if sample.gnss.is_some() {
            self.fixes += 1;
            widen(&mut self.fix_span, sample.t_s);
            if self.sensor_span.is_none() {
                self.before += 1;
            } else if !sensor {
                self.after += 1;
            }
        }
    }

    /// The warnings the fixes' use calls for (`counts` once the estimator has taken any),
    /// each a sentence.
    pub(super) fn warnings(&self, counts: Option<GnssCounts>) -> Vec<String> {
        let mut out = Vec::new();
        let (Some((f0, f1)), fixes) = (self.fix_span, self.fixes) else {
            return out;
        };
        let outside = self.before + self.after;
        if 2 * outside > fixes {
            let sensors = self
                .sensor_span
                .map_or("none".to_string(), |(a, b)| format!("t {a:.1}–{b:.1} s"));
            out.push(format!(
                "{outside} of the {fixes} satellite fixes lie outside the other sensors' rows \
                 (fixes t {f0:.1}–{f1:.1} s, sensors {sensors}): the fixes are stamped on \
                 another clock than the sensors, or come from another recording; a fix is used \
                 only among the sensors' rows"
            ));
        }
        let counts = counts.unwrap_or_default();
        let judged = counts.used + counts.rejected;
        if counts.rejected >= REJECTED_MIN
            && f64::from(counts.rejected) > REJECTED_SHARE * f64::from(judged)
        {
            out.push(format!(
                "{} of the {judged} satellite fixes judged were rejected as too far from the \
                 dead-reckoned track: they and the sensors disagree by more than either's errors \
                 explain — multipath in a city, a `gnss_sigma_m` that claims too much, a lever \
                 arm, track or wheel setting that is off, or fixes stamped seconds late or on \
                 another clock than the sensors; the track follows the fixes only where they \
                 agree with it",
                counts.rejected
            ));
        } else if counts.used == 0 && out.is_empty() {
            out.push(format!(
                "none of the {fixes} satellite fixes was used ({} rejected): a fix is used once \
                 the vehicle moves, and without odometry only its course, at 3 m/s or more",
                counts.rejected
            ));
        }
        out.extend(self.lag_warning());
        out
    }

    /// The fixes' delay, where their course's turns refute the one the estimator assumes.
    fn lag_warning(&self) -> Option<String> {
        let spread_s = GnssConfig::default().latency_sigma_s;
        let latency_s = self.latency_s;
        let found = self.lag.lag();
        let refuted = self
            .lag
            .excess_at(latency_s)
            .is_some_and(|e| e > REFUTED_EXCESS);
        match found {
            Some(f) if f.misfit > NO_FIT_MISFIT && refuted => Some(format!(
                "the satellite fixes' course does not follow the gyro's turns at any delay from \
                 {MIN_LAG_S} to {MAX_LAG_S} s ({} pairs of courses, misfit {:.1} times their \
                 noise): the fixes are stamped on another clock than the gyro, or the course is \
                 not the vehicle's; their positions are judged as if taken {} s before their \
                 stamps",
                f.pairs, f.misfit, latency_s
            )),
            Some(f) if refuted && (f.lag_s - latency_s).abs() > 3.0 * spread_s => {
                let remedy = if f.lag_s > 0.0 {
                    format!(
                        "set \"gnss_latency_s\": {:.2} in the vehicle file, or give the fix rows \
                         the time of their epoch",
                        f.lag_s
                    )
                } else {
                    "give the fix rows the time of their epoch".to_string()
                };
                Some(format!(
                    "the satellite fixes are stamped {:.2} ± {:.2} s after the epoch they \
                     describe (their course follows the gyro's turns that late; {} pairs of \
                     courses), where {latency_s} ± {spread_s} s is assumed: they are stamped on \
                     another clock than the gyro, or queued by the logger; the estimator learns \
                     such a delay as a gyro bias and a track off by the speed times it — {remedy}",
                    f.lag_s, f.sigma_s, f.pairs
                ))
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use truenorth::core::GnssFix;

    fn row(t_s: f64, gyro: bool, fix: bool) -> VehicleSample {
        let mut s = VehicleSample::at(t_s);
        if gyro {
            s = s.with_gyro(0.0);
        }
        if fix {
            s = s.with_gnss(GnssFix::at(52.5, 13.4));
        }
        s
    }

    /// Fixes after the sensors' last row (another clock) are said; fixes among them are not.
    #[test]
    fn fixes_beyond_the_sensors_rows_are_said() {
        let mut apart = FixTimes::new(0.1);
        (0..10).for_each(|k| apart.push(&row(f64::from(k), true, false)));
        (0..10).for_each(|k| apart.push(&row(1000.0 + f64::from(k), false, true)));
        let w = apart.warnings(None);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with("10 of the 10 satellite fixes lie outside"),
            "{w:?}"
        );

        let mut among = FixTimes::new(0.1);
        for k in 0..10 {
            among.push(&row(f64::from(k), true, false));
            among.push(&row(f64::from(k) + 0.5, false, true));
        }
        let used = GnssCounts {
            used: 10,
            ..GnssCounts::default()
        };
        assert!(among.warnings(Some(used)).is_empty());
        let rejected = GnssCounts {
            used: 20,
            rejected: 10,
            restarts: 0,
        };
        assert!(among.warnings(Some(rejected))[0].contains("10 of the 30"));
        let fewer = GnssCounts {
            used: 40,
            rejected: 10,
            restarts: 0,
        };
        assert!(among.warnings(Some(fewer)).is_empty());
        assert!(among.warnings(None)[0].starts_with("none of the 10"));
        assert!(FixTimes::new(0.1).warnings(None).is_empty());
    }
}
