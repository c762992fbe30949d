"""Reads an array output set (tofprobe simulate CONFIG --out DIR) with the tools its users
have: numpy.load for the .npy arrays and pyuff for vibration.uff. Checks the shapes against
summary.json, the UFF nodes against the pixel centres, and every data set 55 against the
amplitude and phase maps (6 significant digits: relative 1e-5), and every pixel's data set
58 spectrum against the same maps (12 significant digits: relative 1e-9).
Exits non-zero on any difference; --break perturbs one value to show the check can fail.
Usage: python array_check.py DIR [--break]"""
import json
import math
import sys

import numpy as np
import pyuff


def main(d, broken):
    s = json.load(open(f"{d}/summary.json"))
    R, C = s["rows"], s["cols"]
    B = len(s["bins"])
    regs = np.load(f"{d}/registers.npy")
    assert regs.dtype == np.int64 and regs.shape == (R, C, s["registers_per_pixel"]), regs.shape
    det = np.load(f"{d}/detections.npy")
    assert det.shape == (R, C) and abs(det.mean() - s["mean_detections_per_pixel"]) < 1e-6
    amp = np.load(f"{d}/amplitude_um.npy")
    ph = np.load(f"{d}/phase_deg.npy")
    assert amp.shape == (B, R, C) and ph.shape == (B, R, C), (amp.shape, ph.shape)
    if broken:
        amp[0, 0, 0] *= 1.01
    for b in s["bins"]:
        assert abs(amp[b["index"]].mean() - b["mean_amplitude_um"]) < 1e-9 * max(1, b["mean_amplitude_um"])
    uff = pyuff.UFF(f"{d}/vibration.uff")
    types = list(uff.get_set_types())
    assert types == [151, 164, 15] + [55] * B + [58] * (R * C), types
    sets = uff.read_sets()
    nodes = sets[2]
    mm = s["mm_per_pixel"]
    for k in range(R * C):
        r, c = divmod(k, C)
        assert int(nodes["node_nums"][k]) == k + 1
        assert math.isclose(nodes["x"][k], (c + 0.5) * mm, rel_tol=1e-5)
        assert math.isclose(nodes["y"][k], (r + 0.5) * mm, rel_tol=1e-5)
    for b in range(B):
        d55 = sets[3 + b]
        assert math.isclose(d55["freq"], s["bins"][b]["frequency_hz"], rel_tol=1e-5), d55["freq"]
        z = np.asarray(d55["r3"]) * 1000.0  # mm -> um
        want = (amp[b] * np.exp(1j * np.radians(ph[b]))).reshape(-1)
        err = np.abs(z - want) - (1e-5 * np.abs(want) + 1e-6)
        if (err > 0).any():
            i = int(np.argmax(err > 0))
            print(f"array-check: bin {b} pixel {divmod(i, C)}: UFF {z[i]} vs maps {want[i]}")
            sys.exit(1)
    for k in range(R * C):
        d58 = sets[3 + B + k]
        assert int(d58["rsp_node"]) == k + 1, d58["rsp_node"]
        r, c = divmod(k, C)
        want = amp[:, r, c] * np.exp(1j * np.radians(ph[:, r, c]))
        got = np.asarray(d58["data"]) * 1000.0
        freqs = [b["frequency_hz"] for b in s["bins"]]
        assert np.allclose(d58["x"], freqs, rtol=1e-5), (d58["x"], freqs)
        if (np.abs(got - want) > 1e-9 * np.abs(want) + 1e-9).any():
            print(f"array-check: data set 58 of pixel ({r}, {c}): {got} vs {want}")
            sys.exit(1)
    print(f"array-check: ok ({R} x {C} pixels, {B} bins: numpy and pyuff agree with the maps)")


if __name__ == "__main__":
    main(sys.argv[1], "--break" in sys.argv[2:])
