//! What a command's input options say (flattened into each command's arguments): how a CSV
//! is split and named, and what is read from a flight or robot log.

use super::columns::{AxisConvention, ColumnMapping, Naming};
use super::logs::options::LogOptions;
use super::records::Delimiter;

/// The options every command that reads a CSV takes (flatten into its arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct InputOptions {
    /// Field delimiter: `auto` (the most frequent of `,` `;` tab in the first line, else runs
    /// of blanks), `,`, `;`, `tab`, `whitespace` (runs of spaces and tabs), or any single
    /// character.
    #[arg(long, value_name = "DELIM", default_value = "auto")]
    pub delimiter: Delimiter,
    /// The input has no header row: its columns are named `1`, `2`, ... (map them with
    /// --column, e.g. `--column mag_x=1,mag_y=2,mag_z=3`).
    #[arg(long)]
    pub no_header: bool,
    /// Read column NAME from the header HEADER (repeat the flag, or separate pairs with
    /// commas); `-HEADER` negates it. NAME is a column truenorth reads (`t_s`, `mag_x`,
    /// `acc_z`, ...) in the sensor's own axes, before --axes. Headers match without regard
    /// to case. Example: `--column t_s=time,mag_x=mx,mag_y=my,mag_z=-mz`.
    #[arg(long = "column", value_name = "NAME=HEADER", value_delimiter = ',')]
    pub columns: Vec<ColumnMapping>,
    /// Which way the sensor's x, y and z axes point: three letters from f/b (forward,
    /// back), r/l (right, left), d/u (down, up). truenorth works in x forward, y right, z
    /// down (`frd`, the default); a sensor with x forward, y left, z up is `flu`, and its
    /// readings are turned into frd before anything else (mag_, acc_ and gyr_ columns).
    #[arg(long, value_name = "XYZ", default_value = "frd")]
    pub axes: AxisConvention,
    /// What to read from a PX4 ULog or ROS 2 MCAP input (found by its magic number).
    #[command(flatten)]
    pub log: LogOptions,
}

impl InputOptions {
    /// How requested names are found in the file: the mapping and the axis convention.
    pub fn naming(&self) -> Naming<'_> {
        Naming {
            mappings: &self.columns,
            axes: self.axes,
        }
    }
}
