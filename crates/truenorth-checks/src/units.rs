//! The units a recording's columns may be in, and the factors that turn them into the
//! library's (rad/s, m/s², nT): what a user declares, and what the checks test it against.

/// Standard gravity, m/s² (ISO 80000-3; the value accelerometers' `g` refers to).
pub const STANDARD_GRAVITY_MPS2: f64 = 9.806_65;

/// Unit of the gyro columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum GyroUnit {
    /// Radians per second (the library's unit).
    #[default]
    #[cfg_attr(feature = "clap", value(name = "rad/s"))]
    RadPerS,
    /// Degrees per second.
    #[cfg_attr(feature = "clap", value(name = "deg/s"))]
    DegPerS,
}

impl GyroUnit {
    /// Both, the library's first.
    pub const ALL: [GyroUnit; 2] = [GyroUnit::RadPerS, GyroUnit::DegPerS];

    /// The unit's name (`rad/s`, `deg/s`), as the command line and the Python package take it.
    pub fn name(self) -> &'static str {
        match self {
            Self::RadPerS => "rad/s",
            Self::DegPerS => "deg/s",
        }
    }

    /// The unit named `name` ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|u| u.name() == name)
    }

    /// The other unit: the one a gyro read in this unit is likely to be in when it is not.
    pub fn other(self) -> Self {
        match self {
            Self::RadPerS => Self::DegPerS,
            Self::DegPerS => Self::RadPerS,
        }
    }

    /// The factor that turns a reading in this unit into rad/s.
    pub fn to_rad_per_s(self) -> f64 {
        match self {
            Self::RadPerS => 1.0,
            Self::DegPerS => core::f64::consts::PI / 180.0,
        }
    }
}

/// Unit of the accelerometer columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum AccUnit {
    /// Metres per second squared (the library's unit).
    #[default]
    #[cfg_attr(feature = "clap", value(name = "m/s2"))]
    MetrePerS2,
    /// Standard gravities (1 g = 9.80665 m/s²).
    #[cfg_attr(feature = "clap", value(name = "g"))]
    G,
    /// Thousandths of a standard gravity.
    #[cfg_attr(feature = "clap", value(name = "mg"))]
    MilliG,
}

impl AccUnit {
    /// Every unit, the library's first.
    pub const ALL: [AccUnit; 3] = [AccUnit::MetrePerS2, AccUnit::G, AccUnit::MilliG];

    /// The unit's name (`m/s2`, `g`, `mg`), as the command line and the Python package take
    /// it.
    pub fn name(self) -> &'static str {
        match self {
            Self::MetrePerS2 => "m/s2",
            Self::G => "g",
            Self::MilliG => "mg",
        }
    }

    /// The unit named `name` ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|u| u.name() == name)
    }

    /// The factor that turns a reading in this unit into m/s².
    pub fn to_mps2(self) -> f64 {
        match self {
            Self::MetrePerS2 => 1.0,
            Self::G => STANDARD_GRAVITY_MPS2,
            Self::MilliG => STANDARD_GRAVITY_MPS2 / 1000.0,
        }
    }
}

/// Units a magnetometer may report in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
pub enum MagUnit {
    /// Nanotesla.
    #[cfg_attr(feature = "clap", value(name = "nT"))]
    NanoTesla,
    /// Microtesla.
    #[cfg_attr(feature = "clap", value(name = "uT"))]
    MicroTesla,
    /// Milligauss (= 100 nT).
    #[cfg_attr(feature = "clap", value(name = "mG"))]
    MilliGauss,
    /// Gauss (= 100 000 nT).
    #[cfg_attr(feature = "clap", value(name = "G"))]
    Gauss,
}

impl MagUnit {
    /// Every unit, smallest first.
    pub const ALL: [MagUnit; 4] = [
        MagUnit::NanoTesla,
        MagUnit::MilliGauss,
        MagUnit::MicroTesla,
        MagUnit::Gauss,
    ];

    /// nT per unit.
    pub fn nanotesla(self) -> f64 {
        match self {
            Self::NanoTesla => 1.0,
            Self::MicroTesla => 1e3,
            Self::MilliGauss => 1e2,
            Self::Gauss => 1e5,
        }
    }

    /// The unit's name (`nT`, `uT`, `mG`, `G`), as the command line and the Python package
    /// take it.
    pub fn name(self) -> &'static str {
        match self {
            Self::NanoTesla => "nT",
            Self::MicroTesla => "uT",
            Self::MilliGauss => "mG",
            Self::Gauss => "G",
        }
    }

    /// The unit named `name` ([`Self::name`]).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|u| u.name() == name)
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

    #[test]
    fn every_unit_is_found_by_its_name() {
        for u in GyroUnit::ALL {
            assert_eq!(GyroUnit::from_name(u.name()), Some(u));
            assert_eq!(u.other().other(), u);
        }
        for u in AccUnit::ALL {
            assert_eq!(AccUnit::from_name(u.name()), Some(u));
        }
        for u in MagUnit::ALL {
            assert_eq!(MagUnit::from_name(u.name()), Some(u));
        }
        assert_eq!(MagUnit::from_name("tesla"), None);
    }
}
