//! The demo's orientation section: the quaternion filter on the simulator's hand-held motion,
//! scored against the truth with BROAD's error split (heading about the vertical,
//! inclination the rest).

use nalgebra::UnitQuaternion;
use truenorth::core::{OrientationEstimator, Result};
use truenorth::fusion::{QuaternionFilter, QuaternionFilterConfig};
use truenorth_sim::{HandheldParams, ImuSensorParams, handheld_motion, imu_streams};

use crate::io::{CliError, CliResult};

/// Heading and inclination parts of the error between an estimate and the truth, radians:
/// `e = q_est ⊗ q_true⁻¹` split into a rotation about the vertical and the rest (BROAD,
/// Laidig et al. 2021).
fn error_parts(est: &UnitQuaternion<f64>, truth: &UnitQuaternion<f64>) -> (f64, f64) {
    let e = (est * truth.inverse()).into_inner();
    let heading = 2.0 * (e.k / e.w).abs().atan();
    let incl = 2.0 * (e.w * e.w + e.k * e.k).sqrt().clamp(0.0, 1.0).acos();
    (heading, incl)
}

/// RMS (heading, inclination) error in degrees after the first `settle_s` seconds.
fn run(use_mag: bool, seed: u64, settle_s: f64) -> Result<(f64, f64)> {
    let truth = handheld_motion(&HandheldParams {
        duration_s: 300.0,
        seed,
        ..HandheldParams::default()
    })?;
    let samples = imu_streams(&truth, &ImuSensorParams::typical(), seed)?;
    let mut f = QuaternionFilter::new(QuaternionFilterConfig {
        use_mag,
        ..QuaternionFilterConfig::default()
    })?;
    let (mut sh, mut si, mut n) = (0.0, 0.0, 0usize);
    for (s, t) in samples.iter().zip(&truth) {
        let est = f.update(s)?;
        if t.t_s >= settle_s {
            let (h, i) = error_parts(&est.attitude, &t.attitude);
            sh += h * h;
            si += i * i;
            n += 1;
        }
    }
    let rms = |s: f64| (s / n.max(1) as f64).sqrt().to_degrees();
    Ok((rms(sh), rms(si)))
}

/// Prints the orientation table.
pub fn orientation_section(seed: u64) -> CliResult {
    println!(
        "\nOrientation: quaternion filter on 300 s of simulated hand-held motion (consumer IMU: gyro bias 0.3 deg/s per axis, never at rest), errors after the first 30 s"
    );
    println!(
        "{:<22} {:>16} {:>20}",
        "configuration", "heading RMS deg", "inclination RMS deg"
    );
    for (name, use_mag) in [
        ("9-D (with magnetometer)", true),
        ("6-D (gyro + accel)", false),
    ] {
        let (h, i) = run(use_mag, seed, 30.0).map_err(|e| CliError::msg(e.to_string()))?;
        let heading = if use_mag {
            format!("{h:.2}")
        } else {
            "drifts".to_string()
        };
        println!("{name:<22} {heading:>16} {i:>20.2}");
    }
    println!(
        "(real recordings: `cargo test --release -p truenorth-fusion --test broad -- --nocapture`)"
    );
    Ok(())
}
