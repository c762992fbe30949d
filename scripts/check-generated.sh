#!/usr/bin/env bash
# Regenerates the committed generated files (rtl/ for the default configuration, and the
# short-frame default RTL + golden vectors under testbench/default-short/, each RTL with its
# FuseSoC core, and the 2 x 2 array example under testbench/array-2x2/) into a temporary directory with the release binary and fails on any byte
# difference.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
cargo build --release -q -p tofprobe-cli
bin="${CARGO_TARGET_DIR:-$root/target}/release/tofprobe"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
(
  cd "$tmp"
  "$bin" rtl --out rtl >/dev/null
  "$bin" rtl --out testbench/default-short/rtl --frame-pulses 64 \
    --core-vectors testbench/default-short/vectors --core-testbench testbench/tb.v >/dev/null
  "$bin" vectors --out testbench/default-short/vectors --frame-pulses 64 --frames 2 --seed 1 >/dev/null
  mkdir -p testbench/array-2x2
  cp "$root/testbench/array-2x2/array-2x2.toml" testbench/array-2x2/
  cfg=testbench/array-2x2/array-2x2.toml
  "$bin" rtl "$cfg" --out testbench/array-2x2/rtl --frame-pulses 16 --rom-depth 16 >/dev/null
  "$bin" vectors "$cfg" --out testbench/array-2x2/vectors --frame-pulses 16 --rom-depth 16 --frames 2 >/dev/null
)
status=0
diff -r "$tmp/rtl" rtl || status=1
diff -r "$tmp/testbench/default-short" testbench/default-short || status=1
diff -r "$tmp/testbench/array-2x2" testbench/array-2x2 || status=1
if [ "$status" -ne 0 ]; then
  echo "check-generated: committed generated files differ from a fresh run (see the diff above);" >&2
  echo "regenerate them with the commands in their headers" >&2
  exit 1
fi
echo "check-generated: rtl/, testbench/default-short/ and testbench/array-2x2/ are up to date"
