//! The fixes the checks find, in the command line's words: the `--gyro-unit`, `--acc-unit`,
//! `--mag-unit` or `--column` that reads the data right, composed with the options the file
//! was read with.

use truenorth::checks::{Finding, Fix, SignedPermutation};

use crate::io::reading::options::InputOptions;

/// Reads the yaw gyro (body z) with its sign flipped.
const FLIP_Z: SignedPermutation = SignedPermutation {
    source: [0, 1, 2],
    sign: [1, 1, -1],
};

/// `finding` as one line: its evidence, then what reads the data right, as options given
/// after `opts` (those the file was read with).
pub fn say(finding: &Finding, opts: &InputOptions) -> String {
    let seen = &finding.seen;
    match &finding.fix {
        Fix::GyroUnit(u) => format!("{seen}: pass --gyro-unit {}", u.name()),
        Fix::AccUnit(u) => format!("{seen}: pass --acc-unit {}", u.name()),
        Fix::MagUnit {
            likely,
            also,
            declared,
        } => {
            let others: String = also.iter().map(|u| format!(" (or {})", u.name())).collect();
            format!(
                "{seen}: the data are probably in {}{others} (--mag-unit {}), not {}",
                likely.name(),
                likely.name(),
                declared.name()
            )
        }
        Fix::GyroAxes(p) => format!(
            "{seen}: pass --column {} after the options given",
            shell_word(&fix_columns(p, opts))
        ),
        Fix::GyroZSign => format!(
            "{seen}: pass --column {}",
            shell_word(&fix_pair(&FLIP_Z, 2, opts))
        ),
        Fix::MagAxes { mirror, rotation } => format!(
            "{seen}: pass --column {} after the options given if an axis is negated or two swapped, or --column {} if the magnetometer is mounted turned",
            shell_word(&sensor_columns("mag", mirror, opts)),
            shell_word(&sensor_columns("mag", rotation, opts))
        ),
        Fix::Advice(advice) => format!("{seen}: {advice}"),
    }
}

/// The `--column` pairs that read the gyro as `fix` says under the options already given:
/// each body axis is read from a sensor column through `opts.axes` and a mapping, so the
/// fix composes with both (a later `--column` overrides an earlier one for the same name).
/// The value as the program takes it; [`shell_word`] quotes it for a command line.
pub fn fix_columns(fix: &SignedPermutation, opts: &InputOptions) -> String {
    sensor_columns("gyr", fix, opts)
}

/// [`fix_columns`] for the sensor whose columns are `stem_x`, `stem_y`, `stem_z`.
fn sensor_columns(stem: &str, fix: &SignedPermutation, opts: &InputOptions) -> String {
    let pairs: Vec<String> = (0..3).map(|b| pair(stem, fix, b, opts)).collect();
    pairs.join(",")
}

/// The one `--column` pair of [`fix_columns`] for body axis `b`.
pub fn fix_pair(fix: &SignedPermutation, b: usize, opts: &InputOptions) -> String {
    pair("gyr", fix, b, opts)
}

/// `stem_?=[-]HEADER` that reads body axis `b` as `fix` says.
fn pair(stem: &str, fix: &SignedPermutation, b: usize, opts: &InputOptions) -> String {
    let (name, _, axis_sign, _) = read_now(stem, b, opts);
    let (_, header, from_axis_sign, from_map_sign) = read_now(stem, fix.source[b], opts);
    // The signs are ±1, their own inverses: the new mapping's sign undoes the axis
    // convention's for this axis and carries the source's.
    let sign = axis_sign * f64::from(fix.sign[b]) * from_axis_sign * from_map_sign;
    let minus = if sign < 0.0 { "-" } else { "" };
    format!("{name}={minus}{header}")
}

/// How body axis `b` of the sensor `stem` is read under `opts`: the sensor column's name,
/// the header it is read from, the axis convention's sign and the mapping's.
fn read_now(stem: &str, b: usize, opts: &InputOptions) -> (String, String, f64, f64) {
    const AXES: [char; 3] = ['x', 'y', 'z'];
    let (i, axis_sign) = opts.axes.source_of(b);
    let name = format!("{stem}_{}", AXES[i]);
    let mapping = opts
        .columns
        .iter()
        .rev()
        .find(|m| m.name.eq_ignore_ascii_case(&name));
    let (header, map_sign) = mapping.map_or((name.clone(), 1.0), |m| {
        (m.header.clone(), if m.negate { -1.0 } else { 1.0 })
    });
    (name, header, axis_sign, map_sign)
}

/// `s` as one shell word: quoted when it holds anything but letters, digits and `_=-,./`.
pub fn shell_word(s: &str) -> String {
    if s.chars()
        .all(|c| c.is_ascii_alphanumeric() || "_=-,./".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fix_composes_with_the_axes_and_the_mapping() {
        let swap = SignedPermutation {
            source: [1, 0, 2],
            sign: [1, 1, 1],
        };
        assert_eq!(
            fix_columns(&swap, &InputOptions::default()),
            "gyr_x=gyr_y,gyr_y=gyr_x,gyr_z=gyr_z"
        );
        let flip_y = SignedPermutation {
            source: [0, 1, 2],
            sign: [1, -1, 1],
        };
        let opts = InputOptions {
            axes: "flu".parse().unwrap(),
            columns: vec!["gyr_y=Gyro Y".parse().unwrap()],
            ..InputOptions::default()
        };
        // Under flu body y is −sensor y; flipping it again reads sensor y as it is.
        let fix = fix_columns(&flip_y, &opts);
        assert_eq!(fix, "gyr_x=gyr_x,gyr_y=-Gyro Y,gyr_z=gyr_z");
        assert_eq!(shell_word(&fix), "'gyr_x=gyr_x,gyr_y=-Gyro Y,gyr_z=gyr_z'");
        assert_eq!(shell_word("it's"), r"'it'\''s'");
    }

    #[test]
    fn each_fix_is_said_as_the_option_that_reads_the_data_right() {
        use truenorth::checks::{AccUnit, GyroUnit, MagUnit};
        let opts = InputOptions::default();
        let said = |fix| say(&Finding::units("seen".into(), fix), &opts);
        assert_eq!(
            said(Fix::GyroUnit(GyroUnit::DegPerS)),
            "seen: pass --gyro-unit deg/s"
        );
        assert_eq!(said(Fix::AccUnit(AccUnit::G)), "seen: pass --acc-unit g");
        assert_eq!(said(Fix::GyroZSign), "seen: pass --column gyr_z=-gyr_z");
        assert_eq!(
            said(Fix::MagUnit {
                likely: MagUnit::Gauss,
                also: vec![MagUnit::MilliGauss],
                declared: MagUnit::MicroTesla
            }),
            "seen: the data are probably in G (or mG) (--mag-unit G), not uT"
        );
        let swap = SignedPermutation {
            source: [1, 0, 2],
            sign: [1, 1, 1],
        };
        assert_eq!(
            said(Fix::GyroAxes(swap)),
            "seen: pass --column gyr_x=gyr_y,gyr_y=gyr_x,gyr_z=gyr_z after the options given"
        );
        assert_eq!(
            said(Fix::Advice("divide by 3.6".into())),
            "seen: divide by 3.6"
        );
    }
}
