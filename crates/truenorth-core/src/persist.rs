//! Persistence: a calibrator or estimator saves what it has learned as a plain, versioned
//! serde value and is rebuilt from it later, continuing exactly where it stopped.

use serde::{Deserialize, Serialize, de::DeserializeOwned};

use crate::{Error, Result};

/// A saved state, tagged with the layout version of the type that wrote it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot<S> {
    /// Layout version of `state` (the writer's [`Persistent::SNAPSHOT_VERSION`]).
    pub version: u32,
    /// Everything needed to continue: configuration and learned state.
    pub state: S,
}

/// Saving and restoring a calibrator or estimator: its state as plain data (as VQF's
/// `getState` / `setState`), and a versioned snapshot of it built once, here.
///
/// `from_state(state())` (or `restore(snapshot())`) followed by the same pushes gives
/// bit-identical results to never having stopped.
pub trait Persistent: Sized {
    /// The serialisable state (configuration included).
    type State: Serialize + DeserializeOwned + Clone;

    /// Layout version written into every snapshot; bumped when `State` changes shape.
    const SNAPSHOT_VERSION: u32;

    /// Everything needed to continue: configuration and learned state.
    fn state(&self) -> Self::State;

    /// Rebuilds from a state, refusing one whose contents are invalid (it may have been
    /// edited or corrupted on disk).
    fn from_state(state: Self::State) -> Result<Self>;

    /// The current state, tagged with [`Self::SNAPSHOT_VERSION`].
    fn snapshot(&self) -> Snapshot<Self::State> {
        Snapshot {
            version: Self::SNAPSHOT_VERSION,
            state: self.state(),
        }
    }

    /// Rebuilds from a snapshot, refusing one of another version or invalid contents.
    fn restore(snapshot: Snapshot<Self::State>) -> Result<Self> {
        check_snapshot_version(snapshot.version, Self::SNAPSHOT_VERSION)?;
        Self::from_state(snapshot.state)
    }
}

/// Checks a snapshot's version against the reader's.
pub fn check_snapshot_version(found: u32, expected: u32) -> Result<()> {
    if found == expected {
        Ok(())
    } else {
        Err(Error::SnapshotVersion { found, expected })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn only_the_same_version_is_read(found in 0u32..5, expected in 0u32..5) {
            let r = check_snapshot_version(found, expected);
            prop_assert_eq!(r.is_ok(), found == expected);
            if let Err(e) = r {
                prop_assert_eq!(e, Error::SnapshotVersion { found, expected });
            }
        }
    }
}
