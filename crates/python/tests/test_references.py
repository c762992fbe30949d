"""The design's analysis calls: a design from a dict, the float references of the user's
own frame (the DFT at the design's bins, float ΣΔ probing) against a synthetic tone whose
amplitude and phase are known, the closed-form noise floor against eq. 12 by hand and
against the DFT of simulated frames, the NTF against its defining properties, the widths
against the summary and the readout's arithmetic, and the EDA sizing with and without its
tools."""

import json
import math
import os
import shutil
import subprocess
import sys
import tomllib

import numpy as np
import pytest

import tofprobe
from conftest import ROOT


def test_from_dict_is_the_same_resolution_as_the_toml(small_text):
    doc = tomllib.loads(small_text)
    a = tofprobe.Design.from_dict(doc)
    b = tofprobe.Design.from_toml_text(small_text)
    assert a.origin == "<dict>"
    sa, sb = a.summary(), b.summary()
    sa.pop("origin"), sb.pop("origin")
    assert sa == sb
    # A changed value is resolved (bins = 4 → 8 registers), not just copied.
    doc["pixel"]["bins"] = 4
    assert tofprobe.Design.from_dict(doc).summary()["registers"] == 8


def test_from_dict_refuses_bad_keys_and_values_naming_them(small_text):
    doc = tomllib.loads(small_text)
    doc["pixel"]["binz"] = 3
    with pytest.raises(ValueError, match="binz"):
        tofprobe.Design.from_dict(doc)
    doc = tomllib.loads(small_text)
    doc["sensorr"] = {}
    with pytest.raises(ValueError, match="sensorr"):
        tofprobe.Design.from_dict(doc)
    doc = tomllib.loads(small_text)
    doc["pixel"]["bins"] = "many"
    with pytest.raises(ValueError, match="bins"):
        tofprobe.Design.from_dict(doc)
    doc["pixel"]["bins"] = None
    with pytest.raises(ValueError, match="None"):
        tofprobe.Design.from_dict(doc)
    doc["pixel"]["bins"] = object()
    with pytest.raises(TypeError, match="`d`"):
        tofprobe.Design.from_dict(doc)
    with pytest.raises(TypeError, match="`d` must be a dict"):
        tofprobe.Design.from_dict([("pixel", {})])


def tone_frame(d, amplitude_codes, phase_deg, bin_index=0, offset=40):
    """A frame whose every pulse detects code offset + A·cos(ω_k n + φ), rounded after a
    uniform ±1/2-code dither (so the rounding error is white, not a periodic error that
    correlates with the tone)."""
    s = d.summary()
    n, fs = s["frame_pulses"], s["laser_rate_hz"]
    f = s["frequencies_hz"][bin_index]
    t = np.arange(n)
    dither = np.random.default_rng(5).uniform(-0.5, 0.5, n)
    codes = np.rint(offset + dither + amplitude_codes * np.cos(2 * np.pi * f / fs * t
                                                               + np.radians(phase_deg)))
    return np.ones(n, bool), codes.astype(np.int32)


def test_the_float_references_read_a_known_tone(small):
    s = small.summary()
    lsb_um = s["tdc_lsb_mm"] * 1000
    valid, tdc = tone_frame(small, 20, 30.0)
    want_um = 20 * lsb_um  # 15 mm
    f, amp, ph = small.dft(valid, tdc)
    assert f.tolist() == s["frequencies_hz"]
    # Dither and rounding add white noise of 2·LSB²/12 (σ = 0.41 codes): at N = 2·10^5 its
    # DFT floor is √(π·0.17/N) ≈ 0.0016 codes, 8·10^−5 of 20 codes; tolerance 1e-3.
    assert amp[0] == pytest.approx(want_um, rel=1e-3)
    assert ph[0] == pytest.approx(30.0, abs=0.1)
    # Every other bin of a periodic (rectangular) record sees no tone: only the rounding.
    assert (amp[1:] < 0.01 * want_um).all()
    # Float ΣΔ: the ±1 probe's in-band quantisation error (the ROM's SNR) and the
    # prefilter's normalisation: within 1 % of the tone, phase within 1°.
    _, amp_sd, ph_sd = small.float_sd(valid, tdc)
    assert amp_sd[0] == pytest.approx(want_um, rel=1e-2)
    assert ph_sd[0] == pytest.approx(30.0, abs=1.0)
    # The bit-true pixel reads the same tone (its integer filter differs by floor residues).
    _, amp_bt, ph_bt = small.spectrum(small.run_pixel(valid, tdc))
    assert amp_bt[0] == pytest.approx(amp_sd[0], rel=1e-2)
    assert ph_bt[0] == pytest.approx(ph_sd[0], abs=1.0)
    # A broken input changes the answer: half the amplitude reads half.
    _, amp_half, _ = small.dft(*tone_frame(small, 10, 30.0))
    assert amp_half[0] == pytest.approx(want_um / 2, rel=2e-3)


def test_noise_floor_is_eq12_and_matches_simulated_frames(small):
    s = small.summary()
    n = s["frame_pulses"]
    # scenes/default.toml: σ_I = 7.5 mm, LSB 0.75 mm, ρ_s = 1, no background, periodic ROM
    # (rectangular: N_eff = N): E|Y| = √(π σ_s²/N), σ_s² = 7.5² + 0.75²/12 (the window's
    # ±4σ truncation lowers σ² by < 0.2 %, the hold at ρ_v ≈ 1 − 6·10^−5 changes nothing).
    want = math.sqrt(math.pi * (7.5**2 + 0.75**2 / 12) / n) * 1000
    floor = small.noise_floor()
    assert floor.shape == (len(s["bins"]),)
    assert floor == pytest.approx(np.full_like(floor, want), rel=5e-3)
    np.testing.assert_allclose(small.noise_floor(pulses=4 * n), floor / 2, rtol=1e-12)
    # The DFT of simulated frames away from the 4.5 kHz tone (bin 0): mean |Y| of 15 bins
    # × 3 seeds (Rayleigh: σ of the mean ≈ 0.52/√45 = 8 %); tolerance 25 %.
    noise = np.concatenate([small.dft(*small.simulate_scene(seed=k))[1][1:] for k in (1, 2, 3)])
    assert noise.mean() == pytest.approx(want, rel=0.25)
    with pytest.raises(ValueError, match="pulses"):
        small.noise_floor(pulses=0)


def test_noise_floor_without_photons_is_zero(small_text):
    # No photon, no detection: the pixel reads nothing (ρ_v = 0), and so does the floor.
    doc = tomllib.loads(small_text)
    doc["sensor"]["signal_rate"] = 0.0
    dark = tofprobe.Design.from_dict(doc)
    assert (dark.noise_floor() == 0).all()
    valid, _ = dark.simulate_scene()
    assert not valid.any()


def test_ntf_has_its_zeros_poles_and_out_of_band_gain(small):
    text = (ROOT / "scenes" / "default.toml").read_text()
    order = int(text.split("order = ")[1].split()[0])
    h_inf = float(text.split("h_inf = ")[1].split()[0])
    ntf = small.ntf(points=257)
    assert ntf["order"] == order and ntf["h_inf"] == h_inf
    assert ntf["zeros"].dtype == np.complex128 and len(ntf["zeros"]) == order
    assert len(ntf["poles"]) == order and (np.abs(ntf["poles"]) < 1).all()
    f, mag = ntf["frequencies_hz"], ntf["magnitude"]
    assert f[0] == 0 and f[-1] == small.summary()["laser_rate_hz"] / 2 and len(f) == 257
    # The Lee criterion sets |NTF(−1)| = H_inf; the zeros near DC null the band.
    assert mag[-1] == pytest.approx(h_inf, rel=1e-6)
    assert mag[0] < 1e-2 * h_inf
    # |NTF| at f from its roots, computed here.
    z = np.exp(2j * np.pi * f[100] / (2 * f[-1]))
    by_hand = abs(np.prod(z - ntf["zeros"]) / np.prod(z - ntf["poles"]))
    assert mag[100] == pytest.approx(by_hand, rel=1e-12)
    with pytest.raises(ValueError, match="points"):
        small.ntf(points=1)


def test_widths_are_the_resolution_and_the_readout_arithmetic(small):
    s, w = small.summary(), small.widths()
    assert w["width"] == s["width"] and w["registers"] == s["registers"]
    assert (w["tdc_bits"], w["frac_bits"]) == (s["tdc_bits"], s["frac_bits"])
    assert w["bits_per_frame"] == s["registers"] * s["width"]
    assert w["readout_bits"] == 8 * math.ceil(w["bits_per_frame"] / 8)
    m = w["memory"]
    assert m["width_bits"] == s["width"] and not m["width_too_small"]
    assert m["raw_bytes_per_frame"] == s["frame_pulses"] * s["tdc_bits"] / 8
    assert m["frames_per_second"] == s["laser_rate_hz"] / s["frame_pulses"]
    assert "array_readout_bits" not in w


def test_size_names_a_missing_tool(small, tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))
    monkeypatch.delenv("TOFPROBE_YOSYS", raising=False)
    monkeypatch.delenv("TOFPROBE_STA", raising=False)
    with pytest.raises(RuntimeError, match="`yosys` was not found"):
        small.size()


def test_size_with_the_tools_reports_area(small):
    if not (shutil.which("yosys") and shutil.which("sta")):
        if os.environ.get("TOFPROBE_REQUIRE_TOOLS") == "1":
            pytest.fail("yosys and sta are required (CI)")
        pytest.skip("yosys/sta not installed")
    w = small.summary()["width"]
    report = small.size(sweep_bins=[4], sweep_widths=[w])
    # The report `tofprobe size --json` prints: the configured pixel, a synthesised area
    # (cells of the liberty) and the same readout figures as widths().
    assert report["design"]["bins"] == 16 and report["design"]["width"] == w
    assert report["area"]["total_area_um2"] > 0 and report["area"]["cell_count"] > 100
    assert report["memory"] == small.widths()["memory"]
    assert (4, w) in {(r["bins"], r["width"]) for r in report["sweep"]}


def test_the_library_timing_runs_the_frame(small):
    valid, tdc = small.simulate_scene()
    seconds = small._time_library_run_pixel(valid, tdc, repeat=2)
    in_codes = small._time_library_run_pixel(valid, tdc, repeat=2, codes=True)
    # 2·10^5 pulses at 1 ns – 1 µs each (the folded driver: ≈ 3 ns; a loaded machine),
    # read in place or from the compact codes alike.
    assert 2e-4 < seconds < 0.2 and 2e-4 < in_codes < 0.2
    # A code out of range is refused by the timed call too, as run_pixel refuses it.
    bad = tdc.astype(np.int64)
    bad[np.flatnonzero(valid)[0]] = 1 << 16
    with pytest.raises(ValueError, match="outside"):
        small._time_library_run_pixel(valid, bad)
    with pytest.raises(ValueError, match="outside"):
        small._time_library_run_pixel(valid, bad, codes=True)


@pytest.mark.parametrize("call", ["dft", "float_sd", "_time_library_run_pixel"])
def test_the_references_refuse_bad_frames_like_run_pixel(small, call):
    f = getattr(small, call)
    valid, tdc = small.simulate_scene()
    with pytest.raises(TypeError, match="`valid` must be a bool array"):
        f(valid.astype(np.uint8), tdc)
    with pytest.raises(TypeError, match="`tdc` must be an integer array"):
        f(valid, tdc.astype(np.float32))
    with pytest.raises(ValueError, match="one code per pulse"):
        f(valid[:-1], tdc)
    with pytest.raises(ValueError, match="one-dimensional"):
        f(valid[None, :], tdc[None, :])
    i = int(np.argmax(valid))
    bad = tdc.astype(np.int64)
    bad[i] = -3
    with pytest.raises(ValueError, match=rf"`tdc\[{i}\]` = -3"):
        f(valid, bad)
    bad[i] = 1 << 40
    with pytest.raises(ValueError, match=rf"`tdc\[{i}\]` = {1 << 40}"):
        f(valid, bad)


def test_an_empty_frame_and_haar_designs_are_refused(small):
    with pytest.raises(ValueError, match="empty frame"):
        small.dft(np.zeros(0, bool), np.zeros(0, np.int32))
    text = (ROOT / "scenes" / "default.toml").read_text()
    text = text.replace("duration_s = 1.0", f"pulses = {1 << 17}")
    text = text.replace('mode = "fourier"', 'mode = "haar"').replace("rom_depth = 20000 ", "rom_depth = 16384 ")
    with pytest.warns(UserWarning, match="probe section is ignored"):
        haar = tofprobe.Design.from_toml_text(text)
    v, t = haar.simulate_scene()
    for call in (lambda: haar.dft(v, t), lambda: haar.float_sd(v, t), haar.noise_floor, haar.ntf):
        with pytest.raises(ValueError, match="fourier"):
            call()
    # Haar widths still resolve: 2^(U+1) − 1 registers of W bits.
    w = haar.widths()
    assert w["bits_per_frame"] == w["registers"] * w["width"]


def test_the_overhead_benchmark_runs_and_prints_its_keys():
    """scripts/python-bench.py, as docs/performance.md runs it, on a short frame: its JSON
    keys and the ordering of its figures (the compact-code call skips the decoding)."""
    script = ROOT / "scripts" / "python-bench.py"
    out = subprocess.run([sys.executable, str(script), "--pulses", "200000", "--repeat", "3",
                          "--json"], capture_output=True, text=True, check=True).stdout
    r = json.loads(out)
    assert r["pulses"] == 200_000 and r["repeat"] == 3
    for key in ["python_seconds", "library_seconds", "library_codes_seconds"]:
        # 2·10^5 pulses at ≈ 1–3 ns each: milliseconds, far from zero and from a second.
        assert 1e-5 < r[key] < 0.5, (key, r[key])
    assert np.isfinite(r["python_overhead_percent"]) and isinstance(r["pass"], bool)
    assert r["pass"] == (r["python_overhead_percent"] <= 5)
