//! The float type of the per-sample paths that also run in single precision.

use nalgebra::RealField;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// A float type a per-sample path can run in: `f64`, the default everywhere, or `f32`, for
/// microcontrollers whose FPU is single precision (Cortex-M4F, M7 single), on which `f64`
/// runs in software many times slower.
///
/// nalgebra's [`RealField`] supplies the arithmetic and the functions (`sqrt`, `sin`,
/// `min`, `clamp`, `copysign`, …) with the same implementation as the inherent `f64`
/// methods (with `std`) or [`Float`](crate::Float) (without), so a path written for `T`
/// gives the same bits for `T = f64` as one written for `f64`. This trait adds the two
/// conversions with `f64`, the type parameters, timestamps and estimates are kept in, and
/// serde, so that a state in either type can be saved.
///
/// ```
/// use truenorth_core::Real;
///
/// fn half_turns<T: Real>(angle_rad: T) -> T {
///     angle_rad / T::of(core::f64::consts::PI)
/// }
/// assert_eq!(half_turns(core::f64::consts::PI), 1.0);
/// assert_eq!(half_turns(core::f32::consts::PI), 1.0);
/// assert_eq!(half_turns(1.5f32).to_f64(), f64::from(1.5f32 / core::f32::consts::PI));
/// ```
pub trait Real: RealField + Copy + Serialize + DeserializeOwned {
    /// `value` in this type: exact for `f64`, rounded to nearest for `f32`. For constants
    /// and parameters, which are written and validated in `f64`.
    fn of(value: f64) -> Self;

    /// This value as `f64` (exact for both types): for validation and for estimates.
    fn to_f64(self) -> f64;
}

impl Real for f64 {
    #[inline(always)]
    fn of(value: f64) -> Self {
        value
    }

    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
}

impl Real for f32 {
    #[inline(always)]
    fn of(value: f64) -> Self {
        value as f32
    }

    #[inline(always)]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}
