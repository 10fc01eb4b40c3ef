//! `truenorth batch` arguments that would run nothing and say nothing: refused before
//! anything runs.

mod common;

use common::p;

/// `--ext ""` (or an empty ending in a list) matches no file: the batch would run nothing
/// and exit 0. It is refused, saying what to give, and creates no output folder.
#[test]
fn an_empty_extension_is_refused() {
    let dir = common::scratch("batch_arguments", "ext");
    std::fs::write(dir.join("a.csv"), "t_s,mag_x,mag_y\n0,1,2\n").unwrap();
    let out = dir.join("out");
    for ext in ["", "csv,", "."] {
        let o = common::truenorth(&[
            "batch",
            p(&dir),
            "--ext",
            ext,
            "--out",
            p(&out),
            "--",
            "inspect",
        ]);
        let (ok, stderr) = common::outcome(&o);
        assert!(!ok, "--ext {ext:?} ran");
        assert!(stderr.contains("empty extension"), "{stderr}");
        assert!(!out.exists(), "nothing created");
    }
}
