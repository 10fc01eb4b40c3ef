//! The seed calibrators, which learn sample by sample without allocating: the binned
//! ellipse (EP 0634001), the merit circle (US 5,297,063), the one-turn calibration of
//! compass and gyro (EP 0640207) with its extremum tracker, the speed coefficient
//! (US 4,788,645), and the quality report they share.

pub mod binned;
pub(crate) mod direction_slots;
pub mod extrema;
pub(crate) mod fit_gap;
pub mod merit_circle;
pub(crate) mod seed_quality;
pub mod speed_coefficient;
pub mod turn;
pub mod turn_gyro;
