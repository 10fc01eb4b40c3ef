//! The wheel columns of a drive log: cumulative distances as the odometer reports them, or
//! wheel speeds (two, or a car's four) integrated into distances.

/// Which of a vehicle's four wheel speeds are its odometer's left and right, by the wheels
/// its description names (VEHICLE.json `odometer_wheels`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FourWheels {
    /// The front wheels (`speed_fl_mps,speed_fr_mps`); the rear ones are not used.
    Front,
    /// The rear wheels (`speed_rl_mps,speed_rr_mps`); the front ones are not used.
    Rear,
    /// Each side's mean (a skid-steered vehicle: its sides turn it, front and rear wheels
    /// of a side driven alike).
    SideMeans,
}

impl FourWheels {
    /// The columns of the four this choice does not use, for the message that says so.
    pub fn unused(self) -> Option<&'static str> {
        match self {
            Self::Front => Some("speed_rl_mps,speed_rr_mps"),
            Self::Rear => Some("speed_fl_mps,speed_fr_mps"),
            Self::SideMeans => None,
        }
    }

    /// Left and right from the four speeds `[fl, fr, rl, rr]`.
    fn sides(self, v: [f64; 4]) -> [f64; 2] {
        match self {
            Self::Front => [v[0], v[1]],
            Self::Rear => [v[2], v[3]],
            Self::SideMeans => [0.5 * (v[0] + v[2]), 0.5 * (v[1] + v[3])],
        }
    }
}

/// The wheel columns, as cumulative distances or as speeds to integrate.
#[derive(Debug, Clone, Copy)]
pub enum WheelColumns {
    /// Cumulative distances of the left and right wheels, m: the column indices.
    Distances([usize; 2]),
    /// Wheel speeds, m/s, integrated by the trapezoid rule.
    Speeds {
        /// The column indices, left and right.
        columns: [usize; 2],
        /// The last row that carried them: time and speeds.
        last: Option<(f64, [f64; 2])>,
        /// Distances integrated so far, m.
        dist: [f64; 2],
    },
    /// A car's four wheel speeds, m/s, of which `pick` makes the left and right, integrated
    /// by the trapezoid rule.
    FourSpeeds {
        /// The column indices: front left, front right, rear left, rear right.
        columns: [usize; 4],
        /// Which wheels are the odometer's.
        pick: FourWheels,
        /// The last row that carried them: time and the left and right speeds.
        last: Option<(f64, [f64; 2])>,
        /// Distances integrated so far, m.
        dist: [f64; 2],
    },
}

impl WheelColumns {
    /// Cumulative distances at time `t` from row `values`, if the row carries the wheels
    /// (speeds are integrated from one row that carries them to the next); a row with one
    /// wheel and not the other is an error.
    pub fn cumulative(&mut self, t: f64, values: &[f64]) -> Result<Option<[f64; 2]>, &'static str> {
        let (v, present, used) = match self {
            Self::Distances(c) | Self::Speeds { columns: c, .. } => {
                let v = [values[c[0]], values[c[1]]];
                (v, v.iter().filter(|x| x.is_finite()).count(), 2)
            }
            Self::FourSpeeds { columns, pick, .. } => {
                let four = columns.map(|c| values[c]);
                let used: &[usize] = match pick {
                    FourWheels::Front => &[0, 1],
                    FourWheels::Rear => &[2, 3],
                    FourWheels::SideMeans => &[0, 1, 2, 3],
                };
                let present = used.iter().filter(|&&k| four[k].is_finite()).count();
                (pick.sides(four), present, used.len())
            }
        };
        if present == 0 {
            return Ok(None);
        }
        if present < used {
            return Err(if used == 2 {
                "has one wheel's value and not the other's; give both wheels on a row, or neither"
            } else {
                "has some of the four wheels' speeds and not the others'; give all four on a row, or none"
            });
        }
        Ok(Some(match self {
            Self::Distances(_) => v,
            Self::Speeds { last, dist, .. } | Self::FourSpeeds { last, dist, .. } => {
                if let Some((t0, v0)) = *last {
                    for k in 0..2 {
                        dist[k] += 0.5 * (v0[k] + v[k]) * (t - t0);
                    }
                }
                *last = Some((t, v));
                *dist
            }
        }))
    }
}

/// The vehicle's one distance column of a drive log (a CAN bus's vehicle speed, or a
/// distance counter): cumulative, or a speed to integrate.
#[derive(Debug, Clone, Copy)]
pub enum DistanceColumn {
    /// Cumulative distance, m (`dist_m`): the column index.
    Distance(usize),
    /// Vehicle speed, m/s (`speed_mps`), integrated by the trapezoid rule.
    Speed {
        /// The column index.
        column: usize,
        /// The last row that carried it: time and speed.
        last: Option<(f64, f64)>,
        /// Distance integrated so far, m.
        dist: f64,
    },
}

impl DistanceColumn {
    /// The cumulative distance at time `t` from row `values`, if the row carries it.
    pub fn cumulative(&mut self, t: f64, values: &[f64]) -> Option<f64> {
        match self {
            Self::Distance(c) => Some(values[*c]).filter(|d| d.is_finite()),
            Self::Speed { column, last, dist } => {
                let v = values[*column];
                if !v.is_finite() {
                    return None;
                }
                if let Some((t0, v0)) = *last {
                    *dist += 0.5 * (v0 + v) * (t - t0);
                }
                *last = Some((t, v));
                Some(*dist)
            }
        }
    }
}
