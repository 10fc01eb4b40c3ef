//! What a simulated receiver reports and the truth behind it: the fix (the core's), what
//! it went through, and where the antenna really was. Data only, so that the rows and the
//! streams that carry fixes need not reach up to the receiver that makes them.

use serde::{Deserialize, Serialize};

/// A fix as the receiver reports it: latitude and longitude in steps of 10⁻⁷°, the
/// accuracy, speed and course when the receiver reports them.
pub use truenorth_core::GnssFix;

/// What a fix went through.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FixCondition {
    /// Open sky.
    Open,
    /// In an urban canyon (a larger error), no jump.
    Canyon,
    /// In a multipath jump.
    Multipath,
    /// The last fix sent again.
    Frozen,
}

/// The truth behind one fix.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GnssTruth {
    /// The epoch it stands for, s on the log's clock (for a frozen fix: when it was sent
    /// again).
    pub epoch_s: f64,
    /// The antenna's true position at the epoch, m north and east of the origin.
    pub antenna_ne_m: [f64; 2],
    /// The reported position minus the antenna's true one, m north and east.
    pub error_ne_m: [f64; 2],
    /// What the fix went through.
    pub condition: FixCondition,
}
