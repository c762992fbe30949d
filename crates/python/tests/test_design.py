"""The design calls: the one resolution from Python (default, TOML file or text, JSON,
pickle), its summary against the configuration's own numbers, and refusals that name the
key."""

import pickle

import pytest

import tofprobe
from conftest import ROOT


def test_default_summary_holds_the_resolved_values():
    s = tofprobe.Design.default().summary()
    # scenes/default.toml: 10^7 pulses at 10 MHz, B = 16, L = 20 000 (bins on k·500 Hz,
    # the 4.5 kHz tone at k = 9), 80 codes of 5 ps → T = 7, S = 5, F = 8, A = 2, C = 16.
    assert s["mode"] == "fourier"
    assert (s["frame_pulses"], s["pulses"], s["rom_depth"]) == (10**7, 10**7, 20_000)
    assert len(s["bins"]) == 16 and s["bins"][0] == 9
    assert s["frequencies_hz"] == [k * 10e6 / 20_000 for k in s["bins"]]
    assert s["frequencies_hz"][0] == 4500.0
    assert (s["tdc_bits"], s["shift"], s["frac_bits"]) == (7, 5, 8)
    assert (s["adders"], s["cycles_per_pulse"], s["registers"]) == (2, 16, 32)
    # W from the sizing of the scene's codes (`tofprobe simulate --json` reports the same
    # width_bits: test_pixel.py), at most T + 1 + F + ⌈log2 N⌉ = 16 + 24 = 40.
    assert s["width"] == 39
    assert s["tdc_lsb_mm"] == pytest.approx(0.75, rel=1e-12)
    assert s["array"] is None and s["superpixel"] is None and s["seed"] == 1


def test_a_superpixel_array_summary_counts_pixels_and_names_g(array_text):
    # The 4 × 3 SPAD test array as 4 × 4 SPADs in 2 × 2 superpixels: 2 × 2 pixels, G = 2.
    text = array_text.replace("cols = 3", "cols = 4\nsuperpixel = 2")
    s = tofprobe.Design.from_toml_text(text).summary()
    assert s["array"] == (2, 2) and s["superpixel"] == 2
    assert tofprobe.Design.from_toml_text(array_text).summary()["superpixel"] == 1


def test_the_cli_prints_the_same_resolution(cli):
    import subprocess

    out = subprocess.run([cli, "config"], capture_output=True, text=True, check=True).stdout
    s = tofprobe.Design.default().summary()
    assert f"{s['pulses']} pulses at {int(s['laser_rate_hz'])} Hz" in out
    assert f"= {s['tdc_bits']} bits" in out


def test_path_text_json_and_pickle_give_the_same_design(tmp_path, small_text):
    path = tmp_path / "small.toml"
    path.write_text(small_text)
    from_path = tofprobe.Design.from_toml(path)
    from_str_path = tofprobe.Design.from_toml(str(path))
    from_text = tofprobe.Design.from_toml_text(small_text)
    assert from_path.origin == str(path) and from_text.origin == "<TOML text>"
    for other in (from_str_path, from_text):
        a, b = other.summary(), from_path.summary()
        a.pop("origin"), b.pop("origin")
        assert a == b
    assert from_path.summary()["frame_pulses"] == 200_000
    again = tofprobe.Design.from_json(from_path.to_json())
    assert again.to_json() == from_path.to_json()
    unpickled = pickle.loads(pickle.dumps(from_path))
    assert unpickled.to_json() == from_path.to_json()


def test_to_toml_reads_back_to_the_same_resolution():
    for name in ["default.toml", "plate-mode.toml", "fig12-step.toml"]:
        d = tofprobe.Design.from_toml(ROOT / "scenes" / name)
        back = tofprobe.Design.from_toml_text(d.to_toml())
        a, b = d.summary(), back.summary()
        a.pop("origin"), b.pop("origin")
        assert a == b, name


def test_an_unknown_key_is_refused_naming_it(small_text):
    bad = small_text.replace("[pixel]\n", "[pixel]\nbinz = 3\n")
    with pytest.raises(ValueError, match="binz"):
        tofprobe.Design.from_toml_text(bad)


def test_an_out_of_range_value_is_refused_naming_the_field(small_text):
    bad = small_text.replace("order = 3 ", "order = 9 ")
    assert bad != small_text
    with pytest.raises(ValueError, match="order") as e:
        tofprobe.Design.from_toml_text(bad)
    assert "9" in str(e.value)
    # A wrong type names the key too.
    with pytest.raises(ValueError, match="bins"):
        tofprobe.Design.from_toml_text(small_text.replace("bins = 16", 'bins = "many"'))


def test_a_missing_file_is_refused_naming_the_path(tmp_path):
    missing = tmp_path / "nope.toml"
    for path in (missing, str(missing)):
        with pytest.raises(FileNotFoundError, match="nope.toml") as e:
            tofprobe.Design.from_toml(path)
        assert isinstance(e.value, tofprobe.Error) and isinstance(e.value, OSError)
    with pytest.raises(TypeError, match="str or os.PathLike"):
        tofprobe.Design.from_toml(42)


def test_help_documents_every_call():
    doc = tofprobe.Design.__doc__
    assert "resolved once" in doc
    for name in ["default", "from_toml", "from_toml_text", "from_dict", "with_overrides",
                 "from_json", "to_toml", "to_json", "summary", "simulate_scene", "run_pixel",
                 "spectrum", "probe_rom", "simulate_array", "tile_rects", "run_tile",
                 "merge_tiles", "dft", "float_sd", "noise_floor", "ntf", "widths", "size"]:
        method = getattr(tofprobe.Design, name)
        assert method.__doc__ and len(method.__doc__) > 40, name
    assert "valid, tdc" in tofprobe.Design.run_pixel.__text_signature__


def test_the_installed_stubs_list_exactly_the_native_calls():
    import ast
    import pathlib

    package = pathlib.Path(tofprobe.__file__).parent
    assert (package / "py.typed").is_file()
    tree = ast.parse((package / "_native.pyi").read_text())
    (cls,) = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Design"]
    stubbed = {n.name for n in cls.body if isinstance(n, ast.FunctionDef)}
    native = {n for n in dir(tofprobe.Design) if not n.startswith("_")} | {
        "__reduce__", "_restore", "_time_library_run_pixel"}
    assert stubbed == native
    summary = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Summary"][0]
    keys = {n.target.id for n in summary.body if isinstance(n, ast.AnnAssign)}
    assert keys == set(tofprobe.Design.default().summary())
