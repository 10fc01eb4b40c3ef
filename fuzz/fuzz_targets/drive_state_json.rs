//! Fuzz target `drive_state_json`: see `truenorth_fuzz::harness::drive_state_json`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::drive_state_json(data));
