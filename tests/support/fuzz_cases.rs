//! What the fuzz tests of every crate share: the case count (`PROPTEST_CASES`, 64 by default
//! for `cargo test`; `scripts/fuzz.sh` raises it) and the per-parser count line it prints.

use std::sync::atomic::{AtomicU64, Ordering};

use proptest::test_runner::Config;

pub fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(64);
    Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    }
}

/// Counts the cases each parser ran; printed for `scripts/fuzz.sh`.
pub fn counted(counter: &AtomicU64, name: &str) {
    let n = counter.fetch_add(1, Ordering::Relaxed) + 1;
    if n == u64::from(config().cases) {
        println!("FUZZ | {name} | {n} cases | 0 panics");
    }
}
