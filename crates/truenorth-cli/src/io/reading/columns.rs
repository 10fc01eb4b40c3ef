//! How a file's columns become the names truenorth reads: a header looked up without regard
//! to case, a column mapping (`NAME=HEADER`, `-HEADER` to negate), and the sensor's axis
//! convention (which way its x, y and z axes point on the body).

use std::fmt;
use std::str::FromStr;

use std::path::Path;

use super::number_parse::{parse_number, value_problem};
use super::records::shown;
use crate::io::CliError;
use crate::io::closest_name::likely_meant;

/// The sensor vectors whose `_x`, `_y`, `_z` columns the axis convention turns into body
/// axes.
pub const VECTOR_STEMS: [&str; 3] = ["mag", "acc", "gyr"];

/// Every sensor column some command reads (body axes, after `--axes` and `--column`): with
/// `t_s`, the names a `--column` may give.
pub const SENSOR_COLUMNS: [&str; 24] = [
    "gyr_x",
    "gyr_y",
    "gyr_z",
    "acc_x",
    "acc_y",
    "acc_z",
    "mag_x",
    "mag_y",
    "mag_z",
    "dist_l_m",
    "dist_r_m",
    "speed_l_mps",
    "speed_r_mps",
    "speed_fl_mps",
    "speed_fr_mps",
    "speed_rl_mps",
    "speed_rr_mps",
    "dist_m",
    "speed_mps",
    "lat_deg",
    "lon_deg",
    "gnss_sigma_m",
    "gnss_speed_mps",
    "gnss_course_deg",
];

/// The optional columns of a drive log.
pub(crate) const DRIVE: [&str; 18] = [
    "dist_l_m",
    "dist_r_m",
    "speed_l_mps",
    "speed_r_mps",
    "speed_fl_mps",
    "speed_fr_mps",
    "speed_rl_mps",
    "speed_rr_mps",
    "dist_m",
    "speed_mps",
    "gyr_z",
    "mag_x",
    "mag_y",
    "lat_deg",
    "lon_deg",
    "gnss_sigma_m",
    "gnss_speed_mps",
    "gnss_course_deg",
];

/// The columns of the CSV contract (ARCHITECTURE.md, "CLI contract") by name.
const CONTRACT_COLUMNS: [&str; 20] = [
    "t_s",
    "mag_x",
    "mag_y",
    "mag_z",
    "acc_x",
    "acc_y",
    "acc_z",
    "gyr_x",
    "gyr_y",
    "gyr_z",
    "dist_l_m",
    "dist_r_m",
    "speed_l_mps",
    "speed_r_mps",
    "speed_fl_mps",
    "speed_fr_mps",
    "speed_rl_mps",
    "speed_rr_mps",
    "speed_mps",
    "dist_m",
];

/// `NAME=HEADER` or `NAME=-HEADER`: read the column truenorth calls NAME from the file's
/// column HEADER, negated with `-`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ColumnMapping {
    /// The name truenorth reads (`mag_x`, `t_s`, ...), lower case.
    pub name: String,
    /// The file's header for it.
    pub header: String,
    /// Whether to negate the values.
    pub negate: bool,
}

impl FromStr for ColumnMapping {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let (name, header) = s
            .split_once('=')
            .ok_or_else(|| format!("`{s}` is not NAME=HEADER (e.g. mag_x=mx)"))?;
        let (name, header) = (name.trim(), header.trim());
        let (negate, header) = match header.strip_prefix('-') {
            Some(h) => (true, h.trim()),
            None => (false, header),
        };
        if name.is_empty() || header.is_empty() {
            return Err(format!("`{s}` is not NAME=HEADER (e.g. mag_x=mx)"));
        }
        Ok(Self {
            name: name.to_ascii_lowercase(),
            header: header.to_string(),
            negate,
        })
    }
}

/// The direction of each sensor axis on the body: for sensor axis `i`, the body axis
/// (0 forward, 1 right, 2 down) it lies along and its sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AxisConvention {
    /// For each sensor axis x, y, z: (body axis, +1 or −1).
    along: [(usize, i8); 3],
}

impl Default for AxisConvention {
    fn default() -> Self {
        Self {
            along: [(0, 1), (1, 1), (2, 1)],
        }
    }
}

impl FromStr for AxisConvention {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || {
            format!(
                "`{s}` is not an axis convention: three letters, one of f/b, one of r/l, one of d/u, for the sensor's x, y, z (e.g. frd, flu)"
            )
        };
        let letters: Vec<char> = s.trim().to_ascii_lowercase().chars().collect();
        if letters.len() != 3 {
            return Err(bad());
        }
        let mut along = [(0usize, 1i8); 3];
        let mut seen = [false; 3];
        for (i, c) in letters.iter().enumerate() {
            let (axis, sign) = match c {
                'f' => (0, 1),
                'b' => (0, -1),
                'r' => (1, 1),
                'l' => (1, -1),
                'd' => (2, 1),
                'u' => (2, -1),
                _ => return Err(bad()),
            };
            if seen[axis] {
                return Err(bad());
            }
            seen[axis] = true;
            along[i] = (axis, sign);
        }
        Ok(Self { along })
    }
}

impl fmt::Display for AxisConvention {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for &(axis, sign) in &self.along {
            let c = match (axis, sign > 0) {
                (0, true) => 'f',
                (0, false) => 'b',
                (1, true) => 'r',
                (1, false) => 'l',
                (_, true) => 'd',
                (_, false) => 'u',
            };
            write!(f, "{c}")?;
        }
        Ok(())
    }
}

impl AxisConvention {
    /// For body axis `body` (0 forward, 1 right, 2 down): the sensor axis along it and the
    /// sign that turns the sensor's reading into the body's.
    pub fn source_of(&self, body: usize) -> (usize, f64) {
        let i = self
            .along
            .iter()
            .position(|&(axis, _)| axis == body)
            .unwrap_or(body);
        (i, f64::from(self.along[i].1))
    }

    /// Whether the convention is a rotation (right-handed like frd) rather than a mirror
    /// image: a left-handed one reverses every turn.
    pub fn is_right_handed(&self) -> bool {
        // The sign of the signed permutation: the permutation's parity times the signs.
        let p = self.along.map(|(a, _)| a);
        let inversions = (0..3)
            .flat_map(|i| (i + 1..3).map(move |j| (i, j)))
            .filter(|&(i, j)| p[i] > p[j])
            .count();
        let signs: i8 = self.along.iter().map(|&(_, s)| s).product();
        (if inversions % 2 == 0 { 1 } else { -1 }) * signs > 0
    }

    /// Turns a sensor-axes vector into body axes.
    #[cfg(test)]
    pub fn to_body(self, sensor: [f64; 3]) -> [f64; 3] {
        core::array::from_fn(|b| {
            let (i, s) = self.source_of(b);
            s * sensor[i]
        })
    }
}

/// How a requested name is found in a file: the column mapping (`--column`) and the
/// sensor's axis convention (`--axes`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Naming<'a> {
    /// `NAME=HEADER` mappings; the last one for a name wins.
    pub mappings: &'a [ColumnMapping],
    /// Which way the sensor's axes point.
    pub axes: AxisConvention,
}

/// The column of the file that a requested name is read from.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnSource {
    /// The requested name (in body axes).
    pub name: String,
    /// The header it is read from.
    pub header: String,
    /// Its 0-based position in a row.
    pub index: usize,
    /// +1, or −1 to negate (axis convention times mapping).
    pub sign: f64,
}

impl ColumnSource {
    /// The number in `cell`, this column's text on one row, before the sign (an empty cell
    /// is no reading, NaN, where the column is not `required`); what is wrong with it
    /// otherwise.
    #[inline]
    pub fn read(&self, cell: &[u8], required: bool) -> Result<f64, String> {
        let v = if cell.is_empty() && !required {
            f64::NAN
        } else {
            parse_number(cell).ok_or_else(|| {
                format!(
                    "column `{}`: `{}` is not a number",
                    self.header,
                    shown(cell)
                )
            })?
        };
        match value_problem(v, required) {
            Some(problem) => Err(format!(
                "column `{}`: `{}` {problem}",
                self.header,
                shown(cell)
            )),
            None => Ok(v),
        }
    }

    /// The error for row `number` of `path`, where this column, which must increase, reads
    /// `t`, not after the previous row's `previous`.
    pub fn not_after(&self, path: &Path, number: usize, t: f64, previous: f64) -> CliError {
        CliError::row(
            path,
            number,
            format!(
                "{} = {t} does not come after the previous row's {previous}; sort by time and drop duplicates",
                self.name
            ),
        )
    }
}

/// The file's header, looked up without regard to case or surrounding blanks.
#[derive(Debug, Clone)]
pub struct Header {
    names: Vec<String>,
}

/// Why a name could not be found in the header.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum LookupError {
    /// No column has this header.
    Missing(String),
    /// Two or more columns have this header (1-based positions).
    Duplicate(String, Vec<usize>),
}

impl Header {
    /// A header from its fields (a leading byte-order mark is dropped).
    pub fn new<'a>(fields: impl IntoIterator<Item = &'a str>) -> Self {
        Self {
            names: fields
                .into_iter()
                .map(|f| f.trim_start_matches('\u{feff}').trim().to_string())
                .collect(),
        }
    }

    /// The header of a file without one: `1`, `2`, ... `n`.
    pub fn numbered(n: usize) -> Self {
        Self {
            names: (1..=n).map(|k| k.to_string()).collect(),
        }
    }

    /// The names, as written.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The position of `name` (compared without regard to ASCII case).
    pub fn find(&self, name: &str) -> Result<usize, LookupError> {
        let hits: Vec<usize> = self
            .names
            .iter()
            .enumerate()
            .filter(|(_, h)| h.eq_ignore_ascii_case(name.trim()))
            .map(|(i, _)| i)
            .collect();
        match hits.as_slice() {
            [] => Err(LookupError::Missing(name.to_string())),
            [i] => Ok(*i),
            _ => Err(LookupError::Duplicate(
                name.to_string(),
                hits.iter().map(|i| i + 1).collect(),
            )),
        }
    }

    /// Where the requested body-axes column `name` comes from under `naming`: through the
    /// axis convention (a `mag_`, `acc_` or `gyr_` vector component comes from the sensor
    /// axis along that body axis), then the column mapping. `Ok(None)` when the column is
    /// absent; an error string (naming what was looked for) when it is named twice, or
    /// mapped to a header that is not there.
    pub fn resolve(&self, name: &str, naming: Naming<'_>) -> Result<Option<ColumnSource>, String> {
        let (sensor_name, axis_sign) = sensor_name(name, &naming.axes);
        let mapping = naming
            .mappings
            .iter()
            .rev()
            .find(|m| m.name.eq_ignore_ascii_case(&sensor_name));
        let (header, map_sign) = match mapping {
            Some(m) => (m.header.as_str(), if m.negate { -1.0 } else { 1.0 }),
            None => (sensor_name.as_str(), 1.0),
        };
        let via = if sensor_name == name {
            String::new()
        } else {
            format!(" (body `{name}` under --axes {})", naming.axes)
        };
        match self.find(header) {
            Ok(index) => Ok(Some(ColumnSource {
                name: name.to_string(),
                header: self.names[index].clone(),
                index,
                sign: axis_sign * map_sign,
            })),
            Err(LookupError::Missing(_)) if mapping.is_some() => Err(format!(
                "--column {sensor_name}={header}: no column `{header}`{via}{} (header has: {})",
                self.did_you_mean(header),
                self.names.join(",")
            )),
            Err(LookupError::Missing(_)) => Ok(None),
            Err(LookupError::Duplicate(h, at)) => Err(format!(
                "the header names column `{h}`{via} {} times (columns {}); rename or drop the extra ones",
                at.len(),
                at.iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        }
    }

    /// The message for a required column that is absent.
    pub fn missing(&self, name: &str, naming: Naming<'_>) -> String {
        let (sensor_name, _) = sensor_name(name, &naming.axes);
        let via = if sensor_name == name {
            String::new()
        } else {
            format!(" (body `{name}` under --axes {})", naming.axes)
        };
        format!(
            "missing column `{sensor_name}`{via}{} (header has: {}); name it with --column {sensor_name}=HEADER",
            self.did_you_mean(&sensor_name),
            self.names.join(",")
        )
    }

    /// ` (did you mean `HEADER`?)` when a header looks like a misspelling of `name`. A
    /// header that is itself a column of the contract (`mag_x` beside a missing `mag_z`)
    /// is that column, not a misspelling.
    fn did_you_mean(&self, name: &str) -> String {
        let names: Vec<&str> = self
            .names
            .iter()
            .map(String::as_str)
            .filter(|h| !CONTRACT_COLUMNS.iter().any(|c| c.eq_ignore_ascii_case(h)))
            .collect();
        likely_meant(name, &names)
            .map(|h| format!(" (did you mean `{h}`?)"))
            .unwrap_or_default()
    }
}

/// The sensor-axes name that the body-axes `name` is read from, and the sign.
fn sensor_name(name: &str, axes: &AxisConvention) -> (String, f64) {
    let lower = name.to_ascii_lowercase();
    for stem in VECTOR_STEMS {
        if let Some(rest) = lower.strip_prefix(stem).and_then(|r| r.strip_prefix('_')) {
            let body = match rest {
                "x" => 0,
                "y" => 1,
                "z" => 2,
                _ => continue,
            };
            let (i, sign) = axes.source_of(body);
            return (format!("{stem}_{}", ['x', 'y', 'z'][i]), sign);
        }
    }
    (lower, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A column mapping and an axis convention, as the options give them.
    struct Opts(Vec<ColumnMapping>, AxisConvention);

    impl Opts {
        fn naming(&self) -> Naming<'_> {
            Naming {
                mappings: &self.0,
                axes: self.1,
            }
        }
    }

    fn opts(axes: &str, columns: &[&str]) -> Opts {
        Opts(
            columns.iter().map(|c| c.parse().unwrap()).collect(),
            axes.parse().unwrap(),
        )
    }

    #[test]
    fn a_misspelt_header_is_suggested_and_a_contract_column_is_not() {
        let h = Header::new(["t_s", "mag_x", "mag_yy"]);
        let m = h.missing("mag_y", Naming::default());
        assert!(
            m.contains("missing column `mag_y` (did you mean `mag_yy`?)"),
            "{m}"
        );
        let h = Header::new(["t_s", "mag_x", "mag_y"]);
        let m = h.missing("mag_z", Naming::default());
        assert!(!m.contains("did you mean"), "{m}");
        let e = h
            .resolve("mag_x", opts("frd", &["mag_x=mag_xx"]).naming())
            .unwrap_err();
        assert!(!e.contains("did you mean"), "{e}");
        let h = Header::new(["time", "MagX", "MagY"]);
        let e = h
            .resolve("mag_x", opts("frd", &["mag_x=magx_"]).naming())
            .unwrap_err();
        assert!(e.contains("(did you mean `MagX`?)"), "{e}");
    }

    #[test]
    fn headers_match_without_case_and_duplicates_are_named() {
        let h = Header::new(["\u{feff}T_s", " Mag_X ", "mag_y", "MAG_Y"]);
        assert_eq!(h.find("t_s"), Ok(0));
        assert_eq!(h.find("mag_x"), Ok(1));
        assert_eq!(
            h.find("mag_y"),
            Err(LookupError::Duplicate("mag_y".into(), vec![3, 4]))
        );
        let e = h.resolve("mag_y", Naming::default()).unwrap_err();
        assert!(e.contains("2 times") && e.contains("columns 3, 4"), "{e}");
        assert_eq!(h.resolve("mag_z", Naming::default()), Ok(None));
    }

    #[test]
    fn mapping_and_negation() {
        let h = Header::new(["time", "mx", "my", "mz"]);
        let o = opts("frd", &["t_s=TIME", "mag_x=mx", "mag_z=-mz"]);
        let o = o.naming();
        let t = h.resolve("t_s", o).unwrap().unwrap();
        assert_eq!((t.index, t.sign), (0, 1.0));
        let z = h.resolve("mag_z", o).unwrap().unwrap();
        assert_eq!((z.index, z.sign), (3, -1.0));
        let bad = opts("frd", &["mag_y=nope"]);
        assert!(
            h.resolve("mag_y", bad.naming())
                .unwrap_err()
                .contains("no column `nope`")
        );
        assert!("mag_x".parse::<ColumnMapping>().is_err());
        assert!("=x".parse::<ColumnMapping>().is_err());
    }

    #[test]
    fn flu_turns_into_frd() {
        // x forward, y left, z up: body y = −sensor y, body z = −sensor z.
        let a: AxisConvention = "flu".parse().unwrap();
        assert_eq!(a.to_body([1.0, 2.0, 3.0]), [1.0, -2.0, -3.0]);
        assert!(a.is_right_handed());
        let h = Header::new(["mag_x", "mag_y", "mag_z"]);
        let y = h
            .resolve("mag_y", opts("flu", &[]).naming())
            .unwrap()
            .unwrap();
        assert_eq!((y.index, y.sign), (1, -1.0));
        // x right, y forward, z up.
        let r: AxisConvention = "rfu".parse().unwrap();
        assert_eq!(r.to_body([1.0, 2.0, 3.0]), [2.0, 1.0, -3.0]);
        assert!(r.is_right_handed());
        assert!(!"fru".parse::<AxisConvention>().unwrap().is_right_handed());
        for bad in ["ff", "ffd", "xyz", "frdd"] {
            assert!(bad.parse::<AxisConvention>().is_err(), "{bad}");
        }
    }

    proptest! {
        /// Every valid convention maps the three body axes onto three distinct sensor axes,
        /// its Display parses back to it, and `to_body` preserves the norm.
        #[test]
        fn conventions_are_signed_permutations(
            perm in Just([0usize, 1, 2]).prop_shuffle(),
            signs in proptest::array::uniform3(proptest::bool::ANY),
            v in proptest::array::uniform3(-1e3f64..1e3),
        ) {
            let letters: String = (0..3).map(|i| {
                let pair = [['f', 'b'], ['r', 'l'], ['d', 'u']][perm[i]];
                pair[usize::from(signs[i])]
            }).collect();
            let a: AxisConvention = letters.parse().unwrap();
            prop_assert_eq!(a.to_string(), letters);
            let b = a.to_body(v);
            let n = |x: [f64; 3]| x.iter().map(|c| c * c).sum::<f64>();
            prop_assert!((n(b) - n(v)).abs() <= 1e-9 * (1.0 + n(v)));
            let mut used: Vec<usize> = (0..3).map(|k| a.source_of(k).0).collect();
            used.sort_unstable();
            prop_assert_eq!(used, vec![0, 1, 2]);
        }
    }
}
