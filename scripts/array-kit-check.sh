#!/usr/bin/env bash
# Runs an array set's verification kit (issue 42, point 6; testbench/README.md "The array
# set's verification kit") in the users' own tools, on a 2 x 3 array of tiny pixels
# (testbench/array-2x2/array-2x2.toml with cols = 3, N = 16, L = 16): `tofprobe rtl`
# renders the set, then its FuseSoC core's `sim` (Icarus) and `sim_verilator` (verilator
# --binary) targets and the cocotb array test (testbench/cocotb/run_array.py, Icarus) must
# all report 0 mismatches; then the same set hand-edited (one readout bit inverted in
# tofprobe_array.v) must fail under FuseSoC's `sim` naming the cycle and under cocotb
# naming the cycle and pixel. Uses the cached venv of scripts/py-venv.sh; work files in
# target/array-kit. (The Icarus and Verilator commands a designer types are
# crates/cli/tests/it/array_kit.rs.)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$("$root/scripts/py-venv.sh")"
export PATH="$venv/bin:$PATH"
(cd "$root" && cargo build --release -q -p tofprobe-cli)
bin="${CARGO_TARGET_DIR:-$root/target}/release/tofprobe"
work="$root/target/array-kit"
rm -rf "$work"
mkdir -p "$work"
cd "$work"
fail() { echo "array-kit-check: FAILED: $*" >&2; exit 1; }

sed 's/^cols = 2$/cols = 3/' "$root/testbench/array-2x2/array-2x2.toml" >array-2x3.toml
grep -q '^cols = 3$' array-2x3.toml || fail "array-2x3.toml: no cols = 3"
"$bin" rtl array-2x3.toml --out set --frame-pulses 16 --rom-depth 16 >rtl.log || {
  cat rtl.log; fail "tofprobe rtl"; }
"$bin" check-set set >/dev/null || fail "set is not a whole output set"

core=tofprobe:tofprobe:tofprobe_array
fusesoc_run() { # set target log
  fusesoc --cores-root "$1" run --build-root "$work/build-$(basename "$1")-$2" --target "$2" "$core" >"$3" 2>&1 || true
}
done_of() { grep -o 'TOFPROBE-COSIM-DONE.*' "$1" | head -1 || true; }

fusesoc_run set sim sim.log
sim_line="$(done_of sim.log)"
[[ "$sim_line" == *" mismatches=0" ]] || { cat sim.log; fail "fusesoc sim: ${sim_line:-no completion line}"; }
fusesoc_run set sim_verilator vl.log
vl_line="$(done_of vl.log)"
[[ "$vl_line" == *" mismatches=0" ]] || { cat vl.log; fail "fusesoc sim_verilator: ${vl_line:-no completion line}"; }
python "$root/testbench/cocotb/run_array.py" set --build "$work/cocotb" >cocotb.log 2>&1 || {
  cat cocotb.log; fail "cocotb"; }
coco_line="$(grep -o 'TOFPROBE-COCOTB-DONE.*' cocotb.log | head -1)"
[[ "$coco_line" == *" mismatches=0" ]] || { cat cocotb.log; fail "cocotb: $coco_line"; }

# The hand-edited set: the port's readout register XORed with 1.
cp -r set edited
sed -i 's/if (beat) ro_data <= dx\[dm \* READOUT_BITS +: READOUT_BITS\];/if (beat) ro_data <= dx[dm * READOUT_BITS +: READOUT_BITS] ^ { {(READOUT_BITS - 1){1'"'"'b0}}, 1'"'"'b1 };/' edited/tofprobe_array.v
cmp -s set/tofprobe_array.v edited/tofprobe_array.v && fail "the edit of tofprobe_array.v changed nothing"
# The first beat on the port: the first cycle array_expect.hex has ro_valid = 1.
beat="$(grep -v '^//' set/array_expect.hex | awk '$3 == 1 {print NR - 1; exit}')"
fusesoc_run edited sim sim-edited.log
edit_line="$(done_of sim-edited.log)"
[[ -n "$edit_line" && "$edit_line" != *" mismatches=0" ]] || { cat sim-edited.log; fail "fusesoc sim passed an edited set: ${edit_line:-no completion line}"; }
grep -q "^TOFPROBE-MISMATCH cycle=$beat signal=ro_data " sim-edited.log || {
  cat sim-edited.log; fail "fusesoc sim: the edit not named at cycle $beat"; }
if python "$root/testbench/cocotb/run_array.py" edited --build "$work/cocotb-edited" >cocotb-edited.log 2>&1; then
  fail "cocotb passed an edited set"
fi
grep -q "TOFPROBE-MISMATCH cycle=$beat beat of frame 0 pixel (0, 0) word 0 signal=ro_data" cocotb-edited.log || {
  cat cocotb-edited.log; fail "cocotb: the edit not named at cycle $beat, pixel (0, 0)"; }
echo "array-kit-check: ok: 2 x 3 array set: fusesoc sim: $sim_line; sim_verilator: $vl_line; cocotb: $coco_line; an inverted readout bit is caught at cycle $beat (pixel (0, 0))"
