//! A track against its reference as a heading relative to the start allows: after the one
//! rotation about the start point that fits them best (least squares), the RMS and the
//! final distance between them.

/// The RMS and final distance, m, between `track` and `reference` (north, east pairs, one for
/// one, starting at the same point) after the rotation about the start that brings `track`
/// closest to `reference` in the least-squares sense. `None` for empty or unequal lengths.
///
/// ```
/// use truenorth_sim::rotated_track_errors;
///
/// // The same square, drawn facing east instead of north: a quarter turn apart.
/// let truth = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)];
/// let drawn = [(0.0, 0.0), (0.0, -10.0), (10.0, -10.0)];
/// let (rms, last) = rotated_track_errors(&drawn, &truth).unwrap();
/// assert!(rms < 1e-9 && last < 1e-9);
/// ```
pub fn rotated_track_errors(track: &[(f64, f64)], reference: &[(f64, f64)]) -> Option<(f64, f64)> {
    if track.is_empty() || track.len() != reference.len() {
        return None;
    }
    let (mut dot, mut cross) = (0.0, 0.0);
    for (e, t) in track.iter().zip(reference) {
        dot += e.0 * t.0 + e.1 * t.1;
        cross += e.0 * t.1 - e.1 * t.0;
    }
    let (s, c) = cross.atan2(dot).sin_cos();
    let err =
        |e: &(f64, f64), t: &(f64, f64)| (c * e.0 - s * e.1 - t.0).hypot(s * e.0 + c * e.1 - t.1);
    let n = track.len() as f64;
    let rms = (track
        .iter()
        .zip(reference)
        .map(|(e, t)| err(e, t).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let last = track.len() - 1;
    Some((rms, err(&track[last], &reference[last])))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A track that is its reference turned about the start by any angle fits it exactly,
        /// and the errors never depend on which of the two is turned.
        #[test]
        fn a_turned_copy_fits_exactly(angle in -3.1f64..3.1, pts in proptest::collection::vec((-1e3f64..1e3, -1e3f64..1e3), 1..20)) {
            let mut truth = vec![(0.0, 0.0)];
            truth.extend(pts);
            let (s, c) = angle.sin_cos();
            let turned: Vec<(f64, f64)> = truth.iter().map(|p| (c * p.0 - s * p.1, s * p.0 + c * p.1)).collect();
            let (rms, last) = rotated_track_errors(&turned, &truth).unwrap();
            prop_assert!(rms < 1e-6 && last < 1e-6, "{rms} {last}");
        }
    }

    #[test]
    fn unequal_or_empty_tracks_have_no_errors() {
        assert!(rotated_track_errors(&[], &[]).is_none());
        assert!(rotated_track_errors(&[(0.0, 0.0)], &[]).is_none());
    }
}
