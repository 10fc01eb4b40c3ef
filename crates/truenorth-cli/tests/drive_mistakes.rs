//! Eleven mistakes a user makes writing a drive log or its vehicle file, each named by
//! `truenorth drive` for what it is, with the file, the row where the evidence is and the fix.

mod common;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use common::scratch;
use truenorth_sim::{DriveSpec, SimulatedDrive};

/// How a log is spoiled.
#[derive(Clone, Copy, Default)]
struct Spoil {
    gyro: f64,
    wheels: [f64; 2],
    swap: bool,
    speeds: bool,
    /// The compass's y axis negated, or its two axes swapped.
    mag: Option<Mirror>,
}

/// How a compass is mirrored.
#[derive(Clone, Copy)]
enum Mirror {
    NegatedY,
    Swapped,
}

fn honest() -> Spoil {
    Spoil {
        gyro: 1.0,
        wheels: [1.0, 1.0],
        ..Spoil::default()
    }
}

fn sim() -> SimulatedDrive {
    SimulatedDrive::new(DriveSpec {
        length_m: 3000.0,
        ..DriveSpec::new(5)
    })
    .unwrap()
}

/// Writes the drive as `spoil` says: wheels as distances (or speeds, m/s before the
/// factor), the gyro times its factor, the compass.
fn write(drive: &SimulatedDrive, path: &Path, spoil: Spoil) {
    let wheels = if spoil.speeds {
        "speed_l_mps,speed_r_mps"
    } else {
        "dist_l_m,dist_r_m"
    };
    let mut s = format!("t_s,{wheels},gyr_z,mag_x,mag_y\n");
    let mut last: Option<(f64, [f64; 2])> = None;
    for x in &drive.samples {
        let (w, m) = (x.wheels.unwrap(), x.mag.unwrap());
        let mut lr = [w.dist_l_m, w.dist_r_m];
        if spoil.speeds {
            let now = lr;
            lr = match last {
                Some((t0, d0)) => [
                    (now[0] - d0[0]) / (x.t_s - t0),
                    (now[1] - d0[1]) / (x.t_s - t0),
                ],
                None => [0.0, 0.0],
            };
            last = Some((x.t_s, now));
        }
        if spoil.swap {
            lr.swap(0, 1);
        }
        let g = x.gyr_z_rps.unwrap() * spoil.gyro;
        let (mx, my) = match spoil.mag {
            None => (m.x, m.y),
            Some(Mirror::NegatedY) => (m.x, -m.y),
            Some(Mirror::Swapped) => (m.y, m.x),
        };
        writeln!(
            s,
            "{},{},{},{g},{},{}",
            x.t_s,
            lr[0] * spoil.wheels[0],
            lr[1] * spoil.wheels[1],
            mx,
            my
        )
        .unwrap();
    }
    std::fs::write(path, s).unwrap();
}

/// Runs `drive` with a vehicle of `track_m`: (success, stderr).
fn drive(dir: &Path, input: &Path, track_m: f64) -> (bool, String) {
    let vehicle = common::rear_vehicle(dir, track_m);
    common::outcome(&common::drive(&vehicle, input, &dir.join("out.csv"), &[]))
}

/// Each mistake is refused with one line naming the log (or the vehicle file), the row
/// where the evidence became clear and the fix; the honest log runs, as distances and as
/// speeds.
#[test]
fn each_mistake_is_named_for_what_it_is() {
    let dir = scratch("drive_mistakes", "sim");
    let sim = sim();
    let speeds = Spoil {
        speeds: true,
        ..honest()
    };
    let cases: Vec<(&str, Spoil, f64, &[&str])> = vec![
        ("honest", honest(), 1.55, &[]),
        ("honest_speeds", speeds, 1.55, &[]),
        (
            "gyro_in_deg_per_s",
            Spoil {
                gyro: 1f64.to_degrees(),
                ..honest()
            },
            1.55,
            &["row ", "in deg/s", "--gyro-unit deg/s"],
        ),
        (
            "gyro_negated",
            Spoil {
                gyro: -1.0,
                ..honest()
            },
            1.55,
            &[
                "row ",
                "sign is flipped",
                "--column gyr_z=-gyr_z",
                "so it is the gyro",
            ],
        ),
        (
            "distances_in_km",
            Spoil {
                wheels: [1e-3, 1e-3],
                ..honest()
            },
            1.55,
            &[
                "row ",
                "distances are in kilometres",
                "multiply them by 1000",
            ],
        ),
        (
            "speeds_in_km_per_h",
            Spoil {
                wheels: [3.6, 3.6],
                ..speeds
            },
            1.55,
            &["row ", "speeds are in km/h", "divide them by 3.6"],
        ),
        (
            "wheels_swapped",
            Spoil {
                swap: true,
                ..honest()
            },
            1.55,
            &[
                "row ",
                "wheels are swapped",
                "--column dist_l_m=dist_r_m,dist_r_m=dist_l_m",
            ],
        ),
        (
            "left_wheel_negated",
            Spoil {
                wheels: [-1.0, 1.0],
                ..honest()
            },
            1.55,
            &[
                "row ",
                "dist_l_m has its sign flipped",
                "--column dist_l_m=-dist_l_m",
            ],
        ),
        (
            "right_wheel_negated",
            Spoil {
                wheels: [1.0, -1.0],
                ..honest()
            },
            1.55,
            &[
                "row ",
                "dist_r_m has its sign flipped",
                "--column dist_r_m=-dist_r_m",
            ],
        ),
        (
            "compass_y_negated",
            Spoil {
                mag: Some(Mirror::NegatedY),
                ..honest()
            },
            1.55,
            &[
                "row ",
                "the compass turns against gyr_z and the wheels",
                "--column mag_y=-mag_y",
            ],
        ),
        (
            "compass_axes_swapped",
            Spoil {
                mag: Some(Mirror::Swapped),
                ..honest()
            },
            1.55,
            &["row ", "mirrored", "mag_x=mag_y,mag_y=mag_x"],
        ),
        (
            "track_of_15_m",
            honest(),
            15.5,
            &["vehicle.json", "`track_m` is 15.5 m, outside 0.05–10 m"],
        ),
        (
            "track_of_4_m",
            honest(),
            4.0,
            &[
                "row ",
                "track_m = 4 m in",
                "vehicle.json",
                "give a track of 1.6",
            ],
        ),
    ];
    for (name, spoil, track, want) in cases {
        let f: PathBuf = dir.join(format!("{name}.csv"));
        write(&sim, &f, spoil);
        let (ran, err) = drive(&dir, &f, track);
        println!("{name}: {}", err.trim());
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        if want.is_empty() {
            assert!(ran, "{name}: {err}");
            continue;
        }
        assert!(!ran, "{name} was accepted: {err}");
        assert!(!err.contains("valid range"), "{name}: {err}");
        for w in want {
            assert!(err.contains(w), "{name}: `{w}` missing from {err}");
        }
        if track < 10.0 {
            assert!(err.contains(&format!("{name}.csv: row ")), "{name}: {err}");
        }
    }
}
