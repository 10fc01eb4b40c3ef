//! Units of the inertial columns as a recording states them, turned into the library's
//! (rad/s, m/s²) as the rows are read.

/// Standard gravity, m/s² (ISO 80000-3; the value accelerometers' `g` refers to).
const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;

/// Unit of the gyro columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum GyroUnit {
    /// Radians per second (the library's unit).
    #[default]
    #[value(name = "rad/s")]
    RadPerS,
    /// Degrees per second.
    #[value(name = "deg/s")]
    DegPerS,
}

impl GyroUnit {
    /// The factor that turns a reading in this unit into rad/s.
    pub fn to_rad_per_s(self) -> f64 {
        match self {
            Self::RadPerS => 1.0,
            Self::DegPerS => core::f64::consts::PI / 180.0,
        }
    }
}

/// Unit of the accelerometer columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum AccUnit {
    /// Metres per second squared (the library's unit).
    #[default]
    #[value(name = "m/s2")]
    MetrePerS2,
    /// Standard gravities (1 g = 9.80665 m/s²).
    #[value(name = "g")]
    G,
    /// Thousandths of a standard gravity.
    #[value(name = "mg")]
    MilliG,
}

impl AccUnit {
    /// The factor that turns a reading in this unit into m/s².
    pub fn to_mps2(self) -> f64 {
        match self {
            Self::MetrePerS2 => 1.0,
            Self::G => STANDARD_GRAVITY_MPS2,
            Self::MilliG => STANDARD_GRAVITY_MPS2 / 1000.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_of_each_unit_is_what_the_library_expects() {
        assert_eq!(GyroUnit::RadPerS.to_rad_per_s(), 1.0);
        assert!((180.0 * GyroUnit::DegPerS.to_rad_per_s() - core::f64::consts::PI).abs() < 1e-15);
        assert_eq!(AccUnit::MetrePerS2.to_mps2(), 1.0);
        assert_eq!(AccUnit::G.to_mps2(), 9.80665);
        assert!((1000.0 * AccUnit::MilliG.to_mps2() - 9.80665).abs() < 1e-12);
    }
}
