//! A vehicle with a gyro and a compass and no odometry, with satellite fixes that report
//! their course: the courses refer its heading to true north and correct it (the position
//! stays unknown: nothing carries it between fixes). Simulated cars with real logs' habits
//! (`truenorth_sim::log_drive`; without odometry the kind of car does not matter), each
//! drive run with its fixes and without them. A robot, below the 3 m/s a course needs,
//! gains nothing from them.

use truenorth_core::{HeadingEstimator, VehicleSample, angle_diff};
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_sim::VehicleKind;
use truenorth_sim::log_drive::{LogDrive, LogDriveConfig, SensorSet};

/// Heading error RMS (rad), rows beyond 3σ, rows scored and the largest |error|/σ of one
/// drive, against the true heading wherever the estimate is referred to north (magnetic by
/// the compass, true by the fixes), against the start heading before.
struct Run {
    rms_rad: f64,
    beyond_3: usize,
    rows: usize,
    max_z: f64,
    true_north_rows: usize,
    position_rows: usize,
    courses: u32,
}

/// The estimator for `d`'s vehicle, under its kind's priors.
fn estimator(d: &LogDrive) -> VehicleEstimator {
    VehicleEstimator::new(VehicleConfig {
        wheels: d.vehicle.wheels,
        ..VehicleConfig::default()
    })
    .unwrap()
}

fn run(d: &LogDrive, samples: &[VehicleSample]) -> Run {
    let mut nav = estimator(d);
    let (psi0, decl) = (d.truth[0].heading_rad, d.errors.declination_rad);
    let mut r = Run {
        rms_rad: 0.0,
        beyond_3: 0,
        rows: 0,
        max_z: 0.0,
        true_north_rows: 0,
        position_rows: 0,
        courses: 0,
    };
    let mut sq = 0.0;
    for (s, t) in samples.iter().zip(&d.truth) {
        let e = nav.update(s).unwrap();
        let reference = if e.status.gnss_frame {
            // Published magnetic with the declination the fixes' place gave.
            t.heading_rad - nav.gnss_declination_rad().unwrap()
        } else if e.status.heading_absolute {
            t.heading_rad - decl
        } else {
            t.heading_rad - psi0
        };
        let err = angle_diff(e.heading.rad(), reference);
        sq += err * err;
        r.rows += 1;
        let z = err.abs() / e.heading_sigma_rad;
        r.beyond_3 += usize::from(z > 3.0);
        r.max_z = r.max_z.max(z);
        r.true_north_rows += usize::from(e.status.gnss_frame);
        r.position_rows += usize::from(e.status.position_known);
    }
    r.rms_rad = (sq / r.rows as f64).sqrt();
    r.courses = nav.gnss_counts().used;
    r
}

/// Held on every drive: the heading referred to true north by the courses, no row with a
/// position, no worse than the same drive without its fixes by more than a tenth, and
/// heading beyond 3σ on at most 2 % of rows, never beyond 6σ, over each kind's drives.
#[test]
fn courses_refer_and_correct_the_heading_of_a_vehicle_without_odometry() {
    let kind = VehicleKind::RearWheelCar;
    let (mut rows, mut beyond, mut max_z) = (0, 0, 0.0f64);
    let (mut with_sq, mut without_sq) = (0.0, 0.0);
    for seed in 0..10 {
        let d = LogDrive::new(LogDriveConfig::new(seed, kind, SensorSet::GYRO_COMPASS).with_gnss())
            .unwrap();
        let samples = d.vehicle_samples();
        let stripped: Vec<VehicleSample> = samples
            .iter()
            .map(|s| VehicleSample { gnss: None, ..*s })
            .collect();
        let with = run(&d, &samples);
        let without = run(&d, &stripped);
        println!(
            "{kind:?} seed {seed}: heading RMS {:.2}° with the courses ({} used), {:.2}° without; beyond 3σ {:.2} % (without {:.2} %), max {:.2}σ ({:.2}σ); true north on {:.0} % of rows",
            with.rms_rad.to_degrees(),
            with.courses,
            without.rms_rad.to_degrees(),
            100.0 * with.beyond_3 as f64 / with.rows as f64,
            100.0 * without.beyond_3 as f64 / without.rows as f64,
            with.max_z,
            without.max_z,
            100.0 * with.true_north_rows as f64 / with.rows as f64,
        );
        assert!(
            with.courses > 0 && with.true_north_rows > 0,
            "{kind:?} seed {seed}"
        );
        assert_eq!(with.position_rows, 0, "{kind:?} seed {seed}");
        rows += with.rows;
        beyond += with.beyond_3;
        max_z = max_z.max(with.max_z);
        with_sq += with.rms_rad.powi(2);
        without_sq += without.rms_rad.powi(2);
    }
    let (with_rms, without_rms) = ((with_sq / 10.0).sqrt(), (without_sq / 10.0).sqrt());
    let share = beyond as f64 / rows as f64;
    println!(
        "{kind:?}: heading RMS {:.2}° with the courses, {:.2}° without; beyond 3σ {:.2} %, max {max_z:.2}σ",
        with_rms.to_degrees(),
        without_rms.to_degrees(),
        100.0 * share
    );
    assert!(with_rms <= 1.1 * without_rms, "{kind:?}");
    assert!(share <= 0.02, "{kind:?}: {:.2} % beyond 3σ", 100.0 * share);
    assert!(max_z < 6.0, "{kind:?}: {max_z:.2}σ");
}

/// A car whose wheels start reading 30 s into the drive, after its fixes' courses referred
/// the heading: no position until the next fix after the wheels start, then the track on
/// the fixes' plane, within a few metres of the truth and within its 3σ at that fix.
#[test]
fn wheels_that_start_late_join_the_plane_at_the_next_fix() {
    use truenorth_geomag::LocalTangentPlane;
    for seed in 0..3 {
        let d = LogDrive::new(
            LogDriveConfig::new(
                seed,
                VehicleKind::RearWheelCar,
                SensorSet::WHEELS_GYRO.with_compass(),
            )
            .with_gnss(),
        )
        .unwrap();
        let t0 = d.truth[0].t_s;
        let samples: Vec<VehicleSample> = d
            .vehicle_samples()
            .iter()
            .map(|s| VehicleSample {
                wheels: s.wheels.filter(|_| s.t_s - t0 >= 30.0),
                ..*s
            })
            .collect();
        let mut nav = estimator(&d);
        let truth_plane = d.plane.unwrap();
        let mut placed_at = None;
        for (k, (s, t)) in samples.iter().zip(&d.truth).enumerate() {
            let e = nav.update(s).unwrap();
            if s.t_s - t0 < 30.0 {
                assert!(!e.status.position_known, "seed {seed} row {k}");
                continue;
            }
            if !e.status.position_known {
                assert!(placed_at.is_none(), "seed {seed}: a placed track lost");
                continue;
            }
            assert!(e.status.gnss_frame, "seed {seed} row {k}");
            if placed_at.is_none() {
                let (lat, lon) = nav.gnss_origin().unwrap();
                let ours = LocalTangentPlane::new(lat, lon, 0.0).unwrap();
                let g = ours.to_geodetic(e.north_m, e.east_m, 0.0).unwrap();
                let [n, east, _] = truth_plane.from_geodetic(&g);
                let off = (n - t.north_m).hypot(east - t.east_m);
                let sigma = e.position_cov_m2.trace().sqrt();
                println!(
                    "seed {seed}: the track joined the plane at {:.1} s, {off:.2} m from the truth (σ {sigma:.2} m)",
                    s.t_s - t0
                );
                assert!(
                    s.t_s - t0 < 32.0,
                    "seed {seed}: joined at {:.1} s",
                    s.t_s - t0
                );
                assert!(off < 3.0 * sigma, "seed {seed}: {off:.2} m, σ {sigma:.2} m");
                placed_at = Some(k);
            }
        }
        assert!(placed_at.is_some(), "seed {seed}: never placed");
    }
}
