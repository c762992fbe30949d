// tofprobe array testbench for Icarus (docs/pixel-contract.md "Array"; crates/cosim/src/array.rs).
// Replays the array's golden vectors (tofprobe_array::rtl_vectors) through the generated
// `tofprobe_array`: each cycle it presents the detections of the next pulse when the model
// says the pixels sample (`pulse_o`), compares the ports with the model's before the rising
// edge, and ends with one line
//   TOFPROBE-COSIM-DONE cycles=<n> mismatches=<n>
// preceded, for each of the first 10 mismatches, by
//   TOFPROBE-MISMATCH cycle=<c> signal=<name> expected=<hex> actual=<hex>
// With AR_RESET_AT defined (array_params.vh) rst is high in that cycle too: a reset in
// the middle of the first frame. Compile with -I VECDIR -DAR_VECTORS=\"VECDIR/\" (where array_params.vh, array_stim.hex and
// array_expect.hex are) and run from the RTL directory (a deep probe ROM's $readmemh); without
// AR_VECTORS the vector files are read from the working directory (an array set's
// verification kit, where `tofprobe rtl` writes this file beside the RTL and the vectors:
// testbench/README.md "The array set's verification kit"). Verilog-2005: runs under Icarus
// and under `verilator --binary` (its timing support drives the #1 steps).
`timescale 1ns / 1ps
`include "array_params.vh"
`ifdef AR_VECTORS
`define AR_FILE(name) {`AR_VECTORS, name}
`else
`define AR_FILE(name) name
`endif
// The inputs: the pixels, or with a superpixel (G > 1) their SPADs (AR_NS = AR_NP * G * G).
`ifndef AR_NS
`define AR_NS `AR_NP
`endif
module array_tb;
    reg clk;
    reg rst;
    reg [`AR_NS - 1:0] valid;
    reg [`AR_NS * `AR_T - 1:0] tdc;
    wire pulse_o;
    wire ready;
    wire ro_valid;
    wire [`AR_B - 1:0] ro_data;
    `AR_TOP dut (
        .clk(clk),
        .rst(rst),
        .valid(valid),
        .tdc(tdc),
        .pulse_o(pulse_o),
        .ready(ready),
        .ro_valid(ro_valid),
        .ro_data(ro_data)
    );
    reg [`AR_NS * (`AR_T + 1) - 1:0] stim [0:`AR_PULSES - 1];
    reg [63:0] expect_mem [0:4 * `AR_CYCLES - 1];
    integer cycle;
    integer pidx;
    integer mism;
    reg [`AR_B - 1:0] want;
    task report(input [8 * 8 - 1:0] name, input [63:0] e, input [63:0] a);
        begin
            if (mism < 10)
                $display("TOFPROBE-MISMATCH cycle=%0d signal=%0s expected=%h actual=%h", cycle, name, e, a);
            mism = mism + 1;
        end
    endtask
    initial begin
        $readmemh(`AR_FILE("array_stim.hex"), stim);
        $readmemh(`AR_FILE("array_expect.hex"), expect_mem);
        clk = 1'b0;
        rst = 1'b1;
        valid = 0;
        tdc = 0;
        pidx = 0;
        mism = 0;
        for (cycle = 0; cycle < `AR_CYCLES; cycle = cycle + 1) begin
`ifdef AR_RESET_AT
            // A reset in the middle of the first frame: one cycle of rst (the vectors'
            // AR_RESET_AT), the array restarts.
            rst = (cycle < 2) || (cycle == `AR_RESET_AT);
`else
            rst = (cycle < 2);
`endif
            if (expect_mem[4 * cycle][0]) begin
                {tdc, valid} = stim[pidx];
                pidx = pidx + 1;
            end else begin
                valid = 0;
                tdc = 0;
            end
            #1;
            want = expect_mem[4 * cycle + 3][`AR_B - 1:0];
            // Before the first edge (cycle 0) the registers hold no value yet: compared
            // from the cycle after the first reset edge.
            if (cycle > 0 && pulse_o !== expect_mem[4 * cycle][0]) report("pulse_o", expect_mem[4 * cycle], {63'd0, pulse_o});
            if (cycle > 0 && ready !== expect_mem[4 * cycle + 1][0]) report("ready", expect_mem[4 * cycle + 1], {63'd0, ready});
            if (cycle > 0 && ro_valid !== expect_mem[4 * cycle + 2][0]) report("ro_valid", expect_mem[4 * cycle + 2], {63'd0, ro_valid});
            if (cycle > 0 && ro_data !== want) report("ro_data", {{(64 - `AR_B){1'b0}}, want}, {{(64 - `AR_B){1'b0}}, ro_data});
            clk = 1'b1;
            #1;
            clk = 1'b0;
            #1;
        end
        $display("TOFPROBE-COSIM-DONE cycles=%0d mismatches=%0d", `AR_CYCLES, mism);
        $finish;
    end
endmodule
