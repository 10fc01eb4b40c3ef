//! World Magnetic Model cost: one full field evaluation (goal ≤ 2 µs), the same with the
//! place-dependent terms prepared once, and the declination helper. Reached through the
//! facade path `truenorth::geomag`, as users see it.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use truenorth::geomag::{Geodetic, PreparedPoint, WorldMagneticModel, declination, field_at};

fn bench(c: &mut Criterion) {
    let (lat, lon, h, year) = (0.7_f64, -1.9_f64, 350.0_f64, 2027.3_f64);
    let mut g = c.benchmark_group("geomag");
    // Everything: input checks, geodetic → geocentric, Legendre recursion, sums over the 90
    // terms for main field and secular variation, rotation, elements.
    g.bench_function("field_at (full evaluation)", |b| {
        b.iter(|| {
            field_at(
                black_box(lat),
                black_box(lon),
                black_box(h),
                black_box(year),
            )
        })
    });
    g.bench_function("declination", |b| {
        b.iter(|| {
            declination(
                black_box(lat),
                black_box(lon),
                black_box(h),
                black_box(year),
            )
        })
    });
    // Place prepared once (Legendre, cos/sin mλ, radial powers): only the date-dependent sums.
    let model = WorldMagneticModel::WMM2025;
    let point = PreparedPoint::new(&Geodetic::new(lat, lon, h).expect("valid place"));
    g.bench_function("field_prepared (new date, same place)", |b| {
        b.iter(|| model.field_prepared(black_box(&point), black_box(year)))
    });
    g.bench_function("PreparedPoint::new", |b| {
        let at = Geodetic::new(lat, lon, h).expect("valid place");
        b.iter(|| PreparedPoint::new(black_box(&at)))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
