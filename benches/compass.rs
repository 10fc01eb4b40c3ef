//! Compass calibration and heading costs.
//!
//! * 2-D least-squares fit of 10,000 readings (goal ≤ 50 µs): the direct fit alone, the
//!   direct fit with the quality report and refusal checks (`refine: false`), and the
//!   default `fit_ellipse` (which refines on the Sampson distance only where that could
//!   change the answer; on this full, evenly covered turn it does not).
//! * Per-sample heading, `CompassCalibration2d::heading_rad` (goal ≤ 20 ns).
//! * 3-D least-squares fit of 10,000 readings, direct and refined.
//! * Per-push cost of the binned-ellipse calibrator (criterion's mean over pushes, and the
//!   median and worst single push of a long turn, printed).
//!
//! Run: `cargo bench --bench compass -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use truenorth::calib::{
    BinnedEllipseCalibrator, EllipseConfig, EllipsoidConfig, fit_ellipse, fit_ellipse_direct,
    fit_ellipsoid, fit_ellipsoid_direct,
};
use truenorth::compass::CompassCalibration2d;
use truenorth::core::{Calibrator, Mag2Sample, NoiseSource, SplitMix64};

const N: usize = 10_000;

/// A full turn of a level compass: hard iron 0.5 × field, soft-iron axis ratio 1.3 at 30°,
/// noise 1 % of the field.
fn turn_2d() -> Vec<Vector2<f64>> {
    let mut rng = SplitMix64::new(7);
    let (s, c) = 30f64.to_radians().sin_cos();
    let r = Matrix2::new(c, -s, s, c);
    let w = r * Matrix2::new(1.3, 0.0, 0.0, 1.0) * r.transpose();
    (0..N)
        .map(|k| {
            let psi = std::f64::consts::TAU * k as f64 / N as f64;
            Vector2::new(0.5, 0.0)
                + w * Vector2::new(psi.cos(), -psi.sin())
                + Vector2::new(rng.normal(0.01), rng.normal(0.01))
        })
        .collect()
}

/// A tumble over the sphere of directions (Fibonacci lattice), hard + symmetric soft iron,
/// noise 1 % of the field.
fn tumble_3d() -> Vec<Vector3<f64>> {
    let mut rng = SplitMix64::new(9);
    let w = Matrix3::new(1.1, 0.05, -0.02, 0.05, 0.95, 0.04, -0.02, 0.04, 1.0);
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..N)
        .map(|k| {
            let z = 1.0 - (2.0 * k as f64 + 1.0) / N as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * k as f64).sin_cos();
            Vector3::new(0.3, -0.5, 0.2)
                + w * Vector3::new(r * c, r * s, z)
                + Vector3::new(rng.normal(0.01), rng.normal(0.01), rng.normal(0.01))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let pts = turn_2d();
    c.bench_function("ellipse/direct_fit_10k", |b| {
        b.iter(|| fit_ellipse_direct(black_box(&pts)).unwrap())
    });
    let no_refine = EllipseConfig {
        refine: false,
        ..Default::default()
    };
    c.bench_function("ellipse/direct_fit_with_quality_10k", |b| {
        b.iter(|| fit_ellipse(black_box(&pts), &no_refine).unwrap())
    });
    let full = EllipseConfig::default();
    c.bench_function("ellipse/refined_fit_with_quality_10k", |b| {
        b.iter(|| fit_ellipse(black_box(&pts), &full).unwrap())
    });

    let cal: CompassCalibration2d = fit_ellipse(&pts, &full).unwrap().params;
    let mut k = 0usize;
    c.bench_function("heading/heading_rad_2d", |b| {
        b.iter(|| {
            k = (k + 1) % N;
            cal.heading_rad(black_box(&pts[k]))
        })
    });

    let pts3 = tumble_3d();
    c.bench_function("ellipsoid/direct_fit_10k", |b| {
        b.iter(|| fit_ellipsoid_direct(black_box(&pts3)).unwrap())
    });
    let full3 = EllipsoidConfig::default();
    c.bench_function("ellipsoid/refined_fit_with_quality_10k", |b| {
        b.iter(|| fit_ellipsoid(black_box(&pts3), &full3).unwrap())
    });

    // Binned ellipse: a slow turn (0.5° per reading), pushed again and again.
    let stream: Vec<Mag2Sample> = (0..20_000)
        .map(|i| Mag2Sample {
            t_s: 0.05 * i as f64,
            mag: pts[(i * 7) % N],
        })
        .collect();
    let mut cal = BinnedEllipseCalibrator::default();
    let mut i = 0usize;
    c.bench_function("binned_ellipse/push", |b| {
        b.iter(|| {
            i = (i + 1) % stream.len();
            cal.push(black_box(&stream[i])).unwrap()
        })
    });
    // Median and worst single push (criterion reports means over batches, which hide the
    // worst push).
    let mut cal = BinnedEllipseCalibrator::default();
    let mut ns: Vec<u128> = stream
        .iter()
        .map(|s| {
            let t0 = std::time::Instant::now();
            black_box(cal.push(black_box(s)).unwrap());
            t0.elapsed().as_nanos()
        })
        .collect();
    ns.sort_unstable();
    println!(
        "binned_ellipse/push single pushes: median {} ns, 99th percentile {} ns, 99.9th {} ns, worst {} ns",
        ns[ns.len() / 2],
        ns[ns.len() * 99 / 100],
        ns[ns.len() * 999 / 1000],
        ns[ns.len() - 1]
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
