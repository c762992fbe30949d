#!/usr/bin/env bash
# The whole tofprobe test suite, as CI runs it (.ci/run): the EDA tools the co-simulation
# and synthesis tests drive, then formatting, lints and every test of the workspace in
# release mode (the Monte-Carlo and bit-true tests are numeric-heavy).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-tools.sh
cargo fmt --all --check
# Release profile, like the tests below: the proc-macros and build scripts clippy compiles are
# then the ones the test build reuses (in the dev profile they were built twice, ≈ 1 min).
cargo clippy --workspace --all-targets --release -- -D warnings
cargo test --workspace --release
scripts/users-tools.sh
