#!/usr/bin/env python3
"""The overhead of the Python package's `run_pixel` over the library call, on a 10^7-pulse
frame of the default design (docs/performance.md records the figures).

Both sides run the same frame through the same pixel (`FrameDriver`): `run_pixel(valid,
tdc)` is the whole Python call (argument checks, numpy borrowing, the driver reading
(valid, tdc) in place, the run, the readout, the int64 array back);
`time_library_run_pixel` times, inside Rust, only what a Rust caller holding the frame in
the drivers' compact codes pays (FrameDriver::new, run, readout). Best of --repeat for each, interleaved,
so a busy machine affects both alike. Prints both, the overhead in % and whether it is
within the issue's 5 %. Usage: python scripts/python-bench.py [--repeat 7] [--pulses N]
"""

import argparse
import time

import numpy as np

import tofprobe


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--pulses", type=int, default=10_000_000)
    a = ap.parse_args()
    d = tofprobe.Design.default()
    n = min(a.pulses, d.summary()["frame_pulses"])
    valid, tdc = d.simulate_scene(seed=1)
    valid, tdc = valid[:n], tdc[:n]
    d.run_pixel(valid[:10], tdc[:10])  # the probe ROM, generated once, outside the timing
    python, library = [], []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        regs = d.run_pixel(valid, tdc)
        python.append(time.perf_counter() - t0)
        library.append(d.time_library_run_pixel(valid, tdc))
    assert regs.shape == (d.summary()["registers"],)
    p, lib = min(python), min(library)
    overhead = (p - lib) / lib * 100
    # Paired: each Python call against the library call right after it (a busy machine
    # slows both of a pair alike), the median of the ratios.
    paired = (float(np.median(np.array(python) / np.array(library))) - 1) * 100
    print(f"run_pixel, {n} pulses: Python call {p * 1e3:.1f} ms, library call "
          f"{lib * 1e3:.1f} ms (best of {a.repeat}); overhead {overhead:+.1f} % "
          f"({'within' if overhead <= 5 else 'OVER'} the 5 % budget)")
    print(f"  medians: Python {np.median(python) * 1e3:.1f} ms, library "
          f"{np.median(library) * 1e3:.1f} ms; median of paired ratios {paired:+.1f} %")


if __name__ == "__main__":
    main()
