//! The demo's scenario table: what each simulated route asks of a navigation system.

use truenorth::core::angle_diff;
use truenorth_sim::{Route, VehicleTruth, scenario, simulate};

use crate::io::outln;
use crate::io::{CliError, CliResult};

/// The calibration circle that opens the demo drive.
pub(super) fn opening_circle() -> truenorth::core::Result<Route> {
    scenario::calibration_circle(12.0, 5.0, 1.25)
}

/// Truth sample rate of the demo, Hz.
pub(super) const RATE_HZ: f64 = 50.0;

/// What a scenario asks of a navigation system.
struct Summary {
    duration_s: f64,
    distance_m: f64,
    turned_deg: f64,
    turns_over_45deg: usize,
    stops: usize,
    max_speed_mps: f64,
}

fn summarise(route: &Route, truth: &[VehicleTruth]) -> Summary {
    let mut turns = 0;
    let mut stops = 0;
    let mut in_turn = 0.0f64;
    let mut moving = false;
    for w in truth.windows(2) {
        let d = angle_diff(w[1].heading_rad, w[0].heading_rad);
        if w[1].curvature_per_m != 0.0 {
            in_turn += d;
        } else if in_turn != 0.0 {
            if in_turn.abs() > 45f64.to_radians() {
                turns += 1;
            }
            in_turn = 0.0;
        }
        if moving && w[1].speed_mps == 0.0 {
            stops += 1;
        }
        moving = w[1].speed_mps > 0.0;
    }
    if in_turn.abs() > 45f64.to_radians() {
        turns += 1;
    }
    let last = truth.last().copied().unwrap_or_default();
    Summary {
        duration_s: last.t_s,
        distance_m: last.distance_m,
        turned_deg: route.turned_rad().to_degrees(),
        turns_over_45deg: turns,
        stops,
        max_speed_mps: truth.iter().map(|s| s.speed_mps).fold(0.0, f64::max),
    }
}

pub(super) fn scenario_table() -> CliResult {
    let scenarios: [(&str, truenorth::core::Result<Route>); 5] = [
        ("calibration circle", opening_circle()),
        ("city blocks", scenario::city_blocks(8, 150.0)),
        ("highway", scenario::highway(3000.0)),
        ("parking", scenario::parking()),
        ("whole demo drive", scenario::demo_drive()),
    ];
    outln!("Scenarios (rear-axle kinematic model, truth at {RATE_HZ} Hz)")?;
    outln!(
        "{:<20} {:>9} {:>11} {:>11} {:>9} {:>6} {:>10}",
        "scenario",
        "time s",
        "distance m",
        "turned deg",
        "turns>45",
        "stops",
        "max km/h"
    )?;
    for (name, route) in scenarios {
        let route = route.map_err(|e| CliError::msg(format!("scenario {name}: {e}")))?;
        let truth = simulate(&route, 0.0, RATE_HZ)
            .map_err(|e| CliError::msg(format!("scenario {name}: {e}")))?;
        let s = summarise(&route, &truth);
        outln!(
            "{:<20} {:>9.1} {:>11.1} {:>11.1} {:>9} {:>6} {:>10.1}",
            name,
            s.duration_s,
            s.distance_m,
            s.turned_deg,
            s.turns_over_45deg,
            s.stops,
            s.max_speed_mps * 3.6
        )?;
    }
    outln!()?;
    Ok(())
}
