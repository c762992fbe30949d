"""Shared fixtures: the repository, small designs (the default with a short frame, a
small [array]) and the `tofprobe` CLI binary the bit-identity tests compare with."""

import os
import pathlib
import shutil

import pytest

import tofprobe

ROOT = pathlib.Path(__file__).resolve().parents[3]


def default_text(pulses: int, seed: int = 1) -> str:
    """The embedded default with a frame of `pulses` pulses and `seed`."""
    text = (ROOT / "scenes" / "default.toml").read_text()
    assert "duration_s = 1.0" in text and "seed = 1\n" in text
    return text.replace("duration_s = 1.0", f"pulses = {pulses}").replace(
        "seed = 1\n", f"seed = {seed}\n"
    )


@pytest.fixture(scope="session")
def small_text() -> str:
    """The default with N = 200 000 pulses (10 periods of its L = 20 000 ROM)."""
    return default_text(200_000)


@pytest.fixture(scope="session")
def small(small_text) -> tofprobe.Design:
    return tofprobe.Design.from_toml_text(small_text)


@pytest.fixture(scope="session")
def array_text() -> str:
    """scenes/plate-mode.toml shrunk to 4 × 3 pixels of 80 mm and 40 000 pulses."""
    text = (ROOT / "scenes" / "plate-mode.toml").read_text()
    for old, new in [
        ("pulses = 1000000", "pulses = 40000"),
        ("rows = 32", "rows = 4"),
        ("cols = 32", "cols = 3"),
        ("mm_per_pixel = 10.0", "mm_per_pixel = 80.0"),
    ]:
        assert old in text, old
        text = text.replace(old, new)
    return text


@pytest.fixture(scope="session")
def cli() -> str:
    """The `tofprobe` binary: $TOFPROBE_CLI, else target/release/tofprobe, else on PATH.
    Missing: a failure under CI (TOFPROBE_REQUIRE_TOOLS=1), a skip otherwise."""
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    for candidate in [os.environ.get("TOFPROBE_CLI"), target / "release" / "tofprobe"]:
        if candidate and pathlib.Path(candidate).is_file():
            return str(candidate)
    found = shutil.which("tofprobe")
    if found:
        return found
    message = "the tofprobe CLI binary is missing (cargo build --release -p tofprobe-cli)"
    if os.environ.get("TOFPROBE_REQUIRE_TOOLS") == "1":
        pytest.fail(message)
    pytest.skip(message)
