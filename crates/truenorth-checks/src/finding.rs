//! What a check found wrong: the evidence in words and figures, and what would read the
//! data right, as data, so that each front end (the command line's options, the Python
//! package's arguments) says the fix in its own terms.

use crate::axes::SignedPermutation;
use crate::units::{AccUnit, GyroUnit, MagUnit};

/// Which declaration a finding contradicts, and so what a user accepts to go on without
/// fixing it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FindingKind {
    /// A unit (a gyro's, an accelerometer's, a magnetometer's, the wheels').
    Units,
    /// An axis or a sign: which way a sensor's columns point.
    Axes,
}

/// What reads the data right.
#[derive(Debug, Clone, PartialEq)]
pub enum Fix {
    /// The gyro columns are in this unit.
    GyroUnit(GyroUnit),
    /// The accelerometer columns are in this unit.
    AccUnit(AccUnit),
    /// The magnetometer is probably in `likely` (or, less likely, in `also`), not in
    /// `declared`.
    MagUnit {
        /// The unit that fits best.
        likely: MagUnit,
        /// Other units that fit, best first.
        also: Vec<MagUnit>,
        /// The unit declared.
        declared: MagUnit,
    },
    /// The gyro's axes as this mapping reads them (body axis `b` from the column along
    /// `source[b]`, times `sign[b]`, each column as it is read now).
    GyroAxes(SignedPermutation),
    /// The yaw gyro (`gyr_z`) with its sign flipped.
    GyroZSign,
    /// The magnetometer's axes read through `mirror` (an axis negated or two swapped) or,
    /// if it is mounted turned, through `rotation` (each as its columns are read now).
    MagAxes {
        /// The mapping that undoes a mirror.
        mirror: SignedPermutation,
        /// The mapping that undoes a turned mounting.
        rotation: SignedPermutation,
    },
    /// What to do, in words, where no declaration reads the data right (a column to
    /// rescale, a value to check).
    Advice(String),
}

/// A contradiction between the data and how they were declared.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// What it is about.
    pub kind: FindingKind,
    /// The evidence, in words and figures.
    pub seen: String,
    /// What would read the data right.
    pub fix: Fix,
    /// The 1-based row of the input (a header is row 1) where the evidence became clear,
    /// if the check knows it.
    pub row: Option<usize>,
}

impl Finding {
    /// A finding about a unit.
    pub fn units(seen: String, fix: Fix) -> Self {
        Self {
            kind: FindingKind::Units,
            seen,
            fix,
            row: None,
        }
    }

    /// A finding about an axis or a sign.
    pub fn axes(seen: String, fix: Fix) -> Self {
        Self {
            kind: FindingKind::Axes,
            seen,
            fix,
            row: None,
        }
    }

    /// The same finding, its evidence clear at `row`.
    pub fn at_row(self, row: Option<usize>) -> Self {
        Self { row, ..self }
    }
}
