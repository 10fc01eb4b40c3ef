"""Type stubs of the truenorth package (the native module `truenorth._truenorth`)."""

import os
from typing import Any, Literal, Optional, Sequence, TypedDict

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]
BoolArray = npt.NDArray[np.bool_]

METHODS: list[str]
"""The calibration methods, as the CLI's `--method`."""

class TruenorthError(ValueError):
    """An error of the library, with its message (naming the row for an array)."""

class Uncertainty:
    """What the readings determine."""
    dilution: float
    hard_iron_sigma: tuple[float, float, float]
    soft_iron_sigma_rel: float
    geometry_error_deg: float

class Verdict:
    """`good`, `usable` or `poor`, with the numbers behind it."""
    grade: Literal["good", "usable", "poor"]
    cause: Literal["none", "calibration", "noise"]
    bound_deg: float
    noise_deg: float
    reason: str
    def to_dict(self) -> dict[str, Any]: ...

class Quality:
    """A compass calibration's quality report."""
    @property
    def points(self) -> int: ...
    @property
    def coverage(self) -> float: ...
    @property
    def residual_rms_rel(self) -> float: ...
    @property
    def condition(self) -> float: ...
    @property
    def heading_error_bound_deg(self) -> float: ...
    @property
    def heading_error_3sigma_deg(self) -> float: ...
    @property
    def heading_error_systematic_deg(self) -> float: ...
    @property
    def heading_noise_rms_deg(self) -> float: ...
    @property
    def field_magnitude(self) -> float: ...
    @property
    def field_ratio_to_expected(self) -> Optional[float]: ...
    @property
    def uncertainty(self) -> Uncertainty: ...
    @property
    def verdict(self) -> Verdict: ...
    def to_dict(self) -> dict[str, Any]: ...

class Calibration:
    """A compass calibration: corrected = soft_iron @ (raw - hard_iron)."""
    @property
    def method(self) -> str: ...
    @property
    def dimensions(self) -> Literal[2, 3]: ...
    @property
    def hard_iron(self) -> FloatArray: ...
    @property
    def soft_iron(self) -> FloatArray: ...
    @property
    def field(self) -> float: ...
    @property
    def quality(self) -> Quality: ...
    @property
    def verdict(self) -> Verdict: ...
    def heading(self, mag: FloatArray, acc: Optional[FloatArray] = None) -> FloatArray:
        """Magnetic heading, degrees in [0, 360), one per row (as `truenorth heading`)."""
    def to_dict(self) -> dict[str, Any]:
        """The layout of the CLI's calibration file."""

class Progress(TypedDict):
    samples: int
    coverage: float
    ready: bool

class Calibrator:
    """A compass calibrator by the CLI's method name (see METHODS)."""
    def __init__(self, method: str, config: Optional[dict[str, Any]] = None) -> None: ...
    @property
    def method(self) -> str: ...
    def push(
        self, t_s: float, mag: Sequence[float], acc: Optional[Sequence[float]] = None
    ) -> Literal["ignored", "accepted", "new_estimate"]: ...
    def push_array(
        self,
        mag: FloatArray,
        t_s: Optional[FloatArray] = None,
        acc: Optional[FloatArray] = None,
    ) -> int: ...
    def progress(self) -> Progress: ...
    def solve(self) -> Calibration: ...
    def estimate(self) -> Optional[Calibration]: ...
    def reset(self) -> None: ...

def calibrate(
    method: str,
    mag: FloatArray,
    t_s: Optional[FloatArray] = None,
    acc: Optional[FloatArray] = None,
    config: Optional[dict[str, Any]] = None,
) -> Calibration:
    """Calibrates in one call, as `truenorth calibrate --method METHOD`."""

class Attitude:
    """One attitude estimate (body -> NED on magnetic north)."""
    t_s: float
    quaternion: tuple[float, float, float, float]
    yaw_deg: float
    pitch_deg: float
    roll_deg: float
    gyro_bias_rps: tuple[float, float, float]
    sigma_deg: Optional[tuple[float, float, float]]
    at_rest: bool
    mag_used: bool
    mag_disturbed: bool
    mag_calibrating: bool
    gap: bool

class OrientationArrays(TypedDict):
    t_s: FloatArray
    quaternion: FloatArray
    euler_deg: FloatArray
    gyro_bias_rps: FloatArray
    sigma_deg: FloatArray
    at_rest: BoolArray
    mag_used: BoolArray
    mag_disturbed: BoolArray
    mag_calibrating: BoolArray
    gap: BoolArray

class OrientationEstimator:
    """Base class of the orientation estimators."""
    def update(
        self,
        t_s: float,
        gyr: Sequence[float],
        acc: Sequence[float],
        mag: Optional[Sequence[float]] = None,
    ) -> Attitude: ...
    def update_array(
        self,
        t_s: FloatArray,
        gyr: FloatArray,
        acc: FloatArray,
        mag: Optional[FloatArray] = None,
        frame: Literal["ned", "enu"] = "ned",
    ) -> OrientationArrays: ...
    def estimate(self) -> Attitude: ...
    def reset(self) -> None: ...

class QuaternionFilter(OrientationEstimator):
    def __init__(self, config: Optional[dict[str, Any]] = None) -> None: ...

class EulerDetector(OrientationEstimator):
    def __init__(self, config: Optional[dict[str, Any]] = None) -> None: ...

class VehicleRow(TypedDict):
    t_s: float
    north_m: float
    east_m: float
    heading_deg: float
    gnss_frame: bool

class VehicleArrays(TypedDict):
    t_s: FloatArray
    north_m: FloatArray
    east_m: FloatArray
    heading_deg: FloatArray
    heading_sigma_deg: FloatArray
    speed_mps: FloatArray
    distance_m: FloatArray
    gap: BoolArray
    gnss_frame: BoolArray

class VehicleEstimator:
    """The fused vehicle estimator (wheels or one vehicle distance, yaw gyro, compass,
    satellite fixes)."""
    def __init__(self, config: Optional[dict[str, Any]] = None) -> None: ...
    def update(
        self,
        t_s: float,
        dist_l_m: Optional[float] = None,
        dist_r_m: Optional[float] = None,
        gyr_z: Optional[float] = None,
        mag: Optional[tuple[float, float]] = None,
        dist_m: Optional[float] = None,
        gnss: Optional[tuple[float, ...]] = None,
    ) -> VehicleRow: ...
    def update_array(
        self,
        t_s: FloatArray,
        dist_l_m: Optional[FloatArray] = None,
        dist_r_m: Optional[FloatArray] = None,
        gyr_z: Optional[FloatArray] = None,
        mag: Optional[FloatArray] = None,
        dist_m: Optional[FloatArray] = None,
        gnss: Optional[FloatArray] = None,
    ) -> VehicleArrays: ...
    def calibration(self) -> dict[str, Any]: ...
    def reset(self) -> None: ...
    @staticmethod
    def priors(wheels: dict[str, Any], speeds: bool = False) -> dict[str, Any]: ...

class MagneticField:
    """The WMM2025 field at a place and date."""
    x_nt: float
    y_nt: float
    z_nt: float
    h_nt: float
    f_nt: float
    incl_deg: float
    decl_deg: float
    year: float
    def to_dict(self) -> dict[str, float]: ...

def field(lat_deg: float, lon_deg: float, year: float, alt_km: float = 0.0) -> MagneticField:
    """The World Magnetic Model 2025 field (as `truenorth field`)."""

class BroadRmse(TypedDict):
    total_deg: float
    heading_deg: float
    inclination_deg: float

def broad_rmse(
    estimate: FloatArray, reference: FloatArray, movement: BoolArray
) -> Optional[BroadRmse]:
    """BROAD's metric: RMSE of the total, heading and inclination error angles, degrees."""

class LogTopic(TypedDict):
    name: str
    kind: str
    messages: int

class LogStream(TypedDict):
    role: Literal["imu", "mag", "attitude", "odometry"]
    topic: str
    samples: int
    dropped: int
    rate_hz: float

class Log(TypedDict):
    format: Literal["PX4 ULog", "MCAP"]
    complete: bool
    time_origin_s: float
    topics: list[LogTopic]
    streams: list[LogStream]
    imu: dict[str, FloatArray]
    """`t_s` (N), `gyr_rps`, `acc_mps2`, `mag_uT` (N x 3; NaN rows: no reading)."""
    mag: dict[str, FloatArray]
    """`t_s` (M), `mag_uT` (M x 3), the magnetometer at its own rate."""
    attitude: dict[str, FloatArray]
    """`t_s` (K), `quaternion` (K x 4, qw qx qy qz, body -> NED)."""
    odometry: dict[str, FloatArray]
    """`t_s` (J), `velocity_mps` (J x 3, body axes), `yaw_rate_rps` (J, + turning right)."""
    gnss: dict[str, FloatArray]
    """`t_s`, `lat_deg`, `lon_deg`, `sigma_m`, `speed_mps`, `course_deg` (F each; NaN where
    not given): an MCAP's NavSatFix fixes (velocity from a twist topic in their frame) or a
    ULog's `vehicle_gps_position`/`sensor_gps`."""

def read_log(
    path: str | os.PathLike[str],
    imu_topic: Optional[str] = None,
    mag_topic: Optional[str] = None,
    attitude_topic: Optional[str] = None,
    odometry_topic: Optional[str] = None,
    accept_incomplete: bool = False,
    gnss_topic: Optional[str] = None,
    gnss_velocity_topic: Optional[str] = None,
) -> Log:
    """A PX4 ULog or ROS 2 MCAP log as arrays per stream (seconds, FRD body axes, rad/s,
    m/s^2, uT), as the `truenorth` command reads it; `mag_topic="none"`: no magnetometer."""

class Finding(TypedDict):
    """What contradicts a recording's declared units or the gyro's axes."""

    kind: Literal["units", "axes", "faults"]
    seen: str
    fix: dict[str, Any]
    row: Optional[int]

class GnssDelay(TypedDict):
    """How late a drive's fixes are stamped, by their course's turns against the gyro's."""

    lag_s: float
    sigma_s: float
    pairs: int
    misfit: float
    excess_at_assumed: Optional[float]

def check_gnss_delay(
    t_s: FloatArray,
    gyr_z: FloatArray,
    lat_deg: FloatArray,
    lon_deg: FloatArray,
    speed_mps: Optional[FloatArray] = None,
    course_deg: Optional[FloatArray] = None,
    assumed_s: float = 0.1,
) -> Optional[GnssDelay]:
    """How long after their epoch the fixes are stamped (rows of `t_s`; NaN latitude where a
    row has no fix; any gyro unit and sign), or None where the turns do not tell;
    `excess_at_assumed` beyond 25 refutes `assumed_s` at 5 sigma, as `truenorth drive` warns."""

def check_imu(
    t_s: FloatArray,
    gyr: FloatArray,
    acc: FloatArray,
    mag: Optional[FloatArray] = None,
    gyro_unit: Literal["rad/s", "deg/s"] = "rad/s",
    acc_unit: Literal["m/s2", "g", "mg"] = "m/s2",
) -> list[Finding]:
    """The gyro's and accelerometer's units and the gyro's axes checked against the physics
    (one gravity at rest; gravity's and the field's directions turning as the gyro says): the
    checks `truenorth orientation` refuses by. Empty when nothing contradicts them; `fix`
    holds `gyro_unit`, `acc_unit`, `gyro_axes` (`x=-y,y=x,z=z`), `mag_axes` with
    `mag_axes_rotation` (a mirrored or turned magnetometer) or `advice` (no unit fits).
    Readings no live sensor gives (clipped, frozen, a zero field) follow with `kind`
    `"faults"` and `row` the index of the run's first reading."""
