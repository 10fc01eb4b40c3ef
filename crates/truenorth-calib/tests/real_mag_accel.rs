//! The joint magnetometer + accelerometer calibration on real recordings (../shared/data):
//! the field-norm spread against the magnetometer-only ellipsoid, and, on the sunsided
//! recordings, the tilt-compensated heading of the static poses and of the single-axis
//! turns under the calibration fitted to the full-sphere recording. Each test prints what
//! it measured; the README's figures are asserted by `readme_figure`.

mod common;
mod recordings;

use common::circular_std;

use nalgebra::Vector3;
use recordings::{read_rows, readme_figure, recording, rel_std};
use truenorth_accel::static_tilt;
use truenorth_calib::{
    EllipsoidConfig, MagAccelCalibration, MagAccelConfig, MagAccelSample, fit_ellipsoid,
    fit_mag_accel,
};
use truenorth_compass::{CompassCalibration3d, tilt_compensated_heading};
use truenorth_core::{EulerZyx, Tilt, angle_diff};

/// A magnetometer reading with the accelerometer and gyro interpolated to its time.
#[derive(Debug, Clone, Copy)]
struct Merged {
    mag: Vector3<f64>,
    /// Specific force in body axes x forward, y right, z down, g.
    acc: Vector3<f64>,
    /// |gyro| less the recording's static bias, degrees/s.
    gyro_dps: f64,
    /// Time, s.
    t_s: f64,
    /// Angular rate less the static bias, body axes x forward, y right, z down, rad/s.
    gyro_rps: Vector3<f64>,
}

/// Gyro bias of the MPU6050 at rest, degrees/s (the recordings' README: +4.5 on x, +1.1 on
/// z).
const GYRO_BIAS_DPS: [f64; 3] = [4.5, 0.0, 1.1];

/// A sunsided recording, each magnetometer sample with the IMU interpolated linearly to its
/// time (samples with no IMU sample within 50 ms on both sides are dropped). The
/// accelerometer reports gravity in axes x forward, y left, z up (the recordings' README):
/// negated it is the specific force, and (x, −y, −z) takes it to x forward, y right, z
/// down. The magnetometer gets the same axis change; its own axes are not documented, and
/// the joint calibration finds its rotation whatever it is.
fn sunsided(rec: &str) -> Option<Vec<Merged>> {
    let dir = recording("magcal_sunsided_mpu6050_hmc5883l")?.join(rec);
    let mag = read_rows(&dir.join("mag.csv.gz"));
    let imu = read_rows(&dir.join("imu.csv.gz"));
    let frd = |v: Vector3<f64>| Vector3::new(v.x, -v.y, -v.z);
    let mut out = Vec::new();
    let mut j = 0;
    for m in &mag {
        let t = m[0];
        while j + 1 < imu.len() && imu[j + 1][0] < t {
            j += 1;
        }
        if j + 1 >= imu.len() || imu[j][0] > t {
            continue;
        }
        let (a, b) = (&imu[j], &imu[j + 1]);
        if t - a[0] > 0.05 || b[0] - t > 0.05 {
            continue;
        }
        let w = (t - a[0]) / (b[0] - a[0]);
        let lerp = |k: usize| a[k] + w * (b[k] - a[k]);
        let g = Vector3::new(lerp(1), lerp(2), lerp(3));
        let gyr = Vector3::new(
            lerp(4) - GYRO_BIAS_DPS[0],
            lerp(5) - GYRO_BIAS_DPS[1],
            lerp(6) - GYRO_BIAS_DPS[2],
        );
        // The gyro's x axis counts clockwise (the recordings' README): negated, the rates
        // are right-handed in x forward, y left, z up.
        let rate_flu = Vector3::new(-gyr.x, gyr.y, gyr.z);
        out.push(Merged {
            mag: frd(Vector3::new(m[1], m[2], m[3])),
            acc: frd(-g),
            gyro_dps: gyr.norm(),
            t_s: t,
            gyro_rps: frd(rate_flu).map(f64::to_radians),
        });
    }
    Some(out)
}

/// The quasi-static readings: turning slower than `max_dps` and with |a| within 3 % of the
/// recording's median (so that the accelerometer senses gravity alone).
fn quasi_static(v: &[Merged], max_dps: f64) -> Vec<Merged> {
    let mut norms: Vec<f64> = v.iter().map(|m| m.acc.norm()).collect();
    norms.sort_by(f64::total_cmp);
    let median = norms[norms.len() / 2];
    v.iter()
        .filter(|m| m.gyro_dps < max_dps && (m.acc.norm() / median - 1.0).abs() < 0.03)
        .copied()
        .collect()
}

fn samples(v: &[Merged]) -> Vec<MagAccelSample> {
    v.iter()
        .enumerate()
        .map(|(k, m)| MagAccelSample {
            t_s: k as f64,
            mag: m.mag,
            acc: m.acc,
        })
        .collect()
}

fn norm_spread(mags: &[Vector3<f64>], cal: &CompassCalibration3d) -> f64 {
    rel_std(mags.iter().map(|m| cal.correct(m).norm()))
}

/// Turning slower than this, degrees/s, a hand-held reading counts as quasi-static for the
/// joint fit (with |a| within 3 % of g): a judgement that keeps a fifth of the full-sphere
/// recording (1824 of 8175 readings) and its centripetal accelerations under about 1 %.
const QUASI_STATIC_DPS: f64 = 30.0;

/// The full-sphere calibrations: the magnetometer-only ellipsoid on every reading, and the
/// joint one on the quasi-static readings.
fn full_sphere() -> Option<(CompassCalibration3d, MagAccelCalibration, Vec<Merged>)> {
    full_sphere_with_quality().map(|(e, j, _, all)| (e, j, all))
}

/// [`full_sphere`] with the joint fit's report.
fn full_sphere_with_quality() -> Option<(
    CompassCalibration3d,
    MagAccelCalibration,
    truenorth_calib::MagAccelQuality,
    Vec<Merged>,
)> {
    let all = sunsided("full-sphere")?;
    let mags: Vec<Vector3<f64>> = all.iter().map(|m| m.mag).collect();
    let ellipsoid = fit_ellipsoid(&mags, &EllipsoidConfig::default())
        .unwrap()
        .params;
    let still = quasi_static(&all, QUASI_STATIC_DPS);
    let joint = fit_mag_accel(&samples(&still), &MagAccelConfig::default()).unwrap();
    let q = joint.quality;
    println!(
        "full-sphere ellipsoid-accel: {} quasi-static readings of {}; dip {:.2} deg, spread {:.2} deg; alignment {:.2} deg; accelerometer residual {:.2} %; {} runs; bound {:.2} deg; verdict {}",
        still.len(),
        all.len(),
        q.dip_deg,
        q.dip_spread_deg,
        q.alignment_deg,
        100.0 * q.accel_residual_rms_rel,
        q.runs,
        q.mag.heading_error_bound_deg(),
        truenorth_calib::quality::Verdict::of(&q.mag).grade,
    );
    readme_figure(
        "full-sphere dip spread",
        q.dip_spread_deg,
        1.29,
        0.005,
        still.len(),
    );
    Some((ellipsoid, joint.params, q, all))
}

/// The heading error of a calibration on a recording, against the gyro: the attitude is
/// propagated by the gyro from the first reading's (TRIAD of the calibrated accelerometer
/// and magnetometer), and the heading of the body x axis by the compass is compared with
/// the propagated one, after removing the best constant offset and drift (the gyro's
/// residual bias). Returns the RMS of what remains, degrees, over readings with the x axis
/// within 60° of level.
fn gyro_referenced_rms(v: &[Merged], attitude: &dyn Fn(&Merged) -> Option<(f64, Tilt)>) -> f64 {
    use nalgebra::UnitQuaternion;
    let Some((h0, t0)) = attitude(&v[0]) else {
        return f64::NAN;
    };
    let mut q = EulerZyx {
        yaw_rad: h0,
        pitch_rad: t0.pitch_rad,
        roll_rad: t0.roll_rad,
    }
    .to_quaternion();
    let mut pts = Vec::new();
    for w in v.windows(2) {
        let dt = w[1].t_s - w[0].t_s;
        let rate = (w[0].gyro_rps + w[1].gyro_rps) * 0.5;
        q *= UnitQuaternion::from_scaled_axis(rate * dt);
        let e = EulerZyx::from_quaternion(&q);
        if let Some((h, t)) = attitude(&w[1])
            && t.pitch_rad.abs() < 60f64.to_radians()
            && e.pitch_rad.abs() < 60f64.to_radians()
        {
            pts.push((w[1].t_s, angle_diff(h, e.yaw_rad)));
        }
    }
    // Least squares of d = a + b t.
    let n = pts.len() as f64;
    let (st, sd) = pts
        .iter()
        .fold((0.0, 0.0), |(a, b), &(t, d)| (a + t, b + d));
    let (mt, md) = (st / n, sd / n);
    let (stt, std_) = pts.iter().fold((0.0, 0.0), |(a, b), &(t, d)| {
        (a + (t - mt) * (t - mt), b + (t - mt) * (d - md))
    });
    let slope = std_ / stt;
    (pts.iter()
        .map(|&(t, d)| (d - md - slope * (t - mt)).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
        .to_degrees()
}

/// The field-norm spread (relative standard deviation of |B| over every reading) after the
/// magnetometer-only ellipsoid and after the joint calibration, on the recordings that have
/// both sensors. (The Python sample has no accelerometer: `real_data.rs` holds its
/// ellipsoid figure.)
#[test]
fn field_norm_spread_of_ellipsoid_and_ellipsoid_accel() {
    if let Some((ell, joint, all)) = full_sphere() {
        let mags: Vec<Vector3<f64>> = all.iter().map(|m| m.mag).collect();
        let (e, j) = (norm_spread(&mags, &ell), norm_spread(&mags, &joint.mag));
        println!(
            "sunsided full-sphere, {} readings: |B| spread ellipsoid {:.3} %, ellipsoid-accel {:.3} %",
            mags.len(),
            100.0 * e,
            100.0 * j
        );
        readme_figure(
            "sunsided ellipsoid-accel spread",
            100.0 * j,
            0.56,
            0.005,
            mags.len(),
        );
    }
    let Some(dir) = recording("magcal_ck_explorer") else {
        return;
    };
    let rows = read_rows(&dir.join("acc_mag_log.csv"));
    let s: Vec<MagAccelSample> = rows
        .iter()
        .enumerate()
        .map(|(k, r)| MagAccelSample {
            t_s: k as f64,
            mag: Vector3::new(r[3], r[4], r[5]),
            acc: Vector3::new(r[0], r[1], r[2]),
        })
        .collect();
    let mags: Vec<Vector3<f64>> = s.iter().map(|m| m.mag).collect();
    let ell = fit_ellipsoid(&mags, &EllipsoidConfig::default())
        .unwrap()
        .params;
    let joint = fit_mag_accel(&s, &MagAccelConfig::default()).unwrap();
    let (e, j) = (
        norm_spread(&mags, &ell),
        norm_spread(&mags, &joint.params.mag),
    );
    let q = joint.quality;
    println!(
        "ck_explorer, {} readings: |B| spread ellipsoid {:.3} %, ellipsoid-accel {:.3} %; dip {:.2} deg, spread {:.2} deg; alignment {:.2} deg",
        mags.len(),
        100.0 * e,
        100.0 * j,
        q.dip_deg,
        q.dip_spread_deg,
        q.alignment_deg
    );
    readme_figure(
        "ck_explorer ellipsoid-accel spread",
        100.0 * j,
        1.26,
        0.005,
        mags.len(),
    );
}

/// The nominal static poses (x forward and level; z forward with x up; z forward with y —
/// the sensor's left — down), the heading steadiness while the sensor rolls about its
/// forward x axis, and the heading of turns against the gyro, under the full-sphere
/// calibrations. There is no orientation reference: the poses are checked for their tilt,
/// and reported for where their forward axis points.
#[test]
fn sunsided_tilt_compensated_heading() {
    let Some((ell, joint, joint_quality, _)) = full_sphere_with_quality() else {
        return;
    };
    let mean = |v: &[Merged]| {
        let n = v.len() as f64;
        (
            v.iter().map(|m| m.mag).sum::<Vector3<f64>>() / n,
            v.iter().map(|m| m.acc).sum::<Vector3<f64>>() / n,
        )
    };
    // (recording, nominal pitch and roll, the body axis pointing forward: the sensor's z,
    // which is −z in x forward, y right, z down)
    let poses = [
        ("unmoved-with-x-pointing-forward", 0.0, 0.0, Vector3::x()),
        (
            "unmoved-with-x-pointing-forward-10min",
            0.0,
            0.0,
            Vector3::x(),
        ),
        (
            "unmoved-with-z-pointing-front-and-x-up",
            90.0,
            f64::NAN,
            -Vector3::z(),
        ),
        (
            "unmoved-with-z-pointing-front-and-y-down",
            0.0,
            -90.0,
            -Vector3::z(),
        ),
    ];
    let mut azimuths = Vec::new();
    for (rec, pitch, roll, front) in poses {
        let Some(v) = sunsided(rec) else { return };
        let (m, a) = mean(&v);
        let (h, t) = joint.attitude(&m, &a).unwrap();
        // The forward axis's azimuth from the whole attitude (the heading of x is undefined
        // when x points up).
        let q = EulerZyx {
            yaw_rad: h.rad(),
            pitch_rad: t.pitch_rad,
            roll_rad: t.roll_rad,
        }
        .to_quaternion();
        let f = q * front;
        println!(
            "{rec}: pitch {:.2} deg, roll {:.2} deg, forward axis azimuth {:.1} deg",
            t.pitch_rad.to_degrees(),
            t.roll_rad.to_degrees(),
            f.y.atan2(f.x).to_degrees().rem_euclid(360.0)
        );
        azimuths.push(f.y.atan2(f.x));
        // A hand places a sensor "level" or "up" to a few degrees.
        assert!((t.pitch_rad.to_degrees() - pitch).abs() < 5.0, "{rec}");
        if roll.is_finite() {
            assert!(
                angle_diff(t.roll_rad, roll.to_radians()).abs() < 5f64.to_radians(),
                "{rec}"
            );
        }
    }
    type Attitude<'a> = Box<dyn Fn(&Merged) -> Option<(f64, Tilt)> + 'a>;
    // The forward axes' spread: the largest difference between two poses.
    let spread = azimuths
        .iter()
        .flat_map(|a| azimuths.iter().map(move |b| angle_diff(*a, *b).abs()))
        .fold(0.0, f64::max)
        .to_degrees();
    // The spread is the largest difference between two of the hand-placed poses: a
    // property of how they were placed, which the calibration moves by at most its own
    // heading bound at each of the two poses. The README's figure holds within that (an RMS
    // rule over four values would allow twice it).
    let bound = joint_quality.mag.heading_error_bound_deg();
    println!(
        "forward axes of the static poses within {spread:.1} deg of each other (calibration bound {bound:.2} deg)"
    );
    let limit = 19.0 + 0.05 + 2.0 * bound;
    assert!(
        spread <= limit,
        "static poses' spread {spread} over {limit}"
    );
    let methods: [(&str, Attitude); 2] = [
        (
            "ellipsoid + raw accelerometer",
            Box::new(|m: &Merged| {
                let t = static_tilt(&m.acc).ok()?;
                Some((tilt_compensated_heading(&ell.correct(&m.mag), &t), t))
            }),
        ),
        (
            "ellipsoid-accel",
            Box::new(|m: &Merged| {
                joint
                    .attitude(&m.mag, &m.acc)
                    .ok()
                    .map(|(h, t)| (h.rad(), t))
            }),
        ),
    ];
    let mut level_turn = [0.0; 2];
    // README figures per method: steadiness of x while rolling, the level turn and the roll
    // against the gyro (RMS over turns of 20-25 s whose errors hang together over about a
    // second: 25 independent draws).
    let quoted = [[7.0, 9.1, 8.8], [6.3, 4.0, 8.2]];
    for (k, (name, attitude)) in methods.iter().enumerate() {
        let Some(roll) = sunsided("rotate-ccw-around-x-pointing-forward") else {
            return;
        };
        let headings: Vec<f64> = roll
            .iter()
            .filter_map(attitude)
            .filter(|(_, t)| t.pitch_rad.abs() < 60f64.to_radians())
            .map(|(h, _)| h)
            .collect();
        let steadiness = circular_std(&headings).to_degrees();
        readme_figure(name, steadiness, quoted[k][0], 0.05, 25);
        let mut line = format!(
            "{name}: heading of x while rolling about it: circular std {steadiness:.2} deg ({} readings);",
            headings.len()
        );
        for rec in [
            "rotate-ccw-around-z-pointing-up",
            "rotate-ccw-around-x-pointing-forward",
        ] {
            let Some(v) = sunsided(rec) else { return };
            let rms = gyro_referenced_rms(&v, attitude.as_ref());
            line += &format!(" {rec} against the gyro: RMS {rms:.2} deg;");
            let j = if rec.contains("z-pointing-up") { 1 } else { 2 };
            readme_figure(name, rms, quoted[k][j], 0.05, 25);
            if j == 1 {
                level_turn[k] = rms;
            }
        }
        println!("{line}");
    }
    // A level turn with the sensor a few degrees off level: the aligned calibration reads
    // it better than the magnetometer ellipsoid with the raw accelerometer. The RMS is
    // taken over a 25-second turn whose errors hang together over about a second: 25
    // independent draws for the README rule.
    assert!(level_turn[1] < level_turn[0], "{level_turn:?}");
    readme_figure(
        "level turn against the gyro, ellipsoid-accel",
        level_turn[1],
        4.0,
        0.005,
        25,
    );
}
