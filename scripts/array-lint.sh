#!/usr/bin/env bash
# Renders an R x C array of the configuration (default: the embedded default with the small
# test pixel of the array tests: B = 2, C = 4) and elaborates it whole, as a designer's lint
# would: `verilator --lint-only -Wall` (zero warnings), `iverilog -g2005` (compiles) and
# yosys (`hierarchy -check`, `proc`: every instance resolved, the array's own logic
# elaborated; synthesis of a slice is `tofprobe size`'s). Prints each tool's wall time,
# CPU time and peak memory. The array RTL is written with generate loops, so the file is
# the same size at any R x C; what grows is the tools' elaboration (R x C pixel
# instances, linear: Verilator about 380 kB per instance of the default small pixel,
# 1.56 GB at 64 x 64, about 25 GB at 256 x 256), which is why this is a script and not a
# test (the tests lint 1 x 1 to 7 x 1, a 64 x 64 tile, and a whole 64 x 64 array whose pixel
# is a stub; docs/performance.md "Whole-array lint by size" has the figures).
#
# Usage: scripts/array-lint.sh ROWS COLS [CONFIG]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
rows=${1:?rows}
cols=${2:?cols}
cfg_in=${3:-}
scripts_dir="$root/scripts"
"$scripts_dir/install-tools.sh"
cargo build --release -q -p tofprobe-cli --manifest-path "$root/Cargo.toml"
bin="${CARGO_TARGET_DIR:-$root/target}/release/tofprobe"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT INT TERM
if [ -n "$cfg_in" ]; then
  cp "$cfg_in" "$work/array.toml"
  printf '\n[array]\nrows = %s\ncols = %s\n' "$rows" "$cols" >>"$work/array.toml"
else
  sed -e 's/^duration_s = 1.0/pulses = 20000/' -e 's/^bins = 16/bins = 2/' \
    -e 's/^cycles_per_pulse = 16/cycles_per_pulse = 4/' "$root/scenes/default.toml" >"$work/array.toml"
  printf '\n[array]\nrows = %s\ncols = %s\npitch_um = 30.0\nmm_per_pixel = 1.0\n' "$rows" "$cols" >>"$work/array.toml"
fi
"$bin" rtl "$work/array.toml" --out "$work/rtl" --frame-pulses 16 --rom-depth 16 --kit-frames 0 >/dev/null
cd "$work/rtl"
echo "array-lint: ${rows} x ${cols}: tofprobe_array.v is $(wc -c <tofprobe_array.v) bytes"
measure() {
  local name=$1
  shift
  /usr/bin/time -f "array-lint: $name: %e s wall, %U s user, %M kB peak" "$@" >"$work/$name.log" 2>&1 || {
    cat "$work/$name.log" >&2
    echo "array-lint: $name FAILED" >&2
    exit 1
  }
  tail -n 1 "$work/$name.log"
}
measure verilator verilator --lint-only -Wall --top-module tofprobe_array ./*.v
if grep -q '%Warning' "$work/verilator.log"; then
  cat "$work/verilator.log" >&2
  echo "array-lint: verilator warned" >&2
  exit 1
fi
measure iverilog iverilog -g2005 -o /dev/null -s tofprobe_array ./*.v
measure yosys yosys -q -p "read_verilog ./*.v; hierarchy -check -top tofprobe_array; proc"
echo "array-lint: ${rows} x ${cols} elaborates cleanly under Verilator, Icarus and yosys"
