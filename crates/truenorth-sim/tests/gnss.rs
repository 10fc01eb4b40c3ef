//! The simulated GNSS receiver, measured from its fixes as one would measure a real one
//! against a reference: the error's spread and correlation time, how honest its reported σ
//! is, outages, multipath jumps, frozen and late fixes, the course at walking speed, the
//! lever arm.

use truenorth_sim::{
    FixCondition, GnssConfig, GnssFix, GnssTruth, Habit, LogDrive, LogDriveConfig, SensorSet, Span,
    VehicleKind, simulate_at,
};

/// A car with a speed, a yaw rate and a receiver, `length_m` of road.
fn car(seed: u64, length_m: f64, gnss: GnssConfig) -> LogDriveConfig {
    let mut c = LogDriveConfig::new(seed, VehicleKind::RearWheelCar, SensorSet::SPEED_YAW);
    c.motion.length_m = length_m;
    c.gnss = Some(gnss);
    c
}

/// A receiver in the open: no outages, canyons, frozen or late fixes.
fn open_sky() -> GnssConfig {
    GnssConfig {
        outages: None,
        canyons: None,
        frozen: None,
        late: None,
        ..GnssConfig::for_car()
    }
}

fn fixes(d: &LogDrive) -> Vec<(f64, GnssFix, GnssTruth)> {
    d.rows
        .iter()
        .zip(&d.measured)
        .filter_map(|(r, m)| Some((r.t_s, r.gnss?, m.gnss?)))
        .collect()
}

/// The error is a Gauss–Markov process: its spread is its σ and its autocorrelation falls
/// as `exp(−lag/τ)`, not at once as white noise's would.
#[test]
fn the_error_is_time_correlated_with_its_sigma_and_correlation_time() {
    let gnss = GnssConfig {
        sigma_m: Span::fixed(2.0),
        tau_s: Span::fixed(10.0),
        white_m: Span::fixed(0.2),
        timing: truenorth_sim::SensorTiming {
            rate_hz: Span::fixed(1.0),
            drop_probability: Span::fixed(0.0),
            ..GnssConfig::for_car().timing
        },
        ..open_sky()
    };
    let (mut var, mut n) = (0.0, 0.0);
    let mut corr = [0.0; 3];
    for seed in 0..3 {
        let d = LogDrive::new(car(seed, 8000.0, gnss)).unwrap();
        let e: Vec<f64> = fixes(&d).iter().map(|f| f.2.error_ne_m[0]).collect();
        for (k, lag) in [1usize, 5, 20].iter().enumerate() {
            corr[k] += e.windows(lag + 1).map(|w| w[0] * w[*lag]).sum::<f64>();
        }
        var += e.iter().map(|x| x * x).sum::<f64>();
        n += e.len() as f64;
    }
    let sd = (var / n).sqrt();
    let expect = 2.0f64.hypot(0.2);
    // Some 150 correlation times: the spread within 15 %.
    assert!((sd / expect - 1.0).abs() < 0.15, "{sd} vs {expect}");
    for (k, lag) in [1.0f64, 5.0, 20.0].iter().enumerate() {
        let rho = corr[k] / var;
        let model = (-lag / 10.0).exp() * 4.0 / (4.0 + 0.04);
        assert!((rho - model).abs() < 0.12, "lag {lag}: {rho} vs {model}");
    }
}

/// In the open the reported σ is the error's, times the receiver's honesty (0.7–1.4).
#[test]
fn the_reported_sigma_is_roughly_honest_in_the_open() {
    let mut ratios = Vec::new();
    for seed in 0..6 {
        let d = LogDrive::new(car(seed, 3000.0, open_sky())).unwrap();
        let g = d.gnss.as_ref().unwrap();
        let f = fixes(&d);
        let mean_sq = f
            .iter()
            .map(|(_, fix, t)| {
                let s = fix.sigma_m.unwrap();
                (t.error_ne_m[0].powi(2) + t.error_ne_m[1].powi(2)) / (2.0 * s * s)
            })
            .sum::<f64>()
            / f.len() as f64;
        // The error over the reported σ, squared, per axis: 1/honesty² in expectation, the
        // drive holding only a few correlation times of it.
        ratios.push(mean_sq * g.sigma_honesty.powi(2));
        assert!((0.7..=1.4).contains(&g.sigma_honesty));
    }
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!((0.5..1.6).contains(&mean), "{ratios:?}");
}

/// Outages leave gaps as long as they are; in canyons multipath jumps of tens of metres
/// come that the reported σ does not cover; frozen fixes repeat the last.
#[test]
fn outages_multipath_and_frozen_fixes_are_what_they_say() {
    let mut gnss = GnssConfig::for_car();
    if let Some(c) = &mut gnss.canyons {
        c.episodes.mean_gap_s = 60.0;
    }
    if let Some(o) = &mut gnss.outages {
        o.mean_gap_s = 120.0;
    }
    if let Some(f) = &mut gnss.frozen {
        f.mean_gap_s = 60.0;
    }
    let d = LogDrive::new(car(4, 6000.0, gnss)).unwrap();
    let g = d.gnss.as_ref().unwrap();
    let f = fixes(&d);
    assert!(!g.outages.is_empty() && !g.jumps.is_empty() && !g.frozen.is_empty());
    let start = d.config.timing.start_s;
    for &(a, b) in &g.outages {
        // No fix measured inside an outage, and the gap in the epochs spans it.
        assert!(
            f.iter()
                .all(|x| x.2.epoch_s - start < a || x.2.epoch_s - start >= b)
        );
        if b < d.route.duration_s() - 1.0 {
            let before = f
                .iter()
                .rev()
                .find(|x| x.2.epoch_s - start < a)
                .unwrap()
                .2
                .epoch_s;
            let after = f
                .iter()
                .find(|x| x.2.epoch_s - start >= b)
                .unwrap()
                .2
                .epoch_s;
            assert!(after - before >= b - a, "{a}..{b}: {before}..{after}");
        }
    }
    let jumps: Vec<f64> = f
        .iter()
        .filter(|x| x.2.condition == FixCondition::Multipath)
        .map(|x| x.2.error_ne_m[0].hypot(x.2.error_ne_m[1]) / x.1.sigma_m.unwrap())
        .collect();
    assert!(!jumps.is_empty());
    // Tens of metres against a σ of metres: most far beyond 3σ.
    let beyond = jumps.iter().filter(|s| **s > 3.0).count();
    assert!(beyond * 2 > jumps.len(), "{beyond} of {}", jumps.len());
    let mut frozen = 0;
    for w in f.windows(2) {
        if w[1].2.condition == FixCondition::Frozen {
            assert_eq!(w[1].1, w[0].1);
            frozen += 1;
        }
    }
    assert!(frozen > 0);
}

#[test]
fn some_fixes_arrive_seconds_late() {
    let mut gnss = open_sky();
    gnss.late = Some(truenorth_sim::LateFixes {
        share: Span::fixed(0.05),
        extra_s: Span::new(0.5, 2.0),
    });
    let d = LogDrive::new(car(5, 2000.0, gnss)).unwrap();
    let clock = d.gnss.as_ref().unwrap().clock;
    let delays: Vec<f64> = fixes(&d).iter().map(|x| x.0 - x.2.epoch_s).collect();
    let usual = clock.latency_s + clock.jitter_s + 5e-4;
    // A late fix holds up the ones behind it, as a stalled receiver or logger does: count
    // the stalls, the late fixes whose predecessor was on time.
    let late: Vec<bool> = delays.iter().map(|x| *x > usual + 0.4).collect();
    let stalls = late.windows(2).filter(|w| w[1] && !w[0]).count();
    let n = delays.len();
    assert!(stalls * 100 > n && stalls * 10 < n, "{stalls} of {n}");
    assert!(
        delays
            .iter()
            .all(|x| *x >= clock.latency_s - 5e-4 && *x < usual + 2.0)
    );
}

/// The course is the noisy velocity's direction: its error is the velocity noise over the
/// speed (σ_v/v rad), a degree at driving speed, noise at walking speed.
#[test]
fn the_course_is_noise_at_walking_speed() {
    // (course error, σ_v/v in degrees) of every fix while moving.
    let errors = |kind: VehicleKind, length_m: f64| {
        let mut c = LogDriveConfig::new(6, kind, SensorSet::SPEED_YAW).with_gnss();
        c.motion.length_m = length_m;
        c.gnss = c.gnss.map(|g| GnssConfig {
            lever_forward_m: Span::fixed(0.0),
            lever_right_m: Span::fixed(0.0),
            velocity_noise_mps: Span::fixed(0.15),
            ..g
        });
        let d = LogDrive::new(c).unwrap();
        let f = fixes(&d);
        let epochs: Vec<f64> = f.iter().map(|x| x.2.epoch_s).collect();
        let truth = simulate_at(&d.route, d.heading0_rad, &epochs).unwrap();
        f.iter()
            .zip(&truth)
            .filter(|(x, t)| t.speed_mps > 0.0 && x.2.condition != FixCondition::Frozen)
            .map(|(x, t)| {
                let e = x.1.course_deg.unwrap() - t.heading_rad.to_degrees();
                (
                    (e + 540.0).rem_euclid(360.0) - 180.0,
                    (0.15 / t.speed_mps).to_degrees(),
                )
            })
            .collect::<Vec<(f64, f64)>>()
    };
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let car = errors(VehicleKind::RearWheelCar, 2000.0);
    let fast: Vec<f64> = car
        .iter()
        .filter(|e| e.1 < 3.0)
        .map(|e| e.0 / e.1)
        .collect();
    let normalised = rms(&fast);
    assert!((0.8..1.25).contains(&normalised), "{normalised}");
    let at_speed: Vec<f64> = car.iter().filter(|e| e.1 < 1.0).map(|e| e.0).collect();
    assert!(rms(&at_speed) < 1.0, "{}°", rms(&at_speed));
    let robot: Vec<f64> = errors(VehicleKind::Differential, 60.0)
        .iter()
        .map(|e| e.0)
        .collect();
    assert!(rms(&robot) > 5.0, "{}°", rms(&robot));
}

/// With no error at all, a fix is the antenna: the rear-axle centre plus the lever arm
/// turned with the heading, to the 10⁻⁷° of a reported latitude (1 cm).
#[test]
fn a_perfect_fix_is_the_antenna_on_its_lever_arm() {
    let gnss = GnssConfig {
        sigma_m: Span::fixed(0.0),
        white_m: Span::fixed(0.0),
        lever_forward_m: Span::fixed(1.5),
        lever_right_m: Span::fixed(-0.2),
        ..open_sky()
    };
    let d = LogDrive::new(car(7, 1500.0, gnss)).unwrap();
    let plane = d.plane.unwrap();
    let f = fixes(&d);
    let epochs: Vec<f64> = f.iter().map(|x| x.2.epoch_s).collect();
    let truth = simulate_at(&d.route, d.heading0_rad, &epochs).unwrap();
    for ((_, fix, t), s) in f.iter().zip(&truth) {
        let g = truenorth_geomag::Geodetic::from_degrees(fix.lat_deg, fix.lon_deg, 74.0).unwrap();
        let [n, e, _] = plane.from_geodetic(&g);
        let (sin, cos) = s.heading_rad.sin_cos();
        let antenna = [
            s.north_m + 1.5 * cos + 0.2 * sin,
            s.east_m + 1.5 * sin - 0.2 * cos,
        ];
        assert!((n - antenna[0]).abs() < 0.01 && (e - antenna[1]).abs() < 0.01);
        assert!(t.error_ne_m[0].abs() < 0.01 && t.error_ne_m[1].abs() < 0.01);
        assert!((t.antenna_ne_m[0] - antenna[0]).abs() < 1e-9);
        assert!((t.antenna_ne_m[1] - antenna[1]).abs() < 1e-9);
    }
}

/// With a receiver the drive is somewhere: the compass sees the World Magnetic Model's
/// declination there, and the CSV carries the fixes' columns.
#[test]
fn a_drive_with_a_receiver_is_somewhere() {
    let d = LogDrive::new(car(8, 300.0, GnssConfig::for_car())).unwrap();
    let o = GnssConfig::for_car().origin;
    let wmm = truenorth_geomag::field_at_deg(o.lat_deg, o.lon_deg, o.height_m / 1e3, 2026.0)
        .unwrap()
        .declination_deg();
    assert!((d.errors.declination_rad.to_degrees() - wmm).abs() < 1e-12);
    assert!(wmm > 3.0, "Berlin's declination is east: {wmm}");
    let header = d.to_csv().lines().next().unwrap().to_string();
    assert_eq!(
        header,
        "t_s,speed_mps,gyr_z,lat_deg,lon_deg,gnss_sigma_m,gnss_speed_mps,gnss_course_deg"
    );
    let f = fixes(&d);
    assert!(
        f.iter()
            .all(|x| ((x.1.lat_deg * 1e7) - (x.1.lat_deg * 1e7).round()).abs() < 1e-6)
    );
    // Without a receiver the compass keeps declination 0.
    let mut c = car(8, 300.0, GnssConfig::for_car());
    c.gnss = None;
    assert_eq!(LogDrive::new(c).unwrap().errors.declination_rad, 0.0);
}

#[test]
fn each_gnss_habit_can_be_left_out() {
    let base = car(9, 3000.0, GnssConfig::for_car());
    for habit in [
        Habit::GnssOutages,
        Habit::GnssCanyons,
        Habit::GnssFrozen,
        Habit::GnssLate,
        Habit::GnssCorrelation,
        Habit::LeverArm,
    ] {
        let d = LogDrive::new(base.without(habit)).unwrap();
        let g = d.gnss.as_ref().unwrap();
        match habit {
            Habit::GnssOutages => assert!(g.outages.is_empty()),
            Habit::GnssCanyons => assert!(g.canyons.is_empty() && g.jumps.is_empty()),
            Habit::GnssFrozen => assert!(g.frozen.is_empty()),
            Habit::GnssLate => assert_eq!(g.late_share, 0.0),
            Habit::GnssCorrelation => assert_eq!(g.tau_s, 0.01),
            _ => assert_eq!(g.lever_arm_m, [0.0, 0.0]),
        }
    }
}

#[test]
fn bad_receivers_are_refused() {
    for bad in [
        GnssConfig {
            sigma_m: Span::new(2.0, 1.0),
            ..GnssConfig::for_car()
        },
        GnssConfig {
            year: 2040.0,
            ..GnssConfig::for_car()
        },
        GnssConfig {
            origin: truenorth_sim::Origin {
                lat_deg: f64::NAN,
                ..GnssConfig::for_car().origin
            },
            ..GnssConfig::for_car()
        },
    ] {
        assert!(LogDrive::new(car(1, 200.0, bad)).is_err());
    }
}
