//! Per-sample cost of the vehicle heading estimators (goal for the fused estimator
//! ≤ 100 ns), on a simulated 8 km mixed drive: at 10 Hz with every sensor on every sample
//! (the worst case: a compass reading on every sample), and at 50 Hz with the compass at
//! 10 Hz (a usual automotive mix).
//!
//! Run: `cargo bench --bench vehicle -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use truenorth::core::{HeadingEstimator, VehicleSample};
use truenorth::fusion::{VehicleConfig, VehicleEstimator, VehicleMethod};
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
    for (name, method, stream) in [
        (
            "fused, 50 Hz, compass 10 Hz",
            VehicleMethod::Fused,
            &compass_at_10_hz,
        ),
        (
            "fused, gyro + wheels + compass",
            VehicleMethod::Fused,
            &samples,
        ),
        ("fused, wheels + compass", VehicleMethod::Fused, &no_gyro),
        (
            "seed US 4,788,645 (wheels + compass)",
            VehicleMethod::SeedOdometerCompass,
            &samples,
        ),
        (
            "seed EP 0640207 (gyro + compass)",
            VehicleMethod::SeedGyroCompass,
            &samples,
        ),
    ] {
        let config = VehicleConfig {
            method,
            ..VehicleConfig::default()
        };
        g.throughput(Throughput::Elements(stream.len() as u64));
        g.bench_function(name, |b| {
            b.iter_batched(
                || VehicleEstimator::new(config).expect("valid config"),
                |mut nav| {
                    for s in stream.iter() {
                        black_box(nav.update(black_box(s)).expect("valid sample"));
                    }
                    nav
                },
                BatchSize::LargeInput,
            )
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
