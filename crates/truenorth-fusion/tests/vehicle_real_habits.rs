//! The fused vehicle estimator on drives as real logs give them
//! ([`truenorth_sim::log_drive`]): in motion from the first row, rests rare and short,
//! each sensor on its own rows and clock with latency, controller-lagged and quantized
//! wheel data, 5 Hz CAN rates, yaw-rate scale errors to ±10 %, a skid-steer's effective
//! track changing with speed and ground — for every kind of vehicle and the sensor sets
//! real vehicles carry, and the three presets modelled on real logs that once beat it.
//!
//! Each drive is scored against plain integration, run on the same rows: the raw yaw rate
//! less the bias it reads at the first rest of a second or more (zero without one) times the
//! wheels' mean or the vehicle's distance. Both tracks are compared with the truth after one
//! rotation about the start (the reference a relative heading allows), as RMS and final
//! error. Held on every drive: the fused track no worse than the baseline's (within a
//! tolerance for the noise of a track's final error, below), heading error beyond 3σ on at
//! most 2 % of rows, never beyond 6σ.
//! Ten drives a set; more: `SEEDS=20 cargo test --release -p truenorth-fusion --test
//! vehicle_real_habits -- --nocapture`.

use truenorth_core::{NavEstimate, VehicleSample, angle_diff};
use truenorth_fusion::vehicle::{TwoPassConfig, TwoPassStart};
use truenorth_fusion::{SensorPriors, VehicleConfig, VehicleEstimator};
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, Odometry, SensorSet};
use truenorth_sim::{VehicleKind, rotated_track_errors};

/// What one drive gave.
#[derive(Debug, Clone, Copy)]
struct Score {
    /// Fused track: RMS and final error after one rotation about the start, m.
    fused_rms_m: f64,
    fused_final_m: f64,
    /// The baseline's, the same way (NaN where it has no track).
    base_rms_m: f64,
    base_final_m: f64,
    /// Heading error RMS, rad, fused and baseline (relative to the start heading, or to
    /// magnetic north once the fused heading is absolute).
    fused_heading_rms: f64,
    base_heading_rms: f64,
    /// Rows scored for heading, beyond 3σ, and the largest |error|/σ.
    rows: usize,
    beyond_3: usize,
    max_z: f64,
    distance_m: f64,
    /// Times the fused estimate fell back to plain integration while the sensors were
    /// learned (the first pass), or after, whichever is more.
    fallbacks: u32,
}

fn config(d: &LogDrive) -> VehicleConfig {
    // Wheel speeds are integrated into the distances the estimator reads, as `drive` does:
    // the priors of speeds from a controller.
    let priors = if matches!(
        d.config.sensors.odometry,
        Odometry::WheelSpeeds | Odometry::FourWheelSpeeds
    ) {
        SensorPriors::for_wheel_speeds(&d.vehicle.wheels)
    } else {
        SensorPriors::for_wheels(&d.vehicle.wheels)
    };
    VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(priors),
        ..VehicleConfig::default()
    }
}

/// Plain integration over `samples`: heading from the raw yaw rate less the first second-long
/// rest's mean (zero without one), track along it from the wheels' mean or the distance.
/// One (heading, north, east) per sample; `None` without a gyro.
fn baseline(samples: &[VehicleSample]) -> Option<Vec<(f64, f64, f64)>> {
    samples.iter().find(|s| s.gyr_z_rps.is_some())?;
    let dist = |s: &VehicleSample| {
        s.wheels
            .map(|w| 0.5 * (w.dist_l_m + w.dist_r_m))
            .or(s.dist_m)
    };
    // The first rest of a second or more: the distance unchanged over it.
    let mut bias = 0.0;
    let (mut start, mut last_d): (Option<f64>, Option<f64>) = (None, None);
    let (mut sum, mut n) = (0.0, 0usize);
    for s in samples {
        if let Some(d) = dist(s) {
            if last_d.is_some_and(|l| (d - l).abs() < 1e-9) {
                start.get_or_insert(s.t_s);
            } else {
                if start.is_some_and(|t0| s.t_s - t0 >= 1.0) && n > 0 {
                    bias = sum / n as f64;
                    break;
                }
                start = None;
                sum = 0.0;
                n = 0;
            }
            last_d = Some(d);
        }
        if let (Some(_), Some(g)) = (start, s.gyr_z_rps) {
            sum += g;
            n += 1;
        }
    }
    let mut out = Vec::with_capacity(samples.len());
    let (mut psi, mut north, mut east) = (0.0, 0.0, 0.0);
    let mut last_g: Option<(f64, f64)> = None;
    let mut last_d: Option<f64> = None;
    for s in samples {
        if let Some(g) = s.gyr_z_rps {
            if let Some((t0, g0)) = last_g {
                psi += 0.5 * (g + g0 - 2.0 * bias) * (s.t_s - t0);
            }
            last_g = Some((s.t_s, g));
        }
        if let Some(d) = dist(s) {
            if let Some(l) = last_d {
                north += (d - l) * psi.cos();
                east += (d - l) * psi.sin();
            }
            last_d = Some(d);
        }
        out.push((psi, north, east));
    }
    Some(out)
}

fn score(d: &LogDrive) -> Score {
    score_from(d, VehicleEstimator::new(config(d)).unwrap())
}

/// [`score`] of the estimator `nav` (configured for `d`, perhaps from a stored calibration).
fn score_from(d: &LogDrive, nav: VehicleEstimator) -> Score {
    let samples = d.vehicle_samples();
    // As `truenorth drive` runs by default: the head of the drive estimated again once the
    // sensors are learned, as the plain baseline uses its rest's bias from the start.
    let mut two = TwoPassStart::new(nav, TwoPassConfig::default()).unwrap();
    let mut estimates: Vec<NavEstimate> = Vec::with_capacity(samples.len());
    let mut fallbacks = 0;
    for s in &samples {
        two.push(s, |_, e, _| estimates.push(*e)).unwrap();
        fallbacks = fallbacks.max(two.estimator().fallbacks());
    }
    two.finish(|_, e, _| estimates.push(*e)).unwrap();
    let psi0 = d.truth[0].heading_rad;
    let decl = d.errors.declination_rad;
    let truth_track: Vec<(f64, f64)> = d.truth.iter().map(|t| (t.north_m, t.east_m)).collect();
    let positioned = estimates.iter().any(|e| e.status.position_known);
    // Each estimate's track is in its own frame: the start heading pointing north until the
    // heading is referred to magnetic north, magnetic north after.
    let truth_in_frame: Vec<(f64, f64)> = estimates
        .iter()
        .zip(&d.truth)
        .map(|(e, t)| {
            let turn = if e.status.heading_absolute {
                decl
            } else {
                psi0
            };
            let (s, c) = turn.sin_cos();
            (c * t.north_m + s * t.east_m, -s * t.north_m + c * t.east_m)
        })
        .collect();
    let (fused_rms_m, fused_final_m) = if positioned {
        rotated_track_errors(
            &estimates
                .iter()
                .map(|e| (e.north_m, e.east_m))
                .collect::<Vec<_>>(),
            &truth_in_frame,
        )
        .unwrap()
    } else {
        (f64::NAN, f64::NAN)
    };
    let base = baseline(&samples);
    let (base_rms_m, base_final_m) = match &base {
        Some(b) if positioned => rotated_track_errors(
            &b.iter().map(|x| (x.1, x.2)).collect::<Vec<_>>(),
            &truth_track,
        )
        .unwrap(),
        _ => (f64::NAN, f64::NAN),
    };
    let (mut rows, mut beyond_3, mut max_z, mut f2, mut b2) = (0, 0, 0.0f64, 0.0, 0.0);
    for (k, (e, t)) in estimates.iter().zip(&d.truth).enumerate() {
        let reference = if e.status.heading_absolute {
            t.heading_rad - decl
        } else {
            t.heading_rad - psi0
        };
        let err = angle_diff(e.heading.rad(), reference);
        f2 += err * err;
        if let Some(b) = &base {
            b2 += angle_diff(b[k].0, t.heading_rad - psi0).powi(2);
        }
        let sigma = e.heading_sigma_rad;
        if sigma.is_finite() && sigma > 0.0 {
            let z = err.abs() / sigma;
            rows += 1;
            beyond_3 += usize::from(z > 3.0);
            max_z = max_z.max(z);
        }
    }
    let n = estimates.len() as f64;
    Score {
        fallbacks,
        fused_rms_m,
        fused_final_m,
        base_rms_m,
        base_final_m,
        fused_heading_rms: (f2 / n).sqrt(),
        base_heading_rms: if base.is_some() {
            (b2 / n).sqrt()
        } else {
            f64::NAN
        },
        rows,
        beyond_3,
        max_z,
        distance_m: d.distance_m(),
    }
}

fn seeds() -> u64 {
    std::env::var("SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10)
}

/// A cell of the ensemble: its name and the drive of each seed.
type Cell = (String, Box<dyn Fn(u64) -> LogDriveConfig>);

/// The three presets modelled on real logs, then every kind of vehicle with every sensor
/// set it can carry.
fn cells() -> Vec<Cell> {
    let mut out: Vec<Cell> = vec![
        (
            "real CAN car".into(),
            Box::new(LogDriveConfig::real_can_car),
        ),
        (
            "real skid-steer".into(),
            Box::new(LogDriveConfig::real_skid_steer),
        ),
        (
            "real circling car".into(),
            Box::new(LogDriveConfig::real_circling_car),
        ),
    ];
    for kind in VehicleKind::ALL {
        for set in SensorSet::every(kind) {
            let name = format!(
                "{kind:?} {:?}{}{}",
                set.odometry,
                if set.gyro { " + gyro" } else { "" },
                if set.compass { " + compass" } else { "" }
            );
            out.push((
                name,
                Box::new(move |seed| LogDriveConfig::new(seed, kind, set)),
            ));
        }
    }
    out
}

/// Held on every cell with a plain baseline (a gyro and a distance), over its seeds: the
/// track's RMS no worse than plain integration's by more than a tenth (the two-pass start
/// and the rest hold move the path a little either way; the final error, one point of a
/// random walk, is printed, not held). Held on every set and the three presets of real
/// logs: heading beyond 3σ on at most 2 % of a set's rows, never beyond 6σ.
#[test]
fn real_habits_never_worse_than_plain_integration_and_sigma_holds() {
    let only = std::env::var("ONLY").unwrap_or_default();
    let mut worst_ratio: (f64, String) = (0.0, String::new());
    let mut worst_drive: (f64, String) = (0.0, String::new());
    let mut ratios = Vec::new();
    for (name, make) in cells() {
        if !name.contains(&only) {
            continue;
        }
        let (mut rows, mut beyond, mut max_z) = (0usize, 0usize, 0.0f64);
        let (mut fused_sq, mut plain_sq, mut n) = (0.0, 0.0, 0.0);
        for seed in 0..seeds() {
            let d = LogDrive::new(make(seed)).unwrap();
            let s = score(&d);
            println!(
                "{name:44} seed {seed}: track fused {:7.1} / {:7.1} m, plain {:7.1} / {:7.1} m ({:5.0} m); heading RMS fused {:6.2}° plain {:6.2}°; beyond 3σ {:5.2} %, max {:5.2}σ",
                s.fused_rms_m,
                s.fused_final_m,
                s.base_rms_m,
                s.base_final_m,
                s.distance_m,
                s.fused_heading_rms.to_degrees(),
                s.base_heading_rms.to_degrees(),
                100.0 * s.beyond_3 as f64 / s.rows.max(1) as f64,
                s.max_z
            );
            rows += s.rows;
            beyond += s.beyond_3;
            max_z = max_z.max(s.max_z);
            if s.base_rms_m.is_finite() {
                let r = s.fused_rms_m / s.base_rms_m;
                ratios.push(r);
                if r > worst_drive.0 {
                    worst_drive = (r, format!("{name} seed {seed}"));
                }
                fused_sq += s.fused_rms_m * s.fused_rms_m;
                plain_sq += s.base_rms_m * s.base_rms_m;
                n += 1.0;
            }
        }
        let share = beyond as f64 / rows.max(1) as f64;
        println!(
            "CELL {name:44} beyond 3σ {:5.2} %, max {max_z:5.2}σ, fused/plain track RMS {}",
            100.0 * share,
            if n > 0.0 {
                format!("{:.2}", (fused_sq / plain_sq).sqrt())
            } else {
                "-".to_string()
            }
        );
        assert!(
            share <= 0.02,
            "{name}: {:.2} % of rows beyond 3σ",
            100.0 * share
        );
        assert!(max_z < 6.0, "{name}: {max_z:.2}σ");
        if n > 0.0 {
            let ratio = (fused_sq / plain_sq).sqrt();
            if ratio > worst_ratio.0 {
                worst_ratio = (ratio, name.clone());
            }
            assert!(
                ratio <= 1.1,
                "{name}: fused track RMS {ratio:.2}× plain integration's"
            );
        }
    }
    ratios.sort_by(f64::total_cmp);
    if !ratios.is_empty() {
        println!(
            "fused/plain track RMS over {} drives: median {:.2}, worst drive {:.2} ({}), worst cell {:.2} ({})",
            ratios.len(),
            ratios[ratios.len() / 2],
            worst_drive.0,
            worst_drive.1,
            worst_ratio.0,
            worst_ratio.1
        );
    }
}

/// A calibration stored from another vehicle, or for a gyro since remounted: both gyro gains
/// 30 % low, claimed to within 0.2 %, on drives where nothing but a turn's size could expose
/// them — one vehicle distance and a gyro, no compass. Where the fused heading departs from
/// plain integration by more than their difference allows, it falls back to it and learns
/// again from the priors. Held: the guard never makes a drive worse than the same estimator
/// without it, it catches some, and over the drives it makes them better.
///
/// Printed, not held — a miss, measured with `SEEDS=10`: the guarded track is still 4.79×
/// plain integration's (unguarded 4.97×); 2 of the 10 drives are caught (88 m against plain
/// integration's 120 m, unguarded 431 m; 56 m against 35 m, unguarded 148 m). Rests in these
/// drives are rare and short and the route's net turn grows, so within a few minutes plain
/// integration itself is uncertain by tens of degrees (the bias's walk since the last rest,
/// the common gain error over the net turn), and a difference of that size is no evidence
/// against the fused estimate.
#[test]
fn a_wrong_stored_calibration_falls_back_to_plain_integration() {
    let set = SensorSet {
        odometry: truenorth_sim::log_drive::Odometry::VehicleDistance,
        gyro: true,
        compass: false,
    };
    let (mut guarded_sq, mut unguarded_sq, mut plain_sq) = (0.0, 0.0, 0.0);
    let mut fallbacks = 0;
    for seed in 0..seeds().max(3) {
        let d = LogDrive::new(LogDriveConfig::new(seed, VehicleKind::RearWheelCar, set)).unwrap();
        let fresh = VehicleEstimator::new(config(&d)).unwrap();
        let mut stored = fresh.calibration();
        for gain in [
            &mut stored.gyro_gain_error_right,
            &mut stored.gyro_gain_error_left,
        ] {
            gain.value = -0.3;
            gain.sigma = 0.002;
        }
        let run = |plain_guard| {
            let c = VehicleConfig {
                plain_guard,
                ..config(&d)
            };
            score_from(&d, VehicleEstimator::with_calibration(c, &stored).unwrap())
        };
        let (on, off) = (run(true), run(false));
        println!(
            "seed {seed}: track RMS guarded {:6.1} m ({} fallbacks), unguarded {:6.1} m, plain {:6.1} m; guarded heading beyond 3σ {:5.2} %, max {:5.2}σ",
            on.fused_rms_m,
            on.fallbacks,
            off.fused_rms_m,
            on.base_rms_m,
            100.0 * on.beyond_3 as f64 / on.rows.max(1) as f64,
            on.max_z
        );
        assert_eq!(off.fallbacks, 0, "seed {seed}: the guard was off");
        assert!(
            on.fused_rms_m <= 1.02 * off.fused_rms_m,
            "seed {seed}: the guard made the track worse: {:.1} m against {:.1} m",
            on.fused_rms_m,
            off.fused_rms_m
        );
        guarded_sq += on.fused_rms_m.powi(2);
        unguarded_sq += off.fused_rms_m.powi(2);
        plain_sq += on.base_rms_m.powi(2);
        fallbacks += on.fallbacks;
    }
    let (guarded, unguarded) = (
        (guarded_sq / plain_sq).sqrt(),
        (unguarded_sq / plain_sq).sqrt(),
    );
    println!(
        "track RMS / plain integration's: guarded {guarded:.2} ({fallbacks} fallbacks), unguarded {unguarded:.2}"
    );
    assert!(fallbacks > 0, "the wrong gains were never caught");
    assert!(
        guarded < unguarded,
        "the guard did not help: {guarded:.2} vs {unguarded:.2}"
    );
}
