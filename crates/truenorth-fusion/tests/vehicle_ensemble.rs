//! The fused vehicle estimator across the whole physical range
//! ([`truenorth_sim::RangeDrive`]): rear- and front-wheel cars, skid-steer and
//! differential-drive robots, each sensor at its own rate with readings missing, opening
//! circles from full lock to 30 m or none, gyro bias to 5 °/s and scale to ±5 %, speed
//! coefficients to 3·10⁻⁴ s²/m², skid-steer tracks 1.5–2.5 times the physical one.
//!
//! Held on every drive of the suite's ensemble: accuracy (cars with a gyro within 0.3 % of
//! the distance once the mean wheel scale no sensor sees is divided out, without a gyro
//! 1 %; robots no worse than gyro-times-wheels dead reckoning), never worse than that
//! baseline, and consistency (the share of rows beyond 3σ and the largest error in σ).
//! The distribution over more drives:
//! `SEEDS=200 cargo test --release -p truenorth-fusion --test vehicle_ensemble -- --ignored --nocapture`.

use truenorth_core::{HeadingEstimator, NavEstimate, VehicleSample};
use truenorth_fusion::vehicle::{TwoPassConfig, TwoPassStart};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_sim::{
    Consistency, DriveScore, RangeDrive, RangeSpec, VehicleKind, gyro_wheels_final_error_pct,
};

/// What one run of one drive gave.
#[derive(Debug, Clone, Copy)]
struct Run {
    score: DriveScore,
    consistency: Consistency,
    /// The same over the rows outside magnetic disturbances and after the first minute.
    clean: Consistency,
    /// Gyro-times-wheels dead reckoning's final error, % (infinite without a gyro), given
    /// the true start heading.
    baseline_pct: f64,
    /// The fused estimator's final error with its own north reference taken out (its track
    /// turned back by the offset it referred the heading to north with, against the truth
    /// turned by the true start heading): the dead reckoning's own error, comparable with
    /// the baseline's, %.
    relative_pct: f64,
    /// The drive opened with a full turn.
    opened: bool,
    distance_m: f64,
}

/// The estimator as a user of this simulator's world would configure it: its roads are flat
/// and its compass level, so no grade or camber tilts the field's vertical part into the
/// heading (the default's 3°, `CompassGates::systematic_deg`); the installation's 0.3° is
/// what is left. `vehicle_real_habits` runs the tilting world with the defaults.
fn config(d: &RangeDrive) -> VehicleConfig {
    let mut priors = truenorth_fusion::SensorPriors::for_wheels(&d.vehicle.wheels);
    priors.wheel_resolution_m = d.wheel_resolution_m();
    VehicleConfig {
        wheels: d.vehicle.wheels,
        priors: Some(priors),
        compass: truenorth_fusion::CompassGates {
            systematic_deg: 0.3,
            ..truenorth_fusion::CompassGates::default()
        },
        ..VehicleConfig::default()
    }
}

fn run(d: &RangeDrive, gyro: bool, two_pass: bool) -> Run {
    let samples: Vec<VehicleSample> = d
        .samples
        .iter()
        .map(|s| VehicleSample {
            gyr_z_rps: s.gyr_z_rps.filter(|_| gyro),
            ..*s
        })
        .collect();
    // A row that carried only the gyro is empty without it: it is no row at all.
    let keep: Vec<bool> = samples
        .iter()
        .map(|s| s.wheels.is_some() || s.gyr_z_rps.is_some() || s.mag.is_some())
        .collect();
    let nav = VehicleEstimator::new(config(d)).unwrap();
    let mut estimates: Vec<NavEstimate> = Vec::with_capacity(samples.len());
    let rows: Vec<VehicleSample> = samples
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(s, _)| *s)
        .collect();
    let offset = if two_pass {
        let mut two = TwoPassStart::new(nav, TwoPassConfig::default()).unwrap();
        for s in &rows {
            two.push(s, |_, e, _| estimates.push(*e)).unwrap();
        }
        two.finish(|_, e, _| estimates.push(*e)).unwrap();
        two.estimator().alignment_offset_rad()
    } else {
        let mut nav = nav;
        for s in &rows {
            estimates.push(nav.update(s).unwrap());
        }
        nav.alignment_offset_rad()
    };
    let truth: Vec<_> = d
        .truth
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(t, _)| *t)
        .collect();
    let score = truenorth_sim::DriveScore::of(
        &truth,
        &estimates,
        |t| d.disturbed_at(t),
        d.mean_wheel_scale(),
    )
    .unwrap();
    let baseline_pct = if gyro {
        gyro_wheels_final_error_pct(&d.truth, &d.samples, d.vehicle.wheels.track_m())
            .unwrap_or(f64::INFINITY)
    } else {
        f64::INFINITY
    };
    let clean: Vec<usize> = (0..truth.len())
        .filter(|&k| !d.disturbed_at(truth[k].t_s) && truth[k].t_s > 60.0)
        .collect();
    let pick_t: Vec<_> = clean.iter().map(|&k| truth[k]).collect();
    let pick_e: Vec<_> = clean.iter().map(|&k| estimates[k]).collect();
    let clean = if pick_t.is_empty() {
        Consistency::default()
    } else {
        // The first row kept stands for the start: re-anchor on the true first row.
        let mut t = vec![truth[0]];
        t.extend(&pick_t);
        let mut e = vec![estimates[0]];
        e.extend(&pick_e);
        Consistency::of(&t, &e).unwrap()
    };
    let last = estimates.last().unwrap();
    let end = truth.last().unwrap();
    let (so, co) = offset.unwrap_or(0.0).sin_cos();
    let (s0, c0) = truth[0].heading_rad.sin_cos();
    let relative_pct = 100.0
        * (co * last.north_m + so * last.east_m - (c0 * end.north_m + s0 * end.east_m))
            .hypot(-so * last.north_m + co * last.east_m - (-s0 * end.north_m + c0 * end.east_m))
        / end.distance_m;
    Run {
        score,
        opened: d.opening_radius_m.is_some(),
        relative_pct,
        clean,
        consistency: Consistency::of(&truth, &estimates).unwrap(),
        baseline_pct,
        distance_m: d.distance_m(),
    }
}

/// Drive `seed` of `kind`; without magnetic disturbances when `NO_DISTURB` is set (for the
/// ignored measurements: what the estimator makes of its own model's errors alone).
fn drive(seed: u64, kind: VehicleKind) -> RangeDrive {
    RangeDrive::new(RangeSpec {
        disturbances: std::env::var("NO_DISTURB").is_err(),
        ..RangeSpec::new(seed, kind)
    })
    .unwrap()
}

/// Prints the distribution of one configuration over `seeds` drives.
fn report(kind: VehicleKind, gyro: bool, two_pass: bool, seeds: u64) {
    let verbose = std::env::var("VERBOSE").is_ok();
    let mut runs: Vec<Run> = (0..seeds)
        .map(|seed| {
            let r = run(&drive(seed, kind), gyro, two_pass);
            if verbose {
                println!(
                    "  seed {seed}: final {:.3} % (relative {:.3}, baseline {:.2}), heading RMS {:.2}°, absolute from {:.0} s, heading >3σ {:.1} % max {:.1}σ, position >3σ {:.1} % max {:.1}σ",
                    r.score.final_error_pct,
                    r.relative_pct,
                    r.baseline_pct,
                    r.score.heading_rms_deg,
                    r.score.absolute_from_s,
                    100.0 * r.consistency.heading.share_beyond(),
                    r.consistency.heading.max_sigmas,
                    100.0 * r.consistency.position.share_beyond(),
                    r.consistency.position.max_sigmas,
                );
            }
            r
        })
        .collect();
    let mut total = Consistency::default();
    let mut clean = Consistency::default();
    for r in &runs {
        total.merge(&r.consistency);
        clean.merge(&r.clean);
    }
    let worse = runs
        .iter()
        .filter(|r| r.relative_pct > r.baseline_pct)
        .count();
    let pct = |runs: &mut Vec<Run>, f: fn(&Run) -> f64| {
        runs.sort_by(|a, b| f(a).total_cmp(&f(b)));
        let n = runs.len();
        (f(&runs[n / 2]), f(&runs[(n * 9) / 10]), f(&runs[n - 1]))
    };
    let mut opened: Vec<Run> = runs.iter().copied().filter(|r| r.opened).collect();
    let fin_opened = pct(&mut opened, |r| r.score.final_error_pct);
    let fin = pct(&mut runs, |r| r.score.final_error_pct);
    let rem = pct(&mut runs, |r| r.score.scale_removed_pct);
    let base = pct(&mut runs, |r| r.baseline_pct);
    let head = pct(&mut runs, |r| r.score.heading_rms_deg);
    let km = pct(&mut runs, |r| r.distance_m / 1e3);
    println!(
        "{kind:?} gyro {gyro} two-pass {two_pass}: {seeds} drives of {:.1}-{:.1} km | final % median/p90/worst {:.3}/{:.3}/{:.3} | scale removed {:.3}/{:.3}/{:.3} | baseline {:.2}/{:.2}/{:.2}, worse than it {worse} | heading RMS ° {:.2}/{:.2}/{:.2} | heading beyond 3σ {:.2} %, max {:.1}σ, mean NEES {:.2} | position beyond 3σ {:.2} %, max {:.1}σ, mean NEES {:.2}",
        runs.iter()
            .map(|r| r.distance_m)
            .fold(f64::INFINITY, f64::min)
            / 1e3,
        km.2,
        fin.0,
        fin.1,
        fin.2,
        rem.0,
        rem.1,
        rem.2,
        base.0,
        base.1,
        base.2,
        head.0,
        head.1,
        head.2,
        100.0 * total.heading.share_beyond(),
        total.heading.max_sigmas,
        total.heading.mean_nees(),
        100.0 * total.position.share_beyond(),
        total.position.max_sigmas,
        total.position.mean_nees(),
    );
    println!(
        "    {} drives opening with a full turn: final % median/p90/worst {:.3}/{:.3}/{:.3}",
        opened.len(),
        fin_opened.0,
        fin_opened.1,
        fin_opened.2
    );
    println!(
        "    outside disturbances, after the first minute: heading beyond 3σ {:.2} %, max {:.1}σ | position beyond 3σ {:.2} %, max {:.1}σ",
        100.0 * clean.heading.share_beyond(),
        clean.heading.max_sigmas,
        100.0 * clean.position.share_beyond(),
        clean.position.max_sigmas,
    );
}

/// Drives per kind of vehicle in the suite's ensemble.
const SUITE_SEEDS: u64 = 16;

/// The suite's ensemble: sixteen drives of each kind, with the gyro and (cars) without, as
/// `truenorth drive` runs them. Held on every drive: the fused track is never worse than
/// gyro-times-wheels dead reckoning given the true start heading (its own north reference
/// taken out, so that both are judged on their dead reckoning). Held over the ensemble: at
/// least twice better than that on the median drive with a gyro,
/// the accuracy goals on the median drive (cars 0.3 % of the distance with a gyro and 1 %
/// without, once the mean wheel scale no sensor on board sees is divided out), and the
/// consistency of the reported σ. A consistent σ leaves 0.27 % of rows beyond 3σ; the
/// estimator does not yet reach that (slow field disturbances that the dead reckoning
/// cannot tell from a turn while it is itself uncertain, and the rows after them), so the
/// shares below hold the figures it reaches, which the README quotes with their goal.
#[test]
fn across_the_physical_range() {
    let configurations: [(VehicleKind, bool, f64, f64); 6] = [
        // kind, gyro, goal on the median final error (scale removed), share beyond 3σ held
        (VehicleKind::RearWheelCar, true, 0.3, 0.01),
        (VehicleKind::FrontWheelCar, true, 0.3, 0.01),
        (VehicleKind::RearWheelCar, false, 1.0, 0.06),
        (VehicleKind::FrontWheelCar, false, 1.0, 0.06),
        (VehicleKind::SkidSteer, true, 1.0, 0.03),
        (VehicleKind::Differential, true, 1.0, 0.03),
    ];
    for (kind, gyro, goal_pct, share) in configurations {
        let mut runs: Vec<Run> = (0..SUITE_SEEDS)
            .map(|seed| {
                run(
                    &RangeDrive::new(RangeSpec::new(seed, kind)).unwrap(),
                    gyro,
                    true,
                )
            })
            .collect();
        let mut total = Consistency::default();
        for (seed, r) in runs.iter().enumerate() {
            total.merge(&r.consistency);
            // Never worse than the best sensor alone.
            assert!(
                r.relative_pct <= r.baseline_pct,
                "{kind:?} seed {seed}: {:.3} % against gyro-times-wheels {:.3} %",
                r.relative_pct,
                r.baseline_pct
            );
        }
        if gyro {
            // Where the compass and the wheels add to the gyro, at least twice better than it
            // on the median drive.
            let mut ratios: Vec<f64> = runs
                .iter()
                .map(|r| r.relative_pct / r.baseline_pct)
                .collect();
            ratios.sort_by(f64::total_cmp);
            let ratio = ratios[ratios.len() / 2];
            println!("{kind:?}: fused over gyro-times-wheels, median {ratio:.3}");
            assert!(ratio <= 0.5, "{kind:?}: median ratio {ratio:.3}");
        }
        runs.sort_by(|a, b| {
            a.score
                .scale_removed_pct
                .total_cmp(&b.score.scale_removed_pct)
        });
        let median = runs[runs.len() / 2].score.scale_removed_pct;
        println!(
            "{kind:?} gyro {gyro}: median final {median:.3} % (goal {goal_pct} %), heading beyond 3σ {:.2} % (max {:.1}σ), position {:.2} % (max {:.1}σ)",
            100.0 * total.heading.share_beyond(),
            total.heading.max_sigmas,
            100.0 * total.position.share_beyond(),
            total.position.max_sigmas
        );
        assert!(
            median <= goal_pct,
            "{kind:?} gyro {gyro}: median {median:.3} %"
        );
        assert!(
            total.heading.share_beyond() <= share,
            "{kind:?} gyro {gyro}: {:.2} % of rows beyond 3σ",
            100.0 * total.heading.share_beyond()
        );
    }
}

#[test]
#[ignore = "measurement: run in release with --ignored --nocapture"]
fn measure() {
    let seeds = std::env::var("SEEDS").map_or(20, |s| s.parse().unwrap());
    let kinds: Vec<VehicleKind> = match std::env::var("KIND") {
        Ok(k) => VehicleKind::ALL
            .into_iter()
            .filter(|v| format!("{v:?}") == k)
            .collect(),
        Err(_) => VehicleKind::ALL.to_vec(),
    };
    let two_pass = std::env::var("SINGLE_PASS").is_err();
    for kind in kinds {
        for gyro in [true, false] {
            report(kind, gyro, two_pass, seeds);
        }
    }
}

#[test]
#[ignore = "diagnosis: one drive's worst rows"]
fn diagnose() {
    let seed: u64 = std::env::var("SEED").map_or(0, |s| s.parse().unwrap());
    let kind = VehicleKind::ALL
        .into_iter()
        .find(|v| Ok(format!("{v:?}")) == std::env::var("KIND"))
        .unwrap_or(VehicleKind::RearWheelCar);
    let gyro = std::env::var("NO_GYRO").is_err();
    let mut d = match std::env::var("LENGTH") {
        Ok(l) => RangeDrive::new(RangeSpec {
            length_m: l.parse().unwrap(),
            ..RangeSpec::new(seed, kind)
        })
        .unwrap(),
        Err(_) => drive(seed, kind),
    };
    if let Ok(wheels) = std::env::var("OLD") {
        // A drive of the typical installation (`truenorth_sim::SimulatedDrive`) instead.
        let old = truenorth_sim::SimulatedDrive::new(truenorth_sim::DriveSpec {
            wheels: if wheels == "front" {
                truenorth_sim::DriveWheels::Front
            } else {
                truenorth_sim::DriveWheels::Rear
            },
            ..truenorth_sim::DriveSpec::new(seed)
        })
        .unwrap();
        d.vehicle.wheels = old.spec.wheels.odometer_wheels();
        d.truth = old.truth;
        d.samples = old.samples;
        d.params = old.params;
        d.disturbances = old.disturbances;
    }
    if std::env::var("TWO").is_ok() {
        let nav = VehicleEstimator::new(config(&d)).unwrap();
        let mut two = TwoPassStart::new(nav, TwoPassConfig::default()).unwrap();
        let mut out = Vec::new();
        // The compass calibration's own error at the true heading of a sample's time.
        let p = d.params;
        let truth_at = |t_s: f64| d.truth.iter().find(|t| t.t_s >= t_s).copied().unwrap();
        let cal_error = |n: &VehicleEstimator, t_s: f64| {
            n.compass_fix().map_or(f64::NAN, |fix| {
                let h = truth_at(t_s).heading_rad;
                let field = nalgebra::Vector2::new(
                    p.horizontal_field * h.cos(),
                    -p.horizontal_field * h.sin(),
                );
                let ideal = p.compass_soft_iron * field + p.compass_hard_iron;
                truenorth_core::angle_diff(fix.calibration.heading_rad(&ideal), h).to_degrees()
            })
        };
        for s in &d.samples {
            let s = VehicleSample {
                gyr_z_rps: s.gyr_z_rps.filter(|_| gyro),
                ..*s
            };
            two.push(&s, |s, e, n| {
                out.push((*s, *e, n.filter().x, cal_error(n, s.t_s)))
            })
            .unwrap();
        }
        two.finish(|s, e, n| out.push((*s, *e, n.filter().x, cal_error(n, s.t_s))))
            .unwrap();
        let psi0 = d.truth[0].heading_rad;
        for (k, ((s, e, x, cal), t)) in out.iter().zip(&d.truth).enumerate() {
            assert_eq!(s.t_s, t.t_s);
            if k % env_every() == 0 {
                let reference = if e.status.heading_absolute {
                    t.heading_rad
                } else {
                    t.heading_rad - psi0
                };
                let err = truenorth_core::angle_diff(e.heading.rad(), reference);
                let (tn, te) = if e.status.heading_absolute {
                    (t.north_m, t.east_m)
                } else {
                    let (s, c) = psi0.sin_cos();
                    (c * t.north_m + s * t.east_m, -s * t.north_m + c * t.east_m)
                };
                let p = e.position_cov_m2;
                println!(
                    "two-pass t {:7.1} err {:7.3}° σ {:6.3}° pos err {:6.1} {:6.1} σ {:5.1} {:5.1} abs {} compass used {} disturbed {} (truth {}) bias {:.3} gains {:.4} {:.4} diff {:.5} track {:.4} compass error {:.2}° (calibration's {:.2}°)",
                    t.t_s,
                    err.to_degrees(),
                    e.heading_sigma_rad.to_degrees(),
                    e.north_m - tn,
                    e.east_m - te,
                    p[(0, 0)].sqrt(),
                    p[(1, 1)].sqrt(),
                    e.status.heading_absolute,
                    e.status.compass_used,
                    e.status.compass_disturbed,
                    d.disturbed_at(t.t_s),
                    x[3].to_degrees(),
                    x[4],
                    x[5],
                    x[6],
                    x[9],
                    x[10].to_degrees(),
                    cal,
                );
            }
        }
        println!("offset {:?}", two.estimator().alignment_offset_rad());
        return;
    }
    let mut nav = VehicleEstimator::new(config(&d)).unwrap();
    let psi0 = d.truth[0].heading_rad;
    let mut worst = (0.0, 0.0);
    let mut worst_position = (0.0, 0.0);
    // The gyro's true bias now: its reading less the true rate through its scale, averaged.
    let mut true_bias = d.params.gyro.bias_rps;
    for (k, (s, t)) in d.samples.iter().zip(&d.truth).enumerate() {
        let s = VehicleSample {
            gyr_z_rps: s.gyr_z_rps.filter(|_| gyro),
            ..*s
        };
        if s.wheels.is_none() && s.gyr_z_rps.is_none() && s.mag.is_none() {
            continue;
        }
        let e = nav.update(&s).unwrap();
        if let Some(g) = s.gyr_z_rps {
            let r = t.yaw_rate_rps;
            let gp = &d.params.gyro;
            let scale = 1.0
                + if r >= 0.0 {
                    gp.scale_error_pos
                } else {
                    gp.scale_error_neg
                };
            true_bias += 0.01 * (g - r * scale - true_bias);
        }
        if let (Some(_), Some(fix), true) = (s.mag, nav.compass_fix(), k % 200 == 0)
            && !d.disturbed_at(t.t_s)
        {
            {
                let p = &d.params;
                let field = nalgebra::Vector2::new(
                    p.horizontal_field * t.heading_rad.cos(),
                    -p.horizontal_field * t.heading_rad.sin(),
                );
                let ideal = p.compass_soft_iron * field + p.compass_hard_iron;
                let h = fix.calibration.heading_rad(&ideal);
                println!(
                    "  compass at {:.1}: heading {:.1}° error {:.3}° (calibration σ {:.3}°, noise {:.3}°)",
                    t.t_s,
                    t.heading_rad.to_degrees(),
                    truenorth_core::angle_diff(h, t.heading_rad).to_degrees(),
                    fix.calibration_sigma_rad.to_degrees(),
                    fix.noise_rad.to_degrees()
                );
            }
        }
        let reference = if e.status.heading_absolute {
            t.heading_rad
        } else {
            t.heading_rad - psi0
        };
        let err = truenorth_core::angle_diff(e.heading.rad(), reference);
        let z = err / e.heading_sigma_rad;
        if z.abs() > worst.0 {
            worst = (z.abs(), t.t_s);
        }
        let (tn, te) = if e.status.heading_absolute {
            (t.north_m, t.east_m)
        } else {
            let (s, c) = psi0.sin_cos();
            (c * t.north_m + s * t.east_m, -s * t.north_m + c * t.east_m)
        };
        let p = e.position_cov_m2;
        let miss = nalgebra::Vector2::new(e.north_m - tn, e.east_m - te);
        let pos_z = p.try_inverse().map_or(0.0, |inv| {
            (miss.transpose() * inv * miss)[(0, 0)].max(0.0).sqrt()
        });
        if e.status.position_known && pos_z > worst_position.0 {
            worst_position = (pos_z, t.t_s);
        }
        if k % env_every() == 0 || (z.abs() > 4.0 || pos_z > 4.0) && k % 50 == 0 {
            let x = &nav.filter().x;
            let dist = (tn * tn + te * te).sqrt().max(1e-9);
            let along = ((e.north_m - tn) * tn + (e.east_m - te) * te) / dist;
            println!(
                "  displacement {:.0} m, travelled {:.0} m, along-track error {:.2} m ({:.3} %)",
                dist,
                t.distance_m,
                along,
                100.0 * along / dist
            );
            println!(
                "t {:7.1} v {:5.1} err {:7.3}° σ {:6.3}° z {:6.1} pos err {:6.1} {:6.1} σ {:5.1} {:5.1} abs {} bias {:.3}/{:.3} gains {:.4}±{:.4} {:.4}±{:.4} (true {:.4} {:.4}) diff {:.5} track {:.4}±{:.4} (true {:.4}) a {:.2e}±{:.1e} (true {:.2e}) distrust {:.1}",
                t.t_s,
                t.speed_mps,
                err.to_degrees(),
                e.heading_sigma_rad.to_degrees(),
                z,
                e.north_m - tn,
                e.east_m - te,
                p[(0, 0)].sqrt(),
                p[(1, 1)].sqrt(),
                e.status.heading_absolute,
                x[3].to_degrees(),
                true_bias.to_degrees(),
                x[4],
                nav.filter().sigma(4),
                x[5],
                nav.filter().sigma(5),
                d.params.gyro.scale_error_pos,
                d.params.gyro.scale_error_neg,
                x[6],
                x[9],
                nav.filter().sigma(9),
                d.vehicle.slip.track_factor - 1.0,
                x[7],
                nav.filter().sigma(7),
                d.params.odometer.speed_coeff_s2_per_m2,
                nav.wheel_distrust(),
            );
        }
    }
    println!(
        "worst heading {:.1}σ at {:.1} s, position {:.1}σ at {:.1} s",
        worst.0, worst.1, worst_position.0, worst_position.1
    );
}

/// Rows between two diagnostic lines (`EVERY`, default 2000).
fn env_every() -> usize {
    std::env::var("EVERY").map_or(2000, |s| s.parse().unwrap())
}

/// The rows of one drive between `FROM` and `TO` seconds: truth and readings.
#[test]
#[ignore = "diagnosis: one drive's rows"]
fn rows() {
    let seed: u64 = std::env::var("SEED").map_or(0, |s| s.parse().unwrap());
    let kind = VehicleKind::ALL
        .into_iter()
        .find(|v| Ok(format!("{v:?}")) == std::env::var("KIND"))
        .unwrap_or(VehicleKind::RearWheelCar);
    let from: f64 = std::env::var("FROM").unwrap().parse().unwrap();
    let to: f64 = std::env::var("TO").unwrap().parse().unwrap();
    let d = drive(seed, kind);
    for (s, t) in d.samples.iter().zip(&d.truth) {
        if t.t_s >= from && t.t_s <= to {
            println!(
                "t {:.3} heading {:.2} rate {:.2}°/s v {:.2} | wheels {:?} gyro {:?} mag {}",
                t.t_s,
                t.heading_unwrapped_rad.to_degrees(),
                t.yaw_rate_rps.to_degrees(),
                t.speed_mps,
                s.wheels.map(|w| (w.dist_l_m, w.dist_r_m)),
                s.gyr_z_rps.map(f64::to_degrees),
                s.mag.is_some()
            );
        }
    }
}
