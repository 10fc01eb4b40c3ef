//! Turns the fuzzer's bytes into the values the targets feed: flags, counts and floats that
//! are realistic most of the time and hostile (NaN, ±inf, ±1e308, subnormal, zero) often.

/// A cursor over the fuzzer's bytes; past the end every read gives zero.
pub struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
}

/// Values every reading should survive.
const HOSTILE: [f64; 12] = [
    0.0,
    -0.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e308,
    -1e308,
    f64::MIN_POSITIVE,
    5e-324,
    f64::EPSILON,
    -1.0,
    1e12,
];

impl<'a> Bytes<'a> {
    /// The cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, at: 0 }
    }

    /// Whether every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.at >= self.data.len()
    }

    /// The bytes not read yet (and consumes them).
    pub fn rest(&mut self) -> &'a [u8] {
        let r = &self.data[self.at.min(self.data.len())..];
        self.at = self.data.len();
        r
    }

    /// One byte.
    pub fn byte(&mut self) -> u8 {
        let b = self.data.get(self.at).copied().unwrap_or(0);
        self.at += 1;
        b
    }

    /// Two bytes, little-endian.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.byte(), self.byte()])
    }

    /// A float scaled to `scale` most of the time: a 16-bit step of `scale / 1000`, a
    /// hostile value, or any 64-bit pattern.
    pub fn f64(&mut self, scale: f64) -> f64 {
        match self.byte() % 16 {
            0 => HOSTILE[usize::from(self.byte()) % HOSTILE.len()],
            1 => {
                let mut b = [0u8; 8];
                b.iter_mut().for_each(|x| *x = self.byte());
                f64::from_le_bytes(b)
            }
            _ => f64::from(self.u16() as i16) * scale / 1000.0,
        }
    }

    /// The next timestamp after `t_s`: mostly `t_s + dt_s`, sometimes a repeat, a step back,
    /// a jump, or a hostile value.
    pub fn time(&mut self, t_s: f64, dt_s: f64) -> f64 {
        match self.byte() % 32 {
            0 => t_s,
            1 => t_s - dt_s,
            2 => t_s + self.f64(1.0),
            3 => self.f64(1000.0),
            4 => t_s + 3600.0,
            _ => t_s + dt_s,
        }
    }
}
