// tofprobe plain-Verilog self-checking testbench (Verilog-2005; see testbench/README.md).
//
// Replays golden vectors through the generated top: per cycle it sets the inputs with clk
// low, samples the outputs, raises clk, then compares the register writes of that edge
// (the pixel's write-enable vector `we` and the register values at the falling edge after
// it, where every register file kind holds them: a latch register file passes a write
// while clk is low) with trace.hex, the output pins with pins.hex (from cycle 1 on) and every readout word with
// readout.hex. It needs a full trace (vectors of short frames). Compile with
//   iverilog -g2005 -I VECDIR -DTB_TOP=tofprobe_top -DTB_VECTORS=\"VECDIR/\" tb.v RTL/*.v
// and run vvp from the RTL directory (the probe ROM's $readmemh file is found there). It
// ends with exactly one line:
//   TOFPROBE-COSIM-DONE cycles=<n> frames=<n> mismatches=<n> seconds=0
// and, under Icarus, exits with status 1 when there was a mismatch. An X on an output pin,
// a readout word or a write enable (a state element reset forgot) is a mismatch.
`timescale 1ns / 1ps
module tb;
`include "tb_params.vh"
    reg clk;
    reg rst;
    reg valid;
    reg [TB_TDC_BITS-1:0] tdc;
    wire pulse_o;
    wire ready;
    wire rd_valid;
    wire [TB_RD_INDEX_BITS-1:0] rd_index;
    wire [TB_WIDTH-1:0] rd_data;

    `TB_TOP dut (
        .clk(clk), .rst(rst), .valid(valid), .tdc(tdc), .pulse_o(pulse_o),
        .ready(ready), .rd_valid(rd_valid), .rd_index(rd_index), .rd_data(rd_data)
    );

    reg [19:0] stim [0:TB_STIMULUS_LINES];
    reg [63:0] ro [0:TB_READOUT_WORDS];
    reg [127:0] trace [0:TB_TRACE_EVENTS];
    reg [127:0] pins [0:TB_PIN_EVENTS];

    integer c, np, tp, pp, ro_i, r, mism, frames, cur;
    // The cycle a mismatch is reported at, and the edge whose writes are still to be
    // observed (at the next falling edge) with its enables and reset.
    integer rep_c, cw;
    reg [63:0] we_w;
    reg rst_w, rst_s, pending;
    reg [19:0] s;
    reg p_s, ready_s, rd_valid_s;
    reg [TB_RD_INDEX_BITS-1:0] rd_index_s;
    reg [63:0] rd_data_s, we, v;
    reg [63:0] exp_data;
    reg exp_ready, exp_valid;
    reg [11:0] exp_index;
    reg reported;
    // Register values after the previous edge (a register without its enable keeps them).
    reg [63:0] y_held [0:TB_REGISTERS-1];
    reg held_known;

    task mismatch;
        input [8*24-1:0] signal;
        input integer reg_index;
        input [63:0] expected;
        input [63:0] actual;
        begin
            mism = mism + 1;
            if (!reported) begin
                reported = 1;
                if (reg_index >= 0)
                    $display("TOFPROBE-MISMATCH cycle=%0d pulse=%0d signal=y[%0d] expected=%0h actual=%0h",
                             rep_c, cur, reg_index, expected, actual);
                else
                    $display("TOFPROBE-MISMATCH cycle=%0d pulse=%0d signal=%0s expected=%0h actual=%0h",
                             rep_c, cur, signal, expected, actual);
            end
        end
    endtask

    // The register writes of edge `cw`, observed at the falling edge after it.
    task observe_writes;
        begin
            rep_c = cw;
            for (r = 0; r < TB_REGISTERS; r = r + 1) begin
                if (we_w[r]) begin
                    v = dut.u_pixel.y[r];
                    if (tp >= TB_TRACE_EVENTS || trace[tp][127:80] != cw || trace[tp][79:64] != r)
                        mismatch("write", r, 64'hffffffffffffffff, v);
                    else if (trace[tp][63:0] !== v)
                        mismatch("write", r, trace[tp][63:0], v);
                    if (tp < TB_TRACE_EVENTS && trace[tp][127:80] == cw) tp = tp + 1;
                end
            end
            // An expected write that did not happen at this edge.
            while (tp < TB_TRACE_EVENTS && trace[tp][127:80] == cw) begin
                mismatch("write", trace[tp][79:64], trace[tp][63:0], 64'hffffffffffffffff);
                tp = tp + 1;
            end
            // A register whose write enable is low keeps its value: a write `we` does not
            // show (a clock gate on the wrong enable, a gate that glitches) fails at its edge.
            for (r = 0; r < TB_REGISTERS; r = r + 1) begin
                v = dut.u_pixel.y[r];
                if (held_known && !rst_w && !we_w[r] && v !== y_held[r])
                    mismatch("write", r, 64'hffffffffffffffff, v);
                y_held[r] = v;
            end
            held_known = 1;
        end
    endtask

    initial begin
        if (TB_STIMULUS_LINES > 0) $readmemh({`TB_VECTORS, "stimulus.hex"}, stim, 0, TB_STIMULUS_LINES - 1);
        if (TB_READOUT_WORDS > 0) $readmemh({`TB_VECTORS, "readout.hex"}, ro, 0, TB_READOUT_WORDS - 1);
        if (TB_TRACE_EVENTS > 0) $readmemh({`TB_VECTORS, "trace.hex"}, trace, 0, TB_TRACE_EVENTS - 1);
        if (TB_PIN_EVENTS > 0) $readmemh({`TB_VECTORS, "pins.hex"}, pins, 0, TB_PIN_EVENTS - 1);
        if (TB_TRACE_FROM != 0 || TB_TRACE_TO != TB_CYCLES) begin
            $display("tb: these vectors hold a partial trace; regenerate them for short frames");
            $finish;
        end
        clk = 0; rst = 1; valid = 0; tdc = 0;
        np = 0; tp = 0; pp = 0; ro_i = 0; mism = 0; frames = 0; cur = 0; reported = 0;
        held_known = 0;
        pending = 0;
        rep_c = 0;
        exp_ready = 0; exp_valid = 0; exp_index = 0; exp_data = 0;
        for (c = 0; c < TB_CYCLES; c = c + 1) begin
            rst = (c < 2);
            s = (np < TB_STIMULUS_LINES) ? stim[np] : 20'd0;
            valid = s[16];
            tdc = s[TB_TDC_BITS-1:0];
            #1;
            if (pending) observe_writes;
            pending = 0;
            rep_c = c;
            p_s = pulse_o;
            ready_s = ready;
            rd_valid_s = rd_valid;
            rd_index_s = rd_index;
            rd_data_s = rd_data;
            // rst wins (the pixel's: the directed top also resets it in the middle of a
            // frame); any X on the write enables (a register reset forgot) is a mismatch.
            rst_s = dut.u_pixel.rst;
            we = rst_s ? 64'd0 : dut.u_pixel.we;
            if (c >= 1 && ^we === 1'bx) mismatch("we", -1, 64'd0, we);
            clk = 1;
            #1;
            if (p_s) begin
                cur = np;
                np = np + 1;
            end
            if (c >= 1) begin
                if (pp < TB_PIN_EVENTS && pins[pp][127:80] == c) begin
                    exp_ready = pins[pp][76];
                    exp_valid = pins[pp][77];
                    exp_index = pins[pp][75:64];
                    exp_data = pins[pp][63:0];
                    pp = pp + 1;
                end
                if (ready_s !== exp_ready) mismatch("ready", -1, exp_ready, ready_s);
                else if (rd_valid_s !== exp_valid) mismatch("rd_valid", -1, exp_valid, rd_valid_s);
                else if (rd_index_s !== exp_index) mismatch("rd_index", -1, exp_index, rd_index_s);
                else if (rd_data_s !== exp_data) mismatch("rd_data", -1, exp_data, rd_data_s);
                if (rd_valid_s) begin
                    if (ro_i >= TB_READOUT_WORDS || rd_data_s !== ro[ro_i])
                        mismatch("readout", -1, ro[ro_i], rd_data_s);
                    ro_i = ro_i + 1;
                    if (rd_index_s == TB_REGISTERS) frames = frames + 1;
                end
            end
            cw = c;
            we_w = we;
            rst_w = rst_s;
            pending = 1;
            clk = 0;
        end
        if (pending) begin
            #1;
            observe_writes;
        end
        rep_c = c;
        if (ro_i != TB_READOUT_WORDS) mismatch("readout_words", -1, TB_READOUT_WORDS, ro_i);
        $display("TOFPROBE-COSIM-DONE cycles=%0d frames=%0d mismatches=%0d seconds=0", TB_CYCLES, frames, mism);
`ifdef __ICARUS__
        // vvp's exit status says FAIL too (a plain $finish exits 0 whatever happened).
        if (mism != 0) $finish_and_return(1);
`endif
        $finish;
    end
endmodule
