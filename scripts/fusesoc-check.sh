#!/usr/bin/env bash
# Runs the FuseSoC cores that `tofprobe rtl` renders beside the committed RTL with the
# users' own tool: `lint` (Verilator --lint-only -Wall) of rtl/tofprobe.core (the default),
# and `sim` (Icarus, testbench/tb.v replaying the short golden vectors) of
# testbench/default-short/rtl/tofprobe.core (rendered with --core-vectors/--core-testbench),
# checking sim's completion line reports 0 mismatches. Both cores are byte-checked against a
# fresh rendering by scripts/check-generated.sh. `synth` (yosys) is defined but not run
# here: it maps the 20,000-entry ROM. Uses the cached venv of scripts/py-venv.sh; work files
# in target/fusesoc.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
work="$root/target/fusesoc"
mkdir -p "$work"
cd "$work"
core=tofprobe:tofprobe:tofprobe_pixel
# A core's users first check that its directory is a whole set (a `tofprobe rtl` killed
# mid-commit leaves no completion marker): `tofprobe check-set DIR`.
bin="${CARGO_TARGET_DIR:-$root/target}/release/tofprobe"
if [[ -x "$bin" ]]; then
  for d in "$root/rtl" "$root/testbench/default-short/rtl" "$root/testbench/default-short/vectors"; do
    "$bin" check-set "$d" >/dev/null || { echo "fusesoc-check: $d is not a whole output set" >&2; exit 1; }
  done
fi
# Each directory holds one core of that name (the default's and the short frame's): one
# cores root at a time.
run() { # cores-root target log
  "$venv/bin/fusesoc" --cores-root "$1" run --build-root "$work/build-$2" --target "$2" "$core" >"$3" 2>&1
}

run "$root/rtl" lint lint.log || {
  cat lint.log; echo "fusesoc-check: lint FAILED" >&2; exit 1; }
grep -q "^%Warning\|^%Error" lint.log && { cat lint.log; echo "fusesoc-check: lint FAILED" >&2; exit 1; }

run "$root/testbench/default-short/rtl" sim sim.log || true
done_line="$(grep '^TOFPROBE-COSIM-DONE' sim.log || true)"
if [[ "$done_line" != *" mismatches=0 "* ]]; then
  cat sim.log
  echo "fusesoc-check: sim FAILED: ${done_line:-no completion line}" >&2
  exit 1
fi
echo "fusesoc-check: ok: lint clean (Verilator), sim: $done_line"
