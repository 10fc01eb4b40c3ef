//! The wheel columns of a drive log: cumulative distances as the odometer reports them, or
//! wheel speeds integrated into distances.

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
}

impl WheelColumns {
    /// Cumulative distances at time `t` from row `values`, if the row carries the wheels
    /// (speeds are integrated from one row that carries them to the next); a row with one
    /// wheel and not the other is an error.
    pub fn cumulative(&mut self, t: f64, values: &[f64]) -> Result<Option<[f64; 2]>, &'static str> {
        let [l, r] = match self {
            Self::Distances(c) | Self::Speeds { columns: c, .. } => *c,
        };
        let v = [values[l], values[r]];
        match (v[0].is_finite(), v[1].is_finite()) {
            (false, false) => return Ok(None),
            (true, true) => {}
            _ => {
                return Err(
                    "has one wheel's value and not the other's; give both wheels on a row, or neither",
                );
            }
        }
        Ok(Some(match self {
            Self::Distances(_) => v,
            Self::Speeds { last, dist, .. } => {
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
