"""truenorth: calibrated heading, orientation and dead reckoning from low-cost sensors.

Arrays are rows of samples, timestamps in seconds, in the units and body axes of the
``truenorth`` command (x forward, y right, z down; gyro rad/s, specific force m/s^2,
magnetometer in any unit). Loops over arrays run in Rust. The library's errors are raised
as :class:`TruenorthError` (a :class:`ValueError`) carrying the library's message.
"""

from ._truenorth import (
    METHODS,
    Attitude,
    Calibration,
    Calibrator,
    EulerDetector,
    MagneticField,
    OrientationEstimator,
    Quality,
    QuaternionFilter,
    TruenorthError,
    Uncertainty,
    VehicleEstimator,
    Verdict,
    broad_rmse,
    calibrate,
    check_gnss_delay,
    check_imu,
    field,
    read_log,
)

__all__ = [
    "METHODS",
    "Attitude",
    "Calibration",
    "Calibrator",
    "EulerDetector",
    "MagneticField",
    "OrientationEstimator",
    "Quality",
    "QuaternionFilter",
    "TruenorthError",
    "Uncertainty",
    "VehicleEstimator",
    "Verdict",
    "broad_rmse",
    "calibrate",
    "check_gnss_delay",
    "check_imu",
    "field",
    "read_log",
]
