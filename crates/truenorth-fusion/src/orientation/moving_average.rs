//! The moving average of the Euler detector's correction definer (WO 00/36376, modes
//! (4)–(6)): a fixed ring, so that `push` allocates nothing, kept as plain data in the
//! detector's saved state.

use serde::de::{Error as _, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use truenorth_core::{Error, Result, check_finite};

use super::euler_config::MAX_DEFINER_WINDOW;

/// A moving average over the last `n` values, `n` at most [`MAX_DEFINER_WINDOW`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MovingAverage {
    #[serde(with = "ring")]
    ring: [f64; MAX_DEFINER_WINDOW],
    n: usize,
    next: usize,
    filled: usize,
    sum: f64,
}

impl MovingAverage {
    /// An empty average over `n` values (clamped to 1..=[`MAX_DEFINER_WINDOW`]).
    pub fn new(n: usize) -> Self {
        Self {
            ring: [0.0; MAX_DEFINER_WINDOW],
            n: n.clamp(1, MAX_DEFINER_WINDOW),
            next: 0,
            filled: 0,
            sum: 0.0,
        }
    }

    /// Adds `x` and returns the mean of the values held.
    pub fn push(&mut self, x: f64) -> f64 {
        if self.filled == self.n {
            self.sum -= self.ring[self.next];
        } else {
            self.filled += 1;
        }
        self.ring[self.next] = x;
        self.sum += x;
        self.next = (self.next + 1) % self.n;
        self.sum / self.filled as f64
    }

    /// Checks a restored average against the window `n` its detector was built with: the
    /// same window, positions inside it, finite values.
    pub(crate) fn check(&self, n: usize) -> Result<()> {
        if self.n != n.clamp(1, MAX_DEFINER_WINDOW) || self.next >= self.n || self.filled > self.n {
            return Err(Error::InvalidSnapshot {
                reason: "a moving average's window differs from the detector's",
            });
        }
        check_finite("moving average sum", self.sum)?;
        for v in &self.ring {
            check_finite("moving average value", *v)?;
        }
        Ok(())
    }
}

/// The ring as a tuple of [`MAX_DEFINER_WINDOW`] numbers (serde derives arrays up to 32).
mod ring {
    use super::*;

    type Ring = [f64; MAX_DEFINER_WINDOW];

    pub(super) fn serialize<S: Serializer>(
        ring: &Ring,
        s: S,
    ) -> core::result::Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(MAX_DEFINER_WINDOW)?;
        for v in ring {
            t.serialize_element(v)?;
        }
        t.end()
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(
        d: D,
    ) -> core::result::Result<Ring, D::Error> {
        struct RingVisitor;
        impl<'de> Visitor<'de> for RingVisitor {
            type Value = Ring;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                write!(f, "{MAX_DEFINER_WINDOW} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> core::result::Result<Ring, A::Error> {
                let mut ring = [0.0; MAX_DEFINER_WINDOW];
                for (i, v) in ring.iter_mut().enumerate() {
                    *v = seq
                        .next_element()?
                        .ok_or_else(|| A::Error::invalid_length(i, &self))?;
                }
                Ok(ring)
            }
        }
        d.deserialize_tuple(MAX_DEFINER_WINDOW, RingVisitor)
    }
}
