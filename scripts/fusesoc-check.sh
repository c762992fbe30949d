#!/usr/bin/env bash
# Runs the default's FuseSoC core (testbench/fusesoc/tofprobe_pixel.core) with the users'
# own tool: `lint` (Verilator --lint-only -Wall on rtl/) and `sim` (Icarus, testbench/tb.v
# replaying the short golden vectors), and checks sim's completion line reports 0
# mismatches. `synth` (yosys) is defined but not run here: it maps the 20,000-entry ROM.
# Uses the cached venv of scripts/py-venv.sh; work files in target/fusesoc.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
work="$root/target/fusesoc"
mkdir -p "$work"
cd "$work"
fusesoc=("$venv/bin/fusesoc" --cores-root "$root/testbench/fusesoc")
core=tofprobe:tofprobe:pixel

# The core lists ../../rtl files: FuseSoC 2.4 warns that this is deprecated; not our error.
quiet() { grep -v "is not within the directory containing the core file" || true; }

"${fusesoc[@]}" run --target lint "$core" 2>&1 | quiet >lint.log || {
  cat lint.log; echo "fusesoc-check: lint FAILED" >&2; exit 1; }
grep -q "^%Warning\|^%Error" lint.log && { cat lint.log; echo "fusesoc-check: lint FAILED" >&2; exit 1; }

"${fusesoc[@]}" run --target sim "$core" 2>&1 | quiet >sim.log || true
done_line="$(grep '^TOFPROBE-COSIM-DONE' sim.log || true)"
if [[ "$done_line" != *" mismatches=0 "* ]]; then
  cat sim.log
  echo "fusesoc-check: sim FAILED: ${done_line:-no completion line}" >&2
  exit 1
fi
echo "fusesoc-check: ok: lint clean (Verilator), sim: $done_line"
