//! A stored compass calibration against the readings it is applied to: the corrected
//! field's magnitude, which a calibration that describes the sensor keeps near its `field`
//! whatever the heading. One from another device (another hard iron) leaves it swinging
//! with the heading; one made in another unit (gauss applied to µT) off by a factor no
//! place on Earth explains. Kept as running sums, so a recording of any length is judged
//! in constant memory.

use truenorth_core::Readable;

/// Readings before the magnitude is judged.
pub const MIN_READINGS: u64 = 50;

/// The largest ratio of the corrected field to the calibration's that a place explains: the
/// Earth's total field runs from about 22 µT (South Atlantic) to 67 µT (near the magnetic
/// poles), a ratio of 3.05; a calibration made anywhere may be used anywhere, since the
/// hard and soft iron belong to the sensor, not the place.
pub const MAX_PLACE_RATIO: f64 = 3.2;

/// The largest RMS of the log of that ratio a calibration that describes the sensor
/// leaves, 2-D: a level two-axis compass reads the horizontal field, which a tilt of θ
/// changes by up to about tan(dip)·θ — 5° of a road's or a hand's tilt at a dip of 65° is
/// 19 %, and twice that is allowed (0.35); 3-D: the total field, which tilt leaves alone,
/// and local iron and the calibration's own residual change by a few per cent (0.15).
pub const MAX_SPREAD_2D: f64 = 0.35;
/// See [`MAX_SPREAD_2D`].
pub const MAX_SPREAD_3D: f64 = 0.15;

/// The corrected field's magnitude over the readings so far, against the calibration's.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FieldFit {
    n: u64,
    sum_log: f64,
    sum_log2: f64,
    /// The row at which the readings became enough to judge.
    judged_at_row: Option<usize>,
}

impl FieldFit {
    /// Adds one reading whose corrected magnitude is `magnitude` against the calibration's
    /// `field`, on input row `row`. A magnitude that is zero or not finite says nothing and
    /// is left out.
    pub fn push(&mut self, magnitude: f64, field: f64, row: usize) {
        let r = (magnitude / field).ln();
        if !r.is_finite() {
            return;
        }
        self.n += 1;
        self.sum_log += r;
        self.sum_log2 += r * r;
        if self.n == MIN_READINGS {
            self.judged_at_row = Some(row);
        }
    }

    /// The geometric mean of the ratio and the RMS of its log about the mean, once there
    /// are [`MIN_READINGS`].
    pub fn ratio_and_spread(&self) -> Option<(f64, f64)> {
        (self.n >= MIN_READINGS).then(|| {
            let n = self.n as f64;
            let mean = self.sum_log / n;
            (
                mean.exp(),
                (self.sum_log2 / n - mean * mean).max(0.0).sqrt(),
            )
        })
    }

    /// Why the calibration does not describe these readings (`dimensions`: 2 or 3), and the
    /// row where the evidence became enough; `None` when it does, or too few readings say.
    pub fn misfit(&self, dimensions: usize) -> Option<(String, Option<usize>)> {
        let (ratio, spread) = self.ratio_and_spread()?;
        let max_spread = if dimensions == 2 {
            MAX_SPREAD_2D
        } else {
            MAX_SPREAD_3D
        };
        let reason = if !(1.0 / MAX_PLACE_RATIO..=MAX_PLACE_RATIO).contains(&ratio) {
            format!(
                "the calibrated field is {} times the calibration's `field` over {} readings, more than any place on Earth explains (at most {MAX_PLACE_RATIO}): the calibration was made in another unit (gauss against µT is 100) or for another sensor",
                Readable(ratio),
                self.n
            )
        } else if spread > max_spread {
            format!(
                "the calibrated field's magnitude swings by {:.0} % (RMS) over {} readings where a calibration of this sensor keeps it within {:.0} %: the calibration is another device's, or the sensor's iron has changed; recalibrate on this recording",
                100.0 * spread,
                self.n,
                100.0 * max_spread
            )
        } else {
            return None;
        };
        Some((reason, self.judged_at_row))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A calibration that describes the sensor, anywhere on Earth and with its tilt,
        /// is never refused; any input never panics.
        #[test]
        fn a_fitting_calibration_is_accepted_anywhere(
            place in 1.0 / 3.0f64..3.0,
            wobble in proptest::collection::vec(-0.2f64..0.2, 60..200),
        ) {
            let mut f = FieldFit::default();
            for (k, w) in wobble.iter().enumerate() {
                f.push(place * (1.0 + w), 1.0, k);
            }
            prop_assert!(f.misfit(2).is_none());
        }

        #[test]
        fn no_input_panics(values in proptest::collection::vec(any::<f64>(), 0..100)) {
            let mut f = FieldFit::default();
            for (k, v) in values.iter().enumerate() {
                f.push(*v, 1.0, k);
            }
            let _ = f.misfit(3);
        }
    }

    #[test]
    fn another_unit_and_another_device_are_named() {
        let mut gauss = FieldFit::default();
        let mut other = FieldFit::default();
        for k in 0..100 {
            gauss.push(48.0, 0.48, k);
            let swing = 1.0 + 0.8 * (0.1 * k as f64).sin();
            other.push(swing, 1.0, k);
        }
        let (why, row) = gauss.misfit(3).unwrap();
        assert!(why.contains("another unit") && row == Some(49), "{why}");
        assert!(other.misfit(2).unwrap().0.contains("another device"));
    }
}
