//! Fuzz target `calibrators`: see `truenorth_fuzz::harness::calibrators`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::calibrators(data));
