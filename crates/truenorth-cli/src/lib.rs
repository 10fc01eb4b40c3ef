//! The `truenorth` command's internals, as a library so that the fuzz targets (`fuzz/` at the
//! top of the repository) and the tests can call its readers and method registries directly.
//!
//! Nothing here is a stable API: the modules are the binary's own, hidden from the docs, and
//! may change with any release. Use the `truenorth` crate for the library.
//!
//! ```
//! use truenorth_cli::registry::CalibrationMethod;
//! assert_eq!(CalibrationMethod::OnlineEllipsoid.dimensions(), 3);
//! ```

/// The binary's internals (subcommands), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod commands;
/// The binary's internals (the `demo` subcommand), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod demo;
/// The binary's internals (the `eval` subcommands), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod eval;
/// The binary's internals (the `inspect` analysis), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod inspect;
/// The binary's internals (CSV and JSON readers and writers), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod io;
/// The binary's internals (SVG plots), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod plot;
/// The binary's internals (the method registries), exposed for the fuzz targets and tests, not a stable API.
#[doc(hidden)]
pub mod registry;
