//! The orientation filters a user would otherwise pick, beside truenorth's quaternion filter,
//! each configured for BROAD's rate (285.714 Hz, dt = 3.5 ms) with the parameters its
//! authors give for it, behind one interface whose attitude is in BROAD's reference frame;
//! and BROAD's trial files (Laidig, Caruso, Cereatti & Seel, *Data* 6(7):72, 2021).
//!
//! Frames. BROAD's reference quaternion turns sensor-axis vectors into ENU with magnetic
//! north (x east, y north, z up), and the readings are in the sensor's own axes with the
//! accelerometer reading +g on the upward axis at rest. Every filter is fed those readings
//! unchanged; only its output is turned into ENU:
//! - truenorth: sensor → NED; ENU = (NED y, NED x, −NED z), `ned_to_enu() * q`.
//! - `ahrs` (Madgwick, Mahony): sensor → the frame of Madgwick's and Mahony's reports, x
//!   along the horizontal field (magnetic north), z up, so y west (NWU); ENU = (−NWU y,
//!   NWU x, NWU z), a quarter turn about z: `q_z(+90°) * q`, as BROAD's example code does.
//! - VQF: sensor → ENU (magnetic north on y) already, the frame BROAD was made for.
//!
//! Heading is not aligned per trial: BROAD's references are already in that frame.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};
use truenorth::core::{ImuSample, OrientationEstimator as _, ned_to_enu};
use truenorth::fusion::{QuaternionFilter, QuaternionFilterConfig};

/// BROAD's sample interval, s (2000/7 Hz).
pub const BROAD_DT_S: f64 = 0.0035;

/// Madgwick's gain β for BROAD: the authors' trial-agnostic good parameter (TAGP), the one
/// value that minimises the mean total RMSE over all 39 trials (BROAD's published results).
pub const MADGWICK_BETA: f64 = 0.12;
/// Mahony's proportional gain Kp for BROAD (BROAD's TAGP), rad/s per unit of error.
pub const MAHONY_KP: f64 = 0.74;
/// Mahony's integral gain Ki for BROAD (BROAD's TAGP).
pub const MAHONY_KI: f64 = 0.0012;

/// One BROAD trial as read from its file.
pub struct Trial {
    /// File name without `.csv.gz`.
    pub name: String,
    /// The IMU samples, sensor axes (rad/s, m/s², µT).
    pub samples: Vec<ImuSample>,
    /// The reference attitude, sensor → ENU with magnetic north; `None` where invalid.
    pub reference: Vec<Option<UnitQuaternion<f64>>>,
    /// Whether the sample belongs to the scored movement phase.
    pub movement: Vec<bool>,
}

/// The trial files of the shared `broad/trials/` folder, sorted; `None` (after a visible
/// skip line) when the recordings are absent outside CI, a panic when absent under CI.
pub fn trial_paths() -> Option<Vec<PathBuf>> {
    let dir = truenorth_sim::shared_data::folder("broad")
        .expect("BROAD recordings present under CI")?
        .join("trials");
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("readable BROAD trials folder")
        .map(|e| e.expect("readable folder entry").path())
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    Some(paths)
}

/// Reads one gzip CSV trial (columns found by name; `NaN` marks an invalid reference).
pub fn read_trial(path: &Path) -> Trial {
    let file = std::fs::File::open(path).expect("readable BROAD trial");
    let mut lines = BufReader::new(flate2::read::GzDecoder::new(file)).lines();
    let header: Vec<String> = lines
        .next()
        .expect("header row")
        .expect("readable header")
        .split(',')
        .map(|c| c.trim().to_string())
        .collect();
    let columns = [
        "t_s", "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z", "mag_x", "mag_y", "mag_z",
        "qw", "qx", "qy", "qz", "movement",
    ]
    .map(|name| {
        header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("column `{name}` in {}", path.display()))
    });
    let mut trial = Trial {
        name: path
            .file_name()
            .map(|n| n.to_string_lossy().replace(".csv.gz", ""))
            .unwrap_or_default(),
        samples: Vec::new(),
        reference: Vec::new(),
        movement: Vec::new(),
    };
    for line in lines {
        let line = line.expect("readable row");
        let cells: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse().expect("numeric cell"))
            .collect();
        let v = columns.map(|c| cells[c]);
        trial.samples.push(ImuSample::new_9d(
            v[0],
            Vector3::new(v[1], v[2], v[3]),
            Vector3::new(v[4], v[5], v[6]),
            Vector3::new(v[7], v[8], v[9]),
        ));
        let q = Quaternion::new(v[10], v[11], v[12], v[13]);
        trial.reference.push(
            (q.coords.iter().all(|x| x.is_finite()) && q.norm() > 0.0)
                .then(|| UnitQuaternion::from_quaternion(q)),
        );
        trial.movement.push(v[14] > 0.5);
    }
    trial
}

/// An orientation filter fed BROAD's samples one by one.
pub trait Peer {
    /// Feeds one sample (its magnetometer ignored by a 6-D filter).
    fn update(&mut self, sample: &ImuSample);
    /// The current attitude, sensor → ENU with magnetic north.
    fn attitude_enu(&self) -> UnitQuaternion<f64>;
}

/// The filters compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// truenorth's quaternion filter, defaults.
    Truenorth,
    /// Madgwick (`ahrs`), β = [`MADGWICK_BETA`].
    Madgwick,
    /// Mahony (`ahrs`), Kp = [`MAHONY_KP`], Ki = [`MAHONY_KI`].
    Mahony,
    /// VQF (`vqf-rs`), defaults.
    Vqf,
}

impl Kind {
    /// Every filter, in table order.
    pub const ALL: [Kind; 4] = [Kind::Truenorth, Kind::Madgwick, Kind::Mahony, Kind::Vqf];

    /// The name in tables: crate and filter.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Truenorth => "truenorth QuaternionFilter",
            Kind::Madgwick => "ahrs Madgwick",
            Kind::Mahony => "ahrs Mahony",
            Kind::Vqf => "vqf-rs VQF",
        }
    }

    /// The filter, 9-D (`use_mag`) or 6-D, started on `first`, the trial's first sample,
    /// as its authors start it.
    pub fn start(self, use_mag: bool, first: &ImuSample) -> Box<dyn Peer> {
        match self {
            Kind::Truenorth => Box::new(Truenorth::new(use_mag)),
            Kind::Madgwick => Box::new(madgwick(use_mag, first)),
            Kind::Mahony => Box::new(mahony(use_mag, first)),
            Kind::Vqf => Box::new(Vqf::new(use_mag)),
        }
    }
}

/// The three triads of a BROAD sample (all present in every row).
fn triads(s: &ImuSample) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let all = "BROAD samples carry all nine axes";
    (
        s.gyr_rps.as_xyz().expect(all),
        s.acc_mps2.as_xyz().expect(all),
        s.mag.as_xyz().expect(all),
    )
}

/// truenorth's quaternion filter with its defaults (as `truenorth eval broad` runs it).
pub struct Truenorth {
    filter: QuaternionFilter,
    attitude_ned: UnitQuaternion<f64>,
}

impl Truenorth {
    /// The default configuration, magnetometer on or off.
    pub fn new(use_mag: bool) -> Self {
        Self::with_sigma(use_mag, true)
    }

    /// The default configuration, magnetometer and σ on or off.
    pub fn with_sigma(use_mag: bool, sigma: bool) -> Self {
        let config = QuaternionFilterConfig {
            use_mag,
            sigma,
            ..QuaternionFilterConfig::default()
        };
        Self {
            filter: QuaternionFilter::new(config).expect("valid default configuration"),
            attitude_ned: UnitQuaternion::identity(),
        }
    }
}

impl Peer for Truenorth {
    fn update(&mut self, sample: &ImuSample) {
        let estimate = self.filter.update(sample).expect("valid BROAD sample");
        self.attitude_ned = estimate.attitude;
    }

    fn attitude_enu(&self) -> UnitQuaternion<f64> {
        ned_to_enu() * self.attitude_ned
    }
}

/// The attitude sensor → NWU (x along the horizontal field, z up) from one accelerometer
/// reading (up) and, in 9-D, one magnetometer reading: BROAD's example code starts
/// Madgwick and Mahony this way (its `quatFromAccMag`). Without a field (6-D) the sensor's
/// x axis, levelled, stands for north (heading is arbitrary in 6-D).
fn nwu_from_acc_mag(acc: Vector3<f64>, mag: Option<Vector3<f64>>) -> UnitQuaternion<f64> {
    let up = acc.normalize();
    let along = mag.unwrap_or_else(Vector3::x);
    let north = (along - up * up.dot(&along)).normalize();
    let west = up.cross(&north);
    // Rows are the NWU axes in sensor coordinates: the matrix turns sensor vectors into NWU.
    let m = Matrix3::from_rows(&[north.transpose(), west.transpose(), up.transpose()]);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m))
}

/// NWU → ENU: a quarter turn about the common vertical.
fn nwu_to_enu() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), core::f64::consts::FRAC_PI_2)
}

/// The start of an `ahrs` filter: NWU from the first sample (its field only in 9-D).
fn ahrs_start(use_mag: bool, first: &ImuSample) -> nalgebra_ahrs::UnitQuaternion<f64> {
    let (_, acc, mag) = triads(first);
    let q = nwu_from_acc_mag(acc, use_mag.then_some(mag));
    nalgebra_ahrs::UnitQuaternion::new_unchecked(nalgebra_ahrs::Quaternion::new(q.w, q.i, q.j, q.k))
}

/// A triad as the `ahrs` crate's nalgebra names it.
fn to_ahrs(v: Vector3<f64>) -> nalgebra_ahrs::Vector3<f64> {
    nalgebra_ahrs::Vector3::new(v.x, v.y, v.z)
}

/// A filter of the `ahrs` crate (Madgwick or Mahony) in 9-D (`update`) or 6-D
/// (`update_imu`).
pub struct AhrsFilter<F> {
    filter: F,
    use_mag: bool,
    attitude_nwu: nalgebra_ahrs::UnitQuaternion<f64>,
}

impl<F> AhrsFilter<F> {
    /// `filter`, built on the attitude `start` (sensor → NWU).
    fn started(filter: F, use_mag: bool, start: nalgebra_ahrs::UnitQuaternion<f64>) -> Self {
        Self {
            filter,
            use_mag,
            attitude_nwu: start,
        }
    }
}

/// Madgwick's gradient-descent filter (Madgwick, Harrison & Vaidyanathan, IEEE ICORR 2011)
/// with β = [`MADGWICK_BETA`], started from the first sample.
pub fn madgwick(use_mag: bool, first: &ImuSample) -> AhrsFilter<ahrs::Madgwick<f64>> {
    let start = ahrs_start(use_mag, first);
    AhrsFilter::started(
        ahrs::Madgwick::new_with_quat(BROAD_DT_S, MADGWICK_BETA, start),
        use_mag,
        start,
    )
}

/// Mahony's explicit complementary filter (Mahony, Hamel & Pflimlin, IEEE Trans. Automatic
/// Control 53(5):1203–1218, 2008) with Kp = [`MAHONY_KP`], Ki = [`MAHONY_KI`], started from
/// the first sample.
pub fn mahony(use_mag: bool, first: &ImuSample) -> AhrsFilter<ahrs::Mahony<f64>> {
    let start = ahrs_start(use_mag, first);
    AhrsFilter::started(
        ahrs::Mahony::new_with_quat(BROAD_DT_S, MAHONY_KP, MAHONY_KI, start),
        use_mag,
        start,
    )
}

impl<F: ahrs::Ahrs<f64>> Peer for AhrsFilter<F> {
    fn update(&mut self, sample: &ImuSample) {
        let (gyr, acc, mag) = triads(sample);
        let (gyr, acc, mag) = (to_ahrs(gyr), to_ahrs(acc), to_ahrs(mag));
        let r = if self.use_mag {
            self.filter.update(&gyr, &acc, &mag).copied()
        } else {
            self.filter.update_imu(&gyr, &acc).copied()
        };
        // A zero accelerometer or field reading is refused; the gyro alone carries on.
        self.attitude_nwu = r.unwrap_or_else(|_| *self.filter.update_gyro(&gyr));
    }

    fn attitude_enu(&self) -> UnitQuaternion<f64> {
        let q = &self.attitude_nwu;
        nwu_to_enu() * UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.i, q.j, q.k))
    }
}

/// VQF (Laidig & Seel, *Information Fusion* 91:187–204, 2023; the `vqf-rs` port of its C++
/// code) with its default parameters (τ_acc 3 s, τ_mag 9 s, rest and motion bias
/// estimation, magnetic disturbance rejection): they are time constants and rates in
/// physical units, so the defaults hold at any sampling rate, the sample time being the only
/// rate input. It starts at identity, as its constructor leaves it, and converges in the
/// opening rest (its first field readings are taken at full weight).
pub struct Vqf {
    filter: vqf_rs::VQF,
    use_mag: bool,
}

impl Vqf {
    /// Default parameters at BROAD's rate, 9-D (field fed) or 6-D (no field).
    pub fn new(use_mag: bool) -> Self {
        Self {
            filter: vqf_rs::VQF::new(BROAD_DT_S, None, None, None),
            use_mag,
        }
    }
}

impl Peer for Vqf {
    fn update(&mut self, sample: &ImuSample) {
        let (gyr, acc, mag) = triads(sample);
        self.filter
            .update(gyr.into(), acc.into(), self.use_mag.then(|| mag.into()));
    }

    fn attitude_enu(&self) -> UnitQuaternion<f64> {
        let q = if self.use_mag {
            self.filter.quat_9d()
        } else {
            self.filter.quat_6d()
        };
        UnitQuaternion::from_quaternion(Quaternion::new(q.0, q.1, q.2, q.3))
    }
}
