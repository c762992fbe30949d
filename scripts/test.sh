#!/usr/bin/env bash
# The whole tofprobe test suite, as CI runs it (.ci/run): the EDA tools the co-simulation
# and synthesis tests drive, then formatting, lints and every test of the workspace in
# release mode (the Monte-Carlo and bit-true tests are numeric-heavy).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

scripts/install-tools.sh
cargo fmt --all --check
cargo clippy --workspace --all-targets -- -D warnings
cargo test --workspace --release
scripts/users-tools.sh
