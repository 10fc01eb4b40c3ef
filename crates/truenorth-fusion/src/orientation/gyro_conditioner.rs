//! One gyro axis's conditioning chain in the Euler detector (WO 00/36376), as
//! selected by [`GyroConditioning`]: the `truenorth-gyro` filters with their memories,
//! kept as plain data in the detector's saved state.

use serde::{Deserialize, Serialize};
use truenorth_core::Result;
use truenorth_gyro::{HighPassCorrection, HighPassFilter, IirHighPass};

use super::euler_config::GyroConditioning;

/// One gyro axis's conditioning chain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GyroConditioner {
    /// The raw rate.
    None,
    /// The high-pass and, optionally, its correction.
    HighPass(HighPassFilter, Option<HighPassCorrection>),
    /// The digital IIR high-pass.
    Iir(IirHighPass),
}

impl GyroConditioner {
    /// The chain `c` selects, before any sample.
    pub fn new(c: &GyroConditioning) -> Result<Self> {
        Ok(match *c {
            GyroConditioning::None => Self::None,
            GyroConditioning::HighPass { filter, correction } => Self::HighPass(
                HighPassFilter::new(filter)?,
                correction.map(HighPassCorrection::new).transpose()?,
            ),
            GyroConditioning::Iir(c) => Self::Iir(IirHighPass::new(c)?),
        })
    }

    /// Conditions the rate `x`, rad/s, taken `dt_s` after the previous one.
    pub fn push(&mut self, x: f64, dt_s: f64) -> Result<f64> {
        match self {
            Self::None => Ok(x),
            Self::HighPass(f, c) => {
                let y = f.push(x, dt_s)?;
                match c {
                    Some(c) => c.push(y, f.rc_s(), dt_s),
                    None => Ok(y),
                }
            }
            Self::Iir(f) => f.push(x, dt_s),
        }
    }

    /// Whether this is the chain `c` selects (the pieces, not their memories).
    pub(crate) fn is_kind_of(&self, c: &GyroConditioning) -> bool {
        match (self, c) {
            (Self::None, GyroConditioning::None) | (Self::Iir(_), GyroConditioning::Iir(_)) => true,
            (Self::HighPass(_, mine), GyroConditioning::HighPass { correction, .. }) => {
                mine.is_some() == correction.is_some()
            }
            _ => false,
        }
    }
}
