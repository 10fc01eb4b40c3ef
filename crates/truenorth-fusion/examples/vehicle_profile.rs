use truenorth_core::HeadingEstimator;
use truenorth_fusion::{VehicleConfig, VehicleEstimator};
use truenorth_sim::{DriveSpec, SimulatedDrive};
fn main() {
    let drive = SimulatedDrive::new(DriveSpec::new(1)).unwrap();
    let mut total = 0.0;
    let runs: usize = std::env::args().nth(1).map_or(200, |a| a.parse().unwrap());
    for _ in 0..runs {
        let mut nav = VehicleEstimator::new(VehicleConfig::default()).unwrap();
        for s in &drive.samples {
            total += nav.update(s).unwrap().north_m;
        }
    }
    println!("{total}");
}
