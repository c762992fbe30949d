#!/usr/bin/env bash
# The whole tofprobe test suite, as CI runs it (.ci/run): the EDA tools the co-simulation
# and synthesis tests drive, then formatting, lints and every test of the workspace in
# release mode (the Monte-Carlo and bit-true tests are numeric-heavy), then the Python
# package's pytest suite and the users' tools checks. Every phase prints its wall time; a
# missing EDA tool fails the tests that need it (TOFPROBE_REQUIRE_TOOLS=1:
# tofprobe_testkit::tools), it never skips them.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

export TOFPROBE_REQUIRE_TOOLS=1
suite_start=$(date +%s)
phase() {
  local name=$1
  shift
  local t0
  t0=$(date +%s)
  "$@"
  echo "test.sh: phase ${name}: $(( $(date +%s) - t0 )) s" >&2
}

phase install-tools scripts/install-tools.sh
phase fmt cargo fmt --all --check
# Release profile, like the tests below: the proc-macros and build scripts clippy compiles are
# then the ones the test build reuses (in the dev profile they were built twice, ≈ 1 min).
phase clippy cargo clippy --workspace --all-targets --release -- -D warnings
phase build-tests cargo test --workspace --release --no-run
phase tests cargo test --workspace --release
# The Python package (crates/python): maturin builds it into the scripts' venv, reusing the
# library crates just built, and pytest runs its suite against the CLI binary built above.
phase python scripts/python-package.sh
phase users-tools scripts/users-tools.sh
echo "test.sh: all phases passed in $(( $(date +%s) - suite_start )) s" >&2
