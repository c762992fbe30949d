"""Builds and runs the cocotb testbench (test_pixel.py) on the committed short RTL and vectors.

Usage: python testbench/cocotb/run.py [--sim icarus|verilator] [--rtl DIR] [--vectors DIR]
(defaults: Icarus, testbench/default-short/rtl and .../vectors). Exits non-zero on failure.
"""

import argparse
import os
import shutil
import sys
from pathlib import Path

from cocotb_tools.runner import get_runner

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim", default="icarus")
    ap.add_argument("--rtl", default=str(ROOT / "testbench/default-short/rtl"))
    ap.add_argument("--vectors", default=str(ROOT / "testbench/default-short/vectors"))
    ap.add_argument("--build", default=str(ROOT / "target/cocotb"))
    a = ap.parse_args()
    rtl = Path(a.rtl).resolve()
    build = Path(a.build).resolve() / a.sim
    build.mkdir(parents=True, exist_ok=True)
    # $readmemh("tofprobe_probe_rom.hex") opens it in the simulator's working directory.
    for hexfile in rtl.glob("*.hex"):
        shutil.copy(hexfile, build / hexfile.name)
    os.environ["TOFPROBE_VECTORS"] = str(Path(a.vectors).resolve())
    sys.path.insert(0, str(HERE))
    runner = get_runner(a.sim)
    runner.build(
        sources=sorted(rtl.glob("*.v")),
        hdl_toplevel="tofprobe_top",
        build_dir=build,
        always=True,
    )
    results = runner.test(
        hdl_toplevel="tofprobe_top",
        test_module="test_pixel",
        test_dir=build,
        build_dir=build,
        extra_env={"TOFPROBE_VECTORS": os.environ["TOFPROBE_VECTORS"],
                   "PYTHONPATH": str(HERE)},
    )
    from cocotb_tools.runner import get_results

    tests, fails = get_results(results)
    print(f"cocotb: {a.sim}: {tests} tests, {fails} failures")
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()
