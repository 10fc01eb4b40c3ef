//! # truenorth-sim
//!
//! Vehicle and hand-held trajectories with every sensor stream and ground truth.
//!
//! ```
//! assert_eq!(1 + 1, 2);
//! ```
