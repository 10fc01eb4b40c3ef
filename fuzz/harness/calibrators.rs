//! Every calibrator behind the CLI's registry: samples pushed one at a time, progress asked
//! on the way, solved at the end, as `calibrate` runs them.

use truenorth::calib::{MagAccelSample, TurnSample};
use truenorth::core::{Calibrator, Mag2Sample, Mag3Sample};
use truenorth::nalgebra::{Vector2, Vector3};
use truenorth_cli::registry::{CalibrationMethod, CompassCalibrator};

use super::input::Bytes;

/// The most samples one input feeds (enough for every method to solve).
const MAX_SAMPLES: usize = 4000;

/// The methods, by the first byte.
const METHODS: [CalibrationMethod; 8] = [
    CalibrationMethod::Ellipse,
    CalibrationMethod::Ellipsoid,
    CalibrationMethod::EllipsoidAccel,
    CalibrationMethod::OnlineEllipse,
    CalibrationMethod::OnlineEllipsoid,
    CalibrationMethod::BinnedEllipse,
    CalibrationMethod::MeritCircle,
    CalibrationMethod::Turn,
];

/// A field seen by a sensor turning about: a centre, radii and a direction that the bytes
/// move, with the bytes' own values put in its place now and then.
struct Field {
    centre: Vector3<f64>,
    radii: Vector3<f64>,
    yaw: f64,
    pitch: f64,
    t_s: f64,
}

impl Field {
    fn new(b: &mut Bytes) -> Self {
        Self {
            centre: Vector3::new(b.f64(20.0), b.f64(20.0), b.f64(20.0)),
            radii: Vector3::new(b.f64(50.0), b.f64(50.0), b.f64(50.0)),
            yaw: 0.0,
            pitch: 0.0,
            t_s: 0.0,
        }
    }

    /// The next reading (time, magnetometer, accelerometer, yaw rate).
    fn next(&mut self, b: &mut Bytes) -> (f64, Vector3<f64>, Vector3<f64>, f64) {
        self.t_s = b.time(self.t_s, 0.01);
        let kind = b.byte();
        let step = f64::from(kind >> 2) * 0.01;
        self.yaw += step;
        if kind & 2 != 0 {
            self.pitch += step * 0.37;
        }
        let dir = Vector3::new(
            self.yaw.cos() * self.pitch.cos(),
            -self.yaw.sin() * self.pitch.cos(),
            self.pitch.sin(),
        );
        let mut mag = self.centre + self.radii.component_mul(&dir);
        let mut acc = Vector3::new(-self.pitch.sin(), 0.0, -self.pitch.cos()) * 9.81;
        let mut rate = step * 100.0;
        if kind & 1 != 0 {
            // The bytes' own values, hostile ones included.
            match b.byte() % 4 {
                0 => mag = Vector3::new(b.f64(100.0), b.f64(100.0), b.f64(100.0)),
                1 => acc = Vector3::new(b.f64(20.0), b.f64(20.0), b.f64(20.0)),
                2 => rate = b.f64(10.0),
                _ => mag.x += b.f64(1.0),
            }
        }
        (self.t_s, mag, acc, rate)
    }
}

/// One calibrator per input: the first byte picks the method and whether an expected field
/// is given, the next the field, then the samples.
pub fn calibrators(data: &[u8]) {
    let mut b = Bytes::new(data);
    let pick = b.byte();
    let method = METHODS[usize::from(pick) % METHODS.len()];
    let expected = (pick & 0x80 != 0).then(|| b.f64(50.0));
    let Ok(calibrator) = method.calibrator(expected) else {
        return;
    };
    let mut field = Field::new(&mut b);
    let mut samples =
        std::iter::from_fn(|| (!b.is_empty()).then(|| field.next(&mut b))).take(MAX_SAMPLES);
    match calibrator {
        CompassCalibrator::Planar(mut c) => {
            for (t, m, _, _) in &mut samples {
                drive(&mut *c, &Mag2Sample::new(t, m.x, m.y));
            }
            finish(&*c);
        }
        CompassCalibrator::Spatial(mut c) => {
            for (t, m, _, _) in &mut samples {
                drive(&mut *c, &Mag3Sample::new(t, m.x, m.y, m.z));
            }
            finish(&*c);
        }
        CompassCalibrator::MagAccel(mut c) => {
            for (t_s, mag, acc, _) in &mut samples {
                drive(&mut *c, &MagAccelSample { t_s, mag, acc });
            }
            finish(&*c);
        }
        CompassCalibrator::Turn {
            mut compass,
            mut with_gyro,
        } => {
            for (t_s, m, _, gyr_z_rps) in &mut samples {
                drive(&mut *compass, &Mag2Sample::new(t_s, m.x, m.y));
                let s = TurnSample {
                    t_s,
                    gyr_z_rps,
                    mag: Vector2::new(m.x, m.y),
                };
                drive(&mut *with_gyro, &s);
            }
            finish(&*compass);
            finish(&*with_gyro);
        }
    }
}

/// One push, and what the calibrator says of its progress after it.
fn drive<C: Calibrator + ?Sized>(c: &mut C, s: &C::Sample) {
    let _ = c.push(s);
    let _ = c.progress();
}

/// The solve, which must agree with what progress promised.
fn finish<C: Calibrator + ?Sized>(c: &C) {
    let ready = c.progress().ready;
    let solved = c.solve();
    assert_eq!(
        ready,
        solved.is_ok(),
        "progress().ready is true exactly when solve() succeeds"
    );
}
