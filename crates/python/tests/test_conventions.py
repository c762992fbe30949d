"""Python conventions (issue 44): a path is a path and text is text, overrides through the
one resolution, exceptions under tofprobe.Error, progress= and threads=, missing extras
named, docstrings that say what the letters are, no benchmark helper in the API."""

import os
import sys

import numpy as np
import pytest

import tofprobe
from conftest import ROOT


def test_a_path_with_an_equals_sign_is_a_path(tmp_path, small_text):
    # "runs/a=3/plate.toml" used to be parsed as TOML text because it holds "=".
    folder = tmp_path / "runs" / "a=3"
    folder.mkdir(parents=True)
    path = folder / "plate.toml"
    path.write_text(small_text)
    for p in (path, str(path)):
        d = tofprobe.Design.from_toml(p)
        assert d.origin == str(path) and d.summary()["frame_pulses"] == 200_000
    # TOML text given as a path is not guessed: a FileNotFoundError pointing at the text call.
    with pytest.raises(FileNotFoundError, match="from_toml_text"):
        tofprobe.Design.from_toml(small_text)
    with pytest.raises(TypeError, match="str or os.PathLike"):
        tofprobe.Design.from_toml(b"scenes/default.toml")
    assert tofprobe.Design.from_toml_text(small_text).origin == "<TOML text>"


def test_a_directory_or_unreadable_path_names_itself(tmp_path):
    with pytest.raises(tofprobe.FileError, match=str(tmp_path)) as e:
        tofprobe.Design.from_toml(tmp_path)
    assert isinstance(e.value, OSError) and "directory" in str(e.value)
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)  # not a regular file: refused before any read (no hang)
    with pytest.raises(tofprobe.FileError, match="pipe.toml"):
        tofprobe.Design.from_toml(fifo)


def test_the_exceptions_share_one_base_and_the_builtins():
    assert issubclass(tofprobe.ConfigError, ValueError)
    assert issubclass(tofprobe.InputError, ValueError)
    assert issubclass(tofprobe.ToolMissingError, RuntimeError)
    assert issubclass(tofprobe.FileError, OSError)
    assert issubclass(tofprobe.errors.FileNotFoundError, FileNotFoundError)
    for e in (tofprobe.ConfigError, tofprobe.InputError, tofprobe.ToolMissingError,
              tofprobe.FileError, tofprobe.errors.FileNotFoundError):
        assert issubclass(e, tofprobe.Error)
    with pytest.raises(tofprobe.ConfigError, match="binz"):
        tofprobe.Design.from_toml_text("[pixel]\nbinz = 3\n")


def test_overrides_go_through_the_one_resolution(small, small_text):
    four = small.with_overrides({"pixel.bins": 4})
    want = tofprobe.Design.from_toml_text(small_text.replace("bins = 16", "bins = 4"))
    a, b = four.summary(), want.summary()
    assert a.pop("origin").endswith("with overrides of pixel.bins")
    b.pop("origin")
    assert a == b and len(a["bins"]) == 4
    assert len(small.summary()["bins"]) == 16, "the design itself is unchanged"
    # None removes a key: back to the whole acquisition as the frame.
    seeded = small.with_overrides({"acquisition.seed": 7, "pixel.frame_pulses": None})
    assert seeded.summary()["seed"] == 7


@pytest.mark.parametrize("bad, key", [
    ({"pixel.binz": 4}, "`pixel.binz` is not a key of [pixel]"),
    ({"pixle.bins": 4}, "`pixle` is not a section"),
    ({"pixel.bins": "many"}, "`pixel.bins` = \"many\" has the wrong type"),
    ({"pixel.bins": 0}, "bins"),
])
def test_a_bad_override_names_the_key_and_no_generated_line(small, bad, key):
    with pytest.raises(tofprobe.ConfigError) as e:
        small.with_overrides(bad)
    assert key in str(e.value) and "line " not in str(e.value), str(e.value)


def test_a_dict_with_an_unknown_key_names_it_without_lines():
    import tomllib

    doc = tomllib.loads((ROOT / "scenes" / "default.toml").read_text())
    doc["pixel"]["binz"] = 3
    with pytest.raises(tofprobe.ConfigError) as e:
        tofprobe.Design.from_dict(doc)
    assert "`pixel.binz` is not a key of [pixel]" in str(e.value) and "line" not in str(e.value)
    del doc["pixel"]["binz"]
    doc["scene"]["depth_mm"] = None
    with pytest.raises(tofprobe.ConfigError, match=r"`scene\.depth_mm` is None"):
        tofprobe.Design.from_dict(doc)


def test_a_missing_tool_is_a_tool_missing_error(small, tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(tofprobe.ToolMissingError, match="yosys"):
        small.size()


def test_progress_callbacks_and_threads(array_text, small):
    calls = []
    valid, tdc = small.simulate_scene(progress=lambda done, total: calls.append((done, total)))
    n = small.summary()["frame_pulses"]
    assert calls and calls[-1] == (n, n)
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))
    one_thread = small.simulate_scene(threads=1)
    assert (one_thread[0] == valid).all() and (one_thread[1] == tdc).all()
    arr = tofprobe.Design.from_toml_text(array_text)
    seen = []
    whole = arr.simulate_array(progress=lambda d, t: seen.append((d, t)))
    rows, cols = arr.summary()["array"]
    total = rows * cols * arr.summary()["frame_pulses"]
    assert seen[-1] == (total, total)
    again = arr.simulate_array(tiles=3, threads=1)
    np.testing.assert_array_equal(again["registers"], whole["registers"])
    with pytest.raises(tofprobe.InputError, match="threads"):
        small.simulate_scene(threads=0)
    with pytest.raises(TypeError, match="progress"):
        small.simulate_scene(progress="yes")
    # An exception in the callback stops the call and is raised.
    def boom(done, total):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        arr.simulate_array(progress=boom)


def test_progress_true_is_a_tqdm_bar_or_names_the_extra(small, monkeypatch, capsys):
    pytest.importorskip("tqdm")
    small.simulate_scene(progress=True)
    assert "simulate_scene" in capsys.readouterr().err
    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    with pytest.raises(ImportError, match=r"tofprobe\[progress\]"):
        small.simulate_scene(progress=True)


@pytest.mark.parametrize("module, extra, hidden", [
    ("tofprobe.plot", "plot", "matplotlib"),
    ("tofprobe.dask", "dask", "distributed"),
])
def test_a_missing_extra_is_an_import_error_naming_it(monkeypatch, module, extra, hidden):
    import importlib

    monkeypatch.setitem(sys.modules, hidden, None)
    monkeypatch.delitem(sys.modules, module, raising=False)
    with pytest.raises(ImportError, match=rf"tofprobe\[{extra}\]"):
        importlib.import_module(module)


def test_the_docstrings_say_what_the_letters_are_and_the_rom_cost():
    doc = tofprobe.Design.__doc__
    for words in ["B is the number of Fourier bins", "W the width in bits",
                  "N the pulses of one frame", "L the depth of the probe ROM",
                  "G the register's fractional bits"]:
        assert words in doc, words
    assert "1.4 s" in doc and "1.4 s" in tofprobe.Design.run_pixel.__doc__


def test_no_benchmark_helper_in_the_public_api():
    public = {n for n in dir(tofprobe.Design) if not n.startswith("_")}
    assert not any("time" in n or "bench" in n for n in public), public


@pytest.mark.parametrize("value, says", [("sse9", "allowed"), ("", None)])
def test_a_bad_forced_isa_is_refused_at_import(value, says):
    # TOFPROBE_ISA is read once, at import, as the CLI reads it at start-up: a name that is
    # no ISA is an error naming the variable, never a panic inside a kernel; empty is unset.
    import subprocess
    env = dict(os.environ, TOFPROBE_ISA=value)
    p = subprocess.run([sys.executable, "-c", "import tofprobe; print('imported')"],
                       env=env, capture_output=True, text=True, timeout=60)
    if says is None:
        assert p.returncode == 0 and "imported" in p.stdout, p.stderr
        return
    assert p.returncode != 0 and "PanicException" not in p.stderr, p.stderr
    assert "TOFPROBE_ISA" in p.stderr and "sse9" in p.stderr and says in p.stderr, p.stderr
