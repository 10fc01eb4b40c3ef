//! Fuzz target `vehicle_json`: see `truenorth_fuzz::harness::vehicle_json`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::vehicle_json(data));
