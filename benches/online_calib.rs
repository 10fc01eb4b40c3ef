//! Per-push cost of the online calibrators (goal: median ≤ 100 ns, worst ≤ 5 µs).
//!
//! * Median: a criterion bench of one push, cycling through a long stream of readings (so
//!   that the refreshes each calibrator schedules are part of the average).
//! * Worst: each push of a 100,000-reading stream timed alone with `Instant`, printed as
//!   max / p99.9 / p99 / median. The maximum includes whatever the operating system does to
//!   the thread meanwhile (an interrupt, a preemption), so p99.9 is the better figure of the
//!   code itself; both are printed.
//! * Breakdowns: the binned ellipse's pushes by the phase of its update (and the step of its
//!   assessment), the merit circle's by the share of its estimate refresh, and the online
//!   ellipsoid's by the refresh stage they ran, to show where the worst pushes come from.
//!
//! Streams: a level compass turning round and round (2-D; hard iron 0.5 × field, soft-iron
//! axis ratio 1.3 at 30°, noise 1 %), and a tumble over the sphere (3-D, noise 1 %).
//!
//! Run: `cargo bench --bench online_calib -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use truenorth_calib::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, MeritCircleCalibrator, MeritCircleConfig,
    OnlineEllipseCalibrator, OnlineEllipseConfig, OnlineEllipsoidCalibrator, OnlineEllipsoidConfig,
    UpdatePhase,
};
use truenorth_core::{Calibrator, Mag2Sample, Mag3Sample, NoiseSource, SplitMix64};

const N: usize = 100_000;

/// Turns of a level compass, one degree per reading.
fn turns_2d() -> Vec<Mag2Sample> {
    let mut rng = SplitMix64::new(7);
    let (s, c) = 30f64.to_radians().sin_cos();
    let r = Matrix2::new(c, -s, s, c);
    let w = r * Matrix2::new(1.3, 0.0, 0.0, 1.0) * r.transpose();
    (0..N)
        .map(|k| {
            let psi = (k as f64).to_radians();
            Mag2Sample {
                t_s: 0.1 * k as f64,
                mag: Vector2::new(0.5, 0.0)
                    + w * Vector2::new(psi.cos(), -psi.sin())
                    + Vector2::new(rng.normal(0.01), rng.normal(0.01)),
            }
        })
        .collect()
}

/// A slow tumble: the field direction sweeps the sphere (Fibonacci lattice of 1,000
/// directions, repeated).
fn tumble_3d() -> Vec<Mag3Sample> {
    let mut rng = SplitMix64::new(9);
    let w = Matrix3::new(1.1, 0.05, -0.02, 0.05, 0.95, 0.04, -0.02, 0.04, 1.0);
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    let m = 1000;
    (0..N)
        .map(|k| {
            let j = k % m;
            let z = 1.0 - (2.0 * j as f64 + 1.0) / m as f64;
            let r = (1.0 - z * z).sqrt();
            let (s, c) = (golden * j as f64).sin_cos();
            Mag3Sample {
                t_s: 0.1 * k as f64,
                mag: Vector3::new(0.3, -0.5, 0.2)
                    + w * Vector3::new(r * c, r * s, z)
                    + Vector3::new(rng.normal(0.01), rng.normal(0.01), rng.normal(0.01)),
            }
        })
        .collect()
}

/// Times every push of `stream` into a fresh calibrator and prints the distribution.
fn worst_push<C: Calibrator>(name: &str, mut cal: C, stream: &[C::Sample]) {
    let mut ns: Vec<u64> = Vec::with_capacity(stream.len());
    for s in stream {
        let t0 = Instant::now();
        let r = cal.push(black_box(s));
        let dt = t0.elapsed();
        black_box(r).ok();
        ns.push(dt.as_nanos() as u64);
    }
    ns.sort_unstable();
    let q = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
    println!(
        "{name}: per push over {} pushes: max {:.2} µs, p99.9 {:.2} µs, p99 {:.3} µs, median {} ns",
        ns.len(),
        q(1.0) as f64 / 1e3,
        q(0.999) as f64 / 1e3,
        q(0.99) as f64 / 1e3,
        q(0.5)
    );
}

/// Groups of the binned ellipse's assessment pushes (by step; the last holds any later).
const ASSESS_GROUPS: usize = 5;

/// The merit circle's pushes grouped by the share of an estimate refresh they did (see
/// `MeritCircleCalibrator::refresh_stage`), max / p99 / median.
fn merit_breakdown(stream: &[Mag2Sample]) {
    let mut cal = MeritCircleCalibrator::new(MeritCircleConfig::default()).unwrap();
    let mut groups: Vec<Vec<u64>> = vec![Vec::new(); 8];
    for s in stream {
        let g = cal.refresh_stage().map_or(7, |k| k.min(6));
        let t0 = Instant::now();
        let r = cal.push(black_box(s));
        let dt = t0.elapsed();
        black_box(r).ok();
        groups[g].push(dt.as_nanos() as u64);
    }
    for (k, mut ns) in groups.into_iter().enumerate() {
        if ns.is_empty() {
            continue;
        }
        ns.sort_unstable();
        let q = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
        let name = match k {
            0 => "acceptance tests".to_string(),
            7 => "no refresh".to_string(),
            k => format!("report step {k}"),
        };
        println!(
            "merit_circle {name}: {} pushes, max {:.2} µs, p99 {:.2} µs, median {} ns",
            ns.len(),
            q(1.0) as f64 / 1e3,
            q(0.99) as f64 / 1e3,
            q(0.5)
        );
    }
}

/// The binned ellipse's pushes grouped by what they did (the phase of its update at the
/// start of the push, and whether the refresh advanced), as max / p99 per group.
fn binned_breakdown(stream: &[Mag2Sample]) {
    let mut cal = BinnedEllipseCalibrator::new(BinnedEllipseConfig::default()).unwrap();
    let mut groups: Vec<(String, Vec<u64>)> = [
        "no update",
        "binning waiting readings",
        "refresh, idle push",
        "refresh, working push",
        "precheck",
    ]
    .iter()
    .map(|n| (n.to_string(), Vec::new()))
    .chain((0..ASSESS_GROUPS).map(|k| (format!("assess step {k}"), Vec::new())))
    .chain(core::iter::once(("apply".to_string(), Vec::new())))
    .collect();
    for s in stream {
        let g = match cal.update_phase() {
            None if cal.waiting_readings() > 0 => 1,
            None => 0,
            Some((UpdatePhase::Refresh, k)) if (k + 1) % 2 != 0 => 2,
            Some((UpdatePhase::Refresh, _)) => 3,
            Some((UpdatePhase::Precheck, _)) => 4,
            Some((UpdatePhase::Assess, _)) => 5 + cal.assessment_steps().min(ASSESS_GROUPS - 1),
            Some((UpdatePhase::Apply, _)) => 5 + ASSESS_GROUPS,
        };
        let t0 = Instant::now();
        let r = cal.push(black_box(s));
        let dt = t0.elapsed();
        black_box(r).ok();
        groups[g].1.push(dt.as_nanos() as u64);
    }
    for (name, mut ns) in groups {
        if ns.is_empty() {
            continue;
        }
        ns.sort_unstable();
        let q = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
        println!(
            "binned_ellipse {name}: {} pushes, max {:.2} µs, p99.9 {:.2} µs, p99 {:.2} µs, median {} ns",
            ns.len(),
            q(1.0) as f64 / 1e3,
            q(0.999) as f64 / 1e3,
            q(0.99) as f64 / 1e3,
            q(0.5)
        );
    }
}

/// The online ellipsoid's pushes grouped by the refresh stage they ran, max / p99 / median.
fn ellipsoid_breakdown(stream: &[Mag3Sample]) {
    let mut cal = OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default()).unwrap();
    let mut groups: Vec<Vec<u64>> = vec![Vec::new(); 64];
    for s in stream {
        let g = cal.refresh_stage().map_or(63, |k| usize::from(k).min(62));
        let t0 = Instant::now();
        let r = cal.push(black_box(s));
        let dt = t0.elapsed();
        black_box(r).ok();
        groups[g].push(dt.as_nanos() as u64);
    }
    for (k, mut ns) in groups.into_iter().enumerate() {
        if ns.is_empty() {
            continue;
        }
        ns.sort_unstable();
        let q = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
        println!(
            "online_ellipsoid stage {k}: {} pushes, max {:.2} µs, p99 {:.2} µs, median {} ns",
            ns.len(),
            q(1.0) as f64 / 1e3,
            q(0.99) as f64 / 1e3,
            q(0.5)
        );
    }
}

/// Criterion bench of one push, going round the stream.
fn median_push<C: Calibrator>(c: &mut Criterion, name: &str, mut cal: C, stream: &[C::Sample]) {
    let mut k = 0usize;
    c.bench_function(name, |b| {
        b.iter(|| {
            k = (k + 1) % stream.len();
            black_box(cal.push(black_box(&stream[k]))).ok()
        })
    });
}

fn bench(c: &mut Criterion) {
    let s2 = turns_2d();
    let s3 = tumble_3d();
    let online2 = || OnlineEllipseCalibrator::new(OnlineEllipseConfig::default()).unwrap();
    let forgetful2 = || {
        OnlineEllipseCalibrator::new(OnlineEllipseConfig {
            forgetting_half_life_samples: Some(500.0),
            ..Default::default()
        })
        .unwrap()
    };
    let online3 = || OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default()).unwrap();
    let merit = || MeritCircleCalibrator::new(MeritCircleConfig::default()).unwrap();
    let binned = || BinnedEllipseCalibrator::new(BinnedEllipseConfig::default()).unwrap();

    worst_push("online_ellipse", online2(), &s2);
    worst_push("online_ellipse (forgetting)", forgetful2(), &s2);
    worst_push("online_ellipsoid", online3(), &s3);
    ellipsoid_breakdown(&s3);
    worst_push("merit_circle", merit(), &s2);
    merit_breakdown(&s2);
    worst_push("binned_ellipse", binned(), &s2);
    binned_breakdown(&s2);

    median_push(c, "push/online_ellipse", online2(), &s2);
    median_push(c, "push/online_ellipse_forgetting", forgetful2(), &s2);
    median_push(c, "push/online_ellipsoid", online3(), &s3);
    median_push(c, "push/merit_circle", merit(), &s2);
    median_push(c, "push/binned_ellipse", binned(), &s2);
}

criterion_group!(benches, bench);
criterion_main!(benches);
