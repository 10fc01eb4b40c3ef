//! Runs of shots that share a pointing direction: consecutive readings in which the
//! pointing axis keeps its direction (within a tolerance) while the instrument rolls about
//! it, found without being told where they are.

extern crate alloc;

use alloc::vec::Vec;
use core::ops::Range;

use nalgebra::{Matrix3, Vector3};

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// How runs are recognised.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RunRule {
    /// Largest angle between the pointing directions of a run's first and any later shot,
    /// radians.
    pub tolerance_rad: f64,
    /// Smallest roll a run must span (the largest rotation between its first and any later
    /// shot), radians: a run that does not roll does not determine the pointing axis.
    pub min_roll_rad: f64,
    /// Fewest shots in a run.
    pub min_shots: usize,
}

/// The angle of the rotation `a · bᵀ` between two orthonormal frames (rows), radians.
fn rotation_angle(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let c = ((a * b.transpose()).trace() - 1.0) * 0.5;
    c.clamp(-1.0, 1.0).acos()
}

/// The runs among `frames` (each shot's level frame, rows north-ish, west-ish, up, as in
/// `level_direction`; `None` where it is undefined) for the pointing axis `p`: maximal
/// stretches of consecutive shots whose pointing directions stay within the tolerance of
/// the first's and whose roll spans at least the minimum.
pub(crate) fn find_runs(
    frames: &[Option<Matrix3<f64>>],
    p: &Vector3<f64>,
    rule: &RunRule,
) -> Vec<Range<usize>> {
    let n = frames.len();
    let mut runs = Vec::new();
    let mut i = 0;
    while i < n {
        let Some(first) = frames[i] else {
            i += 1;
            continue;
        };
        let w0 = first * p;
        let mut j = i + 1;
        let mut roll: f64 = 0.0;
        while j < n {
            let Some(f) = frames[j] else { break };
            if (f * p).angle(&w0) > rule.tolerance_rad {
                break;
            }
            roll = roll.max(rotation_angle(&f, &first));
            j += 1;
        }
        if j - i >= rule.min_shots && roll >= rule.min_roll_rad {
            runs.push(i..j);
            i = j;
        } else {
            // A stretch that does not roll may still hold a run that starts later in it.
            i += ((j - i) / 2).max(1);
        }
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Rotation3;

    fn frame(yaw: f64, pitch: f64, roll: f64) -> Option<Matrix3<f64>> {
        // Body → level: its rows are the level axes in body coordinates.
        Some(Rotation3::from_euler_angles(roll, pitch, yaw).into_inner())
    }

    const RULE: RunRule = RunRule {
        tolerance_rad: 0.17,
        min_roll_rad: 1.57,
        min_shots: 3,
    };

    #[test]
    fn rolled_shots_form_runs_and_assorted_ones_do_not() {
        let mut frames = Vec::new();
        for k in 0..8 {
            frames.push(frame(
                0.3 * k as f64 + 1.0,
                0.5 * (k as f64).sin(),
                0.7 * k as f64,
            ));
        }
        for k in 0..8 {
            frames.push(frame(2.0, 0.4, 0.785 * k as f64));
        }
        // Held still: no roll, no run.
        for _ in 0..5 {
            frames.push(frame(-1.0, 0.1, 0.2));
        }
        for k in 0..8 {
            frames.push(frame(-0.5, -0.3, 0.785 * k as f64));
        }
        let runs = find_runs(&frames, &Vector3::x(), &RULE);
        assert_eq!(runs, vec![8..16, 21..29]);
        assert!(find_runs(&[None, None], &Vector3::x(), &RULE).is_empty());
    }
}
