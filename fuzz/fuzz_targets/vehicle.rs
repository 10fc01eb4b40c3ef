//! Fuzz target `vehicle`: see `truenorth_fuzz::harness::vehicle`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::vehicle(data));
