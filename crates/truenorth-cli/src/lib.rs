//! The `truenorth` command's internals, as a library so that the fuzz targets (`fuzz/` at the
//! top of the repository) and the tests can call its readers and method registries directly.
//!
//! Nothing here is a stable API: the modules are the binary's own, exposed for the fuzz
//! targets and tests, hidden from the docs, and may change with any release. Use the
//! `truenorth` crate for the library. (Each module's documentation is its own, inside it,
//! so that its links resolve among its items.)
//!
//! ```
//! use truenorth_cli::registry::CalibrationMethod;
//! assert_eq!(CalibrationMethod::OnlineEllipsoid.dimensions(), 3);
//! ```

#[doc(hidden)]
pub mod commands;
#[doc(hidden)]
pub mod demo;
#[doc(hidden)]
pub mod eval;
#[doc(hidden)]
pub mod inspect;
#[doc(hidden)]
pub mod io;
#[doc(hidden)]
pub mod plot;
#[doc(hidden)]
pub mod registry;
