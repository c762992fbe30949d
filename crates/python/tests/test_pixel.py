"""The pixel from Python: the frame's photons, the registers, the spectrum and the ROM,
checked against the CLI (`tofprobe simulate`), against a closed form built from the ROM,
against the array model, and refusing bad input with errors that name the argument."""

import json
import subprocess
import threading
import time

import numpy as np
import pytest

import tofprobe
from conftest import default_text


def cli_spectrum(cli, path):
    out = subprocess.run([cli, "simulate", "--json", str(path)], capture_output=True,
                         text=True, check=True).stdout
    return json.loads(out)


@pytest.mark.parametrize("seed", [1, 7])
def test_registers_give_the_cli_spectrum_bit_for_bit(cli, tmp_path, seed):
    # `tofprobe simulate` runs the same frame (the record's first N pulses) through the
    # same pixel and prints the phasors of its registers; its JSON floats round-trip
    # exactly, so equal registers give equal floats and any other register differs.
    path = tmp_path / "small.toml"
    path.write_text(default_text(200_000, seed=seed))
    sim = cli_spectrum(cli, path)
    d = tofprobe.Design.from_toml_text(default_text(200_000, seed=1))
    valid, tdc = d.simulate_scene(seed=seed)
    assert int(valid.sum()) == sim["detections"]
    f, amp, ph = d.spectrum(d.run_pixel(valid, tdc))
    bins = sim["bit_true"]["bins"]
    assert d.summary()["width"] == sim["bit_true"]["width_bits"]
    assert f.tolist() == [b["frequency_hz"] for b in bins]
    assert amp.tolist() == [b["amplitude_um"] for b in bins]
    assert ph.tolist() == [b["phase_deg"] for b in bins]
    # The 4.5 kHz, 0.1 mm tone reads back near 100 µm (noise ≈ 10–100 µm at N = 2·10^5).
    assert 50 < amp[0] < 200


def test_scene_photons(small):
    valid, tdc = small.simulate_scene()
    n = small.summary()["frame_pulses"]
    assert valid.dtype == np.bool_ and tdc.dtype == np.uint16
    assert valid.shape == tdc.shape == (n,)
    # ρ_s = 1, ρ_b = 0: nearly every pulse detects (the window clips the jitter's far
    # tails: ±30 mm = ±4σ, p ≈ 6·10^−5 → ~13 misses of 2·10^5).
    assert 0 < n - valid.sum() < 60
    assert (tdc[~valid] == 0).all()
    # Depth 30 mm, LSB 0.75 mm: codes = floor(depth / LSB) average 40 − 1/2; σ_mean =
    # 10 codes / √N = 0.022, tolerance 7σ.
    assert abs(tdc[valid].mean() - 39.5) < 0.15
    again, tdc2 = small.simulate_scene(seed=1)
    assert (again == valid).all() and (tdc2 == tdc).all()
    other = small.simulate_scene(seed=2)[1]
    assert (other != tdc).mean() > 0.5


def test_registers_match_the_closed_form_of_a_constant_code(small):
    # A constant code c: the first detection primes the prefilter (x = c, nothing added),
    # then every later pulse — detected or held — adds ±c·2^G by its ROM bit, so register
    # j = c·2^G·Σ_{i > p0} rom[i mod L, j], p0 the first detection.
    s = small.summary()
    n, g = s["frame_pulses"], s["register_frac_bits"]
    rom = small.probe_rom().astype(np.int64)
    rng = np.random.default_rng(3)
    for c in [1, 40, 127]:
        valid = rng.random(n) < 0.3
        valid[:5] = False
        p0 = int(np.argmax(valid))
        tdc = np.where(valid, c, 9999)  # an invalid pulse's code is ignored
        want = c * 2**g * rom[np.arange(p0 + 1, n) % rom.shape[0]].sum(axis=0)
        got = small.run_pixel(valid, tdc)
        assert got.dtype == np.int64 and got.shape == (s["registers"],)
        np.testing.assert_array_equal(got, want)
    assert (small.run_pixel(np.zeros(n, bool), np.zeros(n, np.int64)) == 0).all()


def test_probe_rom_and_spectrum_of_zero(small):
    rom = small.probe_rom()
    s = small.summary()
    assert rom.dtype == np.int8 and rom.shape == (s["rom_depth"], s["registers"])
    assert set(np.unique(rom).tolist()) == {-1, 1}
    f, amp, ph = small.spectrum(np.zeros(s["registers"], np.int64))
    assert f.tolist() == s["frequencies_hz"]
    assert (amp == 0).all() and (ph == 0).all()
    with pytest.raises(ValueError, match="readout words"):
        small.spectrum(np.zeros(s["registers"] - 2, np.int64))
    with pytest.raises(TypeError, match="registers"):
        small.spectrum(np.zeros(s["registers"], np.float64))


def test_array_pixels_are_run_pixel_of_their_streams(array_text, cli, tmp_path):
    d = tofprobe.Design.from_toml_text(array_text)
    out = d.simulate_array()
    rows, cols = d.summary()["array"]
    k = d.summary()["registers"]
    b = len(d.summary()["bins"])
    assert out["registers"].shape == (rows, cols, k) and out["registers"].dtype == np.int64
    assert out["amplitude_um"].shape == out["phase_deg"].shape == (b, rows, cols)
    for r in range(rows):
        for c in range(cols):
            valid, tdc = d.simulate_scene(pixel=(r, c))
            assert out["detections"][r, c] == valid.sum()
            regs = d.run_pixel(valid, tdc)
            np.testing.assert_array_equal(regs, out["registers"][r, c])
            _, amp, ph = d.spectrum(regs)
            np.testing.assert_array_equal(amp, out["amplitude_um"][:, r, c])
            np.testing.assert_array_equal(ph, out["phase_deg"][:, r, c])
    # The CLI's array set holds the same registers.
    path = tmp_path / "plate.toml"
    path.write_text(array_text)
    subprocess.run([cli, "simulate", str(path), "--out", str(tmp_path / "set")],
                   capture_output=True, check=True)
    np.testing.assert_array_equal(np.load(tmp_path / "set" / "registers.npy"), out["registers"])
    # A single-pixel design has no array.
    with pytest.raises(ValueError, match=r"\[array\]"):
        tofprobe.Design.default().simulate_array()
    with pytest.raises(ValueError, match="outside"):
        d.simulate_scene(pixel=(rows, 0))


def test_bad_input_names_the_argument(small):
    valid, tdc = small.simulate_scene()
    n = valid.size
    with pytest.raises(TypeError, match="`valid` must be a bool array"):
        small.run_pixel(valid.astype(np.int8), tdc)
    with pytest.raises(TypeError, match="`tdc` must be an integer array"):
        small.run_pixel(valid, tdc.astype(np.float64))
    with pytest.raises(ValueError, match="one code per pulse"):
        small.run_pixel(valid, tdc[:-1])
    with pytest.raises(ValueError, match="one-dimensional"):
        small.run_pixel(valid.reshape(2, -1), tdc.reshape(2, -1))
    i = int(np.argmax(valid))
    for code in [-1, 128]:  # T = 7 bits: codes 0 ..= 127
        bad = tdc.astype(np.int32)  # a signed dtype, to hold −1 (simulate_scene's is uint16)
        bad[i] = code
        with pytest.raises(ValueError, match=rf"`tdc\[{i}\]` = {code} .* 0 ..= 127"):
            small.run_pixel(valid, bad)
    with pytest.raises(ValueError, match="frame_pulses"):
        small.run_pixel(np.ones(n + 1, bool), np.zeros(n + 1, np.int32))
    # Lists, other integer dtypes, strided and misaligned arrays read the same codes.
    want = small.run_pixel(valid, tdc)
    for codes in [
        tdc.astype(np.uint8),
        tdc.astype(np.int32),
        tdc.astype(np.int64),
        tdc.astype(np.uint64),
    ]:
        np.testing.assert_array_equal(small.run_pixel(valid, codes), want)
    raw = np.zeros(2 * n + 1, np.uint8)[1:].view(np.int16)  # an odd address
    raw[:] = tdc
    assert not raw.flags.aligned
    np.testing.assert_array_equal(small.run_pixel(valid, raw), want)
    strided = np.zeros(2 * n, np.int32)
    strided[::2] = tdc
    np.testing.assert_array_equal(small.run_pixel(valid, strided[::2]), want)
    short = small.run_pixel(list(valid[:100]), list(tdc[:100]))
    np.testing.assert_array_equal(short, small.run_pixel(valid[:100], tdc[:100]))


def test_haar_design_has_no_rom():
    # A Haar frame is a power of two (the signs are the pulse counter's bits).
    text = default_text(1 << 17).replace('mode = "fourier"', 'mode = "haar"')
    text = text.replace("rom_depth = 20000 ", "rom_depth = 16384 ")
    # The default's [probe] section is ignored in Haar mode, and said so as the CLI says it
    # on stderr: a UserWarning naming `probe` and `pixel.mode`.
    with pytest.warns(UserWarning, match=r"probe.*pixel\.mode|pixel\.mode.*probe"):
        d = tofprobe.Design.from_toml_text(text)
    s = d.summary()
    assert s["mode"] == "haar" and s["registers"] == 2 ** (s["haar_scales"] + 1) - 1
    valid, tdc = d.simulate_scene()
    regs = d.run_pixel(valid, tdc)
    assert regs.shape == (s["registers"],) and (regs != 0).any()
    with pytest.raises(ValueError, match="fourier"):
        d.probe_rom()
    with pytest.raises(ValueError, match="fourier"):
        d.spectrum(regs)


def test_the_gil_is_released_while_rust_computes():
    d = tofprobe.Design.default()  # N = 10^7 pulses: the call takes tens of ms
    n = d.summary()["frame_pulses"]
    valid, tdc = np.ones(n, bool), np.full(n, 40, np.int32)
    d.run_pixel(valid[:10], tdc[:10])  # the ROM, generated once, outside the timing
    stamps, stop = [], threading.Event()

    def tick():
        while not stop.is_set():
            stamps.append(time.perf_counter())
            time.sleep(0.0005)

    t = threading.Thread(target=tick)
    t.start()
    time.sleep(0.01)
    t0 = time.perf_counter()
    # Several calls: one 10^7-pulse call takes only ≈ 15 ms on idle cores, too short
    # beside the ticker's own sleeps to tell a held GIL from a released one.
    for _ in range(6):
        d.run_pixel(valid, tdc)
    t1 = time.perf_counter()
    stop.set()
    t.join()
    inside = [s for s in stamps if t0 <= s <= t1]
    gaps = np.diff([t0, *inside, t1])
    # Holding the GIL the thread would stall for each whole call (a gap ≈ (t1 − t0)/6);
    # with it released it ticks throughout (gaps of ~1 ms, generously 10 % of the run).
    assert t1 - t0 > 0.05, "the calls are too short to show the GIL"
    assert gaps.max() < 0.1 * (t1 - t0), (gaps.max(), t1 - t0)
