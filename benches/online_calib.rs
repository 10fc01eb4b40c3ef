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

/// The time one push takes, nanoseconds.
fn timed_push<C: Calibrator>(cal: &mut C, s: &C::Sample) -> u64 {
    let t0 = Instant::now();
    let r = cal.push(black_box(s));
    let dt = t0.elapsed();
    black_box(r).ok();
    dt.as_nanos() as u64
}

/// Prints the distribution of push times `ns` (nothing for an empty group).
fn print_quantiles(label: &str, mut ns: Vec<u64>) {
    if ns.is_empty() {
        return;
    }
    ns.sort_unstable();
    let q = |p: f64| ns[((ns.len() - 1) as f64 * p) as usize];
    println!(
        "{label}: {} pushes, max {:.2} µs, p99.9 {:.2} µs, p99 {:.3} µs, median {} ns",
        ns.len(),
        q(1.0) as f64 / 1e3,
        q(0.999) as f64 / 1e3,
        q(0.99) as f64 / 1e3,
        q(0.5)
    );
}

/// Times every push of `stream` into `cal`, filing each under the group `group_of` gives
/// the calibrator's state before the push, and prints each group's distribution.
fn grouped_pushes<C: Calibrator>(
    mut cal: C,
    stream: &[C::Sample],
    labels: &[String],
    group_of: impl Fn(&C) -> usize,
) {
    let mut groups: Vec<Vec<u64>> = vec![Vec::new(); labels.len()];
    for s in stream {
        let g = group_of(&cal);
        groups[g].push(timed_push(&mut cal, s));
    }
    for (label, ns) in labels.iter().zip(groups) {
        print_quantiles(label, ns);
    }
}

/// Times every push of `stream` into a fresh calibrator and prints the distribution.
fn worst_push<C: Calibrator>(name: &str, cal: C, stream: &[C::Sample]) {
    grouped_pushes(cal, stream, &[format!("{name}: per push")], |_| 0);
}

/// Groups of the binned ellipse's assessment pushes (by step; the last holds any later).
const ASSESS_GROUPS: usize = 5;

/// The merit circle's pushes grouped by the share of an estimate refresh they did (see
/// `MeritCircleCalibrator::refresh_stage`).
fn merit_breakdown(stream: &[Mag2Sample]) {
    let labels: Vec<String> = (0..8)
        .map(|k| match k {
            0 => "merit_circle acceptance tests".to_string(),
            7 => "merit_circle no refresh".to_string(),
            k => format!("merit_circle report step {k}"),
        })
        .collect();
    let cal = MeritCircleCalibrator::new(MeritCircleConfig::default()).unwrap();
    grouped_pushes(cal, stream, &labels, |c| {
        c.refresh_stage().map_or(7, |k| k.min(6))
    });
}

/// The binned ellipse's pushes grouped by what they did (the phase of its update at the
/// start of the push, and whether the refresh advanced).
fn binned_breakdown(stream: &[Mag2Sample]) {
    let labels: Vec<String> = [
        "no update",
        "binning waiting readings",
        "refresh, idle push",
        "refresh, working push",
        "precheck",
    ]
    .iter()
    .map(|n| n.to_string())
    .chain((0..ASSESS_GROUPS).map(|k| format!("assess step {k}")))
    .chain(core::iter::once("apply".to_string()))
    .map(|n| format!("binned_ellipse {n}"))
    .collect();
    let cal = BinnedEllipseCalibrator::new(BinnedEllipseConfig::default()).unwrap();
    grouped_pushes(cal, stream, &labels, |c| match c.update_phase() {
        None if c.waiting_readings() > 0 => 1,
        None => 0,
        Some((UpdatePhase::Refresh, k)) if (k + 1) % 2 != 0 => 2,
        Some((UpdatePhase::Refresh, _)) => 3,
        Some((UpdatePhase::Precheck, _)) => 4,
        Some((UpdatePhase::Assess, _)) => 5 + c.assessment_steps().min(ASSESS_GROUPS - 1),
        Some((UpdatePhase::Apply, _)) => 5 + ASSESS_GROUPS,
    });
}

/// The online ellipsoid's pushes grouped by the refresh stage they ran.
fn ellipsoid_breakdown(stream: &[Mag3Sample]) {
    let labels: Vec<String> = (0..64)
        .map(|k| format!("online_ellipsoid stage {k}"))
        .collect();
    let cal = OnlineEllipsoidCalibrator::new(OnlineEllipsoidConfig::default()).unwrap();
    grouped_pushes(cal, stream, &labels, |c| {
        c.refresh_stage().map_or(63, |k| usize::from(k).min(62))
    });
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
