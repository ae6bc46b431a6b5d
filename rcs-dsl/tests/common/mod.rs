//! What the property tests of the analysis share: a proptest runner that
//! plays the same cases on every run (fixed seed, no failure persistence),
//! so CI and a developer see the same plans.

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// A deterministic runner of `env`'s number of cases (the environment
/// variable raises it for a long run), `default` otherwise.
pub fn deterministic_runner(env: &str, default: u32) -> TestRunner {
    let cases = std::env::var(env)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default);
    let config = Config {
        cases,
        failure_persistence: None,
        rng_algorithm: RngAlgorithm::ChaCha,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}
