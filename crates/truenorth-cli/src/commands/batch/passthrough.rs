//! The command a batch runs on every file (what follows `--`): checked once before any file
//! is touched, then turned into each file's command line.

use std::ffi::OsString;
use std::path::Path;

use crate::io::{CliError, CliResult};

/// The commands that take one recording and write one output, and so can run per file.
pub const COMMANDS: [&str; 5] = ["calibrate", "heading", "orientation", "drive", "inspect"];

/// Options the batch supplies per file, or that name one more output per run (which every
/// file would write over): refused in the passthrough.
const SUPPLIED: [&str; 2] = ["--input", "--output"];
const SIDE_OUTPUTS: [&str; 2] = ["--plot", "--calibration-out"];

/// A checked passthrough command.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Passthrough {
    /// The command and its options, as given after `--`.
    pub words: Vec<String>,
}

impl Passthrough {
    /// Checks `words`: a per-file command first, no `--input`/`--output` nor a side output.
    pub fn new(words: &[String]) -> CliResult<Self> {
        let Some(command) = words.first() else {
            return Err(CliError::msg(
                "batch: give the command to run after `--`, e.g. `-- calibrate --method ellipsoid`",
            ));
        };
        if !COMMANDS.contains(&command.as_str()) {
            return Err(CliError::msg(format!(
                "batch: `{command}` cannot run per file; the commands that take one input file are {}",
                COMMANDS.join(", ")
            )));
        }
        for w in &words[1..] {
            let name = w.split('=').next().unwrap_or(w);
            if SUPPLIED.contains(&name) {
                return Err(CliError::msg(format!(
                    "batch: drop `{name}` after `--`: batch gives every file its own input and output (under --out)"
                )));
            }
            if SIDE_OUTPUTS.contains(&name) {
                return Err(CliError::msg(format!(
                    "batch: drop `{name}` after `--`: every file would write the same file"
                )));
            }
        }
        Ok(Self {
            words: words.to_vec(),
        })
    }

    /// The command's name (`calibrate`, …).
    pub fn command(&self) -> &str {
        &self.words[0]
    }

    /// The ending of the output's file name: `json` for a calibration and an `inspect
    /// --json` report, `txt` for an `inspect` table, `csv` for the others.
    pub fn output_suffix(&self) -> &'static str {
        match self.command() {
            "calibrate" => "json",
            "inspect" if self.words.iter().any(|w| w == "--json") => "json",
            "inspect" => "txt",
            _ => "csv",
        }
    }

    /// Whether the command writes its result on standard output (which the batch then
    /// writes to the output file) rather than to `--output`.
    pub fn writes_stdout(&self) -> bool {
        self.command() == "inspect"
    }

    /// The arguments of one file's run: the options as given, then the input and output
    /// (`--input=PATH`, so that a name starting with `-` is not taken for an option;
    /// `inspect` takes its file after `--`).
    pub fn arguments(&self, input: &Path, output: &Path) -> Vec<OsString> {
        let mut args: Vec<OsString> = self.words.iter().map(OsString::from).collect();
        if self.writes_stdout() {
            args.push("--".into());
            args.push(input.as_os_str().to_os_string());
        } else {
            let mut i = OsString::from("--input=");
            i.push(input);
            let mut o = OsString::from("--output=");
            o.push(output);
            args.push(i);
            args.push(o);
        }
        args
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<String> {
        s.split_whitespace().map(str::to_string).collect()
    }

    #[test]
    fn only_per_file_commands_without_their_own_files_pass() {
        assert!(Passthrough::new(&words("calibrate --method ellipse")).is_ok());
        let e = Passthrough::new(&words("field --lat 1")).unwrap_err();
        assert!(e.to_string().contains("cannot run per file"), "{e}");
        let e = Passthrough::new(&words("heading --output=x.csv")).unwrap_err();
        assert!(e.to_string().contains("drop `--output`"), "{e}");
        let e = Passthrough::new(&words("orientation --plot p.svg")).unwrap_err();
        assert!(e.to_string().contains("same file"), "{e}");
        assert!(Passthrough::new(&[]).is_err());
    }

    #[test]
    fn suffixes_and_arguments_follow_the_command() {
        let p = Passthrough::new(&words("inspect --json")).unwrap();
        assert_eq!(p.output_suffix(), "json");
        assert_eq!(
            p.arguments(Path::new("-a.csv"), Path::new("o")),
            ["inspect", "--json", "--", "-a.csv"].map(OsString::from)
        );
        let p = Passthrough::new(&words("heading --calibration c.json")).unwrap();
        assert_eq!(p.output_suffix(), "csv");
        assert_eq!(
            p.arguments(Path::new("a.csv"), Path::new("o.csv"))[3..],
            ["--input=a.csv", "--output=o.csv"].map(OsString::from)
        );
    }
}
