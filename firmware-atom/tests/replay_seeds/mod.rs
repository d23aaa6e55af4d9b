//! Failure seeds kept deliberately in the repository (a `*.proptest-regressions` file beside
//! the test) and replayed before the random cases by every run, but never written by one: a
//! run that fails prints its case and its seed, and leaves no file behind that would make the
//! next run fail. To keep a new case, add its `cc ...` line to the file by hand (and, better,
//! a unit test of its shrunk value beside the code it found wrong).
//!
//! Shared by the property tests of firmware-atom and firmware-basic (`#[path]`).

use std::any::Any;
use std::fmt;

use proptest::test_runner::{FailurePersistence, PersistedSeed};

/// The seeds in a regressions file's text (`include_str!` it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ReplaySeeds(pub &'static str);

impl FailurePersistence for ReplaySeeds {
    fn load_persisted_failures2(&self, _source_file: Option<&'static str>) -> Vec<PersistedSeed> {
        self.0
            .lines()
            .filter(|line| line.starts_with("cc "))
            .filter_map(|line| line.split('#').next()?.trim().parse().ok())
            .collect()
    }

    fn save_persisted_failure2(
        &mut self,
        _source_file: Option<&'static str>,
        seed: PersistedSeed,
        shrunken_value: &dyn fmt::Debug,
    ) {
        eprintln!(
            "proptest: failing case not saved (add `{seed}` to the regressions file to keep it): \
             {shrunken_value:?}"
        );
    }

    fn box_clone(&self) -> Box<dyn FailurePersistence> {
        Box::new(self.clone())
    }

    fn eq(&self, other: &dyn FailurePersistence) -> bool {
        other.as_any().downcast_ref::<Self>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[test]
fn kept_seeds_are_read_and_comments_skipped() {
    let file = "# Seeds for failure cases\n\
                cc 0b4b2a5ba4c18f2302298e3db83404d90af4ef7b6f8236058efede607657a0fa # shrinks to x = 1\n\
                cc not-a-seed\n";
    assert_eq!(ReplaySeeds(file).load_persisted_failures2(None).len(), 1);
}
