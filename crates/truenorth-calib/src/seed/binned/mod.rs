//! The binned-ellipse calibrator (EP 0634001): its configuration, the readings binned by
//! heading, the full-set update that fits the ellipse, its assessment and its saved state.

pub(crate) mod assess;
pub(crate) mod bins;
pub(crate) mod calibrator;
pub(crate) mod config;
pub(crate) mod params;
pub(crate) mod persist;
pub(crate) mod refresh;
pub(crate) mod update;

pub use bins::{BinState, MAX_BINS};
pub use calibrator::{
    BinnedEllipseCalibrator, BinnedEllipseConfig, MAX_INIT_SAMPLES, MAX_UPDATE_PUSHES, UpdatePhase,
};
pub use params::ellipse_parameters;
pub use persist::{BinnedEllipseCalibratorState, BinnedUpdateState};
