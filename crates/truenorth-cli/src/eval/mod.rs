//! Evaluations of the methods on benchmarks with ground truth (`truenorth eval`): the BROAD
//! orientation benchmark ([`broad`]).

pub mod broad;
