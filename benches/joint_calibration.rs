//! Cost of the joint magnetometer + accelerometer calibration (`ellipsoid-accel`):
//! * a 24-shot protocol of a hand-held instrument (8 assorted shots, two rolled runs of 8,
//!   which the fit finds and uses);
//! * 10,000 readings at random attitudes (no runs), as a slow tumble recorded at rate gives.
//!
//! Also the per-reading cost of turning two raw readings into heading and tilt.
//!
//! Run: `cargo bench --bench joint_calibration -- --warm-up-time 1 --measurement-time 5`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use truenorth::calib::{MagAccelConfig, MagAccelSample, fit_mag_accel};
use truenorth::core::SplitMix64;
use truenorth_sim::{FewShotInstrument, Shot, protocol_shots, random_attitude};

fn samples(shots: &[Shot]) -> Vec<MagAccelSample> {
    shots
        .iter()
        .enumerate()
        .map(|(k, s)| MagAccelSample {
            t_s: k as f64,
            mag: s.mag,
            acc: s.acc,
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let ins = FewShotInstrument::typical(3);
    let config = MagAccelConfig::default();
    let protocol = samples(&protocol_shots(&ins, 8, 2, 8, 3));
    let sol = fit_mag_accel(&protocol, &config).unwrap();
    assert_eq!(sol.quality.runs, 2);
    c.bench_function("ellipsoid_accel/solve_24_shots", |b| {
        b.iter(|| fit_mag_accel(black_box(&protocol), &config).unwrap())
    });
    let mut rng = SplitMix64::new(4);
    let tumble: Vec<Shot> = (0..10_000)
        .map(|_| ins.shot(random_attitude(&mut rng, 1.5), &mut rng))
        .collect();
    let tumble = samples(&tumble);
    let mut group = c.benchmark_group("ellipsoid_accel");
    group.sample_size(10);
    group.bench_function("solve_10k_samples", |b| {
        b.iter(|| fit_mag_accel(black_box(&tumble), &config).unwrap())
    });
    group.finish();
    let cal = sol.params;
    let mut k = 0usize;
    c.bench_function("ellipsoid_accel/attitude_per_reading", |b| {
        b.iter(|| {
            k = (k + 1) % tumble.len();
            cal.attitude(black_box(&tumble[k].mag), black_box(&tumble[k].acc))
                .unwrap()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
