//! The check that a property test can fail: the same property run on a deliberately
//! broken input (a stream shifted by a pulse, phases off by one, pixels rotated) must find
//! a failing seed, or the property does not see what it claims to check.

use proptest::prelude::any;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// Whether `property` fails for some seed among `cases` random ones (no failure
/// persistence: a mutant's failing seed is expected, not a regression to replay).
pub fn some_seed_fails(cases: u32, property: impl Fn(u64) -> Result<(), TestCaseError>) -> bool {
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    runner.run(&any::<u64>(), property).is_err()
}
