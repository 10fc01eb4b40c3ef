//! What each fuzz target does with its bytes, shared by the targets (`fuzz_targets/`) and by
//! the workspace test that replays the saved corpus and crash artefacts
//! (`crates/truenorth-cli/tests/fuzz_corpus.rs`), so that CI runs the same code as the fuzzer.
//!
//! Every function takes arbitrary bytes and must return: an error from the code under test
//! is fine (it is the typed refusal of bad input), a panic or an abort is a finding.

mod calibrators;
mod estimators;
mod files;
mod input;

pub use calibrators::calibrators;
pub use estimators::{orientation, vehicle};
pub use files::{calibration_json, csv_reader, drive_state_json, vehicle_json};

/// A target: arbitrary bytes in, a panic if the code under test fails them.
pub type Target = fn(&[u8]);

/// Every target by the name of its `fuzz_targets/` file and corpus folder.
pub const TARGETS: [(&str, Target); 7] = [
    ("csv_reader", csv_reader),
    ("calibration_json", calibration_json),
    ("vehicle_json", vehicle_json),
    ("drive_state_json", drive_state_json),
    ("calibrators", calibrators),
    ("orientation", orientation),
    ("vehicle", vehicle),
];
