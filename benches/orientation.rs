//! Per-update cost of the orientation estimators (goal for the quaternion filter ≤ 150 ns;
//! the same filter in `f32`, for microcontrollers with a single-precision FPU, and the
//! Euler detector of WO 00/36376 beside it),
//! on real BROAD samples when `../shared/data/broad/` is present and on the simulator's
//! hand-held motion otherwise (the bench says which).
//!
//! Run: `cargo bench --bench orientation -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;
use std::io::{BufRead, BufReader};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Vector3;
use truenorth::core::{ImuSample, OrientationEstimator};
use truenorth::fusion::{
    EulerDetector, EulerDetectorConfig, QuaternionFilter, QuaternionFilterConfig,
};
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

const N: usize = 20_000;

/// The first `N` samples of BROAD trial 01, or a simulated stream.
fn samples() -> (Vec<ImuSample>, &'static str) {
    let broad = truenorth_sim::shared_data::folder("broad")
        .ok()
        .flatten()
        .map(|d| d.join("trials/01_undisturbed_slow_rotation_A.csv.gz"))
        .filter(|p| p.is_file());
    if let Some(path) = broad {
        let file = std::fs::File::open(path).expect("readable BROAD trial");
        let lines = BufReader::new(flate2::read::GzDecoder::new(file)).lines();
        let samples = lines
            .skip(1)
            .take(N)
            .map(|l| {
                let v: Vec<f64> = l.unwrap().split(',').map(|x| x.parse().unwrap()).collect();
                ImuSample::new_9d(
                    v[0],
                    Vector3::new(v[1], v[2], v[3]),
                    Vector3::new(v[4], v[5], v[6]),
                    Vector3::new(v[7], v[8], v[9]),
                )
            })
            .collect();
        return (samples, "BROAD trial 01");
    }
    let truth = handheld_motion(&HandheldParams {
        duration_s: N as f64 / 100.0,
        ..HandheldParams::default()
    })
    .expect("valid motion");
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), 3).expect("valid sensors");
    (samples, "simulated hand-held motion")
}

fn bench(c: &mut Criterion) {
    let (samples, source) = samples();
    println!("orientation bench on {source}, {} samples", samples.len());
    let mut g = c.benchmark_group("orientation");
    g.throughput(Throughput::Elements(samples.len() as u64));
    for (name, use_mag) in [
        ("quaternion filter 9-D", true),
        ("quaternion filter 6-D", false),
    ] {
        let config = QuaternionFilterConfig {
            use_mag,
            ..Default::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut f = QuaternionFilter::new(config).expect("valid config");
                for s in &samples {
                    black_box(f.update(black_box(s)).expect("valid sample"));
                }
            })
        });
    }
    // The f32 filter takes its readings as f32 vectors, converted here once, outside the
    // timing, as a single-precision driver would deliver them.
    let single: Vec<_> = samples
        .iter()
        .map(|s| {
            let f32v = |v: Vector3<f64>| v.cast::<f32>();
            (
                s.t_s,
                f32v(s.gyr_rps.as_xyz().expect("three-axis gyro")),
                s.acc_mps2.as_xyz().map(f32v),
                s.mag.as_xyz().map(f32v),
            )
        })
        .collect();
    for (name, use_mag) in [
        ("quaternion filter 9-D f32", true),
        ("quaternion filter 6-D f32", false),
    ] {
        let config = QuaternionFilterConfig {
            use_mag,
            ..Default::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut f = QuaternionFilter::<f32>::with_precision(config).expect("valid config");
                for &(t_s, gyr, acc, mag) in &single {
                    black_box(
                        f.update_readings(t_s, black_box(gyr), black_box(acc), black_box(mag))
                            .expect("valid sample"),
                    );
                    black_box(f.attitude());
                }
            })
        });
    }
    g.bench_function("Euler detector (WO 00/36376)", |b| {
        b.iter(|| {
            let mut d = EulerDetector::new(EulerDetectorConfig::default()).expect("valid config");
            for s in &samples {
                black_box(d.update(black_box(s)).expect("valid sample"));
            }
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
