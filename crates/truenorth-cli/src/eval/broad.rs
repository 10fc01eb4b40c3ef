//! `truenorth eval broad DIR`: run an orientation method over the BROAD benchmark's trials
//! (Laidig, Caruso, Cereatti & Seel, *Data* 6(7):72, 2021) and score it with BROAD's own
//! metric.
//!
//! The metric (BROAD's `example_code/broad_utils.py`) is the library's [`broad_rmse`]: per
//! trial the RMSE of the total, heading and inclination error angles over the samples of the
//! movement phase whose reference is valid; per group the mean of the trial RMSEs
//! ([`BroadRmse::mean`]).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::Serialize;
use truenorth::checks::{AccUnit, GyroUnit};
use truenorth::core::ImuSample;
use truenorth::fusion::orientation::{BroadRmse, broad_rmse};

use crate::io::{CliError, CliResult, InputOptions, InputPath, ReadSpec, RowReader};
use crate::io::{errln, outln, write_stderr};
use crate::registry::{OrientationMethod, Timing};
use truenorth::core::ned_to_enu;

/// Arguments of `truenorth eval broad`.
///
/// DIR is BROAD's folder (with `trials/`) or the trial folder itself: one
/// `NN_<name>.csv.gz` per trial with the columns `t_s, gyr_x..z (rad/s), acc_x..z (m/s²),
/// mag_x..z (µT), qw, qx, qy, qz` (reference orientation, sensor → ENU with magnetic
/// north; NaN where invalid) and `movement` (1 in the scored phase). A trial whose name
/// contains `undisturbed` belongs to the undisturbed group, every other to the disturbed
/// group. Prints per-trial and per-group total, heading and inclination RMSE in degrees
/// (with `--json`, one JSON document instead); progress goes to stderr.
///
/// Example: `truenorth eval broad ../shared/data/broad --method quaternion --no-mag`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// BROAD's folder or its `trials/` folder.
    pub dir: PathBuf,
    /// Orientation method.
    #[arg(long, value_enum, default_value = "quaternion")]
    pub method: OrientationMethod,
    /// Ignore the magnetometer (6-D: only inclination is meaningful).
    #[arg(long)]
    pub no_mag: bool,
    /// What a gyro sample's rate stands for (quaternion filter).
    #[arg(long, value_enum, default_value = "interval-mean")]
    pub gyro_timing: Timing,
    /// Print one JSON document (per-trial and per-group figures) instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Unit of the gyro columns (BROAD's own: rad/s).
    #[arg(long, value_enum, value_name = "UNIT", default_value = "rad/s")]
    pub gyro_unit: GyroUnit,
    /// Unit of the accelerometer columns (BROAD's own: m/s2).
    #[arg(long, value_enum, value_name = "UNIT", default_value = "m/s2")]
    pub acc_unit: AccUnit,
    /// How to read the trial files (delimiter, header, column names, axes), as for the
    /// other commands.
    #[command(flatten)]
    pub input_options: InputOptions,
}

/// One trial as read from its file.
struct Trial {
    samples: Vec<ImuSample>,
    reference: Vec<Option<UnitQuaternion<f64>>>,
    movement: Vec<bool>,
}

#[derive(Serialize)]
struct TrialResult {
    trial: String,
    group: &'static str,
    #[serde(flatten)]
    rmse: BroadRmse,
}

#[derive(Serialize)]
struct GroupResult {
    group: &'static str,
    trials: usize,
    #[serde(flatten)]
    mean: BroadRmse,
}

#[derive(Serialize)]
struct Report {
    method: String,
    use_mag: bool,
    trials: Vec<TrialResult>,
    groups: Vec<GroupResult>,
}

/// Runs the subcommand: each trial in name order, then the group means, printed as tables
/// or as one JSON document.
pub fn run(args: &Args) -> CliResult {
    args.input_options.log.refuse_for_csv_only("eval broad")?;
    let paths = trial_paths(&args.dir)?;
    let mut progress = Progress::new(paths.len());
    let mut results = Vec::with_capacity(paths.len());
    for p in &paths {
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().replace(".csv.gz", ""))
            .unwrap_or_default();
        progress.show(&name);
        results.push(evaluate_trial(args, p, name)?);
    }
    progress.finish();
    let groups = group_means(&results);
    let report = Report {
        method: format!("{:?}", args.method),
        use_mag: !args.no_mag,
        trials: results,
        groups,
    };
    if args.json {
        let text = serde_json::to_string_pretty(&report)
            .map_err(|e| CliError::msg(format!("cannot write JSON: {e}")))?;
        outln!("{text}")?;
    } else {
        print_tables(&report, args.no_mag)?;
    }
    Ok(())
}

/// The trial files (`*.csv.gz`) of BROAD's folder or its `trials/` folder, sorted.
fn trial_paths(dir: &Path) -> CliResult<Vec<PathBuf>> {
    let dir = if dir.join("trials").is_dir() {
        dir.join("trials")
    } else {
        dir.to_path_buf()
    };
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| CliError::file(&dir, format!("cannot read the folder: {e}")))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(".csv.gz"))
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(CliError::file(
            &dir,
            "no BROAD trial files (*.csv.gz) here; give BROAD's folder or its trials/ folder",
        ));
    }
    Ok(paths)
}

/// Runs the method over one trial (a fresh estimator, as BROAD scores each trial) and
/// scores it.
fn evaluate_trial(args: &Args, path: &Path, name: String) -> CliResult<TrialResult> {
    let trial = read_trial(path, args)?;
    let mut method = args
        .method
        .estimator(!args.no_mag, args.gyro_timing)
        .map_err(|e| CliError::msg(e.to_string()))?;
    let to_enu = ned_to_enu();
    let mut q = Vec::with_capacity(trial.samples.len());
    for (k, s) in trial.samples.iter().enumerate() {
        let r = method
            .update(s)
            .map_err(|e| CliError::row(path, k + 2, e.to_string()))?;
        q.push(to_enu * r.attitude);
    }
    let rmse = broad_rmse(&q, &trial.reference, &trial.movement)
        .ok_or_else(|| CliError::file(path, "no scored sample (movement phase empty)"))?;
    let group = if name.contains("undisturbed") {
        "undisturbed"
    } else {
        "disturbed"
    };
    Ok(TrialResult {
        trial: name,
        group,
        rmse,
    })
}

/// The mean of the trial RMSEs per group (undisturbed, disturbed, all), groups without a
/// trial left out.
fn group_means(results: &[TrialResult]) -> Vec<GroupResult> {
    ["undisturbed", "disturbed", "all"]
        .into_iter()
        .filter_map(|g| {
            let members = results
                .iter()
                .filter(|r| g == "all" || r.group == g)
                .map(|r| &r.rmse);
            BroadRmse::mean(members.clone()).map(|mean| GroupResult {
                group: g,
                trials: members.count(),
                mean,
            })
        })
        .collect()
}

/// The per-trial table and the group means.
fn print_tables(report: &Report, no_mag: bool) -> CliResult {
    outln!(
        "BROAD, {} trials, method {}{} (RMSE in degrees, BROAD's metric)",
        report.trials.len(),
        report.method,
        if no_mag { ", 6-D" } else { "" }
    )?;
    outln!(
        "{:<46} {:>8} {:>8} {:>12}",
        "trial",
        "total",
        "heading",
        "inclination"
    )?;
    for r in &report.trials {
        outln!(
            "{:<46} {:8.2} {:8.2} {:12.2}",
            r.trial,
            r.rmse.total_deg,
            r.rmse.heading_deg,
            r.rmse.inclination_deg
        )?;
    }
    outln!()?;
    for g in &report.groups {
        outln!(
            "{:<46} {:8.2} {:8.2} {:12.2}",
            format!("mean, {} ({} trials)", g.group, g.trials),
            g.mean.total_deg,
            g.mean.heading_deg,
            g.mean.inclination_deg
        )?;
    }
    Ok(())
}

/// The columns of a trial after `t_s`: the IMU's, the reference quaternion and the
/// movement flag.
const TRIAL_COLUMNS: [&str; 14] = [
    "gyr_x", "gyr_y", "gyr_z", "acc_x", "acc_y", "acc_z", "mag_x", "mag_y", "mag_z", "qw", "qx",
    "qy", "qz", "movement",
];

/// Reads one trial CSV (gzip or not) through the shared reader under the input options:
/// every column must be there; a `NaN` cell (an invalid reference) reads as NaN.
fn read_trial(path: &Path, args: &Args) -> CliResult<Trial> {
    // Optional only so that NaN cells read as NaN; their presence is checked below.
    let spec = ReadSpec::new(&["t_s"]).optional(&TRIAL_COLUMNS);
    let mut rows = RowReader::open(&InputPath::new(path), &args.input_options, &spec)?;
    let mut idx = [0usize; 15];
    for (i, name) in std::iter::once("t_s").chain(TRIAL_COLUMNS).enumerate() {
        idx[i] = rows
            .index(name)
            .ok_or_else(|| CliError::row(path, 1, format!("missing column `{name}`")))?;
    }
    let (to_rps, to_mps2) = (args.gyro_unit.to_rad_per_s(), args.acc_unit.to_mps2());
    let mut t = Trial {
        samples: Vec::new(),
        reference: Vec::new(),
        movement: Vec::new(),
    };
    while let Some(row) = rows.next_row()? {
        let v = idx.map(|i| row[i]);
        t.samples.push(ImuSample::new_9d(
            v[0],
            Vector3::new(v[1], v[2], v[3]) * to_rps,
            Vector3::new(v[4], v[5], v[6]) * to_mps2,
            Vector3::new(v[7], v[8], v[9]),
        ));
        let q = Quaternion::new(v[10], v[11], v[12], v[13]);
        t.reference.push(
            (q.coords.iter().all(|x| x.is_finite()) && q.norm() > 0.0)
                .then(|| UnitQuaternion::from_quaternion(q)),
        );
        t.movement.push(v[14] > 0.5);
    }
    Ok(t)
}

/// A progress bar on stderr (redrawn on a terminal, one line per trial otherwise).
struct Progress {
    total: usize,
    done: usize,
    terminal: bool,
}

impl Progress {
    fn new(total: usize) -> Self {
        Self {
            total,
            done: 0,
            terminal: std::io::stderr().is_terminal(),
        }
    }

    fn show(&mut self, name: &str) {
        const WIDTH: usize = 30;
        let filled = WIDTH * self.done / self.total;
        let bar = format!(
            "[{}{}] {}/{} {name}",
            "#".repeat(filled),
            ".".repeat(WIDTH - filled),
            self.done + 1,
            self.total
        );
        if self.terminal {
            write_stderr(format_args!("\r\x1b[2K{bar}"));
        } else {
            errln!("{bar}");
        }
        self.done += 1;
    }

    fn finish(&self) {
        if self.terminal {
            errln!("\r\x1b[2K[{}] done", "#".repeat(30));
        }
    }
}
