//! Persistence checks shared by the estimators' tests: restore-and-continue through JSON.

use serde::Serialize;
use serde::de::DeserializeOwned;
use truenorth_core::{Error, HeadingEstimator, NavEstimate, Persistent, Snapshot, VehicleSample};

/// JSON text of `v`: two equal texts are two bit-identical values (non-finite numbers are
/// written by name).
pub fn json<T: Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap()
}

/// Through JSON and back.
pub fn through_json<S: Serialize + DeserializeOwned>(s: &S) -> S {
    serde_json::from_str(&json(s)).unwrap()
}

/// Runs `make()` over every sample, and again stopped at `cut`, saved to JSON, restored and
/// continued: every estimate after the cut, and the final state, must agree bit for bit;
/// the snapshot under another version is refused.
pub fn check_continues<E>(make: impl Fn() -> E, samples: &[VehicleSample], cut: usize)
where
    E: HeadingEstimator + Persistent,
{
    let mut whole = make();
    let expected: Vec<String> = samples
        .iter()
        .map(|s| json(&whole.update(s).unwrap()))
        .collect();
    let mut first = make();
    for s in &samples[..cut] {
        first.update(s).unwrap();
    }
    let saved = through_json(&first.snapshot());
    let mut second = E::restore(saved.clone()).unwrap();
    assert_eq!(
        json(&second.state()),
        json(&first.state()),
        "state at the cut"
    );
    for (k, s) in samples.iter().enumerate().skip(cut) {
        let e: NavEstimate = second.update(s).unwrap();
        assert_eq!(json(&e), expected[k], "estimate {k} after a cut at {cut}");
    }
    assert_eq!(json(&second.state()), json(&whole.state()), "final state");
    let wrong = Snapshot {
        version: saved.version + 1,
        state: saved.state,
    };
    assert!(matches!(
        E::restore(wrong),
        Err(Error::SnapshotVersion { .. })
    ));
}
