#!/usr/bin/env bash
# The whole tofprobe test suite, as CI runs it (.ci/run): the EDA tools the co-simulation
# and synthesis tests drive, then formatting, lints and every test of the workspace in
# release mode (the Monte-Carlo and bit-true tests are numeric-heavy), then the Python
# package's pytest suite and the users' tools checks (the tools' and the venv's downloads run
# in the background during the compile). Every phase prints its wall time; a
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
  # The status is returned, not left to `set -e` (off inside a lane's `||`).
  "$@" || { local rc=$?; echo "test.sh: phase ${name} FAILED (exit ${rc})" >&2; return "$rc"; }
  echo "test.sh: phase ${name}: $(( $(date +%s) - t0 )) s" >&2
}

# The two downloads (Debian's EDA packages, the Python venv's wheels) wait on the network
# and dpkg, not on the cores: they run in the background while cargo compiles, and the
# tests wait for them. Their output is printed when they are awaited; a failure stops the
# suite there. Ctrl-C or a failure elsewhere stops them too.
prep=$(mktemp -d)
killtree() {
  local c
  for c in $(pgrep -P "$1" 2>/dev/null); do killtree "$c"; done
  kill "$1" 2>/dev/null || true
}
trap 'for j in $(jobs -p); do killtree "$j"; done; rm -rf "$prep"' EXIT
background() {
  local name=$1
  shift
  (
    t0=$(date +%s)
    rc=0
    "$@" >"$prep/$name.out" 2>&1 || rc=$?
    echo "$rc $(( $(date +%s) - t0 ))" >"$prep/$name.status"
  ) &
  echo $! >"$prep/$name.pid"
}
await() {
  local name=$1 rc secs
  wait "$(cat "$prep/$name.pid")" || true
  cat "$prep/$name.out" >&2
  read -r rc secs <"$prep/$name.status"
  echo "test.sh: phase ${name}: ${secs} s (in the background)" >&2
  if [ "$rc" != 0 ]; then
    echo "test.sh: phase ${name} FAILED (exit ${rc})" >&2
    exit 1
  fi
}

background install-tools scripts/install-tools.sh
# The venv the Python package and the users' tools use (its path printed; nothing else
# creates it while this runs: the tests below wait for it).
if command -v python3 >/dev/null 2>&1; then
  background python-venv scripts/py-venv.sh
fi
phase fmt cargo fmt --all --check
# Release profile, like the tests below: the proc-macros and build scripts clippy compiles are
# then the ones the test build reuses (in the dev profile they were built twice, ≈ 1 min).
phase clippy cargo clippy --workspace --all-targets --release -- -D warnings
phase build-tests cargo test --workspace --release --no-run
# The libraries' documentation as users read it (`cargo doc`): a broken or ambiguous
# intra-doc link, or maths read as a link, fails here (≈ 15 s: the dependencies' metadata
# is the test build's; 125 such warnings had crept in before this phase existed).
phase doc env RUSTDOCFLAGS="-D warnings" cargo doc --workspace --release --no-deps
await install-tools
[ -f "$prep/python-venv.pid" ] && await python-venv
# Two lanes, so both cores stay busy: a test binary ends on its slowest tests with one core
# idle, and pytest and the users' tools are mostly one process at a time. The CLI's test
# binary (the largest) runs in one lane, every other test binary, then the Python package
# and the users' tools in the other (cargo holds no lock while tests run: the build is done).
# Each lane's output is printed whole when it is awaited; a failing lane fails the suite.
libs_lane() {
  phase tests-libraries cargo test --workspace --release --exclude tofprobe-cli &&
    # The Python package (crates/python): maturin builds it into the scripts' venv, reusing
    # the library crates built above, and pytest runs its suite against the CLI binary.
    phase python scripts/python-package.sh &&
    phase users-tools scripts/users-tools.sh
}
tests_start=$(date +%s)
background lane-cli phase tests-cli cargo test --release -p tofprobe-cli
background lane-libraries libs_lane
await lane-libraries
await lane-cli
echo "test.sh: phase tests (both lanes): $(( $(date +%s) - tests_start )) s" >&2
echo "test.sh: all phases passed in $(( $(date +%s) - suite_start )) s" >&2
