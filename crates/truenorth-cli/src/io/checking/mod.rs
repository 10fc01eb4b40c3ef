//! Checking: the data against what they were declared to be, in the command line's words.
//! The physics is the library's (`truenorth::checks`: units, the gyro's axes, a yaw gyro
//! against the wheels, a compass calibration's plausibility), so that the Python package
//! runs the same checks; this room says each finding as the options that fix it
//! (`fixes`) and refuses or warns by it (`refusal`). A new check's physics belongs in
//! `truenorth-checks`, returning a `Finding` with a `Fix`; only a fix no option says yet
//! needs a line in `fixes::say`.

pub(crate) mod fixes;
pub(crate) mod refusal;
pub(crate) mod stuck;

pub use fixes::{fix_columns, fix_pair, say, shell_word};
pub use refusal::{Refusal, refusals, refuse_or_warn};
pub use stuck::{MagCells, MagWatch, StuckWatch};
