//! The magnetometer's axes against the gyro's and the accelerometer's: where the gyro turns
//! gravity's direction as the accelerometer sees it but turns the field's direction only
//! through another mapping, the magnetometer is the odd one out — mirrored (an axis
//! negated, two swapped) or mounted turned — and blaming the gyro would be the wrong fix.
//! A magnetometer whose columns hold the accelerometer's readings is found too.
//!
//! A field read through a wrong mapping `M` turns, in the body, as if the gyro were read
//! through `det(M)·M`, always a rotation; so the mapping that fits the field's turns, `P`,
//! names `M` up to its sign: `M = −P` (a mirror) or `M = P` (a turned mounting). Turns of
//! directions cannot tell a field from its opposite; the fix gives both.

use crate::axes::{MIN_SPANS, SignedPermutation, axes_are_wrong, fit_over};
#[cfg(any(doc, test))]
use crate::spans::direction_spans;
use crate::spans::{DirectionSpan, Inertial, median};

/// What the magnetometer's axes are, read against a gyro that gravity confirms.
#[derive(Debug, Clone, PartialEq)]
pub struct MagAxes {
    /// The mapping of the magnetometer's columns that undoes a mirror (an axis negated or
    /// two swapped).
    pub mirror_fix: SignedPermutation,
    /// The mapping that undoes a turned mounting.
    pub rotation_fix: SignedPermutation,
    /// The field's turns' median mismatch with the gyro as read, and with the gyro read
    /// through the mapping that fits them, degrees.
    pub as_read_deg: f64,
    /// See `as_read_deg`.
    pub best_deg: f64,
    /// Spans of gravity and of the field judged on.
    pub spans: (usize, usize),
}

/// The magnetometer's axes when they, and not the gyro's, are wrong: the gyro as read turns
/// gravity's direction as well as any mapping does (within 1.5 times the best, on turns that
/// tell mappings apart), and the field's direction turns as the gyro's only through a
/// rotation other than the identity, beyond doubt (the gyro-axes rule, [`axes_are_wrong`]).
/// `gravity` and `field` are the rows' spans of each ([`direction_spans`]).
pub fn wrong_magnetometer_axes(
    rows: &[Inertial],
    gravity: &[DirectionSpan],
    field: &[DirectionSpan],
) -> Option<MagAxes> {
    if gravity.len() < MIN_SPANS || field.len() < MIN_SPANS {
        return None;
    }
    let by_gravity = fit_over(rows, gravity, (gravity.len(), 0), 1.0)?;
    let gyro_confirmed =
        by_gravity.is_informative() && by_gravity.as_read_deg <= 1.5 * by_gravity.best_deg + 0.5;
    if !gyro_confirmed {
        return None;
    }
    let by_field = fit_over(rows, field, (0, field.len()), 1.0)?;
    let p = by_field.best;
    (axes_are_wrong(&by_field) && p.is_proper()).then(|| MagAxes {
        // M = −P or M = P; the columns are read back through M⁻¹ = Mᵀ.
        mirror_fix: p.negated().inverse(),
        rotation_fix: p.inverse(),
        as_read_deg: by_field.as_read_deg,
        best_deg: by_field.best_deg,
        spans: (gravity.len(), field.len()),
    })
}

/// Whether the magnetometer's readings are the accelerometer's (its columns mapped onto
/// them, or copied): parallel on every row to a part in a million, which no field and
/// specific force are with their own noise.
pub fn magnetometer_reads_the_accelerometer(rows: &[Inertial]) -> bool {
    let mut sines: Vec<f64> = rows
        .iter()
        .filter_map(|r| {
            let m = r.mag?;
            let (a, b) = (m.norm(), r.acc.norm());
            (a > 0.0 && b > 0.0).then(|| m.cross(&r.acc).norm() / (a * b))
        })
        .collect();
    sines.len() >= 100 && median(&mut sines).is_some_and(|s| s < 1e-6)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix3, UnitQuaternion, Vector3};

    /// A body tumbling about a slowly wandering axis for 40 s at 100 Hz, with pauses so that
    /// gravity is seen near rest: gyro, specific force and field as read through `mag_map`.
    fn tumbling(mag_map: Matrix3<f64>) -> Vec<Inertial> {
        let field = Vector3::new(18.0, 1.5, 45.0);
        let up = Vector3::new(0.0, 0.0, -9.80665);
        let mut q = UnitQuaternion::identity();
        (0..4000)
            .map(|k| {
                let t = k as f64 * 0.01;
                let pause = (t * 0.5).fract() < 0.3;
                let w = if pause {
                    Vector3::zeros()
                } else {
                    Vector3::new((0.7 * t).sin(), (0.4 * t).cos(), 0.5 * (0.9 * t).sin()) * 1.5
                };
                let row = Inertial {
                    t_s: t,
                    gyr: w,
                    acc: q.inverse() * up,
                    mag: Some(mag_map * (q.inverse() * field)),
                };
                q *= UnitQuaternion::from_scaled_axis(w * 0.01);
                row
            })
            .collect()
    }

    /// The magnetometer's axes judged over the rows' own spans.
    fn judged(rows: &[Inertial]) -> Option<MagAxes> {
        let gravity = direction_spans(rows, crate::spans::Reference::Gravity);
        let field = direction_spans(rows, crate::spans::Reference::Magnetic);
        wrong_magnetometer_axes(rows, &gravity, &field)
    }

    #[test]
    fn a_mirrored_or_turned_magnetometer_is_named_with_its_fix() {
        assert!(judged(&tumbling(Matrix3::identity())).is_none());
        let swap = SignedPermutation {
            source: [1, 0, 2],
            sign: [1, 1, 1],
        };
        let found = judged(&tumbling(swap.matrix())).expect("found");
        assert_eq!(found.mirror_fix, swap.inverse());
        let negate_y = SignedPermutation {
            source: [0, 1, 2],
            sign: [1, -1, 1],
        };
        let found = judged(&tumbling(negate_y.matrix())).expect("found");
        assert_eq!(found.mirror_fix, negate_y);
        let turned = SignedPermutation {
            source: [1, 0, 2],
            sign: [-1, 1, 1],
        };
        let found = judged(&tumbling(turned.matrix())).expect("found");
        assert_eq!(found.rotation_fix, turned.inverse());
    }

    /// Every mapping of the magnetometer but the identity is found, and the fix it names
    /// (the mirror's for a mirror image, the rotation's for a rotation) reads it right —
    /// all but every axis negated, a field read as its opposite, whose directions turn as
    /// the field's do (the module documentation says so).
    #[test]
    fn every_wrong_mapping_is_undone_by_its_fix() {
        let opposite = SignedPermutation::IDENTITY.negated();
        for p in SignedPermutation::all() {
            let found = judged(&tumbling(p.matrix()));
            if p == SignedPermutation::IDENTITY || p == opposite {
                assert!(found.is_none());
                continue;
            }
            let found = found.unwrap_or_else(|| panic!("{p} not found"));
            let fix = if p.is_proper() {
                found.rotation_fix
            } else {
                found.mirror_fix
            };
            assert_eq!(fix.matrix() * p.matrix(), Matrix3::identity(), "{p}");
        }
    }

    proptest::proptest! {
        /// Any readings at all: an answer or none, never a panic.
        #[test]
        fn no_input_panics(
            cells in proptest::collection::vec(
                proptest::prop_oneof![-50.0f64..50.0, proptest::strategy::Just(f64::NAN)], 0..900),
        ) {
            let rows: Vec<Inertial> = cells
                .chunks_exact(9)
                .enumerate()
                .map(|(k, c)| Inertial {
                    t_s: k as f64 * 0.01,
                    gyr: Vector3::new(c[0], c[1], c[2]),
                    acc: Vector3::new(c[3], c[4], c[5]),
                    mag: Some(Vector3::new(c[6], c[7], c[8])),
                })
                .collect();
            let _ = judged(&rows);
            let _ = magnetometer_reads_the_accelerometer(&rows);
        }
    }

    #[test]
    fn the_accelerometer_read_as_a_magnetometer_is_found() {
        let mut rows = tumbling(Matrix3::identity());
        assert!(!magnetometer_reads_the_accelerometer(&rows));
        for r in &mut rows {
            r.mag = Some(r.acc * 5.0);
        }
        assert!(magnetometer_reads_the_accelerometer(&rows));
    }
}
