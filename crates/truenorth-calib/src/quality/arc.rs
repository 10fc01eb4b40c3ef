//! The arc a turn covers: the centre-free turning of the raw locus, and the refusal of a
//! 2-D calibration whose readings span too short an arc.

use nalgebra::Vector2;
use truenorth_core::{Error, Result, angle_diff};

use super::coverage::Coverage;

#[cfg(not(feature = "std"))]
use truenorth_core::Float as _;

/// The shortest arc of a turn, degrees, from which a 2-D calibration is accepted.
///
/// A half circle does not determine an ellipse (the missing half is extrapolated, and a
/// small noise at its ends moves the centre a lot), so every 2-D calibrator refuses spans up
/// to a little beyond 180°; the margin keeps a noisy half circle from slipping through.
pub const MIN_ARC_DEG: f64 = 200.0;

/// How far the tangent of the locus turns along `points` taken in order, radians (≥ 0): a
/// lower bound that errs short.
///
/// A centre-free measure of the arc that a set of readings covers. Tangents at opposite ends
/// of a diameter of any ellipse are parallel, so over half a turn the tangent of the raw
/// locus turns by exactly π whatever the hard and soft iron; over a shorter arc it turns by
/// less. A calibrator whose own centre is wrong sees its readings spread over more of the
/// circle than they are; this measure cannot be fooled that way.
///
/// The turning is taken between successive chords. On a convex curve each chord's direction
/// lies between the tangents at its two ends (mean value theorem), so the result never exceeds
/// the tangent's turning from the first point to the last: half an ellipse never reads as
/// more than π. It falls short by up to one chord's turning at each end. The wrapped
/// differences telescope, so noise enters only through the two end chords; chords shorter
/// than `min_chord` (and than 10⁻¹² of the locus size) are skipped, the next point being
/// taken from the last one kept, so that noisy points a short way apart cannot turn the
/// chords at random. Fewer than three usable points give 0.
pub fn locus_turning_rad<'a>(
    points: impl IntoIterator<Item = &'a Vector2<f64>>,
    min_chord: f64,
) -> f64 {
    let mut prev_point: Option<Vector2<f64>> = None;
    let mut dir: Option<f64> = None;
    let mut turned = 0.0;
    // Compared squared, so that a skipped point costs no square root (the batch fits pass
    // every reading through here).
    let chord2 = min_chord.max(0.0) * min_chord.max(0.0);
    for p in points {
        if !(p.x.is_finite() && p.y.is_finite()) {
            continue;
        }
        let Some(q) = prev_point else {
            prev_point = Some(*p);
            continue;
        };
        let d = p - q;
        let d2 = d.norm_squared();
        // The common case first: a chord shorter than `min_chord` is skipped whatever the
        // scale, without the two norms the scale test needs.
        if d2 <= chord2 {
            continue;
        }
        let scale2 = p
            .norm_squared()
            .max(q.norm_squared())
            .max(f64::MIN_POSITIVE);
        if d2 <= chord2.max(1e-24 * scale2) {
            continue;
        }
        let a = d.y.atan2(d.x);
        if let Some(prev) = dir {
            turned += angle_diff(a, prev);
        }
        dir = Some(a);
        prev_point = Some(*p);
    }
    turned.abs()
}

/// How far beyond each true end of an arc its outermost reading may lie, in standard
/// deviations of the per-reading heading noise: 3. The ends of the arc a set of readings
/// covers are its two outermost directions, and noise scatters a few dozen readings near an
/// end by up to about 3σ (the largest of 30 normal deviates exceeds 3σ with probability
/// 4 %); at 7 % noise that widens a 150° arc to nearly 200°.
pub const ARC_END_NOISE_SIGMAS: f64 = 3.0;

/// Refuses a 2-D calibration whose data span less than `need_deg` of heading (see
/// [`MIN_ARC_DEG`]) with [`Error::InsufficientCoverage`]: the span of `coverage` less
/// [`ARC_END_NOISE_SIGMAS`] of the per-reading heading noise `noise_rad` at each end (0 when
/// unknown), so that noise cannot widen a short arc into an accepted one. The refusal
/// gives both the span and the allowance.
pub fn require_arc(coverage: &Coverage, noise_rad: f64, need_deg: f64) -> Result<()> {
    let noise_deg = if noise_rad.is_finite() && noise_rad > 0.0 {
        (2.0 * ARC_END_NOISE_SIGMAS * noise_rad).to_degrees()
    } else {
        0.0
    };
    let span_deg = coverage.span_rad().to_degrees();
    if need_deg > 0.0 && span_deg - noise_deg < need_deg {
        Err(Error::InsufficientCoverage {
            // Rounded so that a refusal never prints a net span equal to the one it needs.
            covered_deg: span_deg.floor(),
            noise_deg: noise_deg.ceil(),
            need_deg,
        })
    } else {
        Ok(())
    }
}
