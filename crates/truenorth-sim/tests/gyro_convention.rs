//! The gyro sample convention shared by the simulator and the integrator: a sample is the
//! instantaneous rate at its timestamp, and `YawIntegrator` integrates by the trapezoid rule.
//! On the simulator's own stream the integrated heading then tracks the truth to second
//! order in the sample interval.
//!
//! # The bound
//!
//! On a route of constant-curvature commands the yaw rate is `ω(t) = κ·v(t)`; with a
//! constant acceleration per command, `v` and so `ω` are continuous and piecewise linear in
//! `t`, with a kink (a jump `Δm = κ·Δa` in the slope `ω̇`) wherever the acceleration changes.
//!
//! The trapezoid rule is exact for a linear integrand, so steps without a kink contribute no
//! error. On a step of length `h` with a kink at `s = θh` (slope `m₁` before, `m₂` after,
//! `ω(0) = 0` without loss of generality), the exact integral is
//! `m₁s²/2 + m₁s(h − s) + m₂(h − s)²/2` and the trapezoid `h/2·(m₁s + m₂(h − s))`; their
//! difference is `(m₂ − m₁)·s(h − s)/2 = Δm·θ(1 − θ)·h²/2 ≤ |Δm|·h²/8`. So at every sample
//!
//! `|ψ_integrated − ψ_true| ≤ Σ_kinks |κ·Δa|·dt²/8`,
//!
//! second order in `dt`. A stream holding the mean rate over the previous step instead
//! integrates `ω(t − dt/2)` in effect, and is off by about `dt/2·(ω(t) − ω(0))`: first order,
//! far outside the bound (checked below, so the test can fail).

use truenorth_core::{GyroSample, RelativeHeadingSource, angle_diff};
use truenorth_gyro::{GyroAxisParams, YawIntegrator, YawIntegratorConfig};
use truenorth_odometer::{OdometerParams, OdometerWheels};
use truenorth_sim::{Command, Route, VehicleSensorParams, simulate, vehicle_streams};

use nalgebra::{Matrix2, Vector2, Vector3};

const CURVATURE_PER_M: f64 = 1.0 / 20.0;

/// Speeding up in a right turn, holding the speed, then slowing in the same turn: the rate
/// ramps up, holds and ramps down without a jump. Durations are not multiples of the sample
/// intervals used, so both kinks fall inside a step.
fn route() -> Route {
    let cmd = |duration_s, accel_mps2| Command {
        duration_s,
        accel_mps2,
        curvature_per_m: CURVATURE_PER_M,
        curvature_rate_per_m_s: 0.0,
        pivot_rate_rps: 0.0,
    };
    Route {
        start_speed_mps: 5.0,
        commands: vec![cmd(4.03, 1.5), cmd(2.96, 0.0), cmd(2.01, -2.0)],
    }
}

/// Σ |κ·Δa| over the kinks of [`route`], rad/s².
fn kink_slope_jumps() -> f64 {
    let r = route();
    r.commands
        .windows(2)
        .map(|w| (CURVATURE_PER_M * (w[1].accel_mps2 - w[0].accel_mps2)).abs())
        .sum()
}

fn error_free() -> VehicleSensorParams {
    VehicleSensorParams {
        gyro: GyroAxisParams::PERFECT,
        gyro_temp_c: 25.0,
        odometer: OdometerParams::perfect(OdometerWheels::Rear { track_m: 1.5 }),
        compass_hard_iron: Vector2::zeros(),
        compass_soft_iron: Matrix2::identity(),
        compass_noise: 0.0,
        horizontal_field: 20.0,
    }
}

/// Largest |integrated − true heading change| over the samples, integrating `rates`.
fn worst_error(t_s: &[f64], rates: &[f64], truth_rad: &[f64]) -> f64 {
    let mut yaw = YawIntegrator::new(YawIntegratorConfig::default()).unwrap();
    let mut worst = 0.0f64;
    for ((&t, &w), &psi) in t_s.iter().zip(rates).zip(truth_rad) {
        let sample = GyroSample {
            t_s: t,
            gyr_rps: Vector3::new(0.0, 0.0, w),
        };
        yaw.step(&sample).unwrap();
        worst = worst.max((yaw.heading_rad() - (psi - truth_rad[0])).abs());
    }
    worst
}

#[test]
fn integrated_sim_gyro_tracks_the_heading_to_second_order() {
    for rate_hz in [20.0, 50.0, 128.0] {
        let truth = simulate(&route(), 0.0, rate_hz).unwrap();
        let stream = vehicle_streams(&truth, &error_free(), 1).unwrap();
        let t_s: Vec<f64> = truth.iter().map(|s| s.t_s).collect();
        let psi: Vec<f64> = truth.iter().map(|s| s.heading_unwrapped_rad).collect();
        let gyro: Vec<f64> = stream.iter().map(|s| s.gyr_z_rps.unwrap()).collect();

        let dt = 1.0 / rate_hz;
        // 1e-11 rad: rounding of a few thousand sums of terms of order 1 rad.
        let bound = kink_slope_jumps() * dt * dt / 8.0 + 1e-11;
        let err = worst_error(&t_s, &gyro, &psi);
        println!("{rate_hz} Hz: error {err:.3e}, bound {bound:.3e}");
        assert!(
            err <= bound,
            "{rate_hz} Hz: error {err:.3e} > bound {bound:.3e}"
        );

        // The same integration of the mean rate over the previous step (the half-sample lag
        // this convention avoids) is far outside the bound.
        let lagged: Vec<f64> = (0..truth.len())
            .map(|k| match k {
                0 => gyro[0],
                _ => {
                    angle_diff(truth[k].heading_rad, truth[k - 1].heading_rad)
                        / (truth[k].t_s - truth[k - 1].t_s)
                }
            })
            .collect();
        let lag_err = worst_error(&t_s, &lagged, &psi);
        println!("{rate_hz} Hz: mean-rate stream error {lag_err:.3e}");
        assert!(
            lag_err > 10.0 * bound,
            "{rate_hz} Hz: lagged {lag_err:.3e} vs bound {bound:.3e}"
        );
    }
}
