//! Where a ULog message format keeps the fields the reader needs: each located by name and
//! type once per format (a byte offset and a scalar type), then read from every message of
//! that format without parsing it whole.

use px4_ulog::stream_parser::model::{FlattenedFieldType, FlattenedFormat};

/// Degrees per unit of an integer latitude or longitude (`lat`, `lon` in 10⁻⁷ degrees).
const DEG_PER_E7: f64 = 1e-7;

/// A numeric field located by the reader: its byte offset in the message and its type.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Num {
    F32(usize),
    F64(usize),
    U64(usize),
    I32(usize),
    U8(usize),
}

impl Num {
    /// The value, or `None` when the message is shorter than its format says.
    pub(crate) fn read(self, data: &[u8]) -> Option<f64> {
        fn bytes<const N: usize>(data: &[u8], at: usize) -> Option<[u8; N]> {
            data.get(at..at.checked_add(N)?)?.try_into().ok()
        }
        Some(match self {
            Self::F32(at) => f64::from(f32::from_le_bytes(bytes(data, at)?)),
            Self::F64(at) => f64::from_le_bytes(bytes(data, at)?),
            // Microseconds since boot stay exact in f64 for 285 years.
            Self::U64(at) => u64::from_le_bytes(bytes(data, at)?) as f64,
            Self::I32(at) => f64::from(i32::from_le_bytes(bytes(data, at)?)),
            Self::U8(at) => f64::from(*data.get(at)?),
        })
    }
}

pub(crate) fn field(
    format: &FlattenedFormat,
    name: &str,
    types: &[FlattenedFieldType],
) -> Option<Num> {
    types.iter().find_map(|t| {
        let at = usize::from(format.get_field_offset(name, t.clone()).ok()?);
        Some(match t {
            FlattenedFieldType::Float => Num::F32(at),
            FlattenedFieldType::Double => Num::F64(at),
            FlattenedFieldType::UInt64 => Num::U64(at),
            FlattenedFieldType::UInt8 | FlattenedFieldType::Bool => Num::U8(at),
            _ => Num::I32(at),
        })
    })
}

pub(crate) const FLOATS: &[FlattenedFieldType] =
    &[FlattenedFieldType::Float, FlattenedFieldType::Double];

pub(crate) fn float(format: &FlattenedFormat, name: &str) -> Option<Num> {
    field(format, name, FLOATS)
}

pub(crate) fn array<const N: usize>(format: &FlattenedFormat, base: &str) -> Option<[Num; N]> {
    let mut out = [Num::F32(0); N];
    for (k, slot) in out.iter_mut().enumerate() {
        *slot = float(format, &format!("{base}[{k}]"))?;
    }
    Some(out)
}

pub(crate) fn read_all<const N: usize>(fields: &[Num; N], data: &[u8]) -> Option<[f64; N]> {
    let mut out = [0.0; N];
    for (o, f) in out.iter_mut().zip(fields) {
        *o = f.read(data)?;
    }
    Some(out)
}

/// The fields of one role in one message format, or why the format cannot serve it.
pub(crate) type Fields<F> = core::result::Result<F, String>;

pub(crate) struct ImuFields {
    pub(crate) gyr: [Num; 3],
    pub(crate) acc: [Num; 3],
}

pub(crate) struct MagFields {
    pub(crate) field: [Num; 3],
    /// `magnetometer_timestamp_relative` in `sensor_combined` (µs after `timestamp`).
    pub(crate) relative: Option<Num>,
}

/// A fix's fields: latitude and longitude with the degrees per unit they are in, the
/// horizontal accuracy and the fix type where the format has them.
pub(crate) struct GnssFields {
    pub(crate) lat_lon: [Num; 2],
    pub(crate) deg_per_unit: f64,
    pub(crate) eph: Option<Num>,
    pub(crate) fix_type: Option<Num>,
    /// Speed and course over ground (`vel_m_s`, `cog_rad`), where the format has both.
    pub(crate) velocity: Option<[Num; 2]>,
    /// `vel_ned_valid`: whether the velocity holds one.
    pub(crate) velocity_valid: Option<Num>,
}

pub(crate) fn gnss_fields(format: &FlattenedFormat) -> Fields<GnssFields> {
    let degrees = [
        field(format, "latitude_deg", &[FlattenedFieldType::Double]),
        field(format, "longitude_deg", &[FlattenedFieldType::Double]),
    ];
    let e7 = [field_i32(format, "lat"), field_i32(format, "lon")];
    let (lat_lon, deg_per_unit) = match (degrees, e7) {
        ([Some(lat), Some(lon)], _) => ([lat, lon], 1.0),
        (_, [Some(lat), Some(lon)]) => ([lat, lon], DEG_PER_E7),
        _ => {
            return Err(
                "it has neither `latitude_deg`/`longitude_deg` nor `lat`/`lon` fields".to_string(),
            );
        }
    };
    Ok(GnssFields {
        lat_lon,
        deg_per_unit,
        eph: float(format, "eph"),
        fix_type: field(format, "fix_type", &[FlattenedFieldType::UInt8]),
        velocity: float(format, "vel_m_s")
            .zip(float(format, "cog_rad"))
            .map(|(v, c)| [v, c]),
        velocity_valid: field(format, "vel_ned_valid", &[FlattenedFieldType::Bool]),
    })
}

pub(crate) fn imu_fields(format: &FlattenedFormat) -> Fields<ImuFields> {
    match (
        array(format, "gyro_rad"),
        array(format, "accelerometer_m_s2"),
    ) {
        (Some(gyr), Some(acc)) => Ok(ImuFields { gyr, acc }),
        _ => Err("it has no `gyro_rad[3]` and `accelerometer_m_s2[3]` fields".to_string()),
    }
}

pub(crate) fn mag_fields(format: &FlattenedFormat) -> Fields<MagFields> {
    if let Some(field) = array(format, "magnetometer_ga") {
        let relative = field_i32(format, "magnetometer_timestamp_relative");
        return Ok(MagFields { field, relative });
    }
    match (float(format, "x"), float(format, "y"), float(format, "z")) {
        (Some(x), Some(y), Some(z)) => Ok(MagFields {
            field: [x, y, z],
            relative: None,
        }),
        _ => Err("it has neither `magnetometer_ga[3]` nor `x`, `y`, `z` fields".to_string()),
    }
}

pub(crate) fn field_i32(format: &FlattenedFormat, name: &str) -> Option<Num> {
    field(format, name, &[FlattenedFieldType::Int32])
}

pub(crate) fn attitude_fields(format: &FlattenedFormat) -> Fields<[Num; 4]> {
    array(format, "q").ok_or_else(|| "it has no `q[4]` field".to_string())
}
