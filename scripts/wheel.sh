#!/usr/bin/env bash
# Builds the Python package `tofprobe` (crates/python: pyo3 + maturin) as ONE abi3 wheel
# (any CPython >= 3.10 on Linux x86-64) into target/wheels/, with the maturin of the
# scripts' venv (scripts/py-venv.sh), in release mode in the workspace's target dir, so it
# reuses the library crates `cargo test --release` compiled (scripts/python-features.sh
# checks that it can). The wheel holds the compiled library: installing it needs no Rust.
#
# manylinux: maturin audits the module's glibc symbols and tags the wheel with the oldest
# manylinux policy they satisfy (built on Debian 12: manylinux_2_35, glibc >= 2.35 —
# Debian 12, Ubuntu 22.04 and later). TOFPROBE_WHEEL_COMPAT=manylinux_2_XX asks for a
# policy (the audit fails rather than mislabel the wheel when the symbols need a newer
# glibc; an older one needs an older build host or zig), =linux an untagged local wheel.
#
# Usage: scripts/wheel.sh   (prints the wheel's path on stdout, the build time on stderr)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
"$root/scripts/python-features.sh" >&2
target="${CARGO_TARGET_DIR:-$root/target}"
out="$target/wheels"
mkdir -p "$out"
rm -f "$out"/tofprobe-*.whl
start=$(date +%s)
# --release: the profile `cargo test --release` built the library crates in.
"$venv/bin/maturin" build --release --quiet -m "$root/crates/python/Cargo.toml" \
  --interpreter "$venv/bin/python" ${TOFPROBE_WHEEL_COMPAT:+--compatibility "$TOFPROBE_WHEEL_COMPAT"} \
  --out "$out" >&2
shopt -s nullglob
wheels=("$out"/tofprobe-*-abi3-*.whl)
if [ ${#wheels[@]} -ne 1 ]; then
  echo "wheel: FAILED: expected one abi3 wheel in $out, found: $(ls "$out")" >&2
  exit 1
fi
echo "wheel: $(basename "${wheels[0]}") ($(( $(date +%s) - start )) s)" >&2
echo "${wheels[0]}"
