//! A log's rows as the `drive` command reads them (ARCHITECTURE.md, CLI contract): `t_s`,
//! then whichever of the odometry, `gyr_z` and `mag_x,mag_y` the row carries, an empty cell
//! where it carries none.

use core::fmt::Write as _;

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};
use truenorth_core::VehicleSample;

use super::gnss_truth::{GnssFix, GnssTruth};
use crate::VehicleKind;

/// What the odometry gave on a row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum OdometryReading {
    /// The vehicle speed, m/s (`speed_mps`).
    VehicleSpeed(f64),
    /// The cumulative distance, m (`dist_m`).
    VehicleDistance(f64),
    /// The cumulative distances of the odometer wheels or sides, m (`dist_l_m,dist_r_m`).
    WheelDistances([f64; 2]),
    /// The speeds of the odometer wheels or sides, m/s (`speed_l_mps,speed_r_mps`).
    WheelSpeeds([f64; 2]),
    /// The speeds of the four wheels, m/s, front left, front right, rear left, rear right
    /// (`speed_fl_mps,speed_fr_mps,speed_rl_mps,speed_rr_mps`).
    FourWheelSpeeds([f64; 4]),
}

impl OdometryReading {
    /// The CSV columns of this kind of reading.
    pub fn columns(&self) -> &'static [&'static str] {
        match self {
            Self::VehicleSpeed(_) => &["speed_mps"],
            Self::VehicleDistance(_) => &["dist_m"],
            Self::WheelDistances(_) => &["dist_l_m", "dist_r_m"],
            Self::WheelSpeeds(_) => &["speed_l_mps", "speed_r_mps"],
            Self::FourWheelSpeeds(_) => &[
                "speed_fl_mps",
                "speed_fr_mps",
                "speed_rl_mps",
                "speed_rr_mps",
            ],
        }
    }

    /// The values, in the order of [`OdometryReading::columns`].
    pub fn values(&self) -> &[f64] {
        match self {
            Self::VehicleSpeed(v) | Self::VehicleDistance(v) => core::slice::from_ref(v),
            Self::WheelDistances(v) | Self::WheelSpeeds(v) => v,
            Self::FourWheelSpeeds(v) => v,
        }
    }
}

/// One row of a log.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LogRow {
    /// The stamp, s on the log's clock.
    pub t_s: f64,
    /// The odometry's reading, if the row carries one.
    pub odometry: Option<OdometryReading>,
    /// The raw yaw rate, rad/s, positive turning right, if the row carries one.
    pub gyr_z_rps: Option<f64>,
    /// The raw horizontal magnetometer reading, µT, if the row carries one.
    pub mag: Option<Vector2<f64>>,
    /// A GNSS fix, if the row carries one.
    pub gnss: Option<GnssFix>,
}

impl LogRow {
    /// A row at `t_s` with no reading yet.
    pub const fn at(t_s: f64) -> Self {
        Self {
            t_s,
            odometry: None,
            gyr_z_rps: None,
            mag: None,
            gnss: None,
        }
    }
}

/// When each reading on a row was measured (the truth's instant behind it), s on the log's
/// clock; `None` where the row carries no such reading.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Measured {
    /// The odometry's reading (the controller's loop step it comes from).
    pub odometry_s: Option<f64>,
    /// The yaw rate.
    pub gyro_s: Option<f64>,
    /// The gyro's true bias in the row's yaw rate (constant part and random walk), rad/s.
    #[serde(default)]
    pub gyro_bias_rps: Option<f64>,
    /// The compass.
    pub compass_s: Option<f64>,
    /// The truth behind the GNSS fix.
    pub gnss: Option<GnssTruth>,
    /// The body's roll (right side down) and pitch (nose up) under the compass, rad, when
    /// it tilts.
    pub compass_tilt_rad: Option<[f64; 2]>,
    /// By how much the wheels saw the vehicle's turn at the odometry's loop step: a
    /// skid-steer's effective over its physical track (times the wander), `1 +` the tyre
    /// slip of a car.
    pub turn_factor: Option<f64>,
}

/// `rows` as a `DRIVE.csv`: a header of the columns any row carries (`t_s`, the odometry's,
/// `gyr_z`, `mag_x,mag_y`, then `lat_deg,lon_deg,gnss_sigma_m,gnss_speed_mps,gnss_course_deg`
/// as the fixes carry them), then one line per row with an empty cell where the row carries
/// no reading; numbers in the shortest form that reads back to the same `f64`.
pub fn drive_csv(rows: &[LogRow]) -> String {
    let mut odometry: &[&str] = &[];
    let (mut gyro, mut mag, mut fix, mut sigma, mut velocity) = (false, false, false, false, false);
    for r in rows {
        if let Some(o) = r.odometry
            && o.columns().len() > odometry.len()
        {
            odometry = o.columns();
        }
        gyro |= r.gyr_z_rps.is_some();
        mag |= r.mag.is_some();
        if let Some(g) = r.gnss {
            fix = true;
            sigma |= g.sigma_m.is_some();
            velocity |= g.speed_mps.is_some() || g.course_deg.is_some();
        }
    }
    let mut header = vec!["t_s"];
    header.extend_from_slice(odometry);
    if gyro {
        header.push("gyr_z");
    }
    if mag {
        header.extend(["mag_x", "mag_y"]);
    }
    if fix {
        header.extend(["lat_deg", "lon_deg"]);
    }
    if sigma {
        header.push("gnss_sigma_m");
    }
    if velocity {
        header.extend(["gnss_speed_mps", "gnss_course_deg"]);
    }
    let mut out = header.join(",");
    out.push('\n');
    for r in rows {
        let _ = write!(out, "{}", r.t_s);
        let values = r.odometry.as_ref().map_or(&[][..], |o| o.values());
        for k in 0..odometry.len() {
            cell(&mut out, values.get(k).copied());
        }
        if gyro {
            cell(&mut out, r.gyr_z_rps);
        }
        if mag {
            cell(&mut out, r.mag.map(|m| m.x));
            cell(&mut out, r.mag.map(|m| m.y));
        }
        if fix {
            cell(&mut out, r.gnss.map(|g| g.lat_deg));
            cell(&mut out, r.gnss.map(|g| g.lon_deg));
        }
        if sigma {
            cell(&mut out, r.gnss.and_then(|g| g.sigma_m));
        }
        if velocity {
            cell(&mut out, r.gnss.and_then(|g| g.speed_mps));
            cell(&mut out, r.gnss.and_then(|g| g.course_deg));
        }
        out.push('\n');
    }
    out
}

fn cell(out: &mut String, value: Option<f64>) {
    out.push(',');
    if let Some(v) = value {
        let _ = write!(out, "{v}");
    }
}

/// `rows` as the core's samples, one per row, for a vehicle of `kind`: two wheel distances
/// as they are; two wheel speeds integrated by the trapezoid rule from the first speed
/// reading into cumulative distances (as `drive` integrates `speed_l_mps,speed_r_mps`), of
/// four the odometer axle's pair on a car (the front wheels of a front-wheel car, else the
/// rear) and each side's mean on a robot; a vehicle speed integrated the same way, and a
/// single distance as it is, into [`VehicleSample::dist_m`] (a distance with no left and
/// right, which says nothing about turning); the gyro, the compass and the GNSS fix as they
/// are.
pub fn vehicle_samples(rows: &[LogRow], kind: VehicleKind) -> Vec<VehicleSample> {
    let mut pair = Integral::<2>::default();
    let mut single = Integral::<1>::default();
    rows.iter()
        .map(|r| {
            let mut s = VehicleSample::at(r.t_s);
            s.gyr_z_rps = r.gyr_z_rps;
            s.mag = r.mag;
            s.gnss = r.gnss;
            match r.odometry {
                Some(OdometryReading::WheelDistances([l, rr])) => s = s.with_wheels(l, rr),
                Some(OdometryReading::WheelSpeeds(v)) => {
                    let [l, rr] = pair.add(r.t_s, v);
                    s = s.with_wheels(l, rr);
                }
                Some(OdometryReading::FourWheelSpeeds([fl, fr, rl, rr])) => {
                    let v = match kind {
                        VehicleKind::FrontWheelCar => [fl, fr],
                        VehicleKind::RearWheelCar => [rl, rr],
                        _ => [0.5 * (fl + rl), 0.5 * (fr + rr)],
                    };
                    let [l, rr] = pair.add(r.t_s, v);
                    s = s.with_wheels(l, rr);
                }
                Some(OdometryReading::VehicleSpeed(v)) => {
                    s = s.with_distance(single.add(r.t_s, [v])[0]);
                }
                Some(OdometryReading::VehicleDistance(d)) => s = s.with_distance(d),
                None => {}
            }
            s
        })
        .collect()
}

/// Speeds integrated by the trapezoid rule from the first reading.
#[derive(Debug, Clone, Copy)]
struct Integral<const N: usize> {
    last: Option<(f64, [f64; N])>,
    sum: [f64; N],
}

impl<const N: usize> Default for Integral<N> {
    fn default() -> Self {
        Self {
            last: None,
            sum: [0.0; N],
        }
    }
}

impl<const N: usize> Integral<N> {
    /// Adds speeds `v` read at `t_s` and returns the distances so far.
    fn add(&mut self, t_s: f64, v: [f64; N]) -> [f64; N] {
        if let Some((t0, v0)) = self.last {
            let dt = t_s - t0;
            self.sum = core::array::from_fn(|k| self.sum[k] + 0.5 * (v0[k] + v[k]) * dt);
        }
        self.last = Some((t_s, v));
        self.sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_csv_has_the_contract_s_columns_and_empty_cells_where_a_row_has_no_reading() {
        let rows = [
            LogRow {
                gyr_z_rps: Some(0.01),
                ..LogRow::at(0.0)
            },
            LogRow {
                odometry: Some(OdometryReading::WheelDistances([1.5, 1.25])),
                ..LogRow::at(0.05)
            },
            LogRow {
                mag: Some(Vector2::new(20.0, -3.0)),
                ..LogRow::at(0.1)
            },
        ];
        let csv = drive_csv(&rows);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "t_s,dist_l_m,dist_r_m,gyr_z,mag_x,mag_y");
        assert_eq!(lines[1], "0,,,0.01,,");
        assert_eq!(lines[2], "0.05,1.5,1.25,,,");
        assert_eq!(lines[3], "0.1,,,,20,-3");
    }

    #[test]
    fn speeds_become_distances_by_the_trapezoid_rule() {
        let four: Vec<LogRow> = (0..5)
            .map(|k| LogRow {
                odometry: Some(OdometryReading::FourWheelSpeeds([
                    1.0,
                    1.0,
                    2.0,
                    2.0 + k as f64,
                ])),
                ..LogRow::at(k as f64)
            })
            .collect();
        let wheels = |kind| {
            let w = vehicle_samples(&four, kind)[4].wheels.unwrap();
            (w.dist_l_m, w.dist_r_m)
        };
        assert_eq!(wheels(VehicleKind::RearWheelCar), (8.0, 16.0));
        assert_eq!(wheels(VehicleKind::FrontWheelCar), (4.0, 4.0));
        assert_eq!(wheels(VehicleKind::SkidSteer), (6.0, 10.0));
        let speed: Vec<LogRow> = (0..3)
            .map(|k| LogRow {
                odometry: Some(OdometryReading::VehicleSpeed(2.0 * k as f64)),
                ..LogRow::at(0.5 * k as f64)
            })
            .collect();
        let s = vehicle_samples(&speed, VehicleKind::RearWheelCar);
        assert!(s.iter().all(|s| s.wheels.is_none()));
        assert_eq!(s[2].dist_m, Some(2.0));
    }
}
