//! Fuzz target `orientation`: see `truenorth_fuzz::harness::orientation`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::orientation(data));
