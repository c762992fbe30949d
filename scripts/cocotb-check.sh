#!/usr/bin/env bash
# Runs the cocotb testbench (testbench/cocotb) on the committed short RTL and golden vectors
# under Icarus, then proves it can fail: the same run on a copy of the vectors with one
# readout word changed must report a mismatch. Uses the cached venv of scripts/py-venv.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
export PATH="$venv/bin:$PATH"
work="$root/target/cocotb"
mkdir -p "$work"

if ! "$venv/bin/python" "$root/testbench/cocotb/run.py" --build "$work" >"$work/run.log" 2>&1; then
  cat "$work/run.log"; echo "cocotb-check: FAILED" >&2; exit 1
fi
done_line="$(grep -o 'TOFPROBE-COCOTB-DONE.*' "$work/run.log" | head -1)"

# A deliberately broken vector set: the first readout word's last digit changed.
bad="$work/broken-vectors"
rm -rf "$bad"; cp -r "$root/testbench/default-short/vectors" "$bad"
awk 'BEGIN{d=0} !d && $0 !~ /^(\/\/|#)/ && NF {c=substr($0,length($0)); n=(c=="0")?"1":"0"; $0=substr($0,1,length($0)-1) n; d=1} {print}' \
  "$root/testbench/default-short/vectors/readout.hex" >"$bad/readout.hex"
if "$venv/bin/python" "$root/testbench/cocotb/run.py" --build "$work/broken" --vectors "$bad" >"$work/broken.log" 2>&1; then
  echo "cocotb-check: FAILED: a changed readout word was not caught" >&2; exit 1
fi
grep -q "signal=readout\[0\]" "$work/broken.log" || {
  cat "$work/broken.log"; echo "cocotb-check: FAILED: the broken vectors failed for another reason" >&2; exit 1; }
echo "cocotb-check: ok: icarus: $done_line; a changed readout word is caught"
