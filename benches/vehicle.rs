//! Per-sample cost of the vehicle heading estimators (goal for the fused estimator
//! ≤ 100 ns), on a simulated 8 km mixed drive: at 10 Hz with every sensor on every sample
//! (the worst case: a compass reading on every sample), and at 50 Hz with the compass at
//! 10 Hz (a usual automotive mix); and of the fixes' delay check (`CourseLagCheck`) on the
//! 50 Hz drive with a fix and its course at 5 Hz.
//!
//! Run: `cargo bench --bench vehicle -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use truenorth::checks::CourseLagCheck;
use truenorth::core::{GnssFix, HeadingEstimator, VehicleSample};
use truenorth::fusion::vehicle::{
    SeedGyroCompass, SeedGyroCompassConfig, SeedOdometerCompass, SeedOdometerCompassConfig,
};
use truenorth::fusion::{VehicleConfig, VehicleEstimator};
use truenorth_sim::{DriveSpec, SimulatedDrive};

fn bench(c: &mut Criterion) {
    let drive = SimulatedDrive::new(DriveSpec::new(1)).expect("valid drive");
    let fast = SimulatedDrive::new(DriveSpec {
        rate_hz: 50.0,
        ..DriveSpec::new(1)
    })
    .expect("valid drive");
    let compass_at_10_hz: Vec<VehicleSample> = fast
        .samples
        .iter()
        .enumerate()
        .map(|(k, s)| VehicleSample {
            mag: if k % 5 == 0 { s.mag } else { None },
            ..*s
        })
        .collect();
    let samples: Vec<VehicleSample> = drive.samples;
    let no_gyro: Vec<VehicleSample> = samples
        .iter()
        .map(|s| VehicleSample {
            gyr_z_rps: None,
            ..*s
        })
        .collect();
    println!(
        "vehicle bench: {} samples, {:.0} m",
        samples.len(),
        drive.truth.last().map_or(0.0, |t| t.distance_m)
    );
    let mut g = c.benchmark_group("vehicle");
    fn run<E: HeadingEstimator>(
        g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
        name: &str,
        stream: &[VehicleSample],
        make: impl Fn() -> E,
    ) {
        g.throughput(Throughput::Elements(stream.len() as u64));
        g.bench_function(name, |b| {
            b.iter_batched(
                &make,
                |mut nav| {
                    for s in stream {
                        black_box(nav.update(black_box(s)).expect("valid sample"));
                    }
                    nav
                },
                BatchSize::LargeInput,
            )
        });
    }
    let fused = || VehicleEstimator::new(VehicleConfig::default()).expect("valid config");
    run(
        &mut g,
        "fused, 50 Hz, compass 10 Hz",
        &compass_at_10_hz,
        fused,
    );
    run(&mut g, "fused, gyro + wheels + compass", &samples, fused);
    run(&mut g, "fused, wheels + compass", &no_gyro, fused);
    run(
        &mut g,
        "seed US 4,788,645 (wheels + compass)",
        &samples,
        || SeedOdometerCompass::new(SeedOdometerCompassConfig::default()).expect("valid config"),
    );
    run(&mut g, "seed EP 0640207 (gyro + compass)", &samples, || {
        SeedGyroCompass::new(SeedGyroCompassConfig::default()).expect("valid config")
    });
    let with_courses: Vec<VehicleSample> = fast
        .samples
        .iter()
        .zip(&fast.truth)
        .enumerate()
        .map(|(k, (s, t))| VehicleSample {
            gnss: (k % 10 == 0).then(|| {
                GnssFix::at(52.5, 13.4)
                    .with_velocity(t.speed_mps, t.heading_rad.to_degrees().rem_euclid(360.0))
            }),
            ..*s
        })
        .collect();
    g.throughput(Throughput::Elements(with_courses.len() as u64));
    g.bench_function("course lag check, 50 Hz, fixes 5 Hz", |b| {
        b.iter_batched(
            || Box::new(CourseLagCheck::new()),
            |mut check| {
                for s in &with_courses {
                    check.push(black_box(s));
                }
                check
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
