#!/usr/bin/env bash
# Regenerates the committed generated files (rtl/ for the default configuration, and the
# short-frame default RTL + golden vectors under testbench/default-short/, each RTL with its
# FuseSoC core) into a temporary directory with the release binary and fails on any byte
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
)
status=0
diff -r "$tmp/rtl" rtl || status=1
diff -r "$tmp/testbench/default-short" testbench/default-short || status=1
if [ "$status" -ne 0 ]; then
  echo "check-generated: committed generated files differ from a fresh run (see the diff above);" >&2
  echo "regenerate them with the commands in their headers" >&2
  exit 1
fi
echo "check-generated: rtl/ and testbench/default-short/ are up to date"
