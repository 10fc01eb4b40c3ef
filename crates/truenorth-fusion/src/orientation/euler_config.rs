//! Parameters of the [`crate::EulerDetector`] (WO 00/36376): every piece of the
//! seed's detector is a field here, so that each can be switched off and its effect measured.

use serde::{Deserialize, Serialize};
use truenorth_core::{Result, Validate, check_positive, check_range};
use truenorth_gyro::{
    HighPassConfig, HighPassCorrectionConfig, IirHighPassConfig, OscillationRemoverConfig,
};

/// Which angles the detector estimates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EulerVariant {
    /// Yaw, pitch and roll from three gyros (the seed's full detector).
    Full,
    /// Yaw and pitch only, from the gyros on the body y and z axes and one accelerometer on
    /// x; roll is taken as zero (the seed's yaw + pitch variant).
    YawPitch,
}

/// How each gyro's output is conditioned before it is integrated (the seed's gyro
/// conditioning).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GyroConditioning {
    /// The raw rate.
    None,
    /// An analogue-style high-pass with a variable cutoff, optionally followed by its
    /// correction (with or without the offset-error compensator).
    HighPass {
        /// The filter.
        filter: HighPassConfig,
        /// The correction of its distortion; `None` leaves the filter's output as it is.
        correction: Option<HighPassCorrectionConfig>,
    },
    /// The digital IIR variant with buffer reset and input-offset correction.
    Iir(IirHighPassConfig),
}

/// When a static angle is trustworthy enough to correct with (the seed's correction
/// definer, modes (1)–(7)). Every test that is
/// `Some` must pass; `None` switches a test off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CorrectionDefinerConfig {
    /// Modes (1), (2): the static roll and pitch may change by at most this much from one
    /// sample to the next, rad (the seed's B and D). Default 2°: far above the change of a
    /// moving average of a consumer accelerometer's static angle from noise (≈ 0.06° for
    /// σ = 0.05 m/s² over 8 samples), and below what a jolt or a swing's acceleration
    /// does to it.
    pub tilt_change_rad: Option<f64>,
    /// Modes (1), (2) with the current motion angles instead of constants: the static
    /// angle's change may exceed the gyro's motion angle by at most `tilt_change_rad`
    /// (default `true`).
    pub tilt_change_against_motion: bool,
    /// Mode (3): the tentative yaw's change may differ from the yaw motion angle `A_z` by at
    /// most this much, rad. Default 2°, for the same reason.
    pub yaw_change_rad: Option<f64>,
    /// Modes (4)–(6): the tests above applied to moving averages over this many samples
    /// instead of single samples (`C`, at most [`MAX_DEFINER_WINDOW`]); `None` (default 8)
    /// compares single samples.
    pub moving_average: Option<usize>,
    /// Mode (7), three accelerometers: `| |a| − g |` at most this, m/s² (default 1, about
    /// 0.1 g: a hand-held sensor is rarely closer to 1 g than that while it moves, and a
    /// tighter limit leaves the tilt uncorrected for most of a motion).
    pub gravity_tol_mps2: Option<f64>,
}

/// Most samples a moving average of the correction definer spans.
pub const MAX_DEFINER_WINDOW: usize = 64;

impl Default for CorrectionDefinerConfig {
    fn default() -> Self {
        Self {
            tilt_change_rad: Some(2f64.to_radians()),
            tilt_change_against_motion: true,
            yaw_change_rad: Some(2f64.to_radians()),
            moving_average: Some(8),
            gravity_tol_mps2: Some(1.0),
        }
    }
}

impl Validate for CorrectionDefinerConfig {
    /// Thresholds positive, the window in [1, 64].
    fn validate(&self) -> Result<()> {
        if let Some(b) = self.tilt_change_rad {
            check_positive("definer.tilt_change_rad", b)?;
        }
        if let Some(b) = self.yaw_change_rad {
            check_positive("definer.yaw_change_rad", b)?;
        }
        if let Some(c) = self.moving_average {
            check_range(
                "definer.moving_average",
                c as f64,
                1.0,
                MAX_DEFINER_WINDOW as f64,
            )?;
        }
        if let Some(g) = self.gravity_tol_mps2 {
            check_positive("definer.gravity_tol_mps2", g)?;
        }
        Ok(())
    }
}

/// The start-up field a two-axis magnetometer needs for the seed's M_z reconstruction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StartupField {
    /// Total field `Ht`, the magnetometer's unit.
    pub total: f64,
    /// Inclination, rad, positive down.
    pub inclination_rad: f64,
}

/// Parameters of the [`crate::EulerDetector`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EulerDetectorConfig {
    /// Which angles (default [`EulerVariant::Full`]).
    pub variant: EulerVariant,
    /// Gyro conditioning (default [`GyroConditioning::None`]: a MEMS gyro's offset is better
    /// removed by a calibration at rest than by a high-pass, which also removes slow turns).
    pub gyro: GyroConditioning,
    /// The oscillation remover on each gyro (default `None`).
    pub oscillation_remover: Option<OscillationRemoverConfig>,
    /// When a static angle may correct (the correction definer).
    pub definer: CorrectionDefinerConfig,
    /// Time constants of the corrections of roll, pitch and yaw, s: the seed's gain is
    /// `k = dt/τ` per sample (0 < k < 1), so the behaviour does not depend on the sample
    /// rate (default 2, 2, 5).
    pub tau_s: [f64; 3],
    /// Scale the corrections by the seed's Table 1 from the tentative pitch and roll
    /// (default `true`).
    pub coefficient_table: bool,
    /// Use the magnetometer when the samples have one (default `true`).
    pub use_mag: bool,
    /// Start-up field for a two-axis magnetometer (M_z reconstruction); without it a
    /// two-axis magnetometer is refused.
    pub startup_field: Option<StartupField>,
    /// Longest time between samples the gyro is integrated across, s (default 0.5, as the
    /// quaternion filter's `max_gap_s`): after a longer gap the angles are taken anew from
    /// the static angles of the sample (status `gap`), and a time base of mostly such gaps
    /// is refused.
    pub max_gap_s: f64,
}

impl Default for EulerDetectorConfig {
    fn default() -> Self {
        Self {
            variant: EulerVariant::Full,
            gyro: GyroConditioning::None,
            oscillation_remover: None,
            definer: CorrectionDefinerConfig::default(),
            tau_s: [2.0, 2.0, 5.0],
            coefficient_table: true,
            use_mag: true,
            startup_field: None,
            max_gap_s: 0.5,
        }
    }
}

impl Validate for EulerDetectorConfig {
    fn validate(&self) -> Result<()> {
        for t in self.tau_s {
            check_positive("euler.tau_s", t)?;
        }
        match self.gyro {
            GyroConditioning::None => {}
            GyroConditioning::HighPass { filter, correction } => {
                filter.validate()?;
                if let Some(c) = correction {
                    c.validate()?;
                }
            }
            GyroConditioning::Iir(c) => c.validate()?,
        }
        if let Some(o) = self.oscillation_remover {
            o.validate()?;
        }
        self.definer.validate()?;
        super::time_gap::check_max_gap(self.max_gap_s)?;
        if let Some(f) = self.startup_field {
            check_positive("startup_field.total", f.total)?;
            check_range(
                "startup_field.inclination_rad",
                f.inclination_rad,
                -core::f64::consts::FRAC_PI_2,
                core::f64::consts::FRAC_PI_2,
            )?;
        }
        Ok(())
    }
}

/// The seed's Table 1: the factors (m1, m2, m3) on the roll, pitch and yaw corrections for
/// the tentative |pitch| and |roll| in the bands 0–60°, 60–70°, 70–90° (rows pitch,
/// columns roll). A roll beyond 90° (upside down) is folded to 180° − |roll|, the same
/// distance from the vertical.
pub fn coefficient_table(pitch_rad: f64, roll_rad: f64) -> [f64; 3] {
    const TABLE: [[[f64; 3]; 3]; 3] = [
        [[1.0, 1.0, 1.0], [0.7, 1.0, 0.7], [0.3, 1.0, 0.3]],
        [[1.0, 0.7, 0.7], [0.7, 0.7, 0.7], [0.3, 0.7, 0.3]],
        [[1.0, 0.3, 0.3], [0.7, 0.3, 0.3], [0.3, 0.3, 0.3]],
    ];
    let band = |deg: f64| {
        if deg < 60.0 {
            0
        } else if deg < 70.0 {
            1
        } else {
            2
        }
    };
    let p = pitch_rad.abs().to_degrees();
    let mut r = roll_rad.abs().to_degrees();
    if r > 90.0 {
        r = 180.0 - r;
    }
    TABLE[band(p)][band(r)]
}
