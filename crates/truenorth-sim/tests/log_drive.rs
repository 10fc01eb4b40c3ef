//! Drives as real logs come ([`LogDrive`]): each habit measured from the rows, as one would
//! measure it on a real log, against what the configuration says.

use std::f64::consts::PI;

use truenorth_sim::{
    LogDrive, LogDriveConfig, LogRow, Odometry, OdometryReading, RowLayout, SensorSet, Span,
    VehicleKind, VehicleTruth, simulate,
};

/// The truth at 1 kHz, to be read between its samples.
struct Dense {
    truth: Vec<VehicleTruth>,
    start_s: f64,
}

impl Dense {
    fn new(d: &LogDrive) -> Self {
        Self {
            truth: simulate(&d.route, d.heading0_rad, 1000.0).unwrap(),
            start_s: d.config.timing.start_s,
        }
    }

    /// `f` of the truth at `t_s` on the log's clock, linearly between the 1 ms samples.
    fn at(&self, t_s: f64, f: impl Fn(&VehicleTruth) -> f64) -> Option<f64> {
        let x = (t_s - self.start_s) * 1000.0;
        let k = x.floor();
        let (a, b) = (self.truth.get(k as usize)?, self.truth.get(k as usize + 1)?);
        (k >= 0.0).then(|| f(a) + (x - k) * (f(b) - f(a)))
    }
}

/// The delay, s, by which `readings` (stamp, value) follow `quantity` of the truth: the shift
/// in whole milliseconds up to 400 ms whose least-squares fit `value = a·truth(stamp − τ) + b`
/// leaves the smallest residual.
fn delay_s(
    dense: &Dense,
    readings: &[(f64, f64)],
    quantity: impl Fn(&VehicleTruth) -> f64 + Copy,
) -> f64 {
    let residual = |tau: f64| {
        let pairs: Vec<(f64, f64)> = readings
            .iter()
            .filter_map(|&(t, y)| Some((dense.at(t - tau, quantity)?, y)))
            .collect();
        let n = pairs.len() as f64;
        let (mx, my) = pairs
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let (sxx, sxy, syy) = pairs.iter().fold((0.0, 0.0, 0.0), |(a, b, c), (x, y)| {
            (
                a + (x - mx) * (x - mx),
                b + (x - mx) * (y - my),
                c + (y - my) * (y - my),
            )
        });
        syy - sxy * sxy / sxx
    };
    (0..=400)
        .map(|ms| f64::from(ms) * 1e-3)
        .min_by(|a, b| residual(*a).total_cmp(&residual(*b)))
        .unwrap()
}

fn gyro_readings(d: &LogDrive) -> Vec<(f64, f64)> {
    d.rows
        .iter()
        .filter_map(|r| Some((r.t_s, r.gyr_z_rps?)))
        .collect()
}

fn speed_readings(d: &LogDrive) -> Vec<(f64, f64)> {
    d.rows
        .iter()
        .filter_map(|r| match r.odometry {
            Some(OdometryReading::VehicleSpeed(v)) => Some((r.t_s, v)),
            _ => None,
        })
        .collect()
}

/// The rests of a drive's route: (start, length), s.
fn rests(d: &LogDrive) -> Vec<(f64, f64)> {
    let (mut t, mut v) = (0.0, d.route.start_speed_mps);
    let mut out = Vec::new();
    for c in &d.route.commands {
        if v == 0.0 && c.accel_mps2 == 0.0 && c.pivot_rate_rps == 0.0 {
            out.push((t, c.duration_s));
        }
        t += c.duration_s;
        v = (v + c.accel_mps2 * c.duration_s).max(0.0);
    }
    out
}

#[test]
fn drives_start_in_motion_and_rest_rarely_and_briefly() {
    for kind in VehicleKind::ALL {
        for seed in 0..3 {
            let d = LogDrive::new(LogDriveConfig::new(seed, kind, SensorSet::WHEELS_GYRO)).unwrap();
            // In motion at the first row.
            assert!(d.truth[0].speed_mps > 0.2, "{kind:?} {:?}", d.truth[0]);
            let rests = rests(&d);
            let first = if kind.is_car() { 120.0 } else { 60.0 };
            let duration = d.route.duration_s();
            let resting: f64 = rests.iter().map(|r| r.1).sum();
            for &(start, length) in &rests {
                assert!(
                    start >= first && length <= 5.0,
                    "{kind:?}: rest {length} s at {start} s"
                );
            }
            for w in rests.windows(2) {
                assert!(
                    w[1].0 - (w[0].0 + w[0].1) >= first - 1e-9,
                    "{kind:?}: rests {w:?}"
                );
            }
            // Rare: a few per cent of the time at most.
            assert!(
                resting < 0.06 * duration,
                "{kind:?}: {resting} s of {duration} s at rest"
            );
        }
    }
    // A robot like the real one: at rest a few per cent of the time, at some point.
    let d = LogDrive::new(LogDriveConfig {
        motion: truenorth_sim::MotionConfig {
            length_m: 360.0,
            ..truenorth_sim::MotionConfig::for_robot()
        },
        ..LogDriveConfig::real_skid_steer(4)
    })
    .unwrap();
    let resting: f64 = rests(&d).iter().map(|r| r.1).sum();
    let share = resting / d.route.duration_s();
    assert!((0.005..0.06).contains(&share), "{share}");
}

#[test]
fn the_old_habits_remain_on_request() {
    let mut c = LogDriveConfig::new(1, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
    c.motion.start_in_motion = false;
    c.motion.end_in_motion = false;
    c.motion.length_m = 400.0;
    c.motion.rests = None;
    let d = LogDrive::new(c).unwrap();
    assert_eq!(d.truth[0].speed_mps, 0.0);
    assert_eq!(d.route.start_speed_mps, 0.0);
    assert_eq!(d.route.commands.last().unwrap().accel_mps2, 0.0);
    assert_eq!(
        rests(&d).len(),
        2,
        "the standstills at the start and the end only"
    );
}

/// The gyro's rows follow the motion by the gyro's latency, the speed's by its latency and
/// the lag of its filter: measured from the rows by the shift that fits the truth best. The
/// drives are long enough to turn through several corners (a drive of one highway stretch
/// carries too little yaw for the shift to be found), and the cars' filters short against
/// their accelerations (for a robot's lag of 0.3 s the best shift falls short of it; its
/// filter is measured on its own below).
#[test]
fn sensors_arrive_late_by_their_latency_and_50_to_150_ms_apart() {
    for seed in 0..2 {
        let mut c = LogDriveConfig::new(seed, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
        c.motion.length_m = 3000.0;
        c.timing.gyro.rate_hz = Span::fixed(20.0);
        c.timing.odometry.rate_hz = Span::fixed(20.0);
        let d = LogDrive::new(c).unwrap();
        let dense = Dense::new(&d);
        let e = &d.errors;
        let gyro = delay_s(&dense, &gyro_readings(&d), |t| t.yaw_rate_rps);
        let speed = delay_s(&dense, &speed_readings(&d), |t| t.speed_mps);
        // The gyro: its latency and half its 5 ms jitter.
        let expect_gyro = e.gyro_clock.latency_s + 0.0025;
        assert!(
            (gyro - expect_gyro).abs() <= 0.004,
            "gyro {gyro} vs {expect_gyro}"
        );
        // The speed: from its loop step to its stamp (latency, jitter and the wait for the
        // odometry's clock), half a loop step (the step's mean speed), and the lag of the
        // filter as the loop runs it, `dt·q/(1 − q)` with `q = exp(−dt/τ)` (τ − dt/2 for a
        // lag of many steps).
        let sent: Vec<f64> = d
            .rows
            .iter()
            .zip(&d.measured)
            .filter_map(|(r, m)| Some(r.t_s - m.odometry_s?))
            .collect();
        let waited = sent.iter().sum::<f64>() / sent.len() as f64;
        let (dt, q) = (0.01, (-0.01 / e.wheel_lag_s).exp());
        let expect_speed = waited + 0.5 * dt + dt * q / (1.0 - q);
        assert!(
            (speed - expect_speed).abs() <= 0.004,
            "speed {speed} vs {expect_speed}"
        );
        let apart = speed - e.wheel_lag_s - gyro;
        assert!((0.045..=0.16).contains(&apart), "{apart}");
        // The truth records the instant behind every reading.
        for (r, m) in d.rows.iter().zip(&d.measured) {
            if let Some(g) = m.gyro_s {
                let late = r.t_s - g;
                let c = &e.gyro_clock;
                assert!(late >= c.latency_s - 5e-4 && late <= c.latency_s + c.jitter_s + 5e-4);
            }
            if let Some(o) = m.odometry_s {
                assert!(r.t_s - o >= e.odometry_clock.latency_s - 5e-4);
            }
        }
    }
}

/// The time constant of a first-order lag, measured as one measures it on a log: the
/// regression through the origin of `input − output` on the output's rate of change
/// (`τ·ẏ = x − y`).
#[test]
fn a_controller_s_speeds_lag_by_its_filter() {
    for lag in [0.05, 0.25] {
        let mut c = LogDriveConfig::new(3, VehicleKind::SkidSteer, SensorSet::WHEEL_SPEEDS);
        c.motion.length_m = 150.0;
        c.timing.odometry = truenorth_sim::SensorTiming {
            rate_hz: Span::fixed(50.0),
            latency_s: Span::fixed(0.0),
            jitter_s: 0.0,
            drop_probability: Span::fixed(0.0),
        };
        c.wheels.lag_s = Span::fixed(lag);
        c.wheels.speed_quantum_mps = 0.0;
        let d = LogDrive::new(c).unwrap();
        let dense = Dense::new(&d);
        // Each reading with the controller's loop step it comes from.
        let readings: Vec<(f64, f64)> = d
            .rows
            .iter()
            .zip(&d.measured)
            .filter_map(|(r, m)| match r.odometry {
                Some(OdometryReading::WheelSpeeds([l, r2])) => {
                    Some((m.odometry_s?, 0.5 * (l + r2)))
                }
                _ => None,
            })
            .collect();
        let scale = d.mean_wheel_scale();
        let (mut sxy, mut sxx) = (0.0, 0.0);
        for w in readings.windows(3) {
            let rate = (w[2].1 - w[0].1) / (w[2].0 - w[0].0);
            if rate.abs() > 0.05 {
                // The input: the wheels' mean speed over the controller's 10 ms loop step.
                let input = scale * dense.at(w[1].0 - 0.005, |t| t.speed_mps).unwrap();
                sxy += (input - w[1].1) * rate;
                sxx += rate * rate;
            }
        }
        // The loop's zero-order hold shortens the lag by half a step (5 ms).
        let tau = sxy / sxx;
        assert!((tau - (lag - 0.005)).abs() <= 0.003, "{tau} for {lag}");
    }
}

#[test]
fn readings_come_in_their_quanta() {
    let mut c = LogDriveConfig::new(
        5,
        VehicleKind::FrontWheelCar,
        SensorSet::FOUR_WHEEL_SPEEDS_GYRO,
    );
    c.motion.length_m = 800.0;
    let d = LogDrive::new(c).unwrap();
    let whole = |x: f64, q: f64| ((x / q) - (x / q).round()).abs() < 1e-6;
    let kmh = 0.01 / 3.6;
    let mut speeds = Vec::new();
    for r in &d.rows {
        if let Some(OdometryReading::FourWheelSpeeds(v)) = r.odometry {
            assert!(v.iter().all(|x| whole(*x, kmh)), "{v:?}");
            speeds.push(v[2]);
        }
        if let Some(g) = r.gyr_z_rps {
            assert!(whole(g, 0.01f64.to_radians()), "{g}");
        }
    }
    // The smallest change between two readings is one quantum: 0.01 km/h.
    let step = speeds
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 1e-9)
        .fold(f64::MAX, f64::min);
    assert!((step - kmh).abs() < 1e-9, "{step}");
    // Distances in whole pulses, a distance counter in centimetres.
    for (set, tick) in [
        (SensorSet::WHEELS, d.errors.rear.dist_per_pulse_m.unwrap()),
        (SensorSet::DISTANCE_YAW, 0.01),
    ] {
        let d = LogDrive::new(LogDriveConfig { sensors: set, ..c }).unwrap();
        for r in &d.rows {
            match r.odometry {
                Some(OdometryReading::WheelDistances([l, rr])) => {
                    assert!(whole(l, tick) && whole(rr, tick), "{l} {rr} {tick}")
                }
                Some(OdometryReading::VehicleDistance(x)) => assert!(whole(x, tick), "{x}"),
                _ => {}
            }
        }
    }
}

#[test]
fn every_sensor_set_gives_its_columns_on_rows_of_their_own() {
    for kind in VehicleKind::ALL {
        for sensors in SensorSet::every(kind) {
            let mut c = LogDriveConfig::new(2, kind, sensors);
            c.motion.length_m = if kind.is_car() { 300.0 } else { 30.0 };
            let d = LogDrive::new(c).unwrap();
            let header = d.to_csv().lines().next().unwrap().to_string();
            let expect_odometry = match sensors.odometry {
                Odometry::None => "",
                Odometry::VehicleSpeed => ",speed_mps",
                Odometry::VehicleDistance => ",dist_m",
                Odometry::WheelDistances => ",dist_l_m,dist_r_m",
                Odometry::WheelSpeeds => ",speed_l_mps,speed_r_mps",
                Odometry::FourWheelSpeeds => ",speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps",
            };
            let expect = format!(
                "t_s{expect_odometry}{}{}",
                if sensors.gyro { ",gyr_z" } else { "" },
                if sensors.compass { ",mag_x,mag_y" } else { "" }
            );
            assert_eq!(header, expect, "{kind:?} {sensors:?}");
            assert_eq!(d.truth.len(), d.rows.len());
            assert!(d.rows.windows(2).all(|w| w[1].t_s > w[0].t_s));
            let mut shared = 0;
            for (r, m) in d.rows.iter().zip(&d.measured) {
                let n = usize::from(r.odometry.is_some())
                    + usize::from(r.gyr_z_rps.is_some())
                    + usize::from(r.mag.is_some());
                assert!(n >= 1);
                shared += usize::from(n > 1);
                assert_eq!(r.odometry.is_some(), m.odometry_s.is_some());
                assert_eq!(r.gyr_z_rps.is_some(), m.gyro_s.is_some());
                assert_eq!(r.mag.is_some(), m.compass_s.is_some());
                for at in [m.odometry_s, m.gyro_s, m.compass_s].into_iter().flatten() {
                    assert!(at < r.t_s, "measured at {at}, stamped {}", r.t_s);
                }
            }
            // Sensors on rows of their own: a row shared only where two stamps meet in the
            // same millisecond (a few per cent of the rows with a 100 Hz gyro).
            assert!(
                shared * 10 <= d.rows.len(),
                "{kind:?} {sensors:?}: {shared} shared"
            );
            assert_eq!(d.vehicle_samples().len(), d.rows.len());
        }
    }
}

#[test]
fn a_logger_writes_rows_on_its_own_clock() {
    let mut c = LogDriveConfig::real_can_car(6);
    c.motion.length_m = 500.0;
    c.timing.rows = RowLayout::Logger { rate_hz: 5.0 };
    let d = LogDrive::new(c).unwrap();
    let steps: Vec<f64> = d.rows.windows(2).map(|w| w[1].t_s - w[0].t_s).collect();
    // Whole logger steps (0.2 s; 0.4 s where a reading was lost or late).
    assert!(
        steps
            .iter()
            .all(|s| ((s * 5.0) - (s * 5.0).round()).abs() < 1e-6),
        "{steps:?}"
    );
    assert!(steps.iter().filter(|s| **s > 0.3).count() * 20 < steps.len());
    let both = d
        .rows
        .iter()
        .filter(|r| r.odometry.is_some() && r.gyr_z_rps.is_some())
        .count();
    assert!(
        both > d.rows.len() / 2,
        "a 5 Hz speed and yaw rate share most rows: {both}"
    );
}

/// The skid-steer's sides see its turns χ times over, χ changing with the ground and the
/// turn; straight, they agree but for their scale difference.
#[test]
fn a_skid_steer_s_effective_track_changes_with_the_ground() {
    let mut c = LogDriveConfig::real_skid_steer(8);
    c.motion.length_m = 400.0;
    let d = LogDrive::new(c).unwrap();
    let dense = Dense::new(&d);
    let track = d.vehicle.wheels.track_m();
    assert_eq!(track, 0.57);
    let ground = d.ground.as_ref().unwrap();
    let wheels: Vec<(f64, [f64; 2])> = d
        .rows
        .iter()
        .zip(&d.measured)
        .filter_map(|(r, m)| match r.odometry {
            Some(OdometryReading::WheelDistances(w)) => Some((m.odometry_s?, w)),
            _ => None,
        })
        .collect();
    let (mut ratios, mut model) = (Vec::new(), Vec::new());
    let rear = d.errors.rear;
    let tick = rear.dist_per_pulse_m.unwrap();
    for w in wheels.windows(11) {
        let ((t0, a), (t1, b)) = (w[0], w[10]);
        let turned = dense.at(t1, |t| t.heading_unwrapped_rad).unwrap()
            - dense.at(t0, |t| t.heading_unwrapped_rad).unwrap();
        let moved =
            dense.at(t1, |t| t.distance_m).unwrap() - dense.at(t0, |t| t.distance_m).unwrap();
        let sides = ((b[0] - a[0]) - (b[1] - a[1])) / track;
        if turned.abs() > 20f64.to_radians() {
            ratios.push(sides / turned);
            let mid = 0.5 * (t0 + t1);
            let radius = moved / turned.abs();
            let speed = moved / (t1 - t0);
            let dist = dense.at(mid, |t| t.distance_m).unwrap();
            model.push(ground.factor(dist, radius, speed * turned.abs() / (t1 - t0)));
        } else if turned.abs() < 0.1f64.to_radians() && moved > 0.5 {
            let diff = (b[0] - a[0]) - (b[1] - a[1]);
            let allowed = 2.0 * tick
                + (rear.scale_error_l - rear.scale_error_r).abs() * moved
                + 0.1f64.to_radians() * 2.4 * track;
            assert!(
                diff.abs() <= allowed,
                "straight, yet the sides differ by {diff} m"
            );
        }
    }
    assert!(ratios.len() > 50, "{}", ratios.len());
    let (lo, hi) = ratios
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), r| (a.min(*r), b.max(*r)));
    assert!(lo > 1.1 && hi < 3.3 && hi / lo > 1.2, "χ from {lo} to {hi}");
    // The measured χ follows the model's (the wander and the scale errors aside).
    let rel: Vec<f64> = ratios
        .iter()
        .zip(&model)
        .map(|(r, m)| r / m - 1.0)
        .collect();
    let rms = (rel.iter().map(|x| x * x).sum::<f64>() / rel.len() as f64).sqrt();
    assert!(rms < 0.08, "{rms}");
}

#[test]
fn a_circling_car_circles_from_the_first_row() {
    for seed in 0..4 {
        let d = LogDrive::new(LogDriveConfig::real_circling_car(seed)).unwrap();
        let (first, last) = (d.truth[0], *d.truth.last().unwrap());
        assert!(
            first.speed_mps > 2.0 && first.yaw_rate_rps.abs() > 0.1,
            "{first:?}"
        );
        let turned = (last.heading_unwrapped_rad - first.heading_unwrapped_rad).abs();
        assert!((turned - 6.0 * PI).abs() < 0.2, "{}", turned.to_degrees());
        let period = 2.0 * PI / first.yaw_rate_rps.abs();
        assert!((9.0..32.0).contains(&period), "{period}");
        assert!(d.rows.iter().all(|r| r.odometry.is_none()));
    }
}

#[test]
fn a_sensor_s_rows_do_not_depend_on_the_other_sensors() {
    let c = LogDriveConfig::new(9, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
    let c = LogDriveConfig {
        motion: truenorth_sim::MotionConfig {
            length_m: 500.0,
            ..c.motion
        },
        ..c
    };
    let a = LogDrive::new(c).unwrap();
    let b = LogDrive::new(LogDriveConfig {
        sensors: SensorSet::GYRO_COMPASS,
        ..c
    })
    .unwrap();
    assert_eq!(a.route, b.route);
    assert_eq!(a.errors.yaw_rate, b.errors.yaw_rate);
    let gyro = |d: &LogDrive| -> Vec<(f64, f64)> { gyro_readings(d) };
    assert_eq!(gyro(&a), gyro(&b));
    assert_eq!(a.rows, LogDrive::new(c).unwrap().rows);
    assert_ne!(
        a.rows,
        LogDrive::new(LogDriveConfig { seed: 10, ..c })
            .unwrap()
            .rows
    );
}

#[test]
fn the_csv_reads_back_to_the_rows() {
    let mut c = LogDriveConfig::new(
        4,
        VehicleKind::SkidSteer,
        SensorSet::WHEELS_GYRO.with_compass(),
    );
    c.motion.length_m = 20.0;
    c.timing.start_s = 1_700_000_000.0;
    let d = LogDrive::new(c).unwrap();
    let csv = d.to_csv();
    for (line, row) in csv.lines().skip(1).zip(&d.rows) {
        let cells: Vec<Option<f64>> = line
            .split(',')
            .map(|c| (!c.is_empty()).then(|| c.parse().unwrap()))
            .collect();
        let back = LogRow {
            t_s: cells[0].unwrap(),
            odometry: cells[1]
                .zip(cells[2])
                .map(|(l, r)| OdometryReading::WheelDistances([l, r])),
            gyr_z_rps: cells[3],
            mag: cells[4]
                .zip(cells[5])
                .map(|(x, y)| nalgebra::Vector2::new(x, y)),
            gnss: None,
        };
        assert_eq!(&back, row);
    }
    assert!(d.rows[0].t_s > 1.7e9);
}

/// Each habit can be left out alone, and leaving it out removes what it does.
#[test]
fn each_habit_can_be_left_out() {
    use truenorth_sim::Habit;
    let mut base = LogDriveConfig::new(12, VehicleKind::SkidSteer, SensorSet::SPEED_YAW);
    base.motion.length_m = 150.0;
    let with = LogDrive::new(base).unwrap();
    for habit in Habit::ALL {
        let d = LogDrive::new(base.without(habit)).unwrap();
        let e = &d.errors;
        let speeds = speed_readings(&d);
        match habit {
            Habit::InMotion => assert_eq!(d.truth[0].speed_mps, 0.0),
            Habit::RareRests => {
                let (now, before) = (rests(&d), rests(&with));
                assert!(
                    now.len() > before.len() && now[0].0 < 60.0,
                    "{now:?} {before:?}"
                );
            }
            Habit::OwnClocks => assert_eq!(e.gyro_clock.rate_hz, e.odometry_clock.rate_hz),
            Habit::Latency => {
                for (r, m) in d.rows.iter().zip(&d.measured) {
                    if let Some(g) = m.gyro_s {
                        assert!((r.t_s - g).abs() <= 5e-4);
                    }
                }
            }
            Habit::Drops => {
                let c = e.gyro_clock;
                let expect = c.instants(d.route.duration_s()).len();
                assert_eq!(gyro_readings(&d).len(), expect);
            }
            Habit::WheelLag => assert_eq!(e.wheel_lag_s, 0.0),
            Habit::Quanta => {
                let q = 0.001;
                assert!(
                    speeds
                        .iter()
                        .any(|(_, v)| ((v / q) - (v / q).round()).abs() > 1e-3)
                );
            }
            Habit::YawScale => assert_eq!(e.yaw_rate.gain(true), e.yaw_rate.tilt_rad.cos()),
            Habit::Tilt => assert_eq!(e.yaw_rate.tilt_rad, 0.0),
            Habit::VaryingTrack => assert_eq!(d.ground.as_ref().unwrap().patches.len(), 1),
            // The GNSS habits, measured in the GNSS tests.
            _ => assert!(d.gnss.is_none()),
        }
    }
    // Without their own clocks and latency, the sensors share every row, as a simulator
    // that samples them together writes them.
    let d = LogDrive::new(base.without(Habit::OwnClocks).without(Habit::Latency)).unwrap();
    let both = d
        .rows
        .iter()
        .filter(|r| r.odometry.is_some() && r.gyr_z_rps.is_some())
        .count();
    assert!(both * 10 >= d.rows.len() * 9, "{both} of {}", d.rows.len());
}
