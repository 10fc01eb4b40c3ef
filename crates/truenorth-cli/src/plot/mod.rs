//! SVG rendering of the figures the demo and `truenorth orientation --plot` write: an
//! equal-axes x-y plot ([`write_plot`]) and a plot of lines over time
//! ([`write_timeseries`]). No plotting dependency: the figures are a handful of point sets.

mod envelope;
mod equal_axes;
mod timeseries;

pub use envelope::Envelope;
pub use equal_axes::{Series, Style, write_plot};
pub use timeseries::{Band, Line, write_timeseries};
