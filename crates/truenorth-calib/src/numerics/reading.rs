//! Reading a caller's sample coordinate by coordinate.

use nalgebra::{Vector2, Vector3};

/// The vector `v`, read one coordinate at a time.
///
/// A caller typically builds a sample from two separately parsed numbers, storing them
/// with two 8-byte stores just before the push. Loaded back as one 16-byte pair (which the
/// compiler prefers when the push uses the reading as a vector), the load spans both
/// stores, and the processor cannot forward stores to a load they only cover together: it
/// waits for them to reach the cache (a store-forwarding stall, Intel 64 and IA-32
/// Architectures Optimization Reference Manual, "Store Forwarding"), which cost more than
/// the rest of a push. [`core::hint::black_box`] keeps the compiler from merging the two
/// loads; the values are unchanged.
#[inline(always)]
pub(crate) fn read_by_coordinate(v: &Vector2<f64>) -> Vector2<f64> {
    Vector2::new(core::hint::black_box(v.x), core::hint::black_box(v.y))
}

/// [`read_by_coordinate`] for a 3-D reading: three separate stores, which a 16-byte load
/// of the first two would span in the same way.
#[inline(always)]
pub(crate) fn read_by_coordinate3(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(
        core::hint::black_box(v.x),
        core::hint::black_box(v.y),
        core::hint::black_box(v.z),
    )
}
