//! The Rust loop that `QuaternionFilter.update_array` runs, timed on the same recording,
//! for comparing the Python array call with it (`examples/speed.py` runs both).
//!
//! `cargo run --release --example array_loop -- FILE.csv [REPEATS]`: FILE is a plain CSV
//! with a header and `t_s, gyr_x..z (rad/s), acc_x..z (m/s²), mag_x..z` as its first ten
//! columns (a BROAD trial, decompressed). Prints the best time per sample over the repeats,
//! the samples turned into the library's type and the estimates collected into output
//! arrays as `update_array` does, so the two measure the same work.

use std::time::Instant;

use truenorth::core::{Axes, ImuSample, OrientationEstimator};
use truenorth::fusion::QuaternionFilter;
use truenorth::nalgebra::Vector3;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: array_loop FILE.csv [REPEATS]")?;
    let repeats: usize = args.next().map_or(Ok(20), |r| r.parse())?;
    let text = std::fs::read_to_string(&path)?;
    let mut rows: Vec<[f64; 10]> = Vec::new();
    for line in text.lines().skip(1) {
        let mut row = [0.0; 10];
        for (cell, v) in line.split(',').zip(row.iter_mut()) {
            *v = cell.trim().parse()?;
        }
        rows.push(row);
    }
    let mut best = f64::INFINITY;
    let mut checksum = 0.0;
    for _ in 0..repeats {
        let start = Instant::now();
        let mut f = QuaternionFilter::new(Default::default())?;
        let mut quaternions = Vec::with_capacity(4 * rows.len());
        let mut angles = Vec::with_capacity(3 * rows.len());
        let mut bias: Vec<f64> = Vec::with_capacity(3 * rows.len());
        let mut sigma: Vec<f64> = Vec::with_capacity(3 * rows.len());
        let mut flags = Vec::with_capacity(5 * rows.len());
        for r in &rows {
            let mag = Vector3::new(r[7], r[8], r[9]);
            let s = ImuSample {
                t_s: r[0],
                gyr_rps: Axes::xyz(Vector3::new(r[1], r[2], r[3])),
                acc_mps2: Axes::xyz(Vector3::new(r[4], r[5], r[6])),
                mag: if mag.iter().all(|v| v.is_nan()) {
                    Axes::NONE
                } else {
                    Axes::xyz(mag)
                },
            };
            let e = f.update(&s)?;
            let q = e.attitude;
            quaternions.extend([q.w, q.i, q.j, q.k]);
            let a = truenorth::core::EulerZyx::from_quaternion(&q);
            angles.extend([a.yaw_rad, a.pitch_rad, a.roll_rad].map(f64::to_degrees));
            bias.extend(e.gyro_bias_rps.iter());
            sigma.extend(
                e.sigma_rad
                    .unwrap_or_default()
                    .iter()
                    .map(|v| v.to_degrees()),
            );
            let st = e.status;
            flags.extend([
                st.at_rest,
                st.mag_used,
                st.mag_disturbed,
                st.mag_calibrating,
                st.gap,
            ]);
        }
        best = best.min(start.elapsed().as_secs_f64());
        checksum += quaternions.last().copied().unwrap_or(0.0)
            + (angles.len() + bias.len() + sigma.len() + flags.len()) as f64;
    }
    println!(
        "rust loop: {} samples, best of {repeats}: {:.3} ms, {:.1} ns/sample (checksum {checksum:.3})",
        rows.len(),
        best * 1e3,
        best * 1e9 / rows.len() as f64
    );
    Ok(())
}
