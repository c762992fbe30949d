"""cocotb testbench of an array set (issue 42's verification kit): replays the golden
vectors beside the RTL (array_stim.hex per pulse, array_expect.hex per cycle) through the
array module, with the cycle discipline of testbench/array_tb.v (inputs set with clk low,
the next pulse's detections when the model's `pulse_o` says the pixels sample; outputs
compared before the rising edge from cycle 1 on), checks every port every cycle and names
the first mismatch by cycle, pixel (r, c), frame, word and signal.
"""

import os

import cocotb
from cocotb.triggers import Timer

from vectors import ArrayVectors


@cocotb.test()
async def array_golden_vectors(dut):
    v = ArrayVectors.load(os.environ["TOFPROBE_ARRAY_SET"])
    p = v.params
    cycles = p["CYCLES"]
    assert len(v.expect) == cycles, f"array_expect.hex: {len(v.expect)} cycles, AR_CYCLES {cycles}"
    assert len(v.stimulus) == p["PULSES"], f"array_stim.hex: {len(v.stimulus)} lines"
    dut.clk.value = 0
    dut.rst.value = 1
    dut.valid.value = 0
    dut.tdc.value = 0
    pidx = 0
    first = None
    mismatches = 0
    for c in range(cycles):
        e = v.expect[c]
        dut.rst.value = 1 if c < 2 else 0
        if e.pulse_o and pidx < len(v.stimulus):
            valid, tdc = v.stimulus[pidx]
            pidx += 1
        else:
            valid, tdc = 0, 0
        dut.valid.value = valid
        dut.tdc.value = tdc
        await Timer(1, unit="step")
        got = (dut.pulse_o.value, dut.ready.value, dut.ro_valid.value, dut.ro_data.value)
        dut.clk.value = 1
        await Timer(1, unit="step")
        dut.clk.value = 0
        await Timer(1, unit="step")
        # Before the first edge (cycle 0) the registers hold no value yet.
        if c < 1:
            continue
        want = (e.pulse_o, e.ready, e.ro_valid, e.ro_data)
        for name, w, g in zip(("pulse_o", "ready", "ro_valid", "ro_data"), want, got):
            ok = g.is_resolvable and int(g) == w
            if not ok:
                mismatches += 1
                if first is None:
                    a = f"{int(g):x}" if g.is_resolvable else str(g)
                    first = (f"TOFPROBE-MISMATCH cycle={c} {v.where(c)} signal={name} "
                             f"expected={w:x} actual={a}")
                    dut._log.error(first)
                break
    dut._log.info("TOFPROBE-COCOTB-DONE cycles=%d mismatches=%d", cycles, mismatches)
    assert mismatches == 0, f"{mismatches} mismatching cycle(s); first: {first}"
