//! Quality measures shared by every compass calibrator: how much of the circle the data
//! cover, and how large a heading error the residuals allow.

use core::f64::consts::TAU;

use nalgebra::Vector2;
use truenorth_core::wrap_two_pi;

#[allow(unused_imports)]
use truenorth_core::Float as _;

/// Number of heading bins used for coverage (10° each).
pub const COVERAGE_BINS: usize = 36;

/// How much of the circle a set of points covers, seen from a centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coverage {
    /// Share of the [`COVERAGE_BINS`] direction bins that hold at least one point, in [0, 1].
    pub fraction: f64,
    /// The largest empty arc between consecutive occupied directions, radians.
    pub largest_gap_rad: f64,
}

impl Coverage {
    /// The arc covered: 2π minus the largest gap, radians.
    pub fn span_rad(&self) -> f64 {
        TAU - self.largest_gap_rad
    }
}

/// Coverage of `points` seen from `centre`, in bins of 10°. Non-finite points are skipped.
/// Allocates nothing.
pub fn coverage<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    centre: &Vector2<f64>,
) -> Coverage {
    let mut filled = [false; COVERAGE_BINS];
    let mut any = false;
    for p in points {
        let d = p - centre;
        if !(d.x.is_finite() && d.y.is_finite()) || (d.x == 0.0 && d.y == 0.0) {
            continue;
        }
        let a = wrap_two_pi(d.y.atan2(d.x));
        let bin = ((a / TAU) * COVERAGE_BINS as f64) as usize;
        filled[bin.min(COVERAGE_BINS - 1)] = true;
        any = true;
    }
    if !any {
        return Coverage {
            fraction: 0.0,
            largest_gap_rad: TAU,
        };
    }
    let n = filled.iter().filter(|&&f| f).count();
    // Largest run of empty bins, going round the circle.
    let mut gap = 0usize;
    let mut run = 0usize;
    for i in 0..2 * COVERAGE_BINS {
        if filled[i % COVERAGE_BINS] {
            run = 0;
        } else {
            run += 1;
            gap = gap.max(run.min(COVERAGE_BINS));
        }
    }
    Coverage {
        fraction: n as f64 / COVERAGE_BINS as f64,
        largest_gap_rad: gap as f64 * TAU / COVERAGE_BINS as f64,
    }
}
