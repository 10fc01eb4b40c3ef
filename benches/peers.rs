//! Per-update cost of truenorth's quaternion filter beside the Rust filters a user would
//! otherwise pick, in one run on the same real samples: the first 20,000 samples (70 s, rest
//! then motion) of BROAD trial 01 (`$TRUENORTH_SHARED_DATA/broad/`, default
//! `../shared/data/broad/`; the bench prints SKIPPED and measures nothing without it).
//!
//! The filters and their parameters (`peers/filters.rs`):
//! - truenorth `QuaternionFilter`, default configuration, 9-D and 6-D (`use_mag: false`),
//!   and with its σ switched off (`sigma: false`);
//! - `ahrs` 0.8 Madgwick, β = 0.12, and Mahony, Kp = 0.74, Ki = 0.0012 (BROAD's
//!   trial-agnostic good parameters), 9-D `update`, 6-D `update_imu`, at dt = 3.5 ms,
//!   started from the first sample's accelerometer (and field);
//! - `vqf-rs` 0.3 VQF, default parameters at dt = 3.5 ms, 9-D (field fed) and 6-D.
//!
//! One element is one sample: the filter's update and its attitude read out in BROAD's
//! frame (sensor → ENU), through the same `dyn Peer` call for every filter; the filter is
//! made afresh in each iteration, as in the orientation bench.
//!
//! Run: `cargo bench --bench peers -- --warm-up-time 1 --measurement-time 3`.

#[path = "peers/filters.rs"]
mod filters;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use filters::Kind;

const N: usize = 20_000;

fn bench(c: &mut Criterion) {
    let Some(paths) = filters::trial_paths() else {
        return;
    };
    let Some(first_trial) = paths.first() else {
        eprintln!("SKIPPED: no BROAD trial file");
        return;
    };
    let mut trial = filters::read_trial(first_trial);
    trial.samples.truncate(N);
    let samples = trial.samples;
    println!(
        "peers bench on BROAD {}, {} samples",
        trial.name,
        samples.len()
    );
    let mut g = c.benchmark_group("peers");
    g.throughput(Throughput::Elements(samples.len() as u64));
    for (dims, use_mag) in [("9-D", true), ("6-D", false)] {
        for kind in Kind::ALL {
            g.bench_function(format!("{} {dims}", kind.name()), |b| {
                b.iter(|| {
                    let mut peer = kind.start(use_mag, &samples[0]);
                    for s in &samples {
                        peer.update(black_box(s));
                        black_box(peer.attitude_enu());
                    }
                })
            });
        }
        g.bench_function(format!("{}, σ off {dims}", Kind::Truenorth.name()), |b| {
            b.iter(|| {
                let mut peer: Box<dyn filters::Peer> =
                    Box::new(filters::Truenorth::with_sigma(use_mag, false));
                for s in &samples {
                    peer.update(black_box(s));
                    black_box(peer.attitude_enu());
                }
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
