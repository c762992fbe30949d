"""Runs the cocotb array testbench (test_array.py) on an array set's verification kit.

Usage: python testbench/cocotb/run_array.py SETDIR [--sim icarus|verilator] [--build DIR]
SETDIR is what `tofprobe rtl ARRAY_CONFIG --out SETDIR` wrote (the RTL, array_tb.v and the
golden vectors beside it), perhaps edited since. Exits non-zero on failure; the log names
the first mismatch (`TOFPROBE-MISMATCH cycle=... frame ... pixel (r, c) ... signal=...`)
and ends with `TOFPROBE-COCOTB-DONE cycles=<n> mismatches=<n>`.
"""

import argparse
import shutil
import sys
from pathlib import Path

from cocotb_tools.runner import get_results, get_runner

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE))

from vectors import read_defines  # noqa: E402

KIT_FILES = ("array_tb.v", "array_params.vh", "array_stim.hex", "array_expect.hex", "readout.txt")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("set", help="the array set (tofprobe rtl ARRAY_CONFIG --out SETDIR)")
    ap.add_argument("--sim", default="icarus")
    ap.add_argument("--build", default=str(ROOT / "target/cocotb-array"))
    a = ap.parse_args()
    rtl = Path(a.set).resolve()
    missing = [f for f in KIT_FILES if not (rtl / f).is_file()]
    if missing:
        sys.exit(f"run_array: {rtl} carries no verification kit (missing {', '.join(missing)}): "
                 "render it with `tofprobe rtl ARRAY_CONFIG --out DIR` (--kit-frames K > 0)")
    top = read_defines(rtl / "array_params.vh")["TOP"]
    build = Path(a.build).resolve() / a.sim
    build.mkdir(parents=True, exist_ok=True)
    # A deep probe ROM's $readmemh opens its image in the simulator's working directory.
    for hexfile in rtl.glob("*.hex"):
        shutil.copy(hexfile, build / hexfile.name)
    runner = get_runner(a.sim)
    runner.build(
        sources=sorted(p for p in rtl.glob("*.v") if p.name != "array_tb.v"),
        hdl_toplevel=top,
        build_dir=build,
        always=True,
    )
    results = runner.test(
        hdl_toplevel=top,
        test_module="test_array",
        test_dir=build,
        build_dir=build,
        extra_env={"TOFPROBE_ARRAY_SET": str(rtl), "PYTHONPATH": str(HERE)},
    )
    tests, fails = get_results(results)
    print(f"cocotb: {a.sim}: {tests} tests, {fails} failures")
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()
