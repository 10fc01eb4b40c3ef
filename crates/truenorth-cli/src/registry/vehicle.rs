//! Vehicle heading and dead-reckoning methods by name.

use truenorth::core::{HeadingEstimator, NavEstimate, Result, VehicleSample};
use truenorth::fusion::VehicleEstimator;
use truenorth::fusion::vehicle::{
    SeedGyroCompass, SeedGyroCompassConfig, SeedOdometerCompass, SeedOdometerCompassConfig,
    TwoPassConfig, TwoPassStart, VehicleCalibration,
};
use truenorth::odometer::OdometerWheels;

/// How the heading is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum VehicleMethod {
    /// Gyro (if present), wheels and compass fused, every sensor calibrated online.
    Fused,
    /// US 4,788,645: wheels with the speed correction, compass blended in; no gyro.
    SeedOdometerCompass,
    /// EP 0640207: gyro calibrated by the first full turn, compass blended in.
    SeedGyroCompass,
}

/// Receives each sample's final estimate, in order, with the fused estimator that made it
/// when the method is the fused one (its filter's state, the fixes' declination).
pub type Emit<'a> = dyn FnMut(&NavEstimate, Option<&VehicleEstimator>) + 'a;

/// A vehicle method as the commands run it: samples in, each sample's final estimate out in
/// order. A [`HeadingEstimator`] gives each estimate as its sample comes; the fused
/// estimator's two-pass start holds the head of the drive back and gives it at once when it
/// is estimated again.
pub trait VehicleRun {
    /// Takes one sample; `emit` receives the estimates that are final.
    fn push(&mut self, sample: &VehicleSample, emit: &mut Emit) -> Result<()>;
    /// Ends the drive: `emit` receives the estimates still held back.
    fn finish(&mut self, emit: &mut Emit) -> Result<()>;
    /// What the method learned about the sensors, in the form a later drive starts from
    /// (the fused estimator's only).
    fn calibration(&self) -> Option<VehicleCalibration>;
}

impl VehicleRun for TwoPassStart {
    fn push(&mut self, sample: &VehicleSample, emit: &mut Emit) -> Result<()> {
        TwoPassStart::push(self, sample, |_, e, est| emit(e, Some(est)))
    }

    fn finish(&mut self, emit: &mut Emit) -> Result<()> {
        TwoPassStart::finish(self, |_, e, est| emit(e, Some(est)))
    }

    fn calibration(&self) -> Option<VehicleCalibration> {
        Some(self.estimator().calibration())
    }
}

/// The fused estimator run causally: each row written as it comes.
impl VehicleRun for VehicleEstimator {
    fn push(&mut self, sample: &VehicleSample, emit: &mut Emit) -> Result<()> {
        let e = self.update(sample)?;
        emit(&e, Some(self));
        Ok(())
    }

    fn finish(&mut self, _: &mut Emit) -> Result<()> {
        Ok(())
    }

    fn calibration(&self) -> Option<VehicleCalibration> {
        Some(VehicleEstimator::calibration(self))
    }
}

/// A seed configuration, which learns what it needs its own way.
struct Seed(Box<dyn HeadingEstimator>);

impl VehicleRun for Seed {
    fn push(&mut self, sample: &VehicleSample, emit: &mut Emit) -> Result<()> {
        let e = self.0.update(sample)?;
        emit(&e, None);
        Ok(())
    }

    fn finish(&mut self, _: &mut Emit) -> Result<()> {
        Ok(())
    }

    fn calibration(&self) -> Option<VehicleCalibration> {
        None
    }
}

impl VehicleMethod {
    /// The method on a vehicle with odometer `wheels`. The fused method runs `fused` (built
    /// by the caller, which knows where its configuration came from) with the two-pass start,
    /// or causally with `single_pass`; the seed methods leave it unused.
    pub fn runner(
        self,
        wheels: OdometerWheels,
        fused: VehicleEstimator,
        single_pass: bool,
    ) -> Result<Box<dyn VehicleRun>> {
        Ok(match self {
            Self::Fused if single_pass => Box::new(fused),
            Self::Fused => Box::new(TwoPassStart::new(fused, TwoPassConfig::default())?),
            Self::SeedOdometerCompass => Box::new(Seed(Box::new(SeedOdometerCompass::new(
                SeedOdometerCompassConfig {
                    wheels,
                    ..SeedOdometerCompassConfig::default()
                },
            )?))),
            Self::SeedGyroCompass => Box::new(Seed(Box::new(SeedGyroCompass::new(
                SeedGyroCompassConfig {
                    wheels,
                    ..SeedGyroCompassConfig::default()
                },
            )?))),
        })
    }
}
