//! Per-sample cost of the vehicle heading estimators (goal for the fused estimator
//! ≤ 100 ns), on a simulated 8 km mixed drive: at 10 Hz with every sensor on every sample
//! (the worst case: a compass reading on every sample), and at 50 Hz with the compass at
//! 10 Hz (a usual automotive mix).
//!
//! Run: `cargo bench --bench vehicle -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use truenorth::core::{HeadingEstimator, VehicleSample};
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
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
