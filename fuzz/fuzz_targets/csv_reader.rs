//! Fuzz target `csv_reader`: see `truenorth_fuzz::harness::csv_reader`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| truenorth_fuzz::harness::csv_reader(data));
