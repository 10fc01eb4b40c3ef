//! Fuzz target `calibration_json`: see `truenorth_fuzz::harness::calibration_json`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::calibration_json(data));
