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


def read_defines(path):
    """`\\`define AR_<KEY> value` lines of an array's array_params.vh, as {KEY: value}
    (integers where they are, e.g. {"NP": 6, "TOP": "tofprobe_array"})."""
    out = {}
    for m in re.finditer(r"^`define\s+AR_(\w+)\s+(\S+)\s*$", Path(path).read_text(), re.M):
        k, v = m.group(1), m.group(2)
        out[k] = int(v) if v.isdigit() else v
    return out


def data_lines(path):
    """The non-comment, non-empty lines of a vector file."""
    for line in Path(path).read_text().splitlines():
        s = line.strip()
        if s and not s.startswith("//") and not s.startswith("#"):
            yield s


@dataclass(frozen=True)
class ArrayPins:
    """The array's ports the model expects in one cycle (array_expect.hex: one line each)."""

    pulse_o: int
    ready: int
    ro_valid: int
    ro_data: int


@dataclass
class ArrayVectors:
    """An array's golden vectors (crates/rtlgen/src/array_vectors.rs): in an array set's
    verification kit, beside the RTL, or in a `tofprobe vectors` directory."""

    params: dict
    stimulus: list  # per pulse: (valid bits, tdc bits) of every pixel (or SPAD)
    expect: list  # ArrayPins per cycle
    readout: list  # (frame, row, col, [words]) in stream order

    @staticmethod
    def load(vec_dir):
        d = Path(vec_dir)
        params = read_defines(d / "array_params.vh")
        ns = params.get("NS", params["NP"])
        stim = []
        for s in data_lines(d / "array_stim.hex"):
            v = int(s, 16)
            stim.append((v & ((1 << ns) - 1), v >> ns))
        expect = []
        for s in data_lines(d / "array_expect.hex"):
            p, r, v, data = s.split()
            expect.append(ArrayPins(int(p, 16), int(r, 16), int(v, 16), int(data, 16)))
        readout = []
        for s in data_lines(d / "readout.txt"):
            head, words = s.split(":")
            f, r, c = (int(x) for x in head.split())
            readout.append((f, r, c, [int(w, 16) for w in words.split()]))
        return ArrayVectors(params=params, stimulus=stim, expect=expect, readout=readout)

    def where(self, cycle):
        """The readout beat on the port at `cycle` (or the next one): "frame F pixel (r, c)
        word w", from the order of readout.txt and the beats of array_expect.hex."""
        beats = [c for c, e in enumerate(self.expect) if e.ro_valid]
        if not beats or not self.readout:
            return "no readout"
        per_pixel = len(beats) // len(self.readout)
        words = len(self.readout[0][3])
        idx = sum(1 for b in beats if b < cycle)
        idx = min(idx, len(beats) - 1)
        f, r, c, _ = self.readout[min(idx // max(per_pixel, 1), len(self.readout) - 1)]
        w = (idx % max(per_pixel, 1)) * words // max(per_pixel, 1)
        state = "beat of" if self.expect[cycle].ro_valid else "before the beat of"
        return f"{state} frame {f} pixel ({r}, {c}) word {w}"
