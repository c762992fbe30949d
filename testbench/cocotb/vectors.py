"""Reader of tofprobe's golden vector files (testbench/README.md, crates/rtlgen/src/vectors.rs).

Every file is plain text: one hexadecimal value per line, most significant digit first;
lines starting with `//` or `#` (the generator's header) are comments.
"""

import re
from dataclasses import dataclass
from pathlib import Path


def read_hex(path):
    """The values of a vector file, as ints, in order."""
    out = []
    for line in Path(path).read_text().splitlines():
        s = line.strip()
        if not s or s.startswith("//") or s.startswith("#"):
            continue
        out.append(int(s, 16))
    return out


def read_params(path):
    """`localparam integer TB_<KEY> = value;` lines of tb_params.vh, as {KEY: value}."""
    params = {}
    for m in re.finditer(r"localparam\s+integer\s+TB_(\w+)\s*=\s*(-?\d+)\s*;", Path(path).read_text()):
        params[m.group(1)] = int(m.group(2))
    return params


@dataclass(frozen=True)
class Pins:
    """One output-pin change: from cycle `cycle` on, the pins hold these values."""

    cycle: int
    ready: int
    rd_valid: int
    rd_index: int
    rd_data: int

    @staticmethod
    def decode(v):
        # 32 digits: cycle (12) flags (1: bit 0 ready, bit 1 rd_valid) rd_index (3) rd_data (16)
        return Pins(
            cycle=v >> 80,
            ready=(v >> 76) & 1,
            rd_valid=(v >> 77) & 1,
            rd_index=(v >> 64) & 0xFFF,
            rd_data=v & ((1 << 64) - 1),
        )


@dataclass
class Vectors:
    params: dict
    stimulus: list  # (valid, tdc) per pulse
    readout: list  # raw W-bit words: per frame R registers then the status word
    pins: list  # Pins, in cycle order

    @staticmethod
    def load(vec_dir):
        d = Path(vec_dir)
        stim = [((v >> 16) & 1, v & 0xFFFF) for v in read_hex(d / "stimulus.hex")]
        return Vectors(
            params=read_params(d / "tb_params.vh"),
            stimulus=stim,
            readout=read_hex(d / "readout.hex"),
            pins=[Pins.decode(v) for v in read_hex(d / "pins.hex")],
        )
