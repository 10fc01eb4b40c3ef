//! Simulator throughput: truth samples per second for the demo drive and the hand-held motion.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use truenorth_sim::{
    HandheldParams, ImuSensorParams, VehicleSensorParams, handheld_motion, imu_streams, scenario,
    simulate, vehicle_streams,
};

fn bench(c: &mut Criterion) {
    let route = scenario::demo_drive().expect("the demo route is valid");
    let n = simulate(&route, 0.0, 100.0).expect("valid").len() as u64;
    let mut g = c.benchmark_group("sim");
    g.throughput(Throughput::Elements(n));
    g.bench_function("vehicle_truth_demo_drive_100hz", |b| {
        b.iter(|| simulate(black_box(&route), 0.0, 100.0))
    });
    let p = HandheldParams {
        duration_s: 60.0,
        rate_hz: 100.0,
        ..Default::default()
    };
    g.throughput(Throughput::Elements(6001));
    g.bench_function("handheld_truth_60s_100hz", |b| {
        b.iter(|| handheld_motion(black_box(&p)))
    });
    let truth = simulate(&route, 0.0, 100.0).expect("valid");
    let vp = VehicleSensorParams::typical();
    g.throughput(Throughput::Elements(n));
    g.bench_function("vehicle_sensor_streams_demo_drive_100hz", |b| {
        b.iter(|| vehicle_streams(black_box(&truth), &vp, 1))
    });
    let motion = handheld_motion(&p).expect("valid");
    let ip = ImuSensorParams::typical();
    g.throughput(Throughput::Elements(6001));
    g.bench_function("imu_sensor_streams_60s_100hz", |b| {
        b.iter(|| imu_streams(black_box(&motion), &ip, 1))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
