//! Input validation that every crate reuses: finite values, increasing timestamps, dt > 0.

use crate::{Error, Result};
use nalgebra::{Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// A configuration that can check itself: every `Config` in truenorth implements it, and
/// every `new(config)` calls it first, so an invalid parameter is a typed error at
/// construction, never a NaN later.
pub trait Validate {
    /// `Ok` when every parameter is finite and in its documented range; otherwise the first
    /// offending parameter, named.
    fn validate(&self) -> Result<()>;
}

/// Returns `value` if it is finite, otherwise [`Error::NonFinite`] naming `what`.
#[inline]
pub fn check_finite(what: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::NonFinite { what, value })
    }
}

/// Returns `value` if it is finite and within `[min, max]`: otherwise
/// [`Error::NonFinite`] or [`Error::OutOfRange`] naming `what` and the valid range.
#[inline]
pub fn check_range(what: &'static str, value: f64, min: f64, max: f64) -> Result<f64> {
    check_finite(what, value)?;
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(Error::OutOfRange {
            what,
            value,
            min,
            max,
        })
    }
}

/// Returns `value` if it is finite and strictly positive (a length, a gain, a rate).
#[inline]
pub fn check_positive(what: &'static str, value: f64) -> Result<f64> {
    check_finite(what, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(Error::OutOfRange {
            what,
            value,
            // The smallest normal positive number stands for "just above zero".
            min: f64::MIN_POSITIVE,
            max: f64::MAX,
        })
    }
}

/// Checks both components of a 2-vector.
#[inline]
pub fn check_finite2(what: &'static str, v: &Vector2<f64>) -> Result<()> {
    for &x in v.iter() {
        check_finite(what, x)?;
    }
    Ok(())
}

/// Checks all three components of a 3-vector.
#[inline]
pub fn check_finite3(what: &'static str, v: &Vector3<f64>) -> Result<()> {
    for &x in v.iter() {
        check_finite(what, x)?;
    }
    Ok(())
}

/// Derives `dt` from successive timestamps and rejects any that do not increase.
///
/// A rejected timestamp leaves the state unchanged, so the caller can skip that sample and go on.
/// It is plain data (serde), saved with the estimator that owns it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TimeStep {
    last_t_s: Option<f64>,
}

impl TimeStep {
    /// A clock that has seen no timestamp yet.
    pub const fn new() -> Self {
        Self { last_t_s: None }
    }

    /// Accepts timestamp `t_s` and returns the step from the previous one (`None` for the first).
    pub fn dt_s(&mut self, t_s: f64) -> Result<Option<f64>> {
        check_finite("timestamp t_s", t_s)?;
        match self.last_t_s {
            None => {
                self.last_t_s = Some(t_s);
                Ok(None)
            }
            Some(prev_s) if t_s > prev_s => {
                let dt = t_s - prev_s;
                self.last_t_s = Some(t_s);
                Ok(Some(dt))
            }
            Some(prev_s) => Err(Error::NonIncreasingTime { prev_s, t_s }),
        }
    }

    /// The last accepted timestamp.
    pub fn last_s(&self) -> Option<f64> {
        self.last_t_s
    }

    /// Forgets the last timestamp.
    pub fn reset(&mut self) {
        self.last_t_s = None;
    }
}

/// Returns `dt_s` if it is a positive finite time step, otherwise [`Error::InvalidDt`].
pub fn check_dt(dt_s: f64) -> Result<f64> {
    if dt_s.is_finite() && dt_s > 0.0 {
        Ok(dt_s)
    } else {
        Err(Error::InvalidDt { dt_s })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn increasing_timestamps_give_their_differences(
            start in -1e6f64..1e6,
            steps in proptest::collection::vec(1e-6f64..10.0, 1..100),
        ) {
            let mut c = TimeStep::new();
            prop_assert_eq!(c.dt_s(start).unwrap(), None);
            let mut t = start;
            for s in steps {
                let next = t + s;
                let dt = c.dt_s(next).unwrap().unwrap();
                prop_assert!(dt > 0.0);
                prop_assert!((dt - (next - t)).abs() <= 1e-9 * next.abs().max(1.0));
                t = next;
            }
        }

        #[test]
        fn non_increasing_is_rejected_and_state_kept(t in -1e6f64..1e6, back in 0.0f64..10.0) {
            let mut c = TimeStep::new();
            c.dt_s(t).unwrap();
            let is_nonincreasing_error = matches!(
                c.dt_s(t - back),
                Err(Error::NonIncreasingTime { .. })
            );
            prop_assert!(is_nonincreasing_error);
            prop_assert_eq!(c.last_s(), Some(t));
        }

        #[test]
        fn range_checks_accept_exactly_the_range(v in proptest::num::f64::ANY, a in -1e3f64..1e3, w in 0.0f64..1e3) {
            let b = a + w;
            let ok = v.is_finite() && v >= a && v <= b;
            prop_assert_eq!(check_range("v", v, a, b).is_ok(), ok);
            prop_assert_eq!(check_positive("v", v).is_ok(), v.is_finite() && v > 0.0);
            if !v.is_finite() {
                let non_finite = matches!(check_range("v", v, a, b), Err(Error::NonFinite { .. }));
                prop_assert!(non_finite);
            }
        }

        #[test]
        fn any_f64_never_panics(x in proptest::num::f64::ANY, y in proptest::num::f64::ANY) {
            let mut c = TimeStep::new();
            let _ = c.dt_s(x);
            let _ = c.dt_s(y);
            prop_assert_eq!(check_finite("x", x).is_ok(), x.is_finite());
        }
    }
}
