//! Per-push cost of the online calibrators in `f32` against `f64`, on the same readings.
//!
//! A criterion bench of one push, cycling through a long stream (so that the refreshes each
//! calibrator schedules, which run in `f64` in both, are part of the average), and of the
//! per-sample path alone (a configuration whose refreshes never start after the first, so
//! only the sums and the sorting of readings into slots remain).
//!
//! On a desktop CPU both precisions run in hardware and the difference is small; on a
//! single-precision FPU (Cortex-M4F) `f64` is software, see `examples/embedded`.
//!
//! Run: `cargo bench -p truenorth-calib --bench online_precision -- --warm-up-time 1
//! --measurement-time 3`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix2, Vector2, Vector3};
use truenorth_calib::{
    OnlineEllipseCalibrator, OnlineEllipseConfig, OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
};
use truenorth_core::{NoiseSource, Real, SplitMix64};

const N: usize = 20_000;

/// Turns of a level compass, one degree per reading (hard iron 0.5 × field, axis ratio
/// 1.3 at 30°, noise 1 %).
fn turns_2d<T: Real>() -> Vec<Vector2<T>> {
    let mut rng = SplitMix64::new(7);
    let (s, c) = 30f64.to_radians().sin_cos();
    let r = Matrix2::new(c, -s, s, c);
    let w = r * Matrix2::new(1.3, 0.0, 0.0, 1.0) * r.transpose();
    (0..N)
        .map(|k| {
            let psi = (k as f64).to_radians();
            let p = Vector2::new(0.5, 0.0)
                + w * Vector2::new(psi.cos(), -psi.sin())
                + Vector2::new(rng.normal(0.01), rng.normal(0.01));
            p.map(T::of)
        })
        .collect()
}

/// A tumble over a Fibonacci lattice of 1,000 directions, repeated.
fn tumble_3d<T: Real>() -> Vec<Vector3<T>> {
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..N)
        .map(|k| {
            let j = k % 1000;
            let z = 1.0 - (2.0 * j as f64 + 1.0) / 1000.0;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * j as f64).sin_cos();
            (Vector3::new(0.3, -0.5, 0.2) + Vector3::new(r * c, r * s, z)).map(T::of)
        })
        .collect()
}

fn bench_ellipse<T: Real>(c: &mut Criterion, name: &str, refresh_interval_samples: u32) {
    let stream = turns_2d::<T>();
    let cfg = OnlineEllipseConfig {
        refresh_interval_samples,
        ..Default::default()
    };
    let mut cal = OnlineEllipseCalibrator::<T>::with_precision(cfg).unwrap();
    let mut k = 0usize;
    c.bench_function(name, |b| {
        b.iter(|| {
            let r = cal.push_reading(k as f64, black_box(&stream[k % N]));
            k += 1;
            black_box(r).ok()
        })
    });
}

fn bench_ellipsoid<T: Real>(c: &mut Criterion, name: &str) {
    let stream = tumble_3d::<T>();
    let mut cal =
        OnlineEllipsoidCalibrator::<T>::with_precision(OnlineEllipsoidConfig::default()).unwrap();
    let mut k = 0usize;
    c.bench_function(name, |b| {
        b.iter(|| {
            let r = cal.push_reading(k as f64, black_box(&stream[k % N]));
            k += 1;
            black_box(r).ok()
        })
    });
}

fn pushes(c: &mut Criterion) {
    let default = OnlineEllipseConfig::default().refresh_interval_samples;
    bench_ellipse::<f64>(c, "online ellipse push f64", default);
    bench_ellipse::<f32>(c, "online ellipse push f32", default);
    // The sums and slot alone: one refresh at the start, none after.
    bench_ellipse::<f64>(c, "online ellipse push f64, sums only", 1_000_000);
    bench_ellipse::<f32>(c, "online ellipse push f32, sums only", 1_000_000);
    bench_ellipsoid::<f64>(c, "online ellipsoid push f64");
    bench_ellipsoid::<f32>(c, "online ellipsoid push f32");
}

criterion_group!(benches, pushes);
criterion_main!(benches);
