//! Cost of writing one number into an output CSV: the shortest round-trip text (the
//! default) and `--precision 7`, for the two columns `heading` writes (time stamps at
//! 100 Hz and headings in degrees carrying all their bits), and for values across the
//! fixed-point range (1e-5 to 1e16).
//!
//! Run: `cargo bench -p truenorth-cli --bench number_format -- --warm-up-time 1 --measurement-time 3`.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use truenorth_cli::io::Precision;

const N: usize = 10_000;

/// Time stamps `k / 100` s and headings of a slow turn with a fractional part of full
/// precision, alternating (as a `heading` row holds them).
fn heading_rows() -> Vec<f64> {
    (0..N / 2)
        .flat_map(|k| {
            let t_s = k as f64 * 0.01;
            let heading_deg = (k as f64 * 0.072_135_795_1 + 0.1).rem_euclid(360.0);
            [t_s, heading_deg]
        })
        .collect()
}

/// Magnitudes spread evenly in the logarithm over 1e-5..1e16, both signs.
fn wide_values() -> Vec<f64> {
    (0..N)
        .map(|k| {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            sign * 10f64.powf(-5.0 + 21.0 * (k as f64 + 0.5) / N as f64)
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let seven: Precision = "7".parse().expect("a valid precision");
    let mut g = c.benchmark_group("number_format");
    g.throughput(Throughput::Elements(N as u64));
    for (name, values) in [("heading_rows", heading_rows()), ("wide", wide_values())] {
        for (label, precision) in [("shortest", Precision::default()), ("precision_7", seven)] {
            let mut out = String::with_capacity(32 * N);
            g.bench_function(format!("{name}/{label}"), |b| {
                b.iter(|| {
                    out.clear();
                    for &v in black_box(&values) {
                        precision.write(&mut out, v);
                        out.push(',');
                    }
                    black_box(out.len())
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
