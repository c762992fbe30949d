"""cocotb testbench: replays the golden vectors through the generated top (tofprobe_top).

The same cycle discipline as testbench/tb.v and the contract: per cycle set the inputs with
clk low, let them settle, sample the outputs, raise clk. Checks every output pin against
pins.hex (from cycle 1 on) and every readout word against readout.hex, and reports the
first mismatch by cycle, signal, expected and actual. Register writes (trace.hex) are
checked by tb.v and the Verilator harness, which see the pixel's internals.
"""

import os

import cocotb
from cocotb.triggers import Timer

from vectors import Vectors


@cocotb.test()
async def golden_vectors(dut):
    v = Vectors.load(os.environ["TOFPROBE_VECTORS"])
    p = v.params
    cycles, registers = p["CYCLES"], p["REGISTERS"]
    assert len(v.stimulus) == p["STIMULUS_LINES"]
    assert len(v.readout) == p["READOUT_WORDS"]
    dut.clk.value = 0
    dut.rst.value = 1
    dut.valid.value = 0
    dut.tdc.value = 0
    np_, pp, ro_i, frames = 0, 0, 0, 0
    exp = None
    first = None
    mismatches = 0
    for c in range(cycles):
        dut.rst.value = 1 if c < 2 else 0
        valid, tdc = v.stimulus[np_] if np_ < len(v.stimulus) else (0, 0)
        dut.valid.value = valid
        dut.tdc.value = tdc
        await Timer(1, unit="step")
        pulse = int(dut.pulse_o.value)
        # Before the first reset edge (cycle 0) the pins are undefined (X): not compared.
        pins = (dut.ready.value, dut.rd_valid.value, dut.rd_index.value, dut.rd_data.value)
        dut.clk.value = 1
        await Timer(1, unit="step")
        dut.clk.value = 0
        if pulse:
            np_ += 1
        if c < 1:
            continue
        if not all(x.is_resolvable for x in pins):
            mismatches += 1
            first = first or f"cycle={c} pins not 0/1: {[str(x) for x in pins]}"
            continue
        got = tuple(int(x) for x in pins)
        if pp < len(v.pins) and v.pins[pp].cycle == c:
            e = v.pins[pp]
            exp = (e.ready, e.rd_valid, e.rd_index, e.rd_data)
            pp += 1
        for name, e_, g in zip(("ready", "rd_valid", "rd_index", "rd_data"), exp, got):
            if e_ != g:
                mismatches += 1
                first = first or f"cycle={c} signal={name} expected={e_:x} actual={g:x}"
                break
        if got[1]:
            want = v.readout[ro_i] if ro_i < len(v.readout) else None
            if want != got[3]:
                mismatches += 1
                first = first or f"cycle={c} signal=readout[{ro_i}] expected={want} actual={got[3]:x}"
            ro_i += 1
            if got[2] == registers:
                frames += 1
    if ro_i != len(v.readout):
        mismatches += 1
        first = first or f"readout words: expected {len(v.readout)}, got {ro_i}"
    dut._log.info("TOFPROBE-COCOTB-DONE cycles=%d frames=%d mismatches=%d", cycles, frames,
                  mismatches)
    assert mismatches == 0, f"{mismatches} mismatches; first: {first}"
    assert frames == p["FRAMES"], f"frames: expected {p['FRAMES']}, got {frames}"
