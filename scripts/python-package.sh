#!/usr/bin/env bash
# Builds the Python package `tofprobe` (crates/python: pyo3 + maturin, an abi3 wheel,
# scripts/wheel.sh) in release mode in the workspace's target dir (reusing the library
# crates `cargo test --release` compiled), installs it into the scripts' venv
# (scripts/py-venv.sh) and runs its pytest suite (crates/python/tests: among them the
# wheel installed into a fresh venv without Rust running the README's example, and every
# Python snippet of README.md and docs/ run as a script), then runs
# examples/python_pixel.py headless.
# Prints the build, test and example times.
# A missing python3 fails under CI (TOFPROBE_REQUIRE_TOOLS=1 or CI set) and skips otherwise.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if ! command -v python3 >/dev/null 2>&1; then
  if [ "${TOFPROBE_REQUIRE_TOOLS:-0}" = 1 ] || { [ -n "${CI:-}" ] && [ "${CI}" != false ]; }; then
    echo "python-package: FAILED: python3 not found, and CI requires the Python package's tests" >&2
    exit 1
  fi
  echo "python-package: SKIPPED (python3 not found): the Python package was not built or tested"
  exit 0
fi
venv="$("$root/scripts/py-venv.sh")"
target="${CARGO_TARGET_DIR:-$root/target}"
start=$(date +%s)
# The one build: the abi3 wheel of scripts/wheel.sh (target/wheels/), installed here and,
# by tests/test_wheel.py, into a fresh venv without Rust.
wheel="$("$root/scripts/wheel.sh")"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --no-deps --force-reinstall \
  "$wheel" >&2
built=$(date +%s)
# The CLI binary the bit-identity test compares with (built by `cargo test --release`).
export TOFPROBE_CLI="${TOFPROBE_CLI:-$target/release/tofprobe}"
(cd "$root/crates/python" && "$venv/bin/python" -m pytest -q -p no:cacheprovider)
tested=$(date +%s)
# The example, headless (matplotlib's Agg backend), on a short frame and a small array.
example_out="$target/python-example"
rm -rf "$example_out"
MPLBACKEND=Agg "$venv/bin/python" "$root/examples/python_pixel.py" --quick --out "$example_out" >/dev/null
for png in spectrum.png vibration_map.png; do
  if [ ! -s "$example_out/$png" ]; then
    echo "python-package: FAILED: examples/python_pixel.py wrote no $png" >&2
    exit 1
  fi
done
echo "python-package: ok (build+install $(( built - start )) s, pytest $(( tested - built )) s, example $(( $(date +%s) - tested )) s)"
