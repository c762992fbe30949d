#!/usr/bin/env python3
"""tofprobe from Python: simulate a scene, run the bit-true pixel, compare its spectrum with
the float DFT of the same photons and the closed-form noise floor, and plot the spectrum
and an array's vibration map with matplotlib (Agg: no display needed).

Needs the package's [plot] extra (matplotlib): pip install "tofprobe[plot]" (from the
wheel, or "./crates/python[plot]"); without it, importing tofprobe.plot raises an
ImportError naming the extra.

    python examples/python_pixel.py [--out DIR] [--pulses N] [--quick]

Writes DIR/spectrum.png and DIR/vibration_map.png (default DIR: examples-out) and prints
the comparison. --quick shortens the frame and the array (what CI runs).
"""

import argparse
import pathlib

import os

os.environ.setdefault("MPLBACKEND", "Agg")
import numpy as np  # noqa: E402

import tofprobe  # noqa: E402
from tofprobe import plot  # noqa: E402  (the [plot] extra: matplotlib)

ROOT = pathlib.Path(__file__).resolve().parents[1]


def pixel(out: pathlib.Path, pulses: int) -> None:
    text = (ROOT / "scenes" / "default.toml").read_text()
    d = tofprobe.Design.from_toml_text(text.replace("duration_s = 1.0", f"pulses = {pulses}"))
    valid, tdc = d.simulate_scene(seed=1)
    f, amp, phase = d.spectrum(d.run_pixel(valid, tdc))
    _, amp_dft, phase_dft = d.dft(valid, tdc)
    floor = d.noise_floor()
    print(f"{valid.sum()} detections of {valid.size} pulses; bins {f[0]:.0f} .. {f[-1]:.0f} Hz")
    print("  frequency Hz   pixel um    DFT um   floor um")
    for row in zip(f, amp, amp_dft, floor):
        print("  {:>12.1f} {:>10.3f} {:>9.3f} {:>10.3f}".format(*row))
    tone = int(np.argmax(amp))
    print(f"tone at {f[tone]:.1f} Hz: pixel {amp[tone]:.2f} um at {phase[tone]:.1f} deg, "
          f"DFT {amp_dft[tone]:.2f} um at {phase_dft[tone]:.1f} deg")
    fig = plot.spectrum(f, amp, dft_um=amp_dft, floor_um=floor,
                        title=f"{d.summary()['frame_pulses']} pulses, seed 1")
    fig.savefig(out / "spectrum.png", dpi=100)


def array(out: pathlib.Path, quick: bool) -> None:
    text = (ROOT / "scenes" / "plate-mode.toml").read_text()
    if quick:
        for old, new in [("pulses = 1000000", "pulses = 40000"), ("rows = 32", "rows = 8"),
                         ("cols = 32", "cols = 8"), ("mm_per_pixel = 10.0", "mm_per_pixel = 40.0")]:
            text = text.replace(old, new)
    d = tofprobe.Design.from_toml_text(text)
    maps = d.simulate_array(tiles=4)
    k = int(np.argmax(maps["amplitude_um"].mean(axis=(1, 2))))
    amp, phase = maps["amplitude_um"][k], maps["phase_deg"][k]
    print(f"array {amp.shape[0]} x {amp.shape[1]}: dominant bin {maps['frequencies_hz'][k]:.1f} Hz, "
          f"max {amp.max():.1f} um")
    fig = plot.vibration_map(maps, k)
    fig.savefig(out / "vibration_map.png", dpi=100)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("examples-out"))
    ap.add_argument("--pulses", type=int, default=None)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    pixel(a.out, a.pulses or (400_000 if a.quick else 10_000_000))
    array(a.out, a.quick)
    print(f"plots: {a.out / 'spectrum.png'}, {a.out / 'vibration_map.png'}")


if __name__ == "__main__":
    main()
